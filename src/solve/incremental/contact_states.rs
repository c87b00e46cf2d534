//! The state of every contact in a stick/slip run: stick, slip or open, slip direction and
//! history, the linearization across the slip direction, the Coulomb bounds of the fixed
//! point, and the switches that detect chatter.

use super::bound_acceleration::BoundAcceleration;
use super::options::{BOUND_RELAXATION_AFTER, CHATTER_SWITCHES, SETTLING_ITERATIONS};
use super::return_mapping::Trial;
use super::setup::Setup;
use crate::contact::{BlockState, ContactPair, ContactState, Friction};
use nalgebra::Vector2;

/// Per contact, what the next system is assembled with and what the increment commits.
pub(super) struct ContactStates {
    pub states: Vec<ContactState>,
    /// Unit slip directions of sliding contacts (tangent basis).
    pub directions: Vec<Vector2<f64>>,
    /// Committed slips s (tangent basis).
    pub slips: Vec<Vector2<f64>>,
    /// Consistent tangent across the slip direction: (k⊥, anchor) per contact.
    pub perpendicular: Vec<(f64, Vector2<f64>)>,
    /// Coulomb fixed point: each contact's bound c + μ max(N, 0) at the last classification,
    /// the load its sliding force is assembled with (empty without Coulomb friction).
    pub bounds: Vec<f64>,
    /// State switches per contact in this increment (chatter detection).
    pub switches: Vec<usize>,
    /// The fixed point's history in this increment.
    pub acceleration: BoundAcceleration,
    friction: Friction,
    bound_fixed_point: bool,
}

impl ContactStates {
    /// Closed pairs in stick (thesis step 1; frictionless ones slide), the others open.
    pub fn new(setup: &Setup<'_>) -> Self {
        let n = setup.pairs.len();
        let friction = setup.friction();
        ContactStates {
            states: setup
                .pairs
                .iter()
                .map(|p| Self::initial(p, friction))
                .collect(),
            directions: vec![Vector2::zeros(); n],
            slips: vec![Vector2::zeros(); n],
            perpendicular: vec![(0.0, Vector2::zeros()); n],
            bounds: match friction {
                Friction::Coulomb { cohesion, .. } => vec![cohesion; n],
                _ => Vec::new(),
            },
            switches: vec![0; n],
            acceleration: BoundAcceleration::default(),
            friction,
            bound_fixed_point: setup.bound_fixed_point,
        }
    }

    /// The state a contact starts the run in.
    pub fn initial(p: &ContactPair, friction: Friction) -> ContactState {
        if p.gap <= 0.0 {
            if friction == Friction::None {
                ContactState::Slip
            } else {
                ContactState::Stick
            }
        } else {
            ContactState::Open
        }
    }

    /// The friction law contact i is assembled with: Tresca at its bound in the Coulomb fixed
    /// point, else the run's.
    pub fn friction_of(&self, i: usize) -> Friction {
        if self.bound_fixed_point {
            Friction::Tresca {
                bound: self.bounds[i],
            }
        } else {
            self.friction
        }
    }

    /// What contact i's block is assembled from.
    pub fn block(&self, i: usize) -> BlockState {
        BlockState {
            state: self.states[i],
            direction: self.directions[i],
            k_perp: self.perpendicular[i].0,
        }
    }

    /// A contact that chattered and is held in its state for the rest of the increment.
    pub fn held(&self, i: usize) -> bool {
        self.switches[i] >= CHATTER_SWITCHES
    }

    /// Takes the trials of a state iteration that did not converge: the `changed` contacts'
    /// states and directions (counting their switches), the relaxed bounds of the Coulomb
    /// fixed point, and every sliding contact's linearization at its trial.
    pub fn advance(
        &mut self,
        pairs: &[ContactPair],
        trials: &[Trial],
        changed: &[usize],
        iteration: usize,
        direction_tol: f64,
    ) {
        for &i in changed {
            // A change of state always counts as a switch, and after SETTLING_ITERATIONS every
            // change does: a contact that does not settle is then held like a chattering one.
            // Before, with the Coulomb fixed point the slip directions and bounds settle
            // together, linearly, so their changes do not count; without it a change of slip
            // direction counts (a sliding force that is off the bound does not).
            let counts = trials[i].state != self.states[i]
                || iteration > SETTLING_ITERATIONS
                || (!self.bound_fixed_point
                    && self.switched(i, &trials[i], pairs[i].penalty_tangent, direction_tol));
            if counts {
                self.switches[i] += 1;
            }
            self.states[i] = trials[i].state;
            self.directions[i] = trials[i].direction;
        }
        if self.bound_fixed_point {
            let sliding: Vec<usize> = (0..trials.len())
                .filter(|&i| trials[i].state == ContactState::Slip)
                .collect();
            let trial: Vec<f64> = trials.iter().map(|t| t.bound).collect();
            let floor = match self.friction {
                Friction::Coulomb { cohesion, .. } => cohesion,
                _ => 0.0,
            };
            // Where the coupling is strong the plain update oscillates: later iterations
            // take half the step.
            let relaxation = if iteration > BOUND_RELAXATION_AFTER {
                0.5
            } else {
                1.0
            };
            let next = self
                .acceleration
                .next(&sliding, &self.bounds, &trial, floor, relaxation);
            for (&i, b) in sliding.iter().zip(next) {
                self.bounds[i] = b;
            }
        }
        for (i, t) in trials.iter().enumerate() {
            // Newton's next iterate linearizes every sliding contact at this trial: its
            // direction too, however small the change (the spring k⊥ is anchored here).
            if t.state == ContactState::Slip && self.states[i] == ContactState::Slip {
                self.directions[i] = t.direction;
            }
            // A held contact slides along its held direction without the spring: the force
            // it is assembled with is then the one `hold` gives it.
            self.perpendicular[i] = if t.state == ContactState::Slip && t.trial_norm > 0.0 {
                (
                    pairs[i].penalty_tangent * t.bound / t.trial_norm,
                    t.relative,
                )
            } else {
                (0.0, Vector2::zeros())
            };
        }
    }

    /// Whether trial `t` switches contact i: another state, or a slip direction that moved by
    /// |Δd| · |u_t − s| above `direction_tol` (see `SLIP_DIRECTION_TOLERANCE`).
    pub fn switched(&self, i: usize, t: &Trial, penalty_tangent: f64, direction_tol: f64) -> bool {
        t.state != self.states[i]
            || (t.state == ContactState::Slip
                && self.friction != Friction::None
                && t.trial_norm / penalty_tangent * (t.direction - self.directions[i]).norm()
                    > direction_tol)
    }
}
