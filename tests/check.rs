//! `fibercell::check`: the properties of a user's model — symmetry, definiteness,
//! conditioning, a cell's null space — and the penalty study of its moduli (the CLI's `check`:
//! `cli/tests/check.rs`).

use fibercell::check::{check_model, CheckOptions};
use fibercell::homogenize::homogenize_elastic;
use fibercell::io::load_model;
use fibercell::solve::SolveOptions;
use fibercell::Model;
use std::path::Path;

fn small_nonwoven() -> Model {
    load_model(Path::new("fixtures/cells/nonwoven_small.toml")).expect("fixture loads")
}

fn with_penalty_scale(model: &Model, s: f64) -> Model {
    let mut m = model.clone();
    m.contact.as_mut().expect("contact").penalty_scale = s;
    m
}

/// The small non-woven passes every check; its Richardson limits are the rigid-contact
/// limit: A(×1000), computed on its own, lies within 1e-3 of each (its own 1/p error is
/// C/1000 ≈ 1.2·10⁻⁴ of A11, while the model's penalties are 5–6 % off); and at the
/// recommended penalty every diagonal modulus is within the requested 1 % of its limit up to
/// the misfit of the series-spring form A∞ − C/(s + a) (measured: A11 1.0105 %, the entry
/// that set the scale; 5 % of the accuracy allowed), none below half of it (the
/// recommendation is not wasteful).
#[test]
fn small_nonwoven_passes_and_its_limits_are_the_rigid_contact_limit() {
    let model = small_nonwoven();
    let r = check_model(&model, &CheckOptions::default()).expect("checks run");
    assert!(r.passed(), "{:#?}", r.checks);
    assert!(r.matrix.asymmetry <= 1e-14);
    assert!(r.matrix.positive_definite);
    let t = r.translations.as_ref().expect("a cell has translations");
    assert!(t.relative.iter().all(|&v| v <= 1e-12), "{:?}", t.relative);
    let p = r
        .penalty
        .as_ref()
        .expect("a cell with contacts has the study");
    assert!(
        p.failed.is_none() && p.warnings.is_empty(),
        "{:?}",
        p.warnings
    );
    let diag = |abd: &[[f64; 6]; 6]| (0..6).map(|i| abd[i][i]).collect::<Vec<_>>();
    let opts = SolveOptions::default();
    let far = diag(
        &homogenize_elastic(&with_penalty_scale(&model, 1000.0), &opts)
            .unwrap()
            .abd,
    );
    for (e, a) in p.entries.iter().zip(&far) {
        assert!(
            ((e.limit - a) / a).abs() <= 1e-3,
            "{}: limit {} against A(×1000) {a}",
            e.name,
            e.limit
        );
        assert!(
            e.error_at_model > 0.03 && e.error_at_model < 0.08,
            "{}: {}",
            e.name,
            e.error_at_model
        );
    }
    let s = p.recommended_penalty_scale.expect("a recommendation");
    let at = diag(
        &homogenize_elastic(&with_penalty_scale(&model, s), &opts)
            .unwrap()
            .abd,
    );
    let errors: Vec<f64> = p
        .entries
        .iter()
        .zip(&at)
        .map(|(e, a)| ((a - e.limit) / e.limit).abs())
        .collect();
    let worst = errors.iter().fold(0.0f64, |m, &v| m.max(v));
    assert!(
        worst <= 1.05 * p.accuracy && worst > 0.5 * p.accuracy,
        "{errors:?} at scale {s}"
    );
}

/// A penalty so large that a pivot drowns in round-off: the model as given still passes, the
/// study stops at the scale that fails and says so, and requiring an accuracy fails.
#[test]
fn a_penalty_lost_to_round_off_is_reported() {
    let model = with_penalty_scale(&small_nonwoven(), 1e4);
    let r = check_model(&model, &CheckOptions::default()).expect("checks run");
    assert!(r.passed(), "{:#?}", r.checks);
    let p = r.penalty.as_ref().expect("study");
    let failed = p.failed.as_ref().expect("×100 fails");
    assert!(
        failed.contains("100×") && failed.contains("round-off"),
        "{failed}"
    );
    // Conditioning grows like the penalty: ×10⁴ against the model as generated.
    let base = check_model(
        &small_nonwoven(),
        &CheckOptions {
            penalty_study: false,
            ..CheckOptions::default()
        },
    )
    .unwrap();
    let ratio = r.matrix.condition_estimate.unwrap() / base.matrix.condition_estimate.unwrap();
    assert!(ratio > 1e3 && ratio < 1e5, "κ grew by {ratio}");
    let strict = CheckOptions {
        require_accuracy: true,
        ..CheckOptions::default()
    };
    assert!(!check_model(&model, &strict).unwrap().passed());
}

