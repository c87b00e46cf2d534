//! Property checks a user runs on their own model (`fibercell check MODEL`): the symmetry,
//! definiteness and conditioning of the system its job solves (closed contacts in stick), the
//! null space of a cell's system before its anchor (or of a free model's), the contacts'
//! penetration at the solution relative to the radii, and for a cell with contacts the penalty
//! study of its moduli (ABD at p, 10p, 100p, the Richardson limit p → ∞ and the penalty an
//! accuracy needs).
//!
//! The flow: set up the job's system → assemble → factorize and measure → the solution's
//! penetration → (cells) the unanchored system and the penalty study, (free models) the rigid
//! modes → verdict.

mod matrix_checks;
mod null_space;
mod penalty_study;
mod penetration;
mod rigid_modes;

pub use matrix_checks::{asymmetry, matrix_checks, MatrixChecks};
pub use null_space::{translation_residuals, TranslationResiduals};
pub use penalty_study::{penalty_study, PenaltyEntry, PenaltyStudy, STUDY_SCALES};
use penalty_study::{penalty_study_from, ScaledAbd};
pub use penetration::{cell_penetration, solution_penetration, PenetrationCase, PenetrationCheck};
pub use rigid_modes::{rigid_mode_residuals, RigidModes};

use crate::homogenize::{abd_asymmetry, abd_of, cell_rhs, PeriodicSystem, StickSystem};
use crate::solve::{SolveOptions, SolverKind};
use crate::{Error, Model};
use serde::Serialize;

/// Largest accepted max |a_ij − a_ji| / max |a_ij| of an assembled system.
pub const SYMMETRY_TOLERANCE: f64 = 1e-14;
/// Largest accepted ‖K t‖∞ / ‖K‖∞ of a rigid translation t of the unanchored cell.
pub const TRANSLATION_TOLERANCE: f64 = 1e-12;
/// Largest accepted backward error of the check solve.
pub const BACKWARD_ERROR_TOLERANCE: f64 = 1e-10;
/// Default largest penetration of a closed contact relative to the smaller radius of its
/// fibers ([`CheckOptions::max_penetration`]).
pub const DEFAULT_MAX_PENETRATION: f64 = 0.1;
/// Largest accepted ‖K r‖∞ / (‖K‖∞ ‖r‖∞) of a rigid mode r of a free model.
pub const RIGID_MODE_TOLERANCE: f64 = 1e-12;

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
    /// Cells: the size of the macroscopic strains the penetration is measured at (each of
    /// ε11, ε22, γ12 alone; curvatures 2ε/h).
    pub penetration_strain: f64,
    /// Largest accepted penetration of a closed contact relative to the smaller radius of its
    /// fibers.
    pub max_penetration: f64,
}

impl CheckOptions {
    /// An error naming the first option out of its range.
    pub fn validate(&self) -> Result<(), Error> {
        if !(self.accuracy > 0.0 && self.accuracy < 1.0) {
            return Err(Error::InvalidOption(format!(
                "accuracy (--accuracy) {} must lie in (0, 1): it is a relative error",
                self.accuracy
            )));
        }
        for (name, v) in [
            (
                "penetration_strain (--penetration-strain)",
                self.penetration_strain,
            ),
            ("max_penetration (--max-penetration)", self.max_penetration),
        ] {
            if !(v > 0.0 && v.is_finite()) {
                return Err(Error::InvalidOption(format!(
                    "{name} {v} must be a positive number"
                )));
            }
        }
        Ok(())
    }
}

