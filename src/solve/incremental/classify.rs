//! Classification of every contact after a solve: the return mapping of each, chattering
//! contacts held, and the contacts whose state, slip direction, sliding force or Coulomb bound
//! the solve did not match.

use super::options::{
    BOUND_TOLERANCE, EARLY_EQUILIBRIUM_TOLERANCE, EARLY_SETTLE_AFTER, EQUILIBRIUM_TOLERANCE,
    SETTLE_BY_EQUILIBRIUM_AFTER, STALLED_EQUILIBRIUM_TOLERANCE,
};
use super::return_mapping::{classify, gather, hold, unsettled_force, Trial};
use super::StickSlip;
use crate::contact::{ContactState, Friction};
use rayon::prelude::*;

/// The trials of every contact and the contacts they change.
pub(super) struct Classified {
    pub trials: Vec<Trial>,
    pub changed: Vec<usize>,
    /// No changed contact moved its state, slip direction or sign of N: they only carry
    /// sliding forces off the law.
    pub forces_only: bool,
}

/// The strict equilibrium residuals of an increment's settled-looking state iterations, to
/// tell a fixed point still converging from one at its round-off floor.
#[derive(Default)]
pub(super) struct ResidualFloor {
    seen: Vec<(usize, f64)>,
}

impl ResidualFloor {
    /// Records the residual `r` of state iteration `iteration`; whether it stalled there: at
    /// most [`STALLED_EQUILIBRIUM_TOLERANCE`] and not below half the smaller of the two
    /// iterations before (both recorded).
    fn stalled(&mut self, iteration: usize, r: f64) -> bool {
        let at = |k: usize| {
            self.seen
                .iter()
                .find(|(i, _)| *i + k == iteration)
                .map(|&(_, v)| v)
        };
        let before = at(1).zip(at(2)).map(|(a, b)| a.min(b));
        self.seen.push((iteration, r));
        before.is_some_and(|best| r <= STALLED_EQUILIBRIUM_TOLERANCE && r >= 0.5 * best)
    }
}

impl StickSlip<'_, '_, '_> {
    /// [`StickSlip::classify`], with the changes dropped when, from state iteration
    /// [`SETTLE_BY_EQUILIBRIUM_AFTER`] on, they only say that sliding forces are off the law
    /// (no state, slip direction or sign of N moved) while the increment to load factor
    /// `alpha` is in equilibrium with the law's forces to [`EQUILIBRIUM_TOLERANCE`], or its
    /// residual stalled within twice that (`floor`); from [`EARLY_SETTLE_AFTER`] on, to
    /// [`EARLY_EQUILIBRIUM_TOLERANCE`]: the displacements are then a solution,
    /// whatever the linearization still says (on large cells the per-contact test asks the
    /// tangential displacements for more digits than the solves carry).
    pub(super) fn classify_settled(
        &self,
        alpha: f64,
        iteration: usize,
        floor: &mut ResidualFloor,
    ) -> Classified {
        let mut classified = self.classify();
        if iteration >= EARLY_SETTLE_AFTER
            && !classified.changed.is_empty()
            && classified.forces_only
        {
            let r = self.equilibrium_residual(alpha, &classified.trials);
            let settled = if iteration < SETTLE_BY_EQUILIBRIUM_AFTER {
                r <= EARLY_EQUILIBRIUM_TOLERANCE
            } else {
                r <= EQUILIBRIUM_TOLERANCE || floor.stalled(iteration, r)
            };
            if settled {
                classified.changed.clear();
            }
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
        // Per contact: whether it moved (state, slip direction, sign of N) and whether its
        // sliding force lags the law (off its direction or k⊥ spring, or a bound that moved).
        let change = |i: usize| {
            let t = &trials[i];
            let held = contacts.held(i);
            let sliding = t.state == ContactState::Slip && !held;
            let moved = contacts.switched(i, t, pairs[i].penalty_tangent, setup.direction_tol)
                // A sliding Coulomb contact crossed N = 0, where its bound's slope jumps (the
                // consistent tangent).
                || (contacts.consistent_coulomb()
                    && sliding
                    && contacts.compressed[i] != (t.normal_force > 0.0));
            let lags = (!held
                && unsettled_force(
                    t,
                    contacts.directions[i],
                    {
                        let b = contacts.block(i);
                        (b.direction, b.k_perp, contacts.perpendicular[i].1)
                    },
                    // The bound's slope is in the block of a Coulomb contact only.
                    contacts.frozen[i]
                        .filter(|_| matches!(contacts.friction_of(i), Friction::Coulomb { .. }))
                        .map(|f| f.bound),
                ))
                // A sliding Coulomb contact's bound moved (the fixed point on the bounds, or a
                // symmetric step of the consistent tangent).
                || ((setup.bound_fixed_point || contacts.symmetric_step)
                    && sliding
                    && (t.bound - contacts.bounds[i]).abs()
                        > BOUND_TOLERANCE * t.bound.max(contacts.bounds[i]));
            (moved, lags)
        };
        let mut forces_only = true;
        let changed: Vec<usize> = (0..pairs.len())
            .filter(|&i| {
                let (moved, lags) = change(i);
                forces_only &= !moved;
                moved || lags
            })
            .collect();
        Classified {
            trials,
            changed,
            forces_only,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::ResidualFloor;

    /// The strict residuals of the L non-woven's increment 93 under e22 (seed 2), iterations
    /// 8–10, traced: a floor, settled at the third; a residual still falling by more than half
    /// per iteration is not, nor one above 2·10⁻⁸, nor one without two iterations before it.
    #[test]
    fn a_floor_stalls_and_a_falling_residual_does_not() {
        let mut floor = ResidualFloor::default();
        assert!(!floor.stalled(8, 1.093e-8));
        assert!(!floor.stalled(9, 1.091e-8));
        assert!(floor.stalled(10, 1.050e-8));

        let mut falling = ResidualFloor::default();
        assert!(!falling.stalled(8, 1e-7));
        assert!(!falling.stalled(9, 4e-8));
        assert!(!falling.stalled(10, 1.5e-8));

        let mut above = ResidualFloor::default();
        for (i, r) in [(8, 3e-8), (9, 3e-8)] {
            assert!(!above.stalled(i, r));
        }
        assert!(!above.stalled(10, 3e-8));

        let mut gap = ResidualFloor::default();
        assert!(!gap.stalled(8, 1.1e-8));
        assert!(!gap.stalled(10, 1.1e-8));
        assert!(!gap.stalled(11, 1.1e-8), "iteration 9 missing");
        assert!(gap.stalled(12, 1.1e-8));
    }
}
