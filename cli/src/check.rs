//! `fibercell check`: a model's self-checks and their report.

use crate::output::to_pretty;
use fibercell::{io, Error};
use std::path::Path;

pub(crate) fn check(
    model_path: &Path,
    options: &fibercell::check::CheckOptions,
    json: bool,
) -> Result<(), Error> {
    let model = io::load_model(model_path)?;
    let report = fibercell::check::check_model(&model, options)?;
    if json {
        println!("{}", to_pretty(&report)?);
    } else {
        print_check(model_path, &report);
    }
    let failed: Vec<String> = report
        .checks
        .iter()
        .filter(|c| !c.passed)
        .map(|c| format!("{}: {}", c.name, c.value))
        .collect();
    if failed.is_empty() {
        Ok(())
    } else {
        Err(Error::ChecksFailed { failed })
    }
}

fn print_check(model_path: &Path, r: &fibercell::check::CheckReport) {
    println!(
        "{}: {} (n = {}, nnz = {})",
        model_path.display(),
        r.system,
        r.matrix.n,
        r.matrix.nnz
    );
    if let Some(p) = &r.penalty {
        println!(
            "penalty study (penalty_scale {} × 1, 10, 100; limit: A∞ − C/(s + a) through the three):",
            p.model_scale
        );
        println!(
            "  {:<4} {:>12} {:>12} {:>12} {:>12} {:>9} {:>7} {:>9}",
            "", "×1", "×10", "×100", "limit", "±", "ratio", "error ×1"
        );
        for e in &p.entries {
            println!(
                "  {:<4} {:>12.5e} {:>12.5e} {:>12.5e} {:>12.5e} {:>9.1e} {:>7.2} {:>9.2e}",
                e.name,
                e.values[0],
                e.values[1],
                e.values[2],
                e.limit,
                e.limit_error,
                e.convergence_ratio,
                e.error_at_model
            );
        }
        println!(
            "  {:<4} {:>12.1e} {:>12.1e} {:>12.1e}   (round-off: ABD's asymmetry)",
            "rnd", p.roundoff[0], p.roundoff[1], p.roundoff[2]
        );
        if let Some(r) = p.recommended_penalty_scale {
            println!(
                "  for a relative error of {:.0e}: penalty_scale = {r:.3e} in [contact]",
                p.accuracy
            );
        }
        for w in &p.warnings {
            println!("  warning: {w}");
        }
    }
    for c in &r.checks {
        println!(
            "{} {:<28} {}   [{}]",
            if c.passed { "ok  " } else { "FAIL" },
            c.name,
            c.value,
            c.limit
        );
    }
}