/// A supported frame: its reduced K is symmetric and positive definite; no cell parts.
#[test]
fn a_supported_frame_passes_without_cell_checks() {
    let model = load_model(Path::new("fixtures/ok_frame3d.toml")).unwrap();
    let r = check_model(&model, &CheckOptions::default()).unwrap();
    assert!(r.passed(), "{:#?}", r.checks);
    assert!(r.translations.is_none() && r.penalty.is_none());
    assert!(r.matrix.backward_error.unwrap() <= 1e-14);
}

/// Penetration at a supported model's solution, against the closed form of the thesis's two
/// bars (§5.2.2; `fixtures/ok_contact_bars1.toml`): bar, contact spring p and bar in series
/// under ū, so N = k ū / (2 + k/p) and the overlap N/p = 10/3 mm for k = p = 1000 N/m, ū =
/// 1 cm — a third of the 1 cm radius: the check fails at the default 0.1 and passes at 0.5.
#[test]
fn penetration_at_the_solution_is_the_closed_form() {
    let model = load_model(Path::new("fixtures/ok_contact_bars1.toml")).unwrap();
    let (k, p, u, r) = (1000.0, 1000.0, 0.01, 0.01);
    let want = k * u / (2.0 + k / p) / p;
    let report = check_model(&model, &CheckOptions::default()).unwrap();
    let pen = report.penetration.as_ref().expect("contacts");
    let worst = pen.worst().expect("a case");
    assert!((worst.penetration - want).abs() <= 1e-9 * want, "{worst:?}");
    assert!((worst.ratio - want / r).abs() <= 1e-9, "{worst:?}");
    assert_eq!((worst.contact, worst.fibers), (0, [1, 2]));
    assert!(!report.passed());
    let line = report
        .checks
        .iter()
        .find(|c| c.name == "contact penetration");
    assert!(!line.expect("a penetration line").passed);
    let lenient = CheckOptions {
        max_penetration: 0.5,
        ..CheckOptions::default()
    };
    assert!(check_model(&model, &lenient).unwrap().passed());
    let bad = CheckOptions {
        max_penetration: f64::NAN,
        ..CheckOptions::default()
    };
    let e = check_model(&model, &bad).unwrap_err().to_string();
    assert!(e.contains("--max-penetration"), "{e}");
}

/// A cell's penetration under the macroscopic strains: linear in the strain (the generated
/// overlaps are adjusted to ḡ = 0 by default, so nothing is added at rest), and the
/// penalty's: a contact's overlap is N/p_N with N tending to its rigid-contact value, so ten
/// times the penalty gives about a tenth of the worst (between 0.09 and 0.11: N grows by the
/// penalty error of the moduli, 5–6 % here, and the worst contact may change; measured
/// 0.0975–0.1048).
#[test]
fn a_cells_penetration_is_linear_in_strain_and_falls_like_the_penalty() {
    let model = small_nonwoven();
    let at = |model: &Model, strain: f64| {
        let options = CheckOptions {
            penalty_study: false,
            penetration_strain: strain,
            ..CheckOptions::default()
        };
        check_model(model, &options)
            .unwrap()
            .penetration
            .expect("a cell with contacts")
    };
    let one = at(&model, 1e-2);
    let two = at(&model, 2e-2);
    assert_eq!(one.cases.len(), 6);
    for (a, b) in one.cases.iter().zip(&two.cases) {
        assert_eq!(a.contact, b.contact, "{a:?} {b:?}");
        assert!((b.penetration - 2.0 * a.penetration).abs() <= 1e-9 * b.penetration);
    }
    let stiff = at(&with_penalty_scale(&model, 10.0), 1e-2);
    for (a, b) in one.cases.iter().zip(&stiff.cases) {
        let ratio = b.penetration / a.penetration;
        println!(
            "{}: {:.3e} → {:.3e} ({ratio:.4})",
            a.load, a.penetration, b.penetration
        );
        assert!((0.09..=0.11).contains(&ratio), "{}: ratio {ratio}", a.load);
    }
}
