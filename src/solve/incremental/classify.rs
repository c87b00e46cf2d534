//! Classification of every contact after a solve: the return mapping of each, chattering
//! contacts held, and the contacts whose state, slip direction, sliding force or Coulomb bound
//! the solve did not match.

use super::options::{BOUND_TOLERANCE, EQUILIBRIUM_TOLERANCE, SETTLE_BY_EQUILIBRIUM_AFTER};
use super::return_mapping::{classify, gather, hold, unsettled_force, Trial};
use super::StickSlip;
use crate::contact::ContactState;
use rayon::prelude::*;

/// The trials of every contact and the contacts they change.
pub(super) struct Classified {
    pub trials: Vec<Trial>,
    pub changed: Vec<usize>,
}

impl StickSlip<'_, '_> {
    /// [`StickSlip::classify`], with the changes dropped when, from state iteration
    /// [`SETTLE_BY_EQUILIBRIUM_AFTER`] on, they only say that sliding forces are off the law
    /// (no state, slip direction or sign of N moved) while the increment to load factor
    /// `alpha` is in equilibrium with the law's forces to [`EQUILIBRIUM_TOLERANCE`]: the
    /// displacements are then a solution, whatever the linearization still says (on large
    /// cells the per-contact test asks the tangential displacements for more digits than the
    /// solves carry).
    pub(super) fn classify_settled(&self, alpha: f64, iteration: usize) -> Classified {
        let mut classified = self.classify();
        if iteration < SETTLE_BY_EQUILIBRIUM_AFTER || classified.changed.is_empty() {
            return classified;
        }
        let (contacts, pairs) = (&self.contacts, &self.setup.pairs);
        let force_only = |i: usize| {
            let t = &classified.trials[i];
            t.state == contacts.states[i]
                && !contacts.switched(i, t, pairs[i].penalty_tangent, self.setup.direction_tol)
                && !(contacts.consistent_coulomb()
                    && contacts.compressed[i] != (t.normal_force > 0.0))
        };
        if classified.changed.iter().all(|&i| force_only(i))
            && self.equilibrium_residual(alpha, &classified.trials) <= EQUILIBRIUM_TOLERANCE
        {
            classified.changed.clear();
        }
        classified
    }

    /// The return mapping of every contact at the current displacements.
    pub(super) fn classify(&self) -> Classified {
        let (setup, contacts, q) = (&self.setup, &self.contacts, &self.q[..]);
        let pairs = &setup.pairs;
        let trials: Vec<Trial> = pairs
            .par_iter()
            .with_min_len(256)
            .enumerate()
            .map(|(i, p)| {
                let t = classify(
                    p,
                    setup.law,
                    &gather(q, &p.jump.nodes),
                    &contacts.slips[i],
                    (contacts.states[i], contacts.directions[i]),
                    setup.length_tol,
                    setup.fixed[i],
                );
                if contacts.held(i) {
                    hold(t, contacts.states[i], contacts.directions[i])
                } else {
                    t
                }
            })
            .collect();
        let changed: Vec<usize> = (0..pairs.len())
            .filter(|&i| {
                let t = &trials[i];
                let held = contacts.held(i);
                contacts.switched(i, t, pairs[i].penalty_tangent, setup.direction_tol)
                    || (!held
                        && unsettled_force(t, contacts.directions[i], contacts.perpendicular[i]))
                    // A sliding Coulomb contact crossed N = 0, where its bound's slope jumps
                    // (the consistent tangent).
                    || (contacts.consistent_coulomb()
                        && t.state == ContactState::Slip
                        && !held
                        && contacts.compressed[i] != (t.normal_force > 0.0))
                    // A sliding Coulomb contact's bound moved (the fixed point on the bounds, or
                    // a symmetric step of the consistent tangent).
                    || ((setup.bound_fixed_point || contacts.symmetric_step)
                        && t.state == ContactState::Slip
                        && !held
                        && (t.bound - contacts.bounds[i]).abs()
                            > BOUND_TOLERANCE * t.bound.max(contacts.bounds[i]))
            })
            .collect();
        Classified { trials, changed }
    }
}
