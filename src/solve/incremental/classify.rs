//! Classification of every contact after a solve: the return mapping of each, chattering
//! contacts held, and the contacts whose state, slip direction, sliding force or Coulomb bound
//! the solve did not match.

use super::options::BOUND_TOLERANCE;
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
