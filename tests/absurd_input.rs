//! Absurd sizes are refused before anything is allocated, with the limit and the reason:
//! `--steps 18446744073709551615` panicked with "capacity overflow", `--steps 100000000`
//! aborted on a 33 GB allocation and `--steps 10000000` grew without bound; a contact
//! `segment = 18446744073709551615` panicked on `segment + 1` (and wrapped to another fiber's
//! element in a release build); `--length-cv nan` on the CLI was taken for a fixed length
//! where the parameter file refuses it.

use fibercell::homogenize::{elasto_plastic_curve, CurveOptions};
use fibercell::io::load_model;
use fibercell::solve::{
    solve_incremental, IncrementalOptions, MAX_CONTACT_RECORDS, MAX_INCREMENTS,
};
use std::path::Path;
use std::process::Command;

fn curve_error(steps: usize, unload: bool) -> String {
    let model = load_model(Path::new("fixtures/cells/nonwoven_small.toml")).expect("fixture");
    elasto_plastic_curve(
        &model,
        &CurveOptions {
            strain: [0.01, 0.0, 0.0, 0.0, 0.0, 0.0],
            steps,
            unload,
            incremental: IncrementalOptions::default(),
        },
    )
    .expect_err("refused")
    .to_string()
}

#[test]
fn increments_beyond_the_limit_are_refused() {
    for steps in [usize::MAX, 100_000_000, MAX_INCREMENTS + 1] {
        let e = curve_error(steps, false);
        assert!(e.contains(&format!("at most {MAX_INCREMENTS}")), "{e}");
    }
    // Load, unload and reload: three branches of `steps` each.
    let e = curve_error(MAX_INCREMENTS / 3 + 1, true);
    assert!(e.contains("per branch"), "{e}");
    let model = load_model(Path::new("fixtures/ok_contact_bars1.toml")).expect("fixture");
    let e = solve_incremental(
        &model,
        &IncrementalOptions {
            steps: usize::MAX,
            ..IncrementalOptions::default()
        },
    )
    .expect_err("refused")
    .to_string();
    assert!(e.contains(&format!("at most {MAX_INCREMENTS}")), "{e}");
}

/// Within the increment limit, a run whose contact records (one per contact and increment)
/// would pass MAX_CONTACT_RECORDS is refused before it starts, naming both counts.
#[test]
fn runs_whose_records_would_not_fit_are_refused() {
    let e = curve_error(MAX_INCREMENTS, false);
    assert!(e.contains("contact records"), "{e}");
    assert!(e.contains(&MAX_CONTACT_RECORDS.to_string()), "{e}");
}

#[test]
fn a_nan_length_cv_on_the_command_line_is_refused_like_in_the_file() {
    let dir = std::env::temp_dir().join(format!("fibercell-absurd-{}", std::process::id()));
    let out = Command::new(env!("CARGO_BIN_EXE_fibercell"))
        .args([
            "generate",
            "nonwoven",
            "--preset",
            "S",
            "--length-cv",
            "nan",
            "-o",
        ])
        .arg(dir.join("S.toml"))
        .output()
        .expect("runs");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("length cv = NaN"), "{err}");
    assert!(!dir.join("S.toml").exists());
}
