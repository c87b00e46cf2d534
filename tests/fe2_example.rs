//! The FE² example (`examples/fe2_strip.rs`): a strip of membrane elements whose integration
//! points hold states of the non-woven fixture cell, solved by Newton with the cells'
//! consistent tangents.

#[allow(dead_code)]
#[path = "../examples/fe2_strip.rs"]
mod fe2_strip;

use fe2_strip::{Fe2, Grips, Strip};
use fibercell::io::load_model;
use fibercell::solve::IncrementalOptions;
use fibercell::{Cell, Model};

fn fixture() -> Model {
    load_model(std::path::Path::new("fixtures/cells/nonwoven_small.toml")).expect("fixture loads")
}

const STRIP: Strip = Strip {
    nx: 2,
    ny: 2,
    length: 0.1,
    width: 0.05,
};

/// Under a homogeneous macro strain (every boundary node moved affinely, the one interior node
/// found by Newton) every integration point follows the single cell's curve: ε11 = 10⁻³ per
/// step to 4·10⁻³ (contacts sliding from the second step), each point's resultants equal to
/// those of one cell updated by the same increments, to 1e-8 of the largest (the macro Newton
/// tolerance is 1e-9).
#[test]
fn a_homogeneous_strain_gives_the_single_cell_curve() {
    let model = fixture();
    let mut fe2 = Fe2::new(&model, STRIP, Grips::Affine([1.0, 0.0, 0.0])).expect("set up");
    let cell = Cell::new(&model, &IncrementalOptions::default())
        .expect("cell")
        .without_tangent();
    let mut single = cell.new_state();
    for k in 1..=4 {
        let step = fe2.step(1e-3 * k as f64).expect("step converges");
        let one = cell
            .update(&mut single, &[1e-3, 0.0, 0.0, 0.0, 0.0, 0.0])
            .expect("update");
        let scale = one.resultant.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for r in &step.responses {
            for (a, b) in r.resultant.iter().zip(&one.resultant) {
                assert!((a - b).abs() <= 1e-8 * scale, "step {k}: {a} vs {b}");
            }
        }
        if k > 1 {
            assert!(one.slip > 0, "step {k}: nothing slides");
        }
    }
}

/// Between clamped grips (the lateral contraction restrained near them, the strain not
/// uniform) Newton converges quadratically while no contact switches: every step converges,
/// and for each iteration after which no point's contact counts changed, from a residual r
/// above 10⁻⁴ (so that r² stays far above the noise of the cells' own equilibrium, which
/// leaves up to 3·10⁻¹⁰ of the macro forces), the next residual is at most r² (measured
/// ≤ 3.4·10⁻³ r²; a linear rate of 0.3 would give 0.3 r, far above r² there). Contacts slide
/// from the second step on. A macro tangent 10 % off fails it (855 r²); the cell tangent
/// without its Coulomb slope, small at these strains, costs one or two more iterations and
/// is not caught here (`tests/cell_kernel.rs` checks that slope).
#[test]
fn newton_converges_quadratically_while_no_contact_switches() {
    let model = fixture();
    let mut fe2 = Fe2::new(&model, Strip { ny: 1, ..STRIP }, Grips::Clamped).expect("set up");
    let mut checked = 0;
    let mut worst = 0.0f64;
    let mut sliding = 0;
    for k in 1..=5 {
        let step = fe2.step(1e-4 * k as f64).expect("step converges");
        let r = &step.residuals;
        println!("step {k}: residuals {r:?}");
        for i in 1..r.len() - 1 {
            if step.counts[i] == step.counts[i + 1] && r[i] > 1e-4 {
                checked += 1;
                worst = worst.max(r[i + 1] / (r[i] * r[i]));
            }
        }
        sliding = step.responses.iter().map(|r| r.slip).sum();
    }
    println!("{checked} iterations checked, largest r_k+1 / r_k² = {worst:.2}");
    assert!(checked >= 2, "only {checked} iterations without switches");
    assert!(worst <= 1.0, "r_k+1 / r_k² = {worst}");
    assert!(sliding > 0);
}
