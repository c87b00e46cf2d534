//! Kinematics of a contact point (thesis Lemma 4.26): the centerline displacement at a point of
//! an element is interpolated with the element's own shape functions — linear for the axial
//! part, Hermite cubics for the transverse parts — and the jump [u] = u_I − u_II between the two
//! contact points is a linear map B of the DOFs of the nodes involved.
//!
//! Beyond the thesis, the relative rotation [θ] = θ_I − θ_II of the two sides is a second map R
//! (nodal rotations interpolated linearly along an element), used by the rolling resistance of a
//! closed contact (see [`ContactPair::rotation`](super::ContactPair::rotation)). In a periodic cell
//! a side may belong to a periodic image of its element: every node of the block then carries the
//! number of periods its image is shifted by.

use crate::element::{hermite, linear, local_frame};
use crate::model::{ContactSide, Model};
use nalgebra::{Matrix3, SMatrix};

/// Up to five generalized nodes × six DOFs (four nodes of two elements, plus the driver node of a
/// periodic cell).
pub type JumpMatrix = SMatrix<f64, 3, 30>;

/// \[u\] = u_I − u_II = B q and \[θ\] = θ_I − θ_II = R q over `nodes` (DOFs node by node, 6
/// each; columns beyond 6·len are 0).
#[derive(Clone, Debug, PartialEq)]
pub struct Jump {
    /// Node indices of the block (distinct as (node, shift)).
    pub nodes: Vec<usize>,
    /// Periods (i, j) by which each node's image is shifted (all zero outside periodic cells).
    pub shifts: Vec<[i32; 2]>,
    /// The 3 × 6k displacement jump operator, padded to 30 columns.
    pub b: JumpMatrix,
    /// The 3 × 6k rotation jump operator, padded to 30 columns.
    pub r: JumpMatrix,
}

/// The 3×12 map from the element's global DOFs to the global displacement of its centerline at
/// ξ: u = Rᵀ L(ξ) T q (thesis a = C R(s)ᵀ C̄ of 4.49, transposed), with θz = v′ and θy = −w′.
pub fn centerline_interpolation(p1: &[f64; 3], p2: &[f64; 3], xi: f64) -> SMatrix<f64, 3, 12> {
    let (r, l) = local_frame(p1, p2);
    let s = xi * l;
    let n = linear(s, l);
    let h = hermite(s, l);
    // Local displacement from local DOFs (u v w θx θy θz per node).
    let mut loc = SMatrix::<f64, 3, 12>::zeros();
    loc[(0, 0)] = n[0];
    loc[(0, 6)] = n[1];
    loc[(1, 1)] = h[0];
    loc[(1, 5)] = h[1];
    loc[(1, 7)] = h[2];
    loc[(1, 11)] = h[3];
    loc[(2, 2)] = h[0];
    loc[(2, 4)] = -h[1];
    loc[(2, 8)] = h[2];
    loc[(2, 10)] = -h[3];
    let mut out = SMatrix::<f64, 3, 12>::zeros();
    for b in 0..4 {
        let block: Matrix3<f64> = loc.fixed_view::<3, 3>(0, 3 * b).into_owned();
        out.fixed_view_mut::<3, 3>(0, 3 * b)
            .copy_from(&(r.transpose() * block * r));
    }
    out
}

/// A node of a side with its 3 × 6 displacement and rotation blocks.
type SideBlock = (usize, SMatrix<f64, 3, 6>, SMatrix<f64, 3, 6>);

/// The rotation block of weight w: [0 | w I].
fn rotation_block(w: f64) -> SMatrix<f64, 3, 6> {
    let mut m = SMatrix::<f64, 3, 6>::zeros();
    for d in 0..3 {
        m[(d, 3 + d)] = w;
    }
    m
}

/// The part of a side: its nodes and their blocks.
fn side_blocks(model: &Model, side: ContactSide) -> Vec<SideBlock> {
    match side {
        ContactSide::Node(n) => vec![(n, SMatrix::<f64, 3, 6>::identity(), rotation_block(1.0))],
        ContactSide::Point { element, xi } => {
            let e = model.elements()[element];
            let a = centerline_interpolation(
                &model.nodes[e.nodes[0]].x,
                &model.nodes[e.nodes[1]].x,
                xi,
            );
            vec![
                (
                    e.nodes[0],
                    a.fixed_view::<3, 6>(0, 0).into_owned(),
                    rotation_block(1.0 - xi),
                ),
                (
                    e.nodes[1],
                    a.fixed_view::<3, 6>(0, 6).into_owned(),
                    rotation_block(xi),
                ),
            ]
        }
    }
}

/// The jump operators of a contact between side `a` and side `b`, whose element image is
/// shifted by `shift` periods (\[0, 0\] outside periodic cells); `None` if the two sides share
/// a node of the same image (a contact of a node with itself is meaningless).
pub fn jump_operator(
    model: &Model,
    a: ContactSide,
    b: ContactSide,
    shift: [i32; 2],
) -> Option<Jump> {
    let first = side_blocks(model, a);
    let second = side_blocks(model, b);
    if shift == [0, 0]
        && first
            .iter()
            .any(|(n, ..)| second.iter().any(|(m, ..)| m == n))
    {
        return None;
    }
    let mut jump = Jump {
        nodes: Vec::with_capacity(4),
        shifts: Vec::with_capacity(4),
        b: JumpMatrix::zeros(),
        r: JumpMatrix::zeros(),
    };
    for (sign, s, blocks) in [(1.0, [0, 0], first), (-1.0, shift, second)] {
        for (n, mu, mr) in blocks {
            let k = jump.nodes.len();
            jump.nodes.push(n);
            jump.shifts.push(s);
            jump.b
                .fixed_view_mut::<3, 6>(0, 6 * k)
                .copy_from(&(mu * sign));
            jump.r
                .fixed_view_mut::<3, 6>(0, 6 * k)
                .copy_from(&(mr * sign));
        }
    }
    Some(jump)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn interpolation_reproduces_rigid_motions_and_nodal_values() {
        let (p1, p2) = ([0.3, -0.2, 0.5], [1.1, 0.4, 0.9]);
        let omega = Vector3::new(0.02, -0.01, 0.03);
        let t = Vector3::new(0.1, 0.2, -0.3);
        // Rigid motion: u(x) = t + ω × x, θ = ω at both nodes.
        let mut q = SMatrix::<f64, 12, 1>::zeros();
        for (k, p) in [p1, p2].iter().enumerate() {
            let u = t + omega.cross(&Vector3::from(*p));
            for d in 0..3 {
                q[6 * k + d] = u[d];
                q[6 * k + 3 + d] = omega[d];
            }
        }
        for xi in [0.0, 0.25, 0.5, 0.9, 1.0] {
            let x = Vector3::from(p1) + (Vector3::from(p2) - Vector3::from(p1)) * xi;
            let u = centerline_interpolation(&p1, &p2, xi) * q;
            let want = t + omega.cross(&x);
            assert!((u - want).norm() < 1e-14, "ξ = {xi}");
        }
        let a0 = centerline_interpolation(&p1, &p2, 0.0);
        let a1 = centerline_interpolation(&p1, &p2, 1.0);
        for i in 0..3 {
            for j in 0..12 {
                let want0 = if j == i { 1.0 } else { 0.0 };
                let want1 = if j == 6 + i { 1.0 } else { 0.0 };
                assert!((a0[(i, j)] - want0).abs() < 1e-14 && (a1[(i, j)] - want1).abs() < 1e-14);
            }
        }
    }
}
