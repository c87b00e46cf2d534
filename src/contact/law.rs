//! Penalty contact contributions of one contact pair (thesis 4.53–4.65), in terms of the jump
//! operator B ([u] = B q), the unit normal n and an orthonormal basis E = [e₁ e₂] of the tangent
//! plane:
//!
//! * normal (4.53, 4.54): K_N = p_N Bᵀ n nᵀ B, F_N = p_N ḡ Bᵀ n — the contact is active when the
//!   penetration nᵀ B q − ḡ is positive, with normal force N = p_N (nᵀ B q − ḡ);
//! * stick (4.58): K_T = p_T Bᵀ E Eᵀ B, F_T = p_T Bᵀ E s, with s the accumulated slip; the
//!   tangential force is F_t = p_T (Eᵀ B q − s);
//! * Coulomb slip (4.63, 4.64): F_t = μ N d along the slip direction d, so
//!   K_T = μ p_N Bᵀ E d nᵀ B (rank one, **nonsymmetric**), F_T = μ p_N ḡ Bᵀ E d;
//! * Tresca slip (4.65): F_t = G d, a constant load F_T = −G Bᵀ E d;
//! * rolling resistance (not in the thesis): K_R = p_R Rᵀ R on the relative rotation [θ] = R q of
//!   a closed contact, moment M = p_R R q. A point contact transmits forces only, so fibers held
//!   by crossings alone can roll on each other without straining anything (warps spinning about
//!   their axes while wefts translate); a real contact is a patch and resists that. p_R is the
//!   rotational stiffness of a uniform normal penalty over a disc of radius a, p_N a²/4, with a
//!   default a of half the smaller fiber radius; p_R = 0 gives the thesis's point contact.
//!
//! E is built from the tangent of fiber I projected on the tangent plane; for fibers crossing
//! at right angles its two vectors are the two fiber tangents of the thesis.

use super::kinematics::Jump;
use crate::model::Friction;
use nalgebra::{Matrix3, SMatrix, SVector, Vector2, Vector3};

/// A 30 × 30 contact block (the top-left 6k × 6k part is used).
pub type BlockMatrix = SMatrix<f64, 30, 30>;
/// A 30-vector of block loads.
pub type BlockVector = SVector<f64, 30>;

/// State of a contact.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ContactState {
    /// Not in contact (no forces).
    Open,
    /// In contact, tangentially stuck.
    Stick,
    /// In contact, sliding at the friction bound.
    Slip,
}

impl ContactState {
    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            ContactState::Open => "open",
            ContactState::Stick => "stick",
            ContactState::Slip => "slip",
        }
    }
}

/// Geometry and penalties of one contact pair.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactPair {
    /// Jump operator over the block's nodes.
    pub jump: Jump,
    /// Unit normal from side I to side II.
    pub normal: Vector3<f64>,
    /// Orthonormal tangent-plane basis.
    pub tangents: [Vector3<f64>; 2],
    /// Initial gap ḡ (m) used in the penalty law (after any strain-free adjustment).
    pub gap: f64,
    /// Normal penalty p_N (N/m).
    pub penalty_normal: f64,
    /// Tangential penalty p_T (N/m).
    pub penalty_tangent: f64,
    /// Rolling and twisting resistance p_R (N·m/rad); 0 for a point contact.
    pub penalty_rotation: f64,
}

/// Tangent-plane basis from a preferred direction (projected) and the normal.
pub fn tangent_basis(normal: &Vector3<f64>, preferred: &Vector3<f64>) -> [Vector3<f64>; 2] {
    let mut t = preferred - normal * normal.dot(preferred);
    if t.norm() < 1e-8 * preferred.norm().max(1e-300) {
        let k = (0..3)
            .min_by(|&i, &j| normal[i].abs().total_cmp(&normal[j].abs()))
            .unwrap_or(0);
        let mut aux = Vector3::zeros();
        aux[k] = 1.0;
        t = aux - normal * normal[k];
    }
    let e1 = t.normalize();
    [e1, normal.cross(&e1)]
}

/// Per-pair quantities that depend on the displacement of its nodes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairKinematics {
    /// Penetration nᵀ B q − ḡ (positive: in contact).
    pub penetration: f64,
    /// Tangential relative displacement Eᵀ B q.
    pub tangential: Vector2<f64>,
}

impl ContactPair {
    /// Number of rows/columns of the block actually used.
    pub fn size(&self) -> usize {
        6 * self.jump.nodes.len()
    }

    fn bt_n(&self) -> BlockVector {
        self.jump.b.transpose() * self.normal
    }

    fn bt_e(&self, d: &Vector2<f64>) -> BlockVector {
        self.jump.b.transpose() * (self.tangents[0] * d[0] + self.tangents[1] * d[1])
    }

    /// Penetration and tangential relative displacement for the block DOFs `q`.
    pub fn kinematics(&self, q: &BlockVector) -> PairKinematics {
        let jump = self.jump.b * q;
        PairKinematics {
            penetration: self.normal.dot(&jump) - self.gap,
            tangential: Vector2::new(self.tangents[0].dot(&jump), self.tangents[1].dot(&jump)),
        }
    }

    /// K_N and F_N of an active contact (4.53, 4.54).
    pub fn normal(&self) -> (BlockMatrix, BlockVector) {
        let bn = self.bt_n();
        (
            bn * bn.transpose() * self.penalty_normal,
            bn * (self.penalty_normal * self.gap),
        )
    }

    /// K_R = p_R Rᵀ R of the rolling resistance of a closed contact (stick or slip).
    pub fn rotation(&self) -> BlockMatrix {
        self.jump.r.transpose() * self.jump.r * self.penalty_rotation
    }

