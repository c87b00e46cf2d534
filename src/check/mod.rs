//! Property checks a user runs on their own model (`fibercell check MODEL`): the symmetry,
//! definiteness and conditioning of the system its job solves, the null space of a cell's
//! system before its anchor, and for a cell with contacts the penalty study of its moduli
//! (ABD at p, 10p, 100p, the Richardson limit p → ∞ and the penalty an accuracy needs).
//!
//! The flow: set up the job's system → assemble → factorize and measure → (cells) the
//! unanchored system and the penalty study → verdict.

mod matrix_checks;
mod null_space;
mod penalty_study;

pub use matrix_checks::{asymmetry, matrix_checks, MatrixChecks};
pub use null_space::{translation_residuals, TranslationResiduals};
pub use penalty_study::{penalty_study, PenaltyEntry, PenaltyStudy, STUDY_SCALES};

use crate::homogenize::PeriodicSystem;
use crate::solve::{ReducedSystem, SolveOptions, SolverKind};
use crate::{Error, Model};
use serde::Serialize;

/// Largest accepted max |a_ij − a_ji| / max |a_ij| of an assembled system.
pub const SYMMETRY_TOLERANCE: f64 = 1e-14;
/// Largest accepted ‖K t‖∞ / ‖K‖∞ of a rigid translation t of the unanchored cell.
pub const TRANSLATION_TOLERANCE: f64 = 1e-12;
/// Largest accepted backward error of the check solve.
pub const BACKWARD_ERROR_TOLERANCE: f64 = 1e-10;

/// What [`check_model`] does.
#[derive(Clone, Debug)]
pub struct CheckOptions {
    /// Backend and ordering (a Cholesky backend measures definiteness: CHOLMOD when chosen,
    /// otherwise faer's).
    pub solve: SolveOptions,
    /// Run the penalty study (cells with contacts; three homogenizations).
    pub penalty_study: bool,
    /// Relative accuracy wanted of the moduli: the study recommends the penalty for it, and
    /// with [`CheckOptions::require_accuracy`] a larger penalty error fails the check.
    pub accuracy: f64,
    /// Fail when the model's penalty error exceeds `accuracy`.
    pub require_accuracy: bool,
}

impl Default for CheckOptions {
    fn default() -> Self {
        CheckOptions {
            solve: SolveOptions::default(),
            penalty_study: true,
            accuracy: 1e-2,
            require_accuracy: false,
        }
    }
}

/// One line of the verdict.
#[derive(Clone, Debug, Serialize)]
pub struct CheckLine {
    /// What was checked.
    pub name: String,
    /// What was measured.
    pub value: String,
    /// What passes.
    pub limit: String,
    /// Whether it passed.
    pub passed: bool,
}

/// Everything [`check_model`] measured, and the verdict.
#[derive(Clone, Debug, Serialize)]
pub struct CheckReport {
    /// Which system: the six elastic cell problems or the reduced static problem.
    pub system: &'static str,
    /// Symmetry, definiteness and conditioning of that system.
    pub matrix: MatrixChecks,
    /// Cells: the unanchored system on the rigid translations.
    pub translations: Option<TranslationResiduals>,
    /// Cells with contacts: the penalty study.
    pub penalty: Option<PenaltyStudy>,
    /// The verdict, line by line.
    pub checks: Vec<CheckLine>,
}

impl CheckReport {
    /// Whether every check passed.
    pub fn passed(&self) -> bool {
        self.checks.iter().all(|c| c.passed)
    }
}

