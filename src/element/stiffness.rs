//! The 12×12 frame stiffness, local (4.34) and global (4.42).
//!
//! DOF order per node: u, v, w (along e1, e2, e3) and θx, θy, θz. With the Hermite cubics of
//! (4.26), v(s) = H₁v₁ + H₂θz₁ + H₃v₂ + H₄θz₂ (θz = v′) and w(s) = H₁w₁ − H₂θy₁ + H₃w₂ − H₄θy₂
//! (θy = −w′). Integrating k = ∫ Bᵀ D B ds (4.34) with D = diag(EA, EI₃, EI₂, GJ) (torsion is
//! G·J, not EA as printed in 4.10) gives the closed form below; Appendix A.1 swaps I₂/I₃ and
//! signs in its k₁₂ block.

use super::local_frame;
use nalgebra::{Matrix3, SMatrix};

/// A 12×12 element matrix.
pub type Matrix12 = SMatrix<f64, 12, 12>;

/// Section stiffnesses of a frame element.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameStiffness {
    /// Axial stiffness E·A (N).
    pub ea: f64,
    /// Bending stiffness about local e2, E·I₂ (N·m²): deflection w along e3.
    pub ei2: f64,
    /// Bending stiffness about local e3, E·I₃ (N·m²): deflection v along e2.
    pub ei3: f64,
    /// Torsional stiffness G·J (N·m²).
    pub gj: f64,
}

/// The local stiffness k of an element of length `l` (closed form of 4.34).
pub fn local_stiffness(p: &FrameStiffness, l: f64) -> Matrix12 {
    let mut k = Matrix12::zeros();
    let (l2, l3) = (l * l, l * l * l);
    let mut set = |i: usize, j: usize, v: f64| {
        k[(i, j)] = v;
        k[(j, i)] = v;
    };
    // Axial (u1 = 0, u2 = 6) and torsion (θx1 = 3, θx2 = 9).
    let (a, t) = (p.ea / l, p.gj / l);
    set(0, 0, a);
    set(6, 6, a);
    set(0, 6, -a);
    set(3, 3, t);
    set(9, 9, t);
    set(3, 9, -t);
    // Bending in the e1–e2 plane: v (1, 7) with θz (5, 11), stiffness EI₃.
    let e = p.ei3;
    set(1, 1, 12.0 * e / l3);
    set(7, 7, 12.0 * e / l3);
    set(1, 7, -12.0 * e / l3);
    set(1, 5, 6.0 * e / l2);
    set(1, 11, 6.0 * e / l2);
    set(5, 7, -6.0 * e / l2);
    set(7, 11, -6.0 * e / l2);
    set(5, 5, 4.0 * e / l);
    set(11, 11, 4.0 * e / l);
    set(5, 11, 2.0 * e / l);
    // Bending in the e1–e3 plane: w (2, 8) with θy (4, 10), stiffness EI₂; θy = −w′ flips the
    // signs of the w–θ couplings.
    let e = p.ei2;
    set(2, 2, 12.0 * e / l3);
    set(8, 8, 12.0 * e / l3);
    set(2, 8, -12.0 * e / l3);
    set(2, 4, -6.0 * e / l2);
    set(2, 10, -6.0 * e / l2);
    set(4, 8, 6.0 * e / l2);
    set(8, 10, 6.0 * e / l2);
    set(4, 4, 4.0 * e / l);
    set(10, 10, 4.0 * e / l);
    set(4, 10, 2.0 * e / l);
    k
}

/// The global stiffness K = Tᵀ k T of the element from `p1` to `p2` (4.42), T = diag(R, R, R, R)
/// with R from [`local_frame`]; computed block by block (Rᵀ k_ab R).
pub fn global_stiffness(p1: &[f64; 3], p2: &[f64; 3], p: &FrameStiffness) -> Matrix12 {
    let (r, l) = local_frame(p1, p2);
    let k = local_stiffness(p, l);
    let mut out = Matrix12::zeros();
    for a in 0..4 {
        for b in 0..4 {
            let kab: Matrix3<f64> = k.fixed_view::<3, 3>(3 * a, 3 * b).into_owned();
            if kab.iter().all(|v| *v == 0.0) {
                continue;
            }
            out.fixed_view_mut::<3, 3>(3 * a, 3 * b)
                .copy_from(&(r.transpose() * kab * r));
        }
    }
    out
}