impl Default for CheckOptions {
    fn default() -> Self {
        CheckOptions {
            solve: SolveOptions::default(),
            penalty_study: true,
            accuracy: 1e-2,
            require_accuracy: false,
            penetration_strain: 1e-2,
            max_penetration: DEFAULT_MAX_PENETRATION,
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
    /// Free models (no supports, no cell): the system on the rigid modes of its pieces.
    pub rigid_modes: Option<RigidModes>,
    /// Models with contacts: the closed contacts' penetration at the solution.
    pub penetration: Option<PenetrationCheck>,
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

/// Runs the checks on `model`: a cell (with `[cell]`), a supported model or a free one.
pub fn check_model(model: &Model, options: &CheckOptions) -> Result<CheckReport, Error> {
    options.validate()?;
    let mut solve = options.solve.clone();
    if solve.solver != SolverKind::Cholmod {
        solve.solver = SolverKind::FaerCholesky;
    }
    let cell = model.cell.is_some();
    let free = !cell && model.supports.is_empty();
    let mut at_model = None;
    let (matrix, contacts, penetration) = if cell {
        let (checks, contacts, solved) = cell_checks(model, &solve, options.penetration_strain)?;
        let penetration = solved.map(|(p, abd)| {
            at_model = Some(abd);
            p
        });
        (checks, contacts, penetration)
    } else {
        let sys = StickSystem::supported(model)?;
        let values = sys.assemble(model);
        let mut solver = solve
            .solver_config(sys.discretization.node_block_starts())
            .build()?;
        let a = sys.pattern.matrix(&values.values)?;
        let matrix = matrix_checks(a, solver.as_mut(), &|e| sys.locate(model, e))?;
        let penetration = (!free && sys.n_contacts() > 0 && matrix.positive_definite)
            .then(|| solution_penetration(model, &options.solve))
            .transpose()?;
        (matrix, sys.n_contacts(), penetration)
    };
    let translations = cell.then(|| translation_residuals(model)).transpose()?;
    let rigid_modes = free
        .then(|| rigid_mode_residuals(model, &solve))
        .transpose()?;
    let penalty = (cell && contacts > 0 && options.penalty_study && matrix.positive_definite)
        .then(|| penalty_study_from(model, &solve, options.accuracy, at_model))
        .transpose()?;
    let mut report = CheckReport {
        system: match (cell, free, contacts > 0) {
            (true, _, _) => "the six elastic cell problems (closed contacts in stick)",
            (false, true, _) => "the free model's K (no supports: singular by its rigid modes)",
            (false, false, true) => "the static problem with the closed contacts in stick",
            (false, false, false) => "the reduced static problem K u = F",
        },
        matrix,
        translations,
        rigid_modes,
        penetration,
        penalty,
        checks: Vec::new(),
    };
    report.checks = verdict(&report, options);
    Ok(report)
}

/// What [`cell_checks`] measured: the matrix checks, the number of closed contacts and, with
/// contacts and a definite matrix, their penetration and the model's ABD.
type CellChecks = (MatrixChecks, usize, Option<(PenetrationCheck, ScaledAbd)>);

/// A cell's matrix checks, its number of closed contacts and — with contacts and a definite
/// matrix — their penetration under the six macroscopic strains of size `strain` and the
/// model's ABD (the penalty study's ×1), all on one factorization.
fn cell_checks(model: &Model, solve: &SolveOptions, strain: f64) -> Result<CellChecks, Error> {
    let sys = PeriodicSystem::new(model)?;
    let values = sys.assemble(model);
    let a = sys.pattern.matrix(&values.values)?;
    let mut solver = solve
        .solver_config(sys.discretization.node_block_starts())
        .build()?;
    let locate = |e| sys.locate(model, e);
    let checks = matrix_checks(a, solver.as_mut(), &locate)?;
    if !checks.positive_definite || sys.n_contacts() == 0 {
        return Ok((checks, sys.n_contacts(), None));
    }
    let n = sys.n_free();
    let rhs = cell_rhs(&values.couplings, n, 0);
    let (x, report) = crate::solver::solve_checked(solver.as_mut(), a, &rhs, 6).map_err(locate)?;
    let penetration = cell_penetration(model, &sys, &x, strain);
    let abd = abd_of(&values.couplings, &x, n, sys.periodicity.geometry.area());
    let at_model = ScaledAbd {
        abd,
        backward_error: report.backward_error,
        asymmetry: abd_asymmetry(&abd),
    };
    Ok((checks, sys.n_contacts(), Some((penetration, at_model))))
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
fn verdict(report: &CheckReport, options: &CheckOptions) -> Vec<CheckLine> {
    let matrix = &report.matrix;
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
    if let Some(t) = &report.translations {
        let worst = t.relative.iter().fold(0.0f64, |m, &v| m.max(v));
        out.push(line(
            "null space = 3 translations",
            format!("‖K t‖∞/‖K‖∞ ≤ {worst:.2e}"),
            "≤ 1e-12, and the anchored matrix positive definite",
            worst <= TRANSLATION_TOLERANCE && matrix.positive_definite,
        ));
    }
    if let Some(m) = &report.rigid_modes {
        let worst = m.relative.iter().fold(0.0f64, |w, &v| w.max(v));
        out.push(line(
            "null space = 6 rigid modes per piece",
            format!(
                "{} piece(s), ‖K r‖∞/(‖K‖∞‖r‖∞) ≤ {worst:.2e}, {}",
                m.pieces,
                if m.held_positive_definite {
                    "definite with one node per piece held"
                } else {
                    "singular with one node per piece held"
                }
            ),
            "≤ 1e-12, and definite with one node per piece held",
            worst <= RIGID_MODE_TOLERANCE && m.held_positive_definite,
        ));
    }
    if let Some(c) = report.penetration.as_ref().and_then(|p| p.worst()) {
        out.push(line(
            "contact penetration",
            format!(
                "{:.2e} of the smaller radius ({:.2e} m at {}, contact {}, fibers {}–{})",
                c.ratio, c.penetration, c.load, c.contact, c.fibers[0], c.fibers[1]
            ),
            &format!("≤ {} of the smaller radius", options.max_penetration),
            c.ratio <= options.max_penetration,
        ));
    }
    if let Some(p) = &report.penalty {
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
