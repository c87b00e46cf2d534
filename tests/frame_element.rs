//! Properties of the 12×12 frame element: symmetry, positive semi-definiteness with exactly six
//! rigid-body modes for any orientation, length and radius; agreement with an independent
//! Gauss-quadrature integration of ∫ Bᵀ D B ds (thesis 4.34) from the shape functions.

mod common;
use common::quadrature_local_stiffness;
use fibercell::element::{global_stiffness, local_stiffness, FrameStiffness, Matrix12};
use nalgebra::{DMatrix, SymmetricEigen, Vector3};
use proptest::prelude::*;

fn props(r: f64) -> FrameStiffness {
    let (e, g) = (2.0e11, 8.0e10);
    let pi = std::f64::consts::PI;
    FrameStiffness {
        ea: e * pi * r * r,
        ei2: e * pi * r.powi(4) / 4.0,
        ei3: e * pi * r.powi(4) / 4.0,
        gj: g * pi * r.powi(4) / 2.0,
    }
}

/// The six rigid-body motions of the element's two nodes: translations and small rotations
/// u = ω × x, θ = ω.
fn rigid_modes(p1: [f64; 3], p2: [f64; 3]) -> Vec<[f64; 12]> {
    let mut modes = Vec::new();
    for k in 0..3 {
        let mut m = [0.0; 12];
        m[k] = 1.0;
        m[6 + k] = 1.0;
        modes.push(m);
    }
    for k in 0..3 {
        let mut w = Vector3::zeros();
        w[k] = 1.0;
        let mut m = [0.0; 12];
        for (a, p) in [p1, p2].iter().enumerate() {
            let u = w.cross(&Vector3::new(p[0], p[1], p[2]));
            for d in 0..3 {
                m[6 * a + d] = u[d];
                m[6 * a + 3 + d] = w[d];
            }
        }
        modes.push(m);
    }
    modes
}

fn scaled(k: &Matrix12) -> DMatrix<f64> {
    // Congruence with diag(k)^(-1/2): same inertia (Sylvester), far better conditioned.
    let d: Vec<f64> = (0..12).map(|i| 1.0 / k[(i, i)].sqrt()).collect();
    DMatrix::from_fn(12, 12, |i, j| k[(i, j)] * d[i] * d[j])
}

fn point() -> impl Strategy<Value = [f64; 3]> {
    prop::array::uniform3(-2.0f64..2.0)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn symmetric_psd_with_exactly_six_rigid_modes(
        p1 in point(),
        dir in prop::array::uniform3(-1.0f64..1.0),
        len in 1e-3f64..5.0,
        slender in 5.0f64..2000.0,
    ) {
        let norm = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
        prop_assume!(norm > 1e-3);
        let p2 = [p1[0] + len * dir[0] / norm, p1[1] + len * dir[1] / norm, p1[2] + len * dir[2] / norm];
        let k = global_stiffness(&p1, &p2, &props(len / slender));
        let max = k.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        prop_assert!((k - k.transpose()).amax() <= 1e-13 * max);
        // Rigid-body motions produce no forces.
        for m in rigid_modes(p1, p2) {
            let v = nalgebra::SVector::<f64, 12>::from_column_slice(&m);
            let f = k * v;
            prop_assert!(f.amax() <= 1e-9 * max * v.amax().max(1.0), "rigid mode loads the element: {}", f.amax());
        }
        // Exactly six zero eigenvalues, the other six positive.
        let eig = SymmetricEigen::new(scaled(&k)).eigenvalues;
        let mut ev: Vec<f64> = eig.iter().copied().collect();
        ev.sort_by(f64::total_cmp);
        prop_assert!(ev[0] > -1e-10, "negative eigenvalue {}", ev[0]);
        prop_assert!(ev[5] < 1e-10, "fewer than six zero eigenvalues: {ev:?}");
        prop_assert!(ev[6] > 1e-8, "more than six zero eigenvalues: {ev:?}");
    }
}

#[test]
fn local_stiffness_equals_quadrature_of_bt_d_b() {
    let l = 0.37;
    let p = FrameStiffness {
        ea: 3.0e5,
        ei2: 7.0,
        ei3: 11.0,
        gj: 5.0,
    };
    let k = quadrature_local_stiffness(p.ea, p.ei2, p.ei3, p.gj, l);
    let closed = local_stiffness(&p, l);
    let max = k.amax();
    for i in 0..12 {
        for j in 0..12 {
            assert!(
                (closed[(i, j)] - k[(i, j)]).abs() <= 1e-12 * max,
                "entry ({i},{j}): {} vs {}",
                closed[(i, j)],
                k[(i, j)]
            );
        }
    }
}
