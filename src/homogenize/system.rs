//! The periodic cell as a linear system on the periodic [`Discretization`]: slave nodes are
//! eliminated master–slave, u_slave = u_master + (M(x_slave) − M(x_master)) E, with the six
//! macroscopic quantities E as driver DOFs; element and contact matrices become Tᵀ K T, so the
//! reduced system stays symmetric positive definite; the reactions of the drivers are the stress
//! resultants times the cell area. Closed contacts (gap ≤ 0) enter as stick springs
//! (K_N + K_T^st, plus the rolling resistance K_R): the elastic moduli A^elas of thesis (5.5).
//! Contacts are searched with the periodic images, so crossings on the boundary count.

use super::stick_system::StickSystem;
use crate::cell::{anchor_node, check_percolation, pair_boundary_nodes, Periodicity};
use crate::constraints::Discretization;
use crate::contact::{ContactSet, ContactSide};
use crate::model::Model;
use crate::Error;
use std::ops::Deref;

/// Wall-clock seconds of [`PeriodicSystem::new`].
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct SetupTimings {
    /// Boundary pairing, contact search with the periodic images, percolation check.
    pub contacts: f64,
    /// Numbering and element/contact blocks on generalized nodes.
    pub blocks: f64,
    /// The sparsity pattern with its slot maps.
    pub pattern: f64,
}

/// A periodic cell's system: its pairing and geometry, the anchor, and the
/// [`StickSystem`] on the periodic discretization (reached through `Deref`).
#[derive(Clone, Debug)]
pub struct PeriodicSystem {
    /// Pairing and geometry.
    pub periodicity: Periodicity,
    /// The elements and closed contacts on the periodic discretization.
    pub system: StickSystem,
    /// The node whose translations are fixed.
    pub anchor: usize,
    /// How long building it took.
    pub timings: SetupTimings,
}

impl Deref for PeriodicSystem {
    type Target = StickSystem;

    fn deref(&self) -> &StickSystem {
        &self.system
    }
}

/// Node pairs joined by the contact pairs `which` (for connectivity checks), with the period
/// shift of the second side's image.
fn contact_links(
    model: &Model,
    set: &ContactSet,
    which: impl Iterator<Item = usize>,
) -> Vec<([usize; 2], [i32; 2])> {
    let node = |s: ContactSide| match s {
        ContactSide::Node(n) => n,
        ContactSide::Point { element, .. } => model.elements()[element].nodes[0],
    };
    which
        .map(|i| {
            let o = &set.origins[i];
            ([node(o.sides[0]), node(o.sides[1])], o.shift)
        })
        .collect()
}

/// What every cell problem starts from: the boundary pairing, the contacts (searched with the
/// periodic images), the percolation check — through the closed contacts only when
/// `closed_only`, otherwise through every contact — and the anchor node.
pub(crate) fn prepare_cell(
    model: &Model,
    closed_only: bool,
) -> Result<(Periodicity, ContactSet, usize), Error> {
    let periodicity = pair_boundary_nodes(model)?;
    if !model.supports.is_empty() {
        return Err(Error::InvalidOption(
            "a periodic cell is driven by macroscopic strains: remove its [[supports]]".into(),
        ));
    }
    let set = ContactSet::build_with(model, Some(&periodicity))?;
    let links = contact_links(
        model,
        &set,
        (0..set.pairs.len()).filter(|&i| !closed_only || set.pairs[i].gap <= 0.0),
    );
    check_percolation(model, &periodicity, &links)?;
    let anchor = anchor_node(model, &periodicity)?;
    Ok((periodicity, set, anchor))
}

impl PeriodicSystem {
    /// Pairs the boundary, finds the contacts, checks percolation, numbers the unknowns and
    /// builds the pattern.
    pub fn new(model: &Model) -> Result<Self, Error> {
        Self::build(model, true)
    }

    /// [`PeriodicSystem::new`] without the anchor: the translations of every node are
    /// unknowns, so the matrix is singular with the three rigid translations as its null
    /// space (what [`crate::check`] verifies).
    pub fn unanchored(model: &Model) -> Result<Self, Error> {
        Self::build(model, false)
    }

    fn build(model: &Model, anchored: bool) -> Result<Self, Error> {
        let clock = std::time::Instant::now();
        let (periodicity, set, anchor) = prepare_cell(model, true)?;
        let contacts = clock.elapsed().as_secs_f64();
        let discretization =
            Discretization::periodic(model, &periodicity, &[0.0; 6], anchored.then_some(anchor));
        let (system, built) = StickSystem::build(model, discretization, &set)?;
        Ok(PeriodicSystem {
            periodicity,
            system,
            anchor,
            timings: SetupTimings {
                contacts,
                blocks: built.blocks,
                pattern: built.pattern,
            },
        })
    }
}
