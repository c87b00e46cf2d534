//! The state of every contact in a stick/slip run: stick, slip or open, slip direction and
//! history, the linearization across the slip direction, the Coulomb bounds of the fixed
//! point, and the switches that detect chatter.

use super::bound_acceleration::BoundAcceleration;
use super::factors::ReferenceBlock;
use super::options::{
    BOUND_RELAXATION_AFTER, CHATTER_SWITCHES, FROZEN_ITERATIONS, FROZEN_STIFFNESS_CHANGE,
    FROZEN_TURN, SETTLING_ITERATIONS,
};
use super::return_mapping::Trial;
use super::setup::Setup;
use crate::contact::{BlockState, ContactPair, ContactState, Friction};
use nalgebra::{Vector2, Vector6};

/// Per contact, what the next system is assembled with and what the increment commits.
#[derive(Clone)]
pub(super) struct ContactStates {
    pub states: Vec<ContactState>,
    /// Unit slip directions of sliding contacts (tangent basis).
    pub directions: Vec<Vector2<f64>>,
    /// Committed slips s (tangent basis).
    pub slips: Vec<Vector2<f64>>,
    /// Consistent tangent across the slip direction: (k⊥, anchor) per contact.
    pub perpendicular: Vec<(f64, Vector2<f64>)>,
    /// Sliding contacts whose block keeps the reference factorization's tangent (see
    /// [`FrozenTangent`]); `None`: the consistent tangent at the last trial.
    pub frozen: Vec<Option<FrozenTangent>>,
    /// Coulomb fixed point: each contact's bound c + μ max(N, 0) at the last classification,
    /// the load its sliding force is assembled with (empty without Coulomb friction).
    pub bounds: Vec<f64>,
    /// State switches per contact in this increment (chatter detection).
    pub switches: Vec<usize>,
    /// The fixed point's history in this increment.
    pub acceleration: BoundAcceleration,
    /// The converged bounds of the increment before the last, its load factor and which
    /// contacts slid then (for the bounds' predictor), and the last increment's load factor.
    previous: Option<(f64, Vec<f64>, Vec<bool>)>,
    last_alpha: Option<f64>,
    /// With the consistent Coulomb tangent: per contact, whether its last trial normal force
    /// was positive. The bound c + μ max(N, 0) has the slope μ p_N in compression and none in
    /// tension (a bonded crossing pulled apart slides at its cohesion alone), so a sliding
    /// contact is linearized as Coulomb in the first case and as Tresca at c in the second.
    pub compressed: Vec<bool>,
    /// With the consistent Coulomb tangent: this state iteration assembles sliding Coulomb
    /// contacts at their last trial bounds (Tresca), symmetric — the fixed-point step taken
    /// where the nonsymmetric system cannot be solved on the reference factorization (a
    /// sparse LU of a large cell would need many times its memory). Its bounds are checked
    /// like the fixed point's.
    pub symmetric_step: bool,
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
            frozen: vec![None; n],
            bounds: match friction {
                Friction::Coulomb { cohesion, .. } => vec![cohesion; n],
                _ => Vec::new(),
            },
            switches: vec![0; n],
            acceleration: BoundAcceleration::default(),
            previous: None,
            last_alpha: None,
            compressed: vec![false; n],
            symmetric_step: false,
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
        match self.friction {
            _ if self.bound_fixed_point || self.symmetric_step => Friction::Tresca {
                bound: self.bounds[i],
            },
            Friction::Coulomb { cohesion, .. } if !self.compressed[i] => {
                Friction::Tresca { bound: cohesion }
            }
            friction => friction,
        }
    }

    /// Whether sliding Coulomb contacts carry the consistent tangent μ p_N d nᵀ (Newton on
    /// the bounds) rather than the fixed point on the bounds.
    pub fn consistent_coulomb(&self) -> bool {
        !self.bound_fixed_point && matches!(self.friction, Friction::Coulomb { mu, .. } if mu > 0.0)
    }

    /// Whether contact i's normal force was compressive at its last classification (its
    /// Coulomb bound then grows with it).
    pub fn in_compression(&self, i: usize) -> bool {
        match self.friction {
            Friction::Coulomb { cohesion, .. } if self.bound_fixed_point => {
                self.bounds[i] > cohesion
            }
            _ => self.compressed[i],
        }
    }

    /// What contact i's block is assembled from: the consistent tangent at its last trial,
    /// or the reference's where it is frozen.
    pub fn block(&self, i: usize) -> BlockState {
        match self.frozen[i] {
            Some(f) => BlockState {
                state: self.states[i],
                direction: f.direction,
                k_perp: f.k_perp,
            },
            None => self.consistent_block(i),
        }
    }

    /// The load coefficients of contact i in block state `s` (see
    /// [`ContactPair::load_coefficients`]), a frozen tangent's offset included when it slides.
    pub fn load_coefficients(&self, pair: &ContactPair, i: usize, s: &BlockState) -> Vector6<f64> {
        let phi = pair.load_coefficients(
            s,
            &self.perpendicular[i].1,
            &self.slips[i],
            self.friction_of(i),
        );
        with_frozen_offset(phi, s.state, self.frozen_offset(i))
    }

    /// Contact i's consistent tangent at its last trial (the cell tangent's block).
    pub fn consistent_block(&self, i: usize) -> BlockState {
        BlockState {
            state: self.states[i],
            direction: self.directions[i],
            k_perp: self.perpendicular[i].0,
        }
    }

    /// The tangential force f(q_k) − f̃(q_k) contact i's load lacks when its block is frozen
    /// (see [`FrozenTangent`]): b (d − d_f), zero otherwise.
    pub fn frozen_offset(&self, i: usize) -> Vector2<f64> {
        match self.frozen[i] {
            Some(f) if self.states[i] == ContactState::Slip => {
                (self.directions[i] - f.direction) * f.bound
            }
            _ => Vector2::zeros(),
        }
    }

    /// At the start of an increment to load factor `alpha`: the bounds of the contacts that
    /// slid at the end of the last two increments extrapolated linearly in α from their
    /// converged values there (the bounds follow the normal forces, smooth in α while the
    /// states hold), so the fixed point starts second-order close instead of first-order.
    pub fn predict_bounds(&mut self, alpha: f64) {
        if !self.bound_fixed_point {
            return;
        }
        let converged = self.bounds.clone();
        let sliding: Vec<bool> = self
            .states
            .iter()
            .map(|&s| s == ContactState::Slip)
            .collect();
        if let (Some((a2, b2, slid)), Some(a1)) = (&self.previous, self.last_alpha) {
            let floor = match self.friction {
                Friction::Coulomb { cohesion, .. } => cohesion,
                _ => 0.0,
            };
            for i in (0..self.bounds.len()).filter(|&i| sliding[i] && slid[i]) {
                self.bounds[i] = extrapolate((*a2, b2[i]), (a1, converged[i]), alpha, floor);
            }
        }
        if let Some(a1) = self.last_alpha {
            self.previous = Some((a1, converged, sliding));
        }
        self.last_alpha = Some(alpha);
    }

    /// Forgets the load factors of the bounds' predictor: the load path turned, and the
    /// bounds are no longer linear in α across its start.
    pub fn restart_path(&mut self) {
        self.previous = None;
        self.last_alpha = None;
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
        reference: Option<&[ReferenceBlock]>,
    ) {
        for &i in changed {
            // A change of state always counts as a switch, and after SETTLING_ITERATIONS every
            // change does: a contact that does not settle is then held like a chattering one.
            // Before, with Coulomb friction the slip directions and bounds settle together
            // (linearly on the fixed point, quadratically with the consistent tangent), so
            // their changes do not count; otherwise a change of slip direction counts (a
            // sliding force that is off the bound does not).
            let counts = trials[i].state != self.states[i]
                || iteration > SETTLING_ITERATIONS
                || (!self.bound_fixed_point
                    && !self.consistent_coulomb()
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
        let consistent = self.consistent_coulomb();
        self.symmetric_step = false;
        for (i, t) in trials.iter().enumerate() {
            self.compressed[i] = t.normal_force > 0.0;
            if consistent && t.state == ContactState::Slip {
                self.bounds[i] = t.bound;
            }
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
        let reference = reference.filter(|_| iteration < FROZEN_ITERATIONS);
        for i in 0..trials.len() {
            self.frozen[i] = reference.and_then(|r| self.freeze(i, &trials[i], &r[i]));
        }
    }

    /// The reference's tangent for contact i, sliding at trial `t`, when the reference `r` has
    /// it sliding with the same friction law, a slip direction within [`FROZEN_TURN`] and a
    /// k⊥ within [`FROZEN_STIFFNESS_CHANGE`] of the consistent one at `t`.
    fn freeze(&self, i: usize, t: &Trial, r: &ReferenceBlock) -> Option<FrozenTangent> {
        let friction = self.friction_of(i);
        let (k, k_ref) = (self.perpendicular[i].0, r.state.k_perp);
        let sliding = t.state == ContactState::Slip && self.states[i] == ContactState::Slip;
        (sliding
            && !self.held(i)
            && r.state.state == ContactState::Slip
            && std::mem::discriminant(&friction) == std::mem::discriminant(&r.friction)
            && k > 0.0
            && k_ref > 0.0
            && (k / k_ref - 1.0).abs() <= FROZEN_STIFFNESS_CHANGE
            && (self.directions[i] - r.state.direction).norm() <= FROZEN_TURN)
            .then_some(FrozenTangent {
                direction: r.state.direction,
                k_perp: k_ref,
                bound: match friction {
                    Friction::Tresca { bound } => bound,
                    Friction::Coulomb { .. } => t.bound,
                    Friction::None => 0.0,
                },
            })
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

/// Load coefficients `phi` of a contact in `state` with a frozen tangent's `offset` (see
/// [`ContactStates::frozen_offset`]) taken off its tangential rows when it slides.
pub(super) fn with_frozen_offset(
    mut phi: Vector6<f64>,
    state: ContactState,
    offset: Vector2<f64>,
) -> Vector6<f64> {
    if state == ContactState::Slip {
        phi[1] -= offset[0];
        phi[2] -= offset[1];
    }
    phi
}

/// A sliding contact linearized with the reference factorization's tangent instead of the
/// consistent one at its trial (modified Newton): its block keeps the reference's slip
/// direction d_f and k⊥, so it is no change of the correction's capacitance, while its load
/// makes the linearized force exact at the iterate q_k: the block's form f̃ = b d_f + k⊥ p pᵀ
/// (u_t − a) (Coulomb: the bound's slope μ p_N d_f nᵀ too) gives b d_f there, the law b d, and
/// the load carries the difference b (d − d_f). The fixed point is the law's whatever the
/// tangent; the tangent only sets how fast it is reached, hence the bounds on how far it may
/// be from the consistent one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct FrozenTangent {
    pub direction: Vector2<f64>,
    pub k_perp: f64,
    /// The friction bound b at q_k.
    pub bound: f64,
}

/// The value at `alpha` of the line through (α₂, b₂) and (α₁, b₁), at least `floor`; b₁ when
/// α₁ = α₂.
fn extrapolate((a2, b2): (f64, f64), (a1, b1): (f64, f64), alpha: f64, floor: f64) -> f64 {
    let ratio = (alpha - a1) / (a1 - a2);
    if ratio.is_finite() {
        (b1 + ratio * (b1 - b2)).max(floor)
    } else {
        b1
    }
}

#[cfg(test)]
mod tests {
    use super::extrapolate;

    /// A bound linear in α is predicted exactly, forwards and on an unloading path (α
    /// decreasing); the cohesion floors it; equal load factors keep the last bound.
    #[test]
    fn bounds_are_extrapolated_along_the_load_path() {
        let b = |a: f64| 0.2 + 3.0 * a;
        assert!((extrapolate((0.1, b(0.1)), (0.2, b(0.2)), 0.3, 0.0) - b(0.3)).abs() < 1e-15);
        assert!((extrapolate((0.5, b(0.5)), (0.4, b(0.4)), 0.3, 0.0) - b(0.3)).abs() < 1e-15);
        assert_eq!(extrapolate((0.2, 1.0), (0.3, 0.5), 0.5, 0.1), 0.1);
        assert_eq!(extrapolate((0.3, 1.0), (0.3, 0.7), 0.4, 0.0), 0.7);
    }
}
