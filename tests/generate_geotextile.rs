//! Geotextile generator against beam theory.
//!
//! * A biaxial 0°/90° grid with fixed junctions has the closed-form ABD of
//!   `tests/homogenize_lattice.rs` (A11 = EA/s_y, A66 = 12EI/((s_x + s_y) s_x s_y), …).
//! * The same grid turned by 45° (families at ±45°, cell s√2 × s√2) has the tensor rotation of
//!   that ABD: energy invariance gives A_rot = Tᵀ A T with T the engineering-strain rotation.
//! * Two layers (x-fibers below, y-fibers above, joined by connector beams): under ε11 and κ11
//!   the affine plate field u_x = (ε − zκ) x, w = κx²/2 strains no y-fiber and no connector and
//!   leaves every x-fiber uniformly stressed, so it is the solution: A11 = EA/s,
//!   B11 = −EA e/s, D11 = (EI + EA e²)/s with e the x-fibers' height below the mid-surface.
//! * Families that do not fit the periods and bad parameters are errors naming the family.

mod common;
use common::grid_abd::{assert_abd, grid_abd};
use fibercell::generate::{geotextile, FiberFamily, Geotextile, LayerJunction};
use fibercell::homogenize::{homogenize_elastic, Homogenized};
use fibercell::model::ModelDescription;
use fibercell::solve::SolveOptions;
use fibercell::{Error, Model};
use std::f64::consts::PI;

const E: f64 = 1e8;
const NU: f64 = 0.3;
const R: f64 = 5e-4;

fn family(angle_degrees: f64, spacing: f64, layer: usize) -> FiberFamily {
    FiberFamily {
        angle_degrees,
        spacing,
        radius: R,
        offset: None,
        layer,
    }
}

fn homogenize(d: &ModelDescription) -> Homogenized {
    homogenize_elastic(
        &Model::from_description(d).unwrap(),
        &SolveOptions::default(),
    )
    .unwrap()
}

fn grid_closed_form(sx: f64, sy: f64) -> [[f64; 6]; 6] {
    grid_abd(E, NU, R, sx, sy)
}

#[test]
fn a_biaxial_grid_has_the_beam_theory_abd() {
    let g = Geotextile {
        size: [1.2e-2, 1e-2],
        families: vec![family(0.0, 5e-3, 0), family(90.0, 4e-3, 0)],
        ..Geotextile::default()
    };
    let d = geotextile(&g).unwrap();
    // Two x-fibers and three y-fibers per cell, six junctions.
    assert_eq!(d.fibers.len(), 5);
    let h = homogenize(&d);
    assert_abd(&h.abd, &grid_closed_form(4e-3, 5e-3), 1e-8);
    // The stage timings are laps of one clock, but for the pressure load, which runs on a
    // thread beside the analysis and factorization: non-negative, the laps adding up to at
    // most the total.
    let t = h.timings;
    let laps = t.stages();
    assert!(laps.iter().all(|&v| v >= 0.0));
    let serial = laps.iter().sum::<f64>() - t.pressure_load;
    assert!(serial <= t.total * (1.0 + 1e-9) && t.total > 0.0);
    assert!(t.pressure_load <= t.total);
}

#[test]
fn a_grid_turned_by_45_degrees_has_the_rotated_abd() {
    let s = 5e-3;
    let l = s * 2f64.sqrt();
    let g = Geotextile {
        size: [l, l],
        families: vec![family(45.0, s, 0), family(135.0, s, 0)],
        element_length: 1e-3,
        ..Geotextile::default()
    };
    let d = geotextile(&g).unwrap();
    let h = homogenize(&d);
    // Material frame along the fibers: ε' = T ε.
    let (sn, cs) = (PI / 4.0).sin_cos();
    let t = [
        [cs * cs, sn * sn, cs * sn],
        [sn * sn, cs * cs, -cs * sn],
        [-2.0 * cs * sn, 2.0 * cs * sn, cs * cs - sn * sn],
    ];
    let base = grid_closed_form(s, s);
    let mut want = [[0.0; 6]; 6];
    for block in [0, 3] {
        for r in 0..3 {
            for c in 0..3 {
                want[block + r][block + c] = (0..3)
                    .flat_map(|p| (0..3).map(move |q| (p, q)))
                    .map(|(p, q)| t[p][r] * base[block + p][block + q] * t[q][c])
                    .sum();
            }
        }
    }
    assert_abd(&h.abd, &want, 1e-8);
    // Unlike the 0°/90° grid, the turned grid couples the normal strains: A12 ≠ 0.
    assert!(h.abd[0][1].abs() > 1e-3 * h.abd[0][0]);
}

