//! The plain-weave cell of thesis §5.3.4 (rebuilt: two warps, two wefts, four crossovers in
//! contact, E = 10⁶ Pa, ν = 0.3, μ = 0.3): a penalty-convergence table like Table 5.5. The
//! all-stick moduli converge as the penalty grows, with the error of a penalty method ∝ 1/p:
//! once p is well above the yarns' own stiffness, each decade shrinks the change by about ten.
//! The square weave is invariant under the 90° rotation that swaps warps and wefts, so
//! A11 = A22 and D11 = D22.

use fibercell::generate::{plain_weave, PlainWeave};
use fibercell::homogenize::{homogenize_elastic, Homogenized};
use fibercell::solve::SolveOptions;
use fibercell::{io, Model};
use std::path::Path;

fn moduli(p: f64) -> Homogenized {
    let d = plain_weave(&PlainWeave {
        penalty_normal: Some(p),
        ..PlainWeave::default()
    });
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
    assert_eq!(committed, plain_weave(&PlainWeave::default()));
}