    /// The resisting moment p_R \[θ\] (N·m) for the block DOFs `q`.
    pub fn rotation_moment(&self, q: &BlockVector) -> Vector3<f64> {
        self.jump.r * q * self.penalty_rotation
    }

    /// K_N + K_R (4.53), plus K_T^st (4.58) when `stick`, entry (row, column) of the leading
    /// [`ContactPair::size`] square block (the value fill of closed contacts): see
    /// [`ContactPair::springs`].
    pub fn closed_stiffness(&self, stick: bool) -> impl Fn(usize, usize) -> f64 + Sync + '_ {
        let p_t = if stick { self.penalty_tangent } else { 0.0 };
        self.springs(self.penalty_normal, p_t, self.penalty_rotation)
    }

    /// The one formula of a contact's springs in production code: the normal spring p_n, the
    /// tangential one p_t and the rotational one p_r as Bᵀ S B + p_r RᵀR with the 3 × 3
    /// S = p_n n nᵀ + p_t (t₁t₁ᵀ + t₂t₂ᵀ), entry (row, column) of the leading
    /// [`ContactPair::size`] square block, six products per entry and no 30 × 30 temporaries.
    /// K_N = springs(p_N, 0, 0) (4.53), K_T^st = springs(0, p_T, 0) (4.58), K_R =
    /// springs(0, 0, p_R). [`ContactPair::normal`], [`ContactPair::stick`] and
    /// [`ContactPair::rotation`] are the same matrices as outer products, the independent forms
    /// the tests check this one against.
    pub fn springs(
        &self,
        p_n: f64,
        p_t: f64,
        p_r: f64,
    ) -> impl Fn(usize, usize) -> f64 + Sync + '_ {
        let sb = self.spring_matrix(p_n, p_t) * self.jump.b;
        let (b, r) = (&self.jump.b, &self.jump.r);
        move |i, j| b.column(i).dot(&sb.column(j)) + p_r * r.column(i).dot(&r.column(j))
    }

    /// The 3 × 3 S = p_N n nᵀ (+ p_T (t₁t₁ᵀ + t₂t₂ᵀ) when `stick`) of
    /// [`ContactPair::closed_stiffness`]: the jump's stiffness.
    #[inline]
    pub fn jump_stiffness(&self, stick: bool) -> Matrix3<f64> {
        let p_t = if stick { self.penalty_tangent } else { 0.0 };
        self.spring_matrix(self.penalty_normal, p_t)
    }

    /// S = p_n n nᵀ + p_t (t₁t₁ᵀ + t₂t₂ᵀ).
    #[inline]
    fn spring_matrix(&self, p_n: f64, p_t: f64) -> Matrix3<f64> {
        let (n, [t1, t2]) = (&self.normal, &self.tangents);
        Matrix3::from_fn(|i, j| p_n * (n[i] * n[j]) + p_t * (t1[i] * t1[j] + t2[i] * t2[j]))
    }

    /// F_N + F_T of a stuck contact with accumulated slip `slip` (4.53, 4.58), the load that
    /// goes with [`ContactPair::closed_stiffness`]`(true)`: Bᵀ (p_N ḡ n + p_T E s), with no
    /// 30 × 30 temporaries.
    pub fn stick_load(&self, slip: &Vector2<f64>) -> BlockVector {
        let jump_force = self.normal * (self.penalty_normal * self.gap)
            + (self.tangents[0] * slip[0] + self.tangents[1] * slip[1]) * self.penalty_tangent;
        self.jump.b.transpose() * jump_force
    }

    /// K_T^st and F_T of a stuck contact with accumulated slip `slip` (4.58).
    pub fn stick(&self, slip: &Vector2<f64>) -> (BlockMatrix, BlockVector) {
        let b1 = self.bt_e(&Vector2::new(1.0, 0.0));
        let b2 = self.bt_e(&Vector2::new(0.0, 1.0));
        let k = (b1 * b1.transpose() + b2 * b2.transpose()) * self.penalty_tangent;
        let f = (b1 * slip[0] + b2 * slip[1]) * self.penalty_tangent;
        (k, f)
    }

    /// The consistent tangent of the radial return perpendicular to the slip direction `d`: a
    /// spring k⊥ = p_T · bound / |trial| acting on the tangential displacement across `d`,
    /// anchored at the current iterate's tangential displacement `anchor`. It vanishes at
    /// convergence and makes the slip-direction iteration Newton's method (without it a sliding
    /// contact offers no resistance across its direction, and the direction can oscillate).
    pub fn slip_perpendicular(
        &self,
        d: &Vector2<f64>,
        k_perp: f64,
        anchor: &Vector2<f64>,
    ) -> (BlockMatrix, BlockVector) {
        let p = Vector2::new(-d[1], d[0]);
        let bp = self.bt_e(&p);
        (bp * bp.transpose() * k_perp, bp * (k_perp * p.dot(anchor)))
    }

    /// K_T^sl and F_T^sl of a contact sliding along the unit direction `d` (tangent basis).
    pub fn slip(&self, friction: Friction, d: &Vector2<f64>) -> (BlockMatrix, BlockVector) {
        let bd = self.bt_e(d);
        match friction {
            Friction::None => (BlockMatrix::zeros(), BlockVector::zeros()),
            Friction::Coulomb { mu, cohesion } => {
                let bn = self.bt_n();
                (
                    bd * bn.transpose() * (mu * self.penalty_normal),
                    bd * (mu * self.penalty_normal * self.gap - cohesion),
                )
            }
            Friction::Tresca { bound } => (BlockMatrix::zeros(), bd * (-bound)),
        }
    }
}
