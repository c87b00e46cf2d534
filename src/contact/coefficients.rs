//! A contact block in the basis of its jump rows: every block the incremental solver assembles
//! (K_N 4.53, K_T^st 4.58, K_T^sl, the consistent tangent k⊥, K_R and the stabilizing springs)
//! is G D Gᵀ with G = [Bᵀn, Bᵀt₁, Bᵀt₂, Rᵀe₁, Rᵀe₂, Rᵀe₃] the contact's six jump rows and D a
//! 6 × 6 coefficient matrix. A change of state or slip direction changes D only, so it is a
//! change of rank ≤ 6 (2 between stick and slip) in a basis fixed for the whole analysis.

use super::law::{BlockVector, ContactPair, ContactState};
use crate::model::Friction;
use nalgebra::{Matrix3, SMatrix, Vector2, Vector3, Vector6};

/// The 6 × 6 coefficients D of a contact block G D Gᵀ, in the order normal, the two tangents,
/// the three rotation components.
pub type BlockCoefficients = SMatrix<f64, 6, 6>;

/// What a contact's block depends on in the incremental solver.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlockState {
    /// Open, stick or slip.
    pub state: ContactState,
    /// Unit slip direction in the tangent basis (used when sliding).
    pub direction: Vector2<f64>,
    /// The consistent tangent k⊥ across the slip direction (0: none).
    pub k_perp: f64,
}

impl ContactPair {
    /// The basis G: Bᵀn, Bᵀt₁, Bᵀt₂, Rᵀe₁, Rᵀe₂, Rᵀe₃ (block DOFs, padded to 30).
    pub fn jump_basis(&self) -> [BlockVector; 6] {
        let b = self.jump.b.transpose();
        let r = self.jump.r.transpose();
        [
            b * self.normal,
            b * self.tangents[0],
            b * self.tangents[1],
            r * Vector3::x(),
            r * Vector3::y(),
            r * Vector3::z(),
        ]
    }

    /// The coefficients D of the block the incremental solver assembles for `s`, with friction
    /// `friction` and stabilization ε: stick p_N, p_T, p_T, p_R ×3 on the diagonal; open ε times
    /// that; slip p_N, ε p_T (+ k⊥ p pᵀ across the direction, p = (−d₂, d₁)), p_R ×3, and for
    /// Coulomb μ p_N d in the tangential rows of the normal column (K_T^sl = μ p_N Bᵀd nᵀB).
    pub fn block_coefficients(
        &self,
        s: &BlockState,
        friction: Friction,
        stabilization: f64,
    ) -> BlockCoefficients {
        let (pn, pt, pr) = (
            self.penalty_normal,
            self.penalty_tangent,
            self.penalty_rotation,
        );
        let stick =
            BlockCoefficients::from_diagonal(&nalgebra::Vector6::new(pn, pt, pt, pr, pr, pr));
        match s.state {
            ContactState::Stick => stick,
            ContactState::Open => stick * stabilization,
            ContactState::Slip => {
                let mut d = BlockCoefficients::from_diagonal(&nalgebra::Vector6::new(
                    pn,
                    stabilization * pt,
                    stabilization * pt,
                    pr,
                    pr,
                    pr,
                ));
                if let Friction::Coulomb { mu, .. } = friction {
                    d[(1, 0)] += mu * pn * s.direction[0];
                    d[(2, 0)] += mu * pn * s.direction[1];
                }
                if s.k_perp > 0.0 {
                    let p = Vector2::new(-s.direction[1], s.direction[0]);
                    for a in 0..2 {
                        for b in 0..2 {
                            d[(1 + a, 1 + b)] += s.k_perp * p[a] * p[b];
                        }
                    }
                }
                d
            }
        }
    }

