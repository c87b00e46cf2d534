//! Coulomb sliding with its consistent tangent μ p_N d nᵀ (Newton on the bounds) against the
//! fixed point on the bounds (the default): both solve the same Coulomb law, so on the bonded
//! small non-woven they give the same curve, each increment in equilibrium.
//!
//! The generated mat's crossings are bonded: a crossing pulled apart (N < 0) still slides, at
//! its cohesion c alone, where the bound c + μ max(N, 0) has no slope. Before the tangent took
//! that into account (it used c + μ N), the consistent curve drifted off the law with nothing
//! to notice it: N11 at 1 % 1.3 % low on the S preset, equilibrium residual 4·10⁻².

use fibercell::homogenize::{elasto_plastic_curve, Curve, CurveOptions};
use fibercell::io::load_model;
use fibercell::solve::IncrementalOptions;

fn curve(incremental: IncrementalOptions) -> Curve {
    let model = load_model(std::path::Path::new("fixtures/cells/nonwoven_small.toml"))
        .expect("fixture loads");
    elasto_plastic_curve(
        &model,
        &CurveOptions {
            strain: fibercell::cell::parse_macro_strain("e11=0.01").expect("strain"),
            steps: 50,
            unload: false,
            incremental,
        },
    )
    .expect("the curve runs")
}

/// Every point of the consistent-tangent curve equals the fixed point's to 10⁻⁷ of the largest
/// resultant (both stop when the sliding forces are within 10⁻⁸ of their bounds), is in
/// equilibrium to 10⁻⁸ without holding a contact, and Newton needs fewer state iterations than
/// the fixed point (quadratic against linear convergence of the bounds).
fn assert_same_curve(consistent: &Curve, fixed_point: &Curve) {
    assert_eq!(consistent.points.len(), fixed_point.points.len());
    let scale = fixed_point
        .points
        .iter()
        .map(|p| p.resultant[0].abs())
        .fold(0.0, f64::max);
    for (a, b) in consistent.points.iter().zip(&fixed_point.points) {
        for k in 0..6 {
            let d = (a.resultant[k] - b.resultant[k]).abs();
            assert!(
                d <= 1e-7 * scale,
                "step {} N{k}: {a:?} against {b:?}",
                a.step
            );
        }
        assert!(
            a.equilibrium_residual <= 1e-8 && a.held == 0,
            "step {}: residual {:.2e}, held {}",
            a.step,
            a.equilibrium_residual,
            a.held
        );
    }
    assert!(
        fixed_point.points.last().expect("points").slip > 0,
        "no contact slides"
    );
}

#[test]
fn the_consistent_tangent_gives_the_fixed_points_curve_in_fewer_iterations() {
    let fixed_point = curve(IncrementalOptions::default());
    let consistent = curve(IncrementalOptions {
        consistent_coulomb_tangent: true,
        ..IncrementalOptions::default()
    });
    assert_same_curve(&consistent, &fixed_point);
    let iterations = |c: &Curve| c.points.iter().map(|p| p.iterations).sum::<usize>();
    assert!(
        iterations(&consistent) < iterations(&fixed_point),
        "{} state iterations with the consistent tangent, {} on the fixed point",
        iterations(&consistent),
        iterations(&fixed_point)
    );
}

/// Where the nonsymmetric system cannot be solved on the reference factorization (here: the
/// capacitance order is capped), a state iteration takes a symmetric fixed-point step instead
/// of a sparse LU; the curve is the same.
#[test]
fn symmetric_steps_where_the_reference_cannot_serve_give_the_same_curve() {
    let fixed_point = curve(IncrementalOptions::default());
    let consistent = curve(IncrementalOptions {
        consistent_coulomb_tangent: true,
        max_capacitance_order: Some(40),
        ..IncrementalOptions::default()
    });
    assert_same_curve(&consistent, &fixed_point);
    let increments = &consistent.solution.increments;
    assert!(increments.iter().all(|r| r.backend != "faer-lu"));
    assert!(
        increments
            .iter()
            .any(|r| r.slip > 0 && r.factorizations > 0),
        "no symmetric step was factorized"
    );
}
