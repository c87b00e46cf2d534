//! The return mapping of one contact (thesis §4.3): from its displacement jump and committed
//! slip, the trial state, forces and friction bound.

use super::options::BOUND_TOLERANCE;
use crate::contact::{BlockVector, ContactPair, ContactState, Friction};
use nalgebra::Vector2;

/// A contact's trial in one state iteration: its state, slip direction, forces and bound from
/// the return mapping, and the kinematics they came from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Trial {
    pub state: ContactState,
    /// Unit slip direction in the tangent basis (zero without a trial force).
    pub direction: Vector2<f64>,
    /// N = p_N max(g, 0) (bonded: p_N g, a tension allowed).
    pub normal_force: f64,
    /// Tangential force in the tangent basis.
    pub tangential: Vector2<f64>,
    /// Friction bound: c + μ max(N, 0), or Tresca's.
    pub bound: f64,
    /// Tangential relative displacement of the contact points.
    pub relative: Vector2<f64>,
    /// Penetration (positive: overlapping).
    pub penetration: f64,
    /// |p_T (u_t − s)|, the trial force's magnitude.
    pub trial_norm: f64,
}

/// The contact law of a run: friction, and whether initially closed contacts are bonded
/// (never open).
#[derive(Clone, Copy, Debug)]
pub(super) struct Law {
    pub friction: Friction,
    pub bonded: bool,
}

/// The trial `t` of a contact held in `state` with slip direction `direction` (a contact that
/// chattered): forces consistent with that state (stick: the trial force; slip: the bound along
/// `direction`; open: none).
pub(super) fn hold(mut t: Trial, state: ContactState, direction: Vector2<f64>) -> Trial {
    let trial = t.direction * t.trial_norm;
    match state {
        ContactState::Open => {
            t.normal_force = 0.0;
            t.tangential = Vector2::zeros();
        }
        ContactState::Stick => t.tangential = trial,
        ContactState::Slip => {
            t.direction = direction;
            t.tangential = direction * t.bound;
        }
    }
    t.state = state;
    t
}

/// Return mapping of one contact for the block displacement `q` and committed slip `s`.
/// `previous` is the state the system was solved with: within the tolerances (`length_tol` on
/// the penetration, a relative 1e-10 on the friction bound) a contact keeps it, so a contact
/// exactly at the switch point does not flip back and forth. A trial tangential force below
/// p_T · `length_tol` is roundoff: a closed contact keeps its state and slip direction (a
/// contact that carries nothing would otherwise slide in a direction set by noise).
pub(super) fn classify(
    pair: &ContactPair,
    law: Law,
    q: &BlockVector,
    slip: &Vector2<f64>,
    previous: (ContactState, Vector2<f64>),
    length_tol: f64,
    fixed_direction: Option<Vector2<f64>>,
) -> Trial {
    let (previous, previous_direction) = previous;
    let friction = law.friction;
    let kin = pair.kinematics(q);
    let mut t = Trial {
        state: ContactState::Open,
        direction: Vector2::zeros(),
        normal_force: 0.0,
        tangential: Vector2::zeros(),
        bound: 0.0,
        relative: kin.tangential,
        penetration: kin.penetration,
        trial_norm: 0.0,
    };
    let closed_before = previous != ContactState::Open;
    let closes = if law.bonded {
        pair.gap <= 0.0
    } else if closed_before {
        kin.penetration > -length_tol
    } else {
        kin.penetration > length_tol
    };
    if !closes {
        return t;
    }
    t.normal_force = if law.bonded {
        pair.penalty_normal * kin.penetration
    } else {
        pair.penalty_normal * kin.penetration.max(0.0)
    };
    let trial = (kin.tangential - slip) * pair.penalty_tangent;
    let norm = trial.norm();
    t.trial_norm = norm;
    t.direction = if norm > 0.0 {
        trial / norm
    } else {
        Vector2::zeros()
    };
    t.bound = match friction {
        Friction::None => 0.0,
        Friction::Coulomb { mu, cohesion } => cohesion + mu * t.normal_force.max(0.0),
        Friction::Tresca { bound } => bound,
    };
    if closed_before && friction != Friction::None && norm <= pair.penalty_tangent * length_tol {
        t.state = previous;
        if previous == ContactState::Slip {
            t.direction = previous_direction;
            t.tangential = previous_direction * t.bound;
        } else {
            t.tangential = trial;
        }
        return t;
    }
    let margin = if previous == ContactState::Slip {
        1.0 - 1e-10
    } else {
        1.0 + 1e-10
    };
    if friction != Friction::None && norm <= t.bound * margin {
        t.state = ContactState::Stick;
        t.tangential = trial;
    } else if previous == ContactState::Slip
        && friction != Friction::None
        && t.direction.dot(&previous_direction) < 0.0
    {
        // A sliding contact cannot reverse without passing through stick: try stick first
        // (the solve under the old slip force says nothing about the elastic range).
        t.state = ContactState::Stick;
        t.tangential = trial;
    } else {
        t.state = ContactState::Slip;
        if let Some(d) = fixed_direction.filter(|d| d.norm() > 0.0) {
            t.direction = d;
        }
        t.tangential = t.direction * t.bound;
    }
    t
}

/// Whether a sliding contact's force in the solved system differs from the law's, the bound
/// along the trial direction, by more than [`BOUND_TOLERANCE`] of the bound. The solved force
/// is the bound along the direction it was assembled with (`direction`) plus the k⊥ spring of
/// its block stretched from its anchor (`block`: the block's slip direction, k⊥ and anchor),
/// and, for a block frozen at the linearization bound b_k (`frozen`, see
/// `contact_states::FrozenTangent`), (b − b_k)(d_f − d) from the bound's slope along the
/// block's direction d_f. The direction test of the state iteration measures the change in
/// displacement, which misses this where p_T (and with it k⊥) is large: on the S cell a
/// contact with k⊥ = 1.6·10⁷ N/m passed it with a spring force of 3.6·10⁻³ of its bound, the
/// equilibrium residual of the increment 5.6·10⁻⁴.
pub(super) fn unsettled_force(
    t: &Trial,
    direction: Vector2<f64>,
    block: (Vector2<f64>, f64, Vector2<f64>),
    frozen: Option<f64>,
) -> bool {
    if t.state != ContactState::Slip || !(t.bound > 0.0) {
        return false;
    }
    let (block_direction, k_perp, anchor) = block;
    let across = Vector2::new(-block_direction[1], block_direction[0]);
    let spring = k_perp * across.dot(&(t.relative - anchor));
    let slope = frozen.map_or(0.0, |b| {
        (t.bound - b) * (block_direction - direction).norm()
    });
    let error = t.bound * (t.direction - direction).norm() + slope.abs() + spring.abs();
    error > BOUND_TOLERANCE * t.bound
}

/// The 30-vector of `q` at `nodes` (six DOFs each), the block displacement of a contact.
pub(crate) fn gather(q: &[f64], nodes: &[usize]) -> BlockVector {
    let mut v = BlockVector::zeros();
    for (k, &n) in nodes.iter().enumerate() {
        for d in 0..6 {
            v[6 * k + d] = q[6 * n + d];
        }
    }
    v
}
