//! The values of the stick/slip system's matrix, kept as the reference factorization's plus
//! the blocks of the contacts changed since. A₀'s own values are not copied: only those of the
//! slots a changed contact touches are saved, when it first changes, to restore them from.

use super::super::ContactChange;
use crate::assembly::{add_contact_block, Pattern, NO_SLOT};
use crate::contact::ContactPair;

/// Marks a contact whose slots are not saved.
const NOT_SAVED: usize = usize::MAX;

/// The matrix values of the current state iteration, and A₀'s values of the slots of the
/// contacts changed since the reference factorization A₀.
pub(super) struct MatrixValues {
    /// The current matrix's values in the pattern's slots.
    pub values: Vec<f64>,
    /// Per contact: where its slots' A₀ values start in `saved` (`NOT_SAVED`: not yet).
    saved_at: Vec<usize>,
    /// A₀'s values of the saved contacts' slots, each contact's in the order of
    /// [`Pattern::extra_slots`] (slots shared by two contacts are saved twice, alike).
    saved: Vec<f64>,
    /// The contacts whose blocks `values` has on top of A₀'s (None: no reference).
    changed_since_reference: Option<Vec<usize>>,
}

impl MatrixValues {
    /// No values (the first assembly writes them) and no reference yet.
    pub fn empty() -> Self {
        Self::new(Vec::new())
    }

    /// The values `values` and no reference yet.
    pub fn new(values: Vec<f64>) -> Self {
        MatrixValues {
            values,
            saved_at: Vec::new(),
            saved: Vec::new(),
            changed_since_reference: None,
        }
    }

    /// Makes the current values A₀'s: a new reference factorization was made of them.
    pub fn set_reference(&mut self) {
        self.saved_at.clear();
        self.saved.clear();
        self.changed_since_reference = Some(Vec::new());
    }

    /// Takes `reference` as A₀'s values and the current ones (a shared factorization adopted).
    pub fn adopt_reference(&mut self, reference: &[f64]) {
        self.values.clear();
        self.values.extend_from_slice(reference);
        self.set_reference();
    }

    /// Forgets the reference: the values are assembled anew.
    pub fn drop_reference(&mut self) {
        self.saved_at.clear();
        self.saved.clear();
        self.changed_since_reference = None;
    }

    /// Brings `values` to A₀'s values plus the blocks of `changes` when `behind`: the slots of
    /// the contacts changed before restored from their saved A₀ values, then the slots of
    /// contacts changing for the first time saved and the changes added. The stick/slip
    /// iteration calls it only where the matrix is read, so iterations that neither check a
    /// residual nor factorize skip it.
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
        let Some(before) = self.changed_since_reference.take() else {
            unreachable!("changes are only made against a reference")
        };
        for c in before {
            self.restore(pattern, c);
        }
        // Every slot is A₀'s now: a contact changing for the first time saves its own.
        if self.saved_at.len() != pairs.len() {
            self.saved_at = vec![NOT_SAVED; pairs.len()];
        }
        for ch in changes {
            self.save(pattern, ch.contact);
        }
        self.changed_since_reference = Some(changes.iter().map(|ch| ch.contact).collect());
        for ch in changes {
            let pair = &pairs[ch.contact];
            let slots = pattern.extra_slots(ch.contact);
            add_contact_block(pair, &pair.block_of(&ch.stiffness), slots, &mut self.values);
        }
    }

    /// Saves contact `c`'s slots' values (A₀'s) unless saved.
    fn save(&mut self, pattern: &Pattern, c: usize) {
        if self.saved_at[c] != NOT_SAVED {
            return;
        }
        self.saved_at[c] = self.saved.len();
        let values = &self.values;
        self.saved.extend(pattern.extra_slots(c).iter().map(|slot| {
            if slot == NO_SLOT {
                0.0
            } else {
                values[slot as usize]
            }
        }));
    }

    /// Gives contact `c`'s slots their saved A₀ values.
    fn restore(&mut self, pattern: &Pattern, c: usize) {
        let start = self.saved_at[c];
        let slots = pattern.extra_slots(c);
        for (slot, &v) in slots.iter().zip(&self.saved[start..start + slots.len()]) {
            if slot != NO_SLOT {
                self.values[slot as usize] = v;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    // A periodic non-woven cell of 60 fibers: contacts sharing nodes, and so slots.
    use crate::assembly::test_system as system;
    use crate::contact::BlockCoefficients;
    use nalgebra::Vector6;

    /// A change of contact `c` (a normal and a tangential spring, by `scale`).
    fn change(c: usize, scale: f64) -> ContactChange {
        let mut stiffness = BlockCoefficients::zeros();
        stiffness[(0, 0)] = scale * (1.0 + c as f64);
        stiffness[(1, 1)] = 0.5 * scale;
        ContactChange {
            contact: c,
            stiffness,
            load: Vector6::zeros(),
        }
    }

    /// After any sequence of change sets — contacts leaving, coming back, new ones, many
    /// sharing slots — the values are A₀'s plus the current set's blocks, bit for bit as
    /// adding them to a copy of A₀ (the restore writes saved values, it subtracts nothing).
    #[test]
    fn catching_up_gives_the_reference_plus_the_current_changes() {
        let sys = system();
        let (pattern, pairs) = (&sys.pattern, &sys.contacts);
        assert!(pairs.len() > 20, "{} contacts", pairs.len());
        let reference: Vec<f64> = (0..pattern.nnz()).map(|k| 1.0 + k as f64 * 1e-3).collect();
        let mut m = MatrixValues::new(reference.clone());
        m.set_reference();
        let sets: [Vec<ContactChange>; 4] = [
            (0..10).map(|c| change(c, 1.0)).collect(),
            (5..20).map(|c| change(c, 2.0)).collect(),
            vec![],
            (0..pairs.len())
                .step_by(3)
                .map(|c| change(c, 3.0))
                .collect(),
        ];
        for changes in &sets {
            let mut behind = true;
            m.catch_up(&mut behind, pattern, pairs, Some(changes));
            let mut want = reference.clone();
            for ch in changes {
                let pair = &pairs[ch.contact];
                let slots = pattern.extra_slots(ch.contact);
                add_contact_block(pair, &pair.block_of(&ch.stiffness), slots, &mut want);
            }
            assert!(!behind);
            assert!(m.values == want, "{} changes", changes.len());
        }
        assert!(m.values != reference);
    }
}
