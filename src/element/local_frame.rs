//! The element's local axes, well defined for every orientation.

use nalgebra::{Matrix3, Vector3};

/// Rotation whose rows are the local axes e1 (along the element, first → second node), e2, e3
/// in global coordinates; it maps global components to local ones (the thesis's C^eᵀ, 4.41).
///
/// e2 is built from the global axis least aligned with e1, so the frame never degenerates
/// (fibers parallel to z included). Circular sections make the stiffness independent of the
/// choice of e2.
pub fn local_frame(p1: &[f64; 3], p2: &[f64; 3]) -> (Matrix3<f64>, f64) {
    let d = Vector3::new(p2[0] - p1[0], p2[1] - p1[1], p2[2] - p1[2]);
    let length = d.norm();
    let e1 = d / length;
    let k = (0..3)
        .min_by(|&a, &b| e1[a].abs().total_cmp(&e1[b].abs()))
        .unwrap_or(2);
    let mut aux = Vector3::zeros();
    aux[k] = 1.0;
    let e2 = (aux - e1 * e1.dot(&aux)).normalize();
    let e3 = e1.cross(&e2);
    (
        Matrix3::from_rows(&[e1.transpose(), e2.transpose(), e3.transpose()]),
        length,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orthonormal_right_handed_for_axis_aligned_and_oblique() {
        for p2 in [
            [0.0, 0.0, 2.0],
            [0.0, 0.0, -1.0],
            [3.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, -2.0, 0.5],
        ] {
            let (r, l) = local_frame(&[0.0; 3], &p2);
            let n = (p2[0] * p2[0] + p2[1] * p2[1] + p2[2] * p2[2]).sqrt();
            assert!((l - n).abs() < 1e-15);
            assert!((r * r.transpose() - Matrix3::identity()).norm() < 1e-14);
            assert!((r.determinant() - 1.0).abs() < 1e-14);
            for k in 0..3 {
                assert!((r[(0, k)] - p2[k] / n).abs() < 1e-15);
            }
        }
    }
}