#[test]
fn two_layers_joined_by_connectors_follow_the_affine_plate_field() {
    let s = 5e-3;
    let g = Geotextile {
        families: vec![family(0.0, s, 0), family(90.0, s, 1)],
        ..Geotextile::default()
    };
    let d = geotextile(&g).unwrap();
    // Four fibers and four connectors.
    assert_eq!(d.fibers.len(), 8);
    let zs: Vec<f64> = d.nodes.iter().map(|n| n.x[2]).collect();
    let (lo, hi) = zs
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &z| (a.min(z), b.max(z)));
    let e = 0.5 * (hi - lo); // the x-fibers sit e below the mid-surface
    assert!((e - R).abs() < 1e-8 * R);
    let h = homogenize(&d);
    let (a, i) = (PI * R * R, PI * R.powi(4) / 4.0);
    let close = |got: f64, want: f64| (got - want).abs() <= 1e-8 * want.abs();
    assert!(close(h.abd[0][0], E * a / s), "A11 {:e}", h.abd[0][0]);
    assert!(close(h.abd[1][1], E * a / s), "A22 {:e}", h.abd[1][1]);
    assert!(
        close(h.abd[0][3].abs(), E * a * e / s),
        "B11 {:e}",
        h.abd[0][3]
    );
    assert!(
        close(h.abd[3][3], (E * i + E * a * e * e) / s),
        "D11 {:e}",
        h.abd[3][3]
    );
    // The y-fibers lie above: B22 has the opposite sign of B11.
    assert!(h.abd[0][3] * h.abd[1][4] < 0.0);
}

#[test]
fn layers_in_contact_close_every_crossing() {
    let g = Geotextile {
        families: vec![family(0.0, 5e-3, 0), family(90.0, 5e-3, 1)],
        layer_junction: LayerJunction::Contact { mu: 0.3 },
        ..Geotextile::default()
    };
    let d = geotextile(&g).unwrap();
    assert_eq!(d.fibers.len(), 4, "no connectors");
    let m = Model::from_description(&d).unwrap();
    let stats = fibercell::stats::network_stats(&m).unwrap();
    assert_eq!(stats.contacts, 4);
    let h = homogenize(&d);
    assert_eq!(h.contacts, 4);
    let a = PI * R * R;
    // Stretching along the fibers does not load the contacts.
    assert!((h.abd[0][0] - E * a / 5e-3).abs() <= 1e-8 * h.abd[0][0]);
}

#[test]
fn every_boundary_node_pairs_for_oblique_families() {
    // Three families at 0°, 60° and 120° in a 1 × √3 cell: oblique pieces cross the faces, and
    // the lattice has the hexagonal symmetry that makes A isotropic.
    let s = 2.5e-3 * 3f64.sqrt();
    let g = Geotextile {
        size: [5e-3, 5e-3 * 3f64.sqrt()],
        families: vec![family(0.0, s, 0), family(60.0, s, 0), family(120.0, s, 0)],
        element_length: 5e-4,
        ..Geotextile::default()
    };
    let d = geotextile(&g).unwrap();
    let m = Model::from_description(&d).unwrap();
    let p = fibercell::cell::pair_boundary_nodes(&m).unwrap();
    assert!(p.n_slaves() > 0);
    let h = homogenize(&d);
    // A triangular lattice is isotropic in plane: A11 = A22, A66 = (A11 − A12)/2.
    let a = h.abd;
    assert!((a[0][0] - a[1][1]).abs() < 1e-8 * a[0][0]);
    assert!((a[2][2] - 0.5 * (a[0][0] - a[0][1])).abs() < 1e-8 * a[0][0]);
}

#[test]
fn families_that_do_not_fit_the_periods_are_errors() {
    let g = Geotextile {
        families: vec![family(0.0, 5e-3, 0), family(30.0, 5e-3, 0)],
        ..Geotextile::default()
    };
    let err = geotextile(&g).unwrap_err();
    assert!(matches!(err, Error::InvalidOption(_)));
    assert!(err.to_string().contains("families[1]"), "{err}");
    for bad in [
        Geotextile {
            families: vec![FiberFamily {
                radius: -1.0,
                ..family(0.0, 5e-3, 0)
            }],
            ..Geotextile::default()
        },
        Geotextile {
            families: vec![family(0.0, 5e-3, 0), family(90.0, 5e-3, 2)],
            ..Geotextile::default()
        },
        Geotextile {
            families: vec![FiberFamily {
                offset: Some(0.0),
                ..family(0.0, 5e-3, 0)
            }],
            ..Geotextile::default()
        },
    ] {
        let err = geotextile(&bad).unwrap_err();
        assert!(matches!(err, Error::InvalidOption(_)), "{err}");
    }
}