/// Runs the checks on `model`: a cell (with `[cell]`) or a supported model.
pub fn check_model(model: &Model, options: &CheckOptions) -> Result<CheckReport, Error> {
    let mut solve = options.solve.clone();
    if solve.solver != SolverKind::Cholmod {
        solve.solver = SolverKind::FaerCholesky;
    }
    let cell = model.cell.is_some();
    let (matrix, contacts) = if cell {
        let sys = PeriodicSystem::new(model)?;
        let values = sys.assemble(model);
        let a = sys.pattern.matrix(&values.values)?;
        let mut solver = solve
            .solver_config(sys.discretization.node_block_starts())
            .build()?;
        let checks = matrix_checks(a, solver.as_mut(), &|e| sys.locate(model, e))?;
        (checks, sys.n_contacts())
    } else {
        let sys = ReducedSystem::assemble(model, solve.fill)?;
        let mut solver = solve.solver_config(sys.dofs.node_block_starts()).build()?;
        let locate = |e| sys.dofs.locate(model, e);
        (matrix_checks(sys.matrix()?, solver.as_mut(), &locate)?, 0)
    };
    let translations = cell.then(|| translation_residuals(model)).transpose()?;
    let penalty = (cell && contacts > 0 && options.penalty_study && matrix.positive_definite)
        .then(|| penalty_study(model, &solve, options.accuracy))
        .transpose()?;
    let checks = verdict(&matrix, translations.as_ref(), penalty.as_ref(), options);
    Ok(CheckReport {
        system: if cell {
            "the six elastic cell problems (closed contacts in stick)"
        } else {
            "the reduced static problem K u = F"
        },
        matrix,
        translations,
        penalty,
        checks,
    })
}

fn line(name: &str, value: String, limit: &str, passed: bool) -> CheckLine {
    CheckLine {
        name: name.into(),
        value,
        limit: limit.into(),
        passed,
    }
}

/// The pass/fail lines of the measurements.
fn verdict(
    matrix: &MatrixChecks,
    translations: Option<&TranslationResiduals>,
    penalty: Option<&PenaltyStudy>,
    options: &CheckOptions,
) -> Vec<CheckLine> {
    let mut out = vec![
        line(
            "symmetric",
            format!("{:.2e}", matrix.asymmetry),
            "max|a_ij − a_ji| / max|a| ≤ 1e-14",
            matrix.asymmetry <= SYMMETRY_TOLERANCE,
        ),
        line(
            "positive definite",
            match &matrix.definiteness_error {
                None => "Cholesky succeeded".into(),
                Some(e) => e.clone(),
            },
            "every pivot > 1e-12 of its scaled diagonal",
            matrix.positive_definite,
        ),
    ];
    if let Some(b) = matrix.backward_error {
        out.push(line(
            "backward error",
            format!(
                "{b:.2e} (κ₁ ≈ {:.2e})",
                matrix.condition_estimate.unwrap_or(f64::NAN)
            ),
            "≤ 1e-10",
            b <= BACKWARD_ERROR_TOLERANCE,
        ));
    }
    if let Some(t) = translations {
        let worst = t.relative.iter().fold(0.0f64, |m, &v| m.max(v));
        out.push(line(
            "null space = 3 translations",
            format!("‖K t‖∞/‖K‖∞ ≤ {worst:.2e}"),
            "≤ 1e-12, and the anchored matrix positive definite",
            worst <= TRANSLATION_TOLERANCE && matrix.positive_definite,
        ));
    }
    if let Some(p) = penalty {
        let worst = p
            .entries
            .iter()
            .map(|e| e.error_at_model)
            .fold(0.0f64, f64::max);
        let value = match (&p.failed, p.recommended_penalty_scale) {
            (Some(f), _) => f.clone(),
            (None, Some(r)) => {
                format!("{worst:.2e} (penalty_scale {r:.3e} for {:.0e})", p.accuracy)
            }
            (None, None) => format!("{worst:.2e}"),
        };
        out.push(line(
            "penalty error of the moduli",
            value,
            if options.require_accuracy {
                "≤ the requested accuracy"
            } else {
                "reported (pass --accuracy to require it)"
            },
            !options.require_accuracy || (p.failed.is_none() && worst <= p.accuracy),
        ));
    }
    out
}
