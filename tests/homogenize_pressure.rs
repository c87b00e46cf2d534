//! The out-of-plane pressure problem Θ (thesis 3.28, 5.2, 5.4): 1 Pa on the fibers seen from
//! above, balanced by a uniform body force, zero macroscopic strain; B^hom is the averaged
//! resultant per unit pressure.
//!
//! * A flat network of straight fibers under vertical loads has no in-plane forces (membrane
//!   and bending decouple), and every fiber's mean bending and twisting moment is EI·[w′] / L or
//!   GJ·[θ] / L over a period — zero, since slopes and twists are periodic when E = 0. So
//!   B^hom = 0 exactly.
//! * Betti's reciprocity gives B^hom without the Θ solve: with ñ_k the periodic fluctuation of
//!   the k-th unit cell problem (u − M(x) e_k) and P the pressure load, B^hom_k |Y| =
//!   −(work of P on ñ_k) (the continuum identity behind 5.4). It is checked on a cell whose
//!   tilted contacts couple the pressure to stretching and bending (B^hom ≠ 0), cut through a
//!   contact so that some of the load sits on periodic images.
//! * Coverage: a cross of one x- and one y-fiber covers (2r Lx + 2r Ly − 4r²) / (Lx Ly) of the
//!   cell, to the pixel resolution.

mod common;
use common::zigzag;
use common::GridCell;
use fibercell::cell::macro_matrix;
use fibercell::homogenize::{homogenize_elastic, pressure_load, Homogenized};
use fibercell::solve::SolveOptions;
use fibercell::Model;

fn homogenize(d: &fibercell::model::ModelDescription) -> (Model, Homogenized) {
    let m = Model::from_description(d).unwrap();
    let h = homogenize_elastic(&m, &SolveOptions::default()).unwrap();
    (m, h)
}

const R: f64 = 2e-4;

/// A grid cell with fixed junctions at the given fractions of the periods.
fn grid(
    size: [f64; 2],
    joint: [f64; 2],
    periods: [usize; 2],
    sub: usize,
) -> fibercell::model::ModelDescription {
    GridCell {
        young: 1e9,
        poisson: 0.3,
        radius: R,
        size,
        joint: [joint[0] * size[0], joint[1] * size[1]],
        periods,
        sub,
    }
    .build()
}

#[test]
fn a_flat_network_has_no_pressure_resultants() {
    let (lx, ly) = (4e-3, 3e-3);
    let d = grid([lx, ly], [0.3, 0.6], [2, 1], 3);
    let (_, h) = homogenize(&d);
    let p = &h.pressure;
    assert!(p.coverage > 0.1 && p.coverage < 1.0);
    // The solution is not trivial: the fibers bend under the load.
    let w = p
        .displacements
        .iter()
        .map(|u| u[2].abs())
        .fold(0.0, f64::max);
    assert!(w > 0.0);
    for k in 0..3 {
        assert!(p.b_hom[k].abs() <= 1e-9 * lx, "N[{k}] = {}", p.b_hom[k]);
        assert!(
            p.b_hom[3 + k].abs() <= 1e-9 * lx * lx,
            "M[{k}] = {}",
            p.b_hom[3 + k]
        );
    }
}

#[test]
fn b_hom_is_the_work_of_the_pressure_on_the_unit_cell_problems() {
    for x0 in [0.0, zigzag::seam()] {
        let (m, h) = homogenize(&zigzag::cell(x0, 1.0));
        let g = h.geometry.unwrap();
        // The physical nodal loads, recomputed from the public load builder.
        let load = pressure_load(&m, &g, 1.0, h.pressure.pixel);
        let mut nodal = vec![[0.0; 6]; m.nodes.len()];
        for (e, _, f) in &load.elements {
            for (k, &n) in m.elements()[*e].nodes.iter().enumerate() {
                for d in 0..6 {
                    nodal[n][d] += f[6 * k + d];
                }
            }
        }
        // The periodic fluctuation of case k at every node (the same for every image).
        let fluctuation = |k: usize, n: usize| {
            let x = g.relative(&m.nodes[n].x);
            let mm = macro_matrix(x[0], x[1], x[2]);
            let u = h.cases[k][n];
            std::array::from_fn::<f64, 6, _>(|d| u[d] - mm[(d, k)])
        };
        let total_z: f64 = nodal.iter().map(|f| f[2]).sum();
        assert!(total_z.abs() <= 1e-12 * load.force, "self-equilibrated");
        let scale = h.pressure.b_hom.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        assert!(
            scale > 0.0,
            "tilted contacts couple pressure and stretching"
        );
        for k in 0..6 {
            let work: f64 = nodal
                .iter()
                .enumerate()
                .map(|(n, f)| {
                    let u = fluctuation(k, n);
                    (0..6).map(|d| f[d] * u[d]).sum::<f64>()
                })
                .sum();
            let want = -work / h.area;
            let got = h.pressure.b_hom[k];
            // Rows have different units (m, m²): compare with the largest |B| of its kind.
            let kind = (if k < 3 { 0..3 } else { 3..6 })
                .map(|j| h.pressure.b_hom[j].abs())
                .fold(0.0, f64::max);
            assert!(
                (got - want).abs() <= 1e-7 * kind,
                "cut at {x0}: B[{k}] = {got} vs reciprocity {want}"
            );
        }
    }
}

#[test]
fn the_pressure_acts_on_the_covered_area() {
    let (lx, ly, r) = (4e-3, 5e-3, R);
    let d = grid([lx, ly], [0.37, 0.61], [1, 1], 2);
    let m = Model::from_description(&d).unwrap();
    let g = fibercell::cell::pair_boundary_nodes(&m).unwrap().geometry;
    let pixel = r / 16.0;
    let load = pressure_load(&m, &g, 1.0, pixel);
    let want = (2.0 * r * lx + 2.0 * r * ly - 4.0 * r * r) / (lx * ly);
    // Each band edge is resolved to a pixel: at most one pixel per edge and column.
    assert!(
        (load.coverage - want).abs()
            <= 2.0 * load.pixel / (lx.min(ly)) + 2.0 * load.pixel * (lx + ly) / (lx * ly),
        "{} vs {want}",
        load.coverage
    );
    assert!((load.force - load.coverage * lx * ly).abs() <= 1e-12 * load.force);
}
