//! Increment cutback: an increment that ends with contacts held off equilibrium is redone as
//! halves. The generated S non-woven sheared to γ12 = 1 % in two increments: in the second,
//! 62 more crossings start to slide at once and, before, the state iteration held 81 contacts
//! and accepted a residual of 4.5·10⁻⁵ (below the error bar `MAX_HELD_RESIDUAL`, far above
//! the equilibrium tolerance 10⁻⁸).

use fibercell::generate::{nonwoven, nonwoven_preset};
use fibercell::homogenize::{elasto_plastic_curve, Curve, CurveOptions};
use fibercell::solve::{IncrementalOptions, EQUILIBRIUM_TOLERANCE};

fn shear(steps: usize) -> Curve {
    let desc = nonwoven(&nonwoven_preset("S", 1).expect("preset"))
        .expect("cell")
        .description;
    let model = fibercell::Model::from_description(&desc).expect("model");
    elasto_plastic_curve(
        &model,
        &CurveOptions {
            strain: [0.0, 0.0, 0.01, 0.0, 0.0, 0.0],
            steps,
            unload: false,
            incremental: IncrementalOptions::default(),
        },
    )
    .expect("the curve runs")
}

/// The second increment is halved once and both halves converge: nothing held, residual
/// within the tolerance; still one point per requested increment, and N12 at 1 % within
/// 0.5 % of the 100-increment curve's (measured 0.07 %: the two-step path is coarse, not
/// wrong).
#[test]
fn a_coarse_increment_that_holds_contacts_is_halved() {
    let coarse = shear(2);
    assert_eq!(coarse.points.len(), 2);
    let last = &coarse.points[1];
    assert!(last.cutbacks >= 1, "{last:?}");
    for p in &coarse.points {
        assert_eq!(p.held, 0, "step {}", p.step);
        assert!(p.equilibrium_residual <= EQUILIBRIUM_TOLERANCE, "{p:?}");
    }
    let fine = shear(100);
    assert!(fine.points.iter().all(|p| p.cutbacks == 0));
    let (a, b) = (last.resultant[2], fine.points[99].resultant[2]);
    assert!((a - b).abs() <= 5e-3 * b.abs(), "N12 {a} against {b}");
    // The dissipation of the halves is the increment's: more than the first point's.
    assert!(last.dissipated > coarse.points[0].dissipated);
}
