//! The plain-weave cell of thesis §5.3.4 (rebuilt: two warps, two wefts, four crossovers in
//! contact, E = 10⁶ Pa, ν = 0.3, μ = 0.3): a penalty-convergence table like Table 5.5. The
//! all-stick moduli converge as the penalty grows, with the error of a penalty method ∝ 1/p:
//! once p is well above the yarns' own stiffness, each decade shrinks the change by about ten.
//! The square weave is invariant under the 90° rotation that swaps warps and wefts, so
//! A11 = A22 and D11 = D22.

mod common;
use common::grid_abd::{assert_abd, elastic_abd};
use fibercell::generate::{weave, Weave, WeavePattern};
use fibercell::homogenize::{homogenize_elastic, Homogenized};
use fibercell::solve::SolveOptions;
use fibercell::{io, Model};
use std::path::Path;

fn moduli(p: f64) -> Homogenized {
    let d = weave(&Weave {
        penalty_normal: Some(p),
        ..Weave::default()
    })
    .unwrap();
    homogenize_elastic(
        &Model::from_description(&d).unwrap(),
        &SolveOptions::default(),
    )
    .unwrap()
}

#[test]
fn the_moduli_converge_as_the_penalty_grows() {
    let table: Vec<[f64; 4]> = (4..=7)
        .map(|k| {
            let h = moduli(10f64.powi(k));
            assert_eq!(h.contacts, 4, "the four crossovers are closed");
            let m = &h.moduli;
            [m.a11_11, m.a22_22, m.a12_12, m.a22_11]
        })
        .collect();
    for j in 0..4 {
        let deltas: Vec<f64> = table
            .windows(2)
            .map(|w| (w[1][j] - w[0][j]).abs())
            .collect();
        for w in deltas.windows(2) {
            assert!(
                w[1] < 0.2 * w[0],
                "modulus {j}: changes {deltas:?} do not shrink like 1/p"
            );
        }
        let last = table[3][j];
        assert!(deltas[2] < 2e-2 * last.abs(), "modulus {j} not converged");
    }
}

#[test]
fn the_square_weave_is_symmetric_under_the_quarter_turn() {
    let h = moduli(1e5);
    let a = h.abd;
    assert!((a[0][0] - a[1][1]).abs() <= 1e-9 * a[0][0]);
    assert!((a[3][3] - a[4][4]).abs() <= 1e-9 * a[3][3]);
    assert!(h.asymmetry < 1e-10);
}

#[test]
fn the_committed_fixture_is_the_generated_cell() {
    let committed = io::read_description(Path::new("fixtures/woven_plain.toml")).unwrap();
    assert_eq!(committed, weave(&Weave::default()).unwrap());
}

fn twill(over: usize, under: usize) -> fibercell::model::ModelDescription {
    let r = (over + under) as f64;
    weave(&Weave {
        pattern: WeavePattern::Twill { over, under },
        size: [2e-3 * r, 2e-3 * r],
        ..Weave::default()
    })
    .unwrap()
}

#[test]
fn twill_crossovers_are_all_closed_and_follow_the_pattern() {
    for (over, under) in [(2, 1), (2, 2), (3, 1)] {
        let d = twill(over, under);
        let r = over + under;
        assert_eq!(d.fibers.len(), 2 * r);
        assert_eq!(
            fibercell::stats::network_stats(&Model::from_description(&d).unwrap())
                .unwrap()
                .fibers,
            2 * r,
            "each yarn runs around the cell: one ring"
        );
        let m = Model::from_description(&d).unwrap();
        let s = fibercell::stats::network_stats(&m).unwrap();
        assert_eq!(
            s.contacts,
            r * r,
            "{over}/{under} twill: every crossover closed"
        );
        // Warp j floats over `over` consecutive wefts: at weft i (x = (i + ½) L/R) it is up.
        for j in 0..r {
            let warp = &d.fibers[j];
            let ups = (0..r)
                .filter(|&i| {
                    let x = (i as f64 + 0.5) * 2e-3;
                    warp.nodes.iter().any(|&id| {
                        let p = d.nodes[id as usize - 1].x;
                        (p[0] - x).abs() < 1e-12 && p[2] > 0.0
                    })
                })
                .count();
            assert_eq!(ups, over, "warp {j} of the {over}/{under} twill");
        }
    }
}

#[test]
fn a_balanced_twill_homogenizes_with_equal_warp_and_weft_stiffness() {
    // A 2/2 twill maps onto itself when warps and wefts swap (and the cell shifts by one
    // yarn), so A11 = A22 and D11 = D22.
    let h = homogenize_elastic(
        &Model::from_description(&twill(2, 2)).unwrap(),
        &SolveOptions::default(),
    )
    .unwrap();
    assert_eq!(h.contacts, 16);
    let a = h.abd;
    assert!(h.asymmetry < 1e-10);
    assert!(
        (a[0][0] - a[1][1]).abs() <= 1e-8 * a[0][0],
        "{} {}",
        a[0][0],
        a[1][1]
    );
    assert!(
        (a[3][3] - a[4][4]).abs() <= 1e-8 * a[3][3],
        "{} {}",
        a[3][3],
        a[4][4]
    );
    assert!((0..6).all(|k| a[k][k] > 0.0));
}

#[test]
fn bad_weave_parameters_name_the_field() {
    for (bad, field) in [
        (
            Weave {
                radius: 1e-3,
                ..Weave::default()
            },
            "diameter",
        ),
        (
            Weave {
                pattern: WeavePattern::Twill { over: 0, under: 2 },
                ..Weave::default()
            },
            "over 0",
        ),
        (
            Weave {
                young: f64::NAN,
                ..Weave::default()
            },
            "young",
        ),
    ] {
        let err = weave(&bad).unwrap_err().to_string();
        assert!(err.contains(field), "{err}");
    }
}

#[test]
fn the_plain_weave_is_mirror_symmetric_and_independent_of_fiber_direction() {
    // Reflecting x (with a shift of half a cell in y) maps the plain weave onto itself, so every
    // coupling of (ε11, ε22, κ11, κ22) with (γ12, κ12) vanishes; and reversing the node order of
    // every yarn describes the same cell. Both hold only if a crossover, where the discretized
    // yarns are equally close on both sides of the crossover nodes, is placed symmetrically.
    let d = weave(&Weave::default()).unwrap();
    let mut reversed = d.clone();
    for f in &mut reversed.fibers {
        f.nodes.reverse();
    }
    let a = elastic_abd(&d);
    assert_abd(&elastic_abd(&reversed), &a, 1e-9);
    for r in 0..6 {
        for c in 0..6 {
            let scale = (a[r][r] * a[c][c]).sqrt();
            let odd = (r == 2 || r == 5) != (c == 2 || c == 5);
            if odd {
                assert!(
                    a[r][c].abs() <= 1e-9 * scale,
                    "ABD[{r}][{c}] = {:e}",
                    a[r][c]
                );
            }
        }
    }
}
