//! A triangular lattice with rigid joints: as the slenderness r/L → 0 its membrane stiffness
//! tends to the pin-jointed, stretch-dominated limit. Three bar families at 0°, 60°, 120°, one
//! bar of each per lattice node, node area √3/2 L²: C_ijkl = (EA L / A_node) Σ n_i n_j n_k n_l, so
//! A11 = A22 = (3√3/4) EA/L, A12 = A66 = (√3/4) EA/L (ν = 1/3). Rigid joints add bending, a
//! correction of relative order (r/L)².

use fibercell::homogenize::homogenize_elastic;
use fibercell::model::{CellSpec, FiberSpec, MaterialSpec, ModelDescription, NodeSpec};
use fibercell::solve::SolveOptions;
use fibercell::Model;
use std::collections::HashMap;
use std::f64::consts::PI;

const L: f64 = 1e-3;
const E: f64 = 1e9;

/// The lattice in a rectangular cell L × √3 L (two lattice nodes), shifted so that no lattice
/// node lies on the boundary; bars are split where they cross the cell faces.
fn lattice(r: f64) -> ModelDescription {
    let (lx, ly) = (L, 3f64.sqrt() * L);
    let mut d = ModelDescription {
        materials: vec![MaterialSpec {
            name: "m".into(),
            young: E,
            poisson: Some(0.3),
            shear: None,
        }],
        cell: Some(CellSpec {
            size: [lx, ly],
            origin: Some([0.0, 0.0]),
            thickness: Some(2.0 * r),
            tolerance: None,
        }),
        ..Default::default()
    };
    let mut ids: HashMap<(i64, i64), u64> = HashMap::new();
    let mut node = |d: &mut ModelDescription, x: f64, y: f64| -> u64 {
        let key = ((x / L * 1e9).round() as i64, (y / L * 1e9).round() as i64);
        *ids.entry(key).or_insert_with(|| {
            let id = d.nodes.len() as u64 + 1;
            d.nodes.push(NodeSpec { id, x: [x, y, 0.0] });
            id
        })
    };
    let (ox, oy) = (0.27 * lx, 0.21 * ly);
    let lattice_nodes = [(ox, oy), (ox + 0.5 * L, oy + 0.5 * ly)];
    let mut fid = 0;
    for &(px, py) in &lattice_nodes {
        for k in 0..3 {
            let a = k as f64 * PI / 3.0;
            let (qx, qy) = (px + L * a.cos(), py + L * a.sin());
            // Parameters where the bar crosses the lines x = i Lx and y = j Ly.
            let mut ts = vec![0.0, 1.0];
            for (p0, p1, period) in [(px, qx, lx), (py, qy, ly)] {
                let (lo, hi) = (p0.min(p1), p0.max(p1));
                let mut m = (lo / period).ceil();
                while m * period < hi {
                    ts.push((m * period - p0) / (p1 - p0));
                    m += 1.0;
                }
            }
            ts.sort_by(f64::total_cmp);
            ts.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
            for w in ts.windows(2) {
                let at = |t: f64| (px + t * (qx - px), py + t * (qy - py));
                let mid = at(0.5 * (w[0] + w[1]));
                let (sx, sy) = ((mid.0 / lx).floor() * lx, (mid.1 / ly).floor() * ly);
                let (a0, a1) = (at(w[0]), at(w[1]));
                let n0 = node(&mut d, a0.0 - sx, a0.1 - sy);
                let n1 = node(&mut d, a1.0 - sx, a1.1 - sy);
                fid += 1;
                d.fibers.push(FiberSpec {
                    id: fid,
                    nodes: vec![n0, n1],
                    radius: r,
                    material: "m".into(),
                });
            }
        }
    }
    d
}

#[test]
fn triangular_lattice_tends_to_the_stretch_dominated_limit() {
    let mut errors = Vec::new();
    for slender in [0.02, 0.01, 0.005] {
        let r = slender * L;
        let h = homogenize_elastic(
            &Model::from_description(&lattice(r)).unwrap(),
            &SolveOptions::default(),
        )
        .unwrap();
        let ea_l = E * PI * r * r / L;
        let s3 = 3f64.sqrt();
        let want = [
            (0, 0, 3.0 * s3 / 4.0),
            (1, 1, 3.0 * s3 / 4.0),
            (0, 1, s3 / 4.0),
            (2, 2, s3 / 4.0),
        ];
        let mut worst = 0.0f64;
        for (i, j, c) in want {
            let w = c * ea_l;
            worst = worst.max((h.abd[i][j] - w).abs() / w);
        }
        // Off-diagonal membrane terms vanish (isotropy).
        assert!(h.abd[0][2].abs() <= 1e-9 * ea_l && h.abd[1][2].abs() <= 1e-9 * ea_l);
        assert!(
            worst <= 50.0 * slender * slender,
            "r/L = {slender}: relative error {worst:e}"
        );
        assert!((h.orthotropic.nu12 - 1.0 / 3.0).abs() <= 50.0 * slender * slender);
        errors.push(worst);
    }
    // The correction is of order (r/L)²: halving r/L divides it by about four.
    for w in errors.windows(2) {
        let ratio = w[1] / w[0];
        assert!(ratio > 0.2 && ratio < 0.3, "ratio {ratio} ({errors:?})");
    }
}