    /// The coefficients φ of the load G φ that goes with [`ContactPair::block_coefficients`]:
    /// stick p_N ḡ, p_T s (F_N + F_T, 4.53, 4.58, `slip` the committed slip s); open none;
    /// slip p_N ḡ and along the direction d the friction force (Tresca −G, Coulomb μ p_N ḡ) plus
    /// the k⊥ spring's k⊥ (p·a) p, `anchor` a its anchor.
    pub fn load_coefficients(
        &self,
        s: &BlockState,
        anchor: &Vector2<f64>,
        slip: &Vector2<f64>,
        friction: Friction,
    ) -> Vector6<f64> {
        let pn_gap = self.penalty_normal * self.gap;
        let mut phi = Vector6::zeros();
        match s.state {
            ContactState::Open => {}
            ContactState::Stick => {
                phi[0] = pn_gap;
                phi[1] = self.penalty_tangent * slip[0];
                phi[2] = self.penalty_tangent * slip[1];
            }
            ContactState::Slip => {
                phi[0] = pn_gap;
                let along = match friction {
                    Friction::None => 0.0,
                    Friction::Coulomb { mu, cohesion } => mu * pn_gap - cohesion,
                    Friction::Tresca { bound } => -bound,
                };
                let p = Vector2::new(-s.direction[1], s.direction[0]);
                let across = if s.k_perp > 0.0 {
                    s.k_perp * p.dot(anchor)
                } else {
                    0.0
                };
                phi[1] = along * s.direction[0] + across * p[0];
                phi[2] = along * s.direction[1] + across * p[1];
            }
        }
        phi
    }
}

/// A contact block G D Gᵀ written on the displacement jump: Bᵀ S B + ρ RᵀR, S the 3 × 3
/// stiffness of the jump B q (nonsymmetric for the Coulomb consistent tangent) and ρ that of
/// the rotation jump R q. The one form in which every contact block is assembled: the cell
/// problems' closed contacts, the stick/slip system and its changes (see
/// [`crate::assembly::ContactColumns`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactBlock {
    /// S.
    pub jump: Matrix3<f64>,
    /// ρ.
    pub rotation: f64,
}

impl ContactPair {
    /// The block of coefficients `d` (see [`ContactPair::block_coefficients`]): S = Q D_tt Qᵀ
    /// with Q = [n t₁ t₂], ρ = D_rr. Every block the solver builds has a rotational part ρ I
    /// uncoupled from the translational one (checked in debug builds); G D Gᵀ = Bᵀ S B + ρ RᵀR
    /// then, as G = [Bᵀ Q, Rᵀ].
    pub fn block_of(&self, d: &BlockCoefficients) -> ContactBlock {
        debug_assert!(
            (0..3).all(|a| (0..3).all(|b| {
                d[(a, 3 + b)] == 0.0
                    && d[(3 + a, b)] == 0.0
                    && (a == b || d[(3 + a, 3 + b)] == 0.0)
                    && d[(3 + a, 3 + a)] == d[(3, 3)]
            })),
            "rotational coefficients not ρ I: {d}"
        );
        let q = [self.normal, self.tangents[0], self.tangents[1]];
        let jump = Matrix3::from_fn(|i, j| {
            let mut s = 0.0;
            for (a, qa) in q.iter().enumerate() {
                for (b, qb) in q.iter().enumerate() {
                    s += d[(a, b)] * qa[i] * qb[j];
                }
            }
            s
        });
        ContactBlock {
            jump,
            rotation: d[(3, 3)],
        }
    }

    /// The block of a closed contact in the cell problems: K_N + K_R, plus K_T^st when `stick`
    /// (4.53, 4.58).
    pub fn closed_block(&self, stick: bool) -> ContactBlock {
        ContactBlock {
            jump: self.jump_stiffness(stick),
            rotation: self.penalty_rotation,
        }
    }

    /// (Bᵀ S B + ρ RᵀR) x for the block DOFs `x`.
    pub fn apply_block(&self, block: &ContactBlock, x: &BlockVector) -> BlockVector {
        let (b, r) = (&self.jump.b, &self.jump.r);
        b.transpose() * (block.jump * (b * x)) + r.transpose() * ((r * x) * block.rotation)
    }

    /// The load G φ of coefficients `phi` (see [`ContactPair::load_coefficients`]): Bᵀ Q φ_t
    /// + Rᵀ φ_r.
    pub fn load_of(&self, phi: &Vector6<f64>) -> BlockVector {
        let force = self.normal * phi[0] + self.tangents[0] * phi[1] + self.tangents[1] * phi[2];
        let moment = Vector3::new(phi[3], phi[4], phi[5]);
        self.jump.b.transpose() * force + self.jump.r.transpose() * moment
    }
}
