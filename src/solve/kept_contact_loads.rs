//! The summed loads of the contacts in their base states, kept across load increments.
//!
//! Each increment of the stick/slip iteration starts from the load with every contact stuck
//! (open ones open) at the committed slips. Between increments only the contacts that slid or
//! opened change that load, so the sum is updated at those instead of summed anew.

use crate::contact::ContactState;
use nalgebra::Vector2;

/// Σ of the included contacts' loads, with the state and slip each was summed at.
#[derive(Clone)]
pub(crate) struct KeptContactLoads {
    states: Vec<ContactState>,
    slips: Vec<Vector2<f64>>,
    sum: Vec<f64>,
}

impl KeptContactLoads {
    /// The sum `sum` of the loads at `states` and `slips` (one entry per contact).
    pub(crate) fn new(states: &[ContactState], slips: &[Vector2<f64>], sum: Vec<f64>) -> Self {
        KeptContactLoads {
            states: states.to_vec(),
            slips: slips.to_vec(),
            sum,
        }
    }

    /// Moves every `included` contact whose state or slip differs to `states` and `slips`, in
    /// contact order: `add(i, state, slip, sign, sum)` adds `sign` times contact i's load at
    /// that state and slip into the sum, once with the old pair (−1) and once with the new (+1).
    pub(crate) fn update(
        &mut self,
        states: &[ContactState],
        slips: &[Vector2<f64>],
        included: impl Fn(usize) -> bool,
        mut add: impl FnMut(usize, ContactState, &Vector2<f64>, f64, &mut [f64]),
    ) {
        for i in (0..states.len()).filter(|&i| included(i)) {
            if self.states[i] == states[i] && self.slips[i] == slips[i] {
                continue;
            }
            add(i, self.states[i], &self.slips[i], -1.0, &mut self.sum);
            add(i, states[i], &slips[i], 1.0, &mut self.sum);
            self.states[i] = states[i];
            self.slips[i] = slips[i];
        }
    }

    /// The sum.
    pub(crate) fn sum(&self) -> &[f64] {
        &self.sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Contact i's load is (i + 1) × slip.x on entry i when stuck, zero when open.
    fn add(i: usize, state: ContactState, slip: &Vector2<f64>, sign: f64, sum: &mut [f64]) {
        if state == ContactState::Stick {
            sum[i] += sign * (i as f64 + 1.0) * slip.x;
        }
    }

    fn full(states: &[ContactState], slips: &[Vector2<f64>]) -> Vec<f64> {
        let mut sum = vec![0.0; states.len()];
        for i in 0..states.len() {
            add(i, states[i], &slips[i], 1.0, &mut sum);
        }
        sum
    }

    #[test]
    fn an_update_equals_the_sum_anew_and_skips_excluded_contacts() {
        use ContactState::{Open, Stick};
        let states = [Stick, Stick, Open, Stick];
        let slips = [Vector2::new(0.5, 0.0); 4];
        let mut kept = KeptContactLoads::new(&states, &slips, full(&states, &slips));
        // Contact 0 slid, 1 opened, 2 closed, 3 is excluded (its change is not taken).
        let new_states = [Stick, Open, Stick, Open];
        let new_slips = [
            Vector2::new(2.0, 0.0),
            Vector2::new(0.5, 0.0),
            Vector2::new(0.25, 0.0),
            Vector2::new(0.5, 0.0),
        ];
        kept.update(&new_states, &new_slips, |i| i != 3, add);
        // Small integers times powers of two: every sum exact.
        assert_eq!(kept.sum(), &[2.0, 0.0, 0.75, 2.0]);
        let again = kept.sum().to_vec();
        kept.update(
            &new_states,
            &new_slips,
            |i| i != 3,
            |_, _, _, _, _| panic!("no change"),
        );
        assert_eq!(kept.sum(), &again[..]);
    }
}
