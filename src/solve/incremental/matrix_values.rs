//! The values of the stick/slip system's matrix, kept as the reference factorization's plus
//! the blocks of the contacts changed since.

use super::super::ContactChange;
use crate::assembly::{add_contact_block, Pattern, NO_SLOT};
use crate::contact::ContactPair;
use std::sync::Arc;

/// The matrix values of the current state iteration and of the reference factorization A₀.
pub(super) struct MatrixValues {
    /// The current matrix's values in the pattern's slots.
    pub values: Vec<f64>,
    /// A₀'s values (shared with the cell's factorization at rest when that is A₀).
    pub reference: Arc<Vec<f64>>,
    /// When `values` is `reference` plus the blocks of these contacts only: restoring their
    /// slots is enough to start the next iteration from the reference.
    pub changed_since_reference: Option<Vec<usize>>,
}

impl MatrixValues {
    /// The elastic values `k_elastic` and no reference yet (an empty one).
    pub fn new(k_elastic: &[f64]) -> Self {
        MatrixValues {
            values: k_elastic.to_vec(),
            reference: Arc::default(),
            changed_since_reference: None,
        }
    }

    /// Brings `values` to A₀'s values plus the blocks of `changes` when `behind`: the slots of
    /// the contacts changed since the reference restored (every value when unknown), then the
    /// changes added. The stick/slip iteration calls it only where the matrix is read, so
    /// iterations that neither check a residual nor factorize skip it.
    pub fn catch_up(
        &mut self,
        behind: &mut bool,
        pattern: &Pattern,
        pairs: &[ContactPair],
        changes: Option<&[ContactChange]>,
    ) {
        let (true, Some(changes)) = (std::mem::take(behind), changes) else {
            return;
        };
        match self.changed_since_reference.take() {
            Some(contacts) => {
                for i in contacts {
                    for &slot in pattern.extra_slots(i) {
                        if slot != NO_SLOT {
                            self.values[slot as usize] = self.reference[slot as usize];
                        }
                    }
                }
            }
            None => self.values.copy_from_slice(&self.reference[..]),
        }
        self.changed_since_reference = Some(changes.iter().map(|ch| ch.contact).collect());
        for ch in changes {
            let pair = &pairs[ch.contact];
            let slots = pattern.extra_slots(ch.contact);
            add_contact_block(pair, &pair.block_of(&ch.stiffness), slots, &mut self.values);
        }
    }
}
