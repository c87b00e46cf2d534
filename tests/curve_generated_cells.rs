//! The friction curve of every generator's default cell, as `fibercell curve CELL --strain X`
//! runs it: in equilibrium at every increment, or refused with a typed error, never garbage.

use fibercell::generate::{geotextile, knitted, Geotextile, Knit};
use fibercell::homogenize::{elasto_plastic_curve, Curve, CurveOptions};
use fibercell::model::ModelDescription;
use fibercell::solve::IncrementalOptions;
use fibercell::Error;

fn curve(desc: &ModelDescription, strain: &str) -> Result<Curve, Error> {
    let model = fibercell::Model::from_description(desc).expect("model");
    elasto_plastic_curve(
        &model,
        &CurveOptions {
            strain: fibercell::cell::parse_macro_strain(strain).expect("strain"),
            steps: 100,
            unload: false,
            incremental: IncrementalOptions::default(),
        },
    )
}

fn max_residual(c: &Curve) -> f64 {
    c.points
        .iter()
        .map(|p| p.equilibrium_residual)
        .fold(0.0, f64::max)
}

/// The default knit (bonded: interlocked loops) under e11, e22 and g12: every contact slides
/// by 1 %, nothing is held, every increment within 1e-8 (measured 2.2–2.7e-9).
#[test]
fn the_default_knit_runs_in_equilibrium() {
    let desc = knitted(&Knit::default()).expect("knit");
    for strain in ["e11=0.01", "e22=0.01", "g12=0.01"] {
        let c = curve(&desc, strain).expect("the curve runs");
        assert!(c.points.iter().all(|p| p.held == 0), "{strain}");
        assert!(max_residual(&c) <= 1e-8, "{strain}: {:e}", max_residual(&c));
        assert!(c.points.last().is_some_and(|p| p.slip > 0), "{strain}");
    }
}

/// Unloaded back to zero strain the knit's contacts carry almost no normal force, hence almost
/// no friction: near zero the state iteration holds them (all 16 from increment 152 of 300),
/// the increments report it, and their residual, measured against the peak load's forces,
/// stays below 10⁻³ (measured 6.2·10⁻⁴); where nothing is held it is below 10⁻⁸. Before, the
/// residual was measured against the nearly vanishing forces at zero strain, read 0.2–0.4 and
/// stopped the curve at the end of unloading.
#[test]
fn the_default_knit_unloads_to_zero() {
    let desc = knitted(&Knit::default()).expect("knit");
    let model = fibercell::Model::from_description(&desc).expect("model");
    let c = elasto_plastic_curve(
        &model,
        &CurveOptions {
            strain: [0.01, 0.0, 0.0, 0.0, 0.0, 0.0],
            steps: 100,
            unload: true,
            incremental: IncrementalOptions::default(),
        },
    )
    .expect("the curve runs");
    assert_eq!(c.points.len(), 300);
    for p in &c.points {
        let bar = if p.held == 0 { 1e-8 } else { 1e-3 };
        assert!(
            p.equilibrium_residual <= bar,
            "increment {} ({} held): {:e}",
            p.step,
            p.held,
            p.equilibrium_residual
        );
    }
}

/// With unilateral contacts the relaxed knit has no hold in shear: every contact opens or
/// slides in the first increment and the held state is a mechanism. That is an error — before,
/// the curve "completed" with resultants of 10¹⁴³ N/m and residuals of order 1. Which error
/// depends on the last bits of the factorization: where the mechanism's pivot comes out as
/// roundoff, the solve returns huge displacements and the increment is `NoEquilibrium`, naming
/// the increment, the held contacts and the remedy (the release build); where it comes out
/// zero, the factorization reports the singular node and fiber (the test profile).
#[test]
fn a_knit_without_hold_is_an_error_not_garbage() {
    let mut desc = knitted(&Knit::default()).expect("knit");
    desc.contact.as_mut().expect("contact").bonded = false;
    let e = curve(&desc, "g12=0.01").expect_err("no equilibrium");
    let text = e.to_string();
    match e {
        Error::NoEquilibrium { step: 1, .. } => assert!(
            text.contains("--bonded") && text.contains("contact 1 ("),
            "{text}"
        ),
        _ => assert!(
            text.contains("singular") && text.contains("fiber"),
            "neither NoEquilibrium at increment 1 nor a singular stiffness: {text}"
        ),
    }
}

/// A cell without contacts (the default geotextile) is linear, and its residual is measured
/// against the elements' forces on every DOF: before, on the free DOFs alone, those vanish at
/// equilibrium and the residual read 1.0 at every increment.
#[test]
fn a_cell_without_contacts_reports_a_small_residual() {
    let desc = geotextile(&Geotextile::default()).expect("geotextile");
    for strain in ["e11=0.01", "g12=0.01"] {
        let c = curve(&desc, strain).expect("the curve runs");
        assert!(max_residual(&c) <= 1e-9, "{strain}: {:e}", max_residual(&c));
    }
}
