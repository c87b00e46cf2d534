//! The backends the mechanics can use, by name.

use crate::Error;
use fibercell_solver::{FillOrdering, LinearSolver};
use std::fmt;
use std::str::FromStr;

/// A linear solver backend.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SolverKind {
    /// faer sparse Cholesky LLᵀ (default; no system packages).
    #[default]
    FaerCholesky,
    /// faer sparse LU.
    FaerLu,
    /// Conjugate gradients with node-block Jacobi.
    Cg,
    /// SuiteSparse CHOLMOD (cargo feature `cholmod`).
    Cholmod,
}

impl SolverKind {
    /// All kinds, in the order of the CLI help.
    pub const ALL: [SolverKind; 4] = [
        SolverKind::FaerCholesky,
        SolverKind::FaerLu,
        SolverKind::Cg,
        SolverKind::Cholmod,
    ];

    /// The CLI name.
    pub fn name(self) -> &'static str {
        match self {
            SolverKind::FaerCholesky => "faer-cholesky",
            SolverKind::FaerLu => "faer-lu",
            SolverKind::Cg => "cg",
            SolverKind::Cholmod => "cholmod",
        }
    }

    /// Whether this build has the backend.
    pub fn is_available(self) -> bool {
        self != SolverKind::Cholmod || cfg!(feature = "cholmod")
    }
}

impl fmt::Display for SolverKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for SolverKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        SolverKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| {
                format!("unknown solver \"{s}\" (use faer-cholesky, faer-lu, cg or cholmod)")
            })
    }
}

/// Everything a backend is built from, in one value: the backend and its fill-reducing
/// ordering (the CLI's `--solver` and `--ordering`), the first unknown of every node block (CG's
/// block-Jacobi preconditioner; empty: blocks of six unknowns) and CG's stopping tolerance.
/// Every job builds its backend through [`SolverConfig::build`]; a job gets its config from
/// [`super::SolveOptions::solver_config`] with its discretization's node blocks.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SolverConfig {
    /// Backend.
    pub kind: SolverKind,
    /// Fill-reducing ordering of the direct backends (ignored by faer-lu, which orders its
    /// columns by COLAMD, and by CG).
    pub ordering: FillOrdering,
    /// First unknown of every node block, increasing from 0 (CG's preconditioner); empty for
    /// uniform blocks of six unknowns.
    pub node_blocks: Vec<usize>,
    /// CG's relative residual ‖r‖/‖b‖ at which it stops (default 1e-12 when `None`).
    pub cg_tolerance: Option<f64>,
}

impl SolverConfig {
    /// `kind` with the automatic ordering, uniform node blocks and the default tolerances.
    pub fn new(kind: SolverKind) -> Self {
        SolverConfig {
            kind,
            ..SolverConfig::default()
        }
    }

    /// Builds the backend.
    pub fn build(&self) -> Result<Box<dyn LinearSolver>, Error> {
        Ok(match self.kind {
            SolverKind::FaerCholesky => Box::new(fibercell_faer::FaerCholesky::new(
                fibercell_faer::CholeskyVariant::Llt,
                self.ordering.clone(),
            )),
            SolverKind::FaerLu => Box::new(fibercell_faer::FaerLu::new()),
            SolverKind::Cg => {
                let mut cg = fibercell_cg::ConjugateGradient::new();
                if !self.node_blocks.is_empty() {
                    cg = cg.with_blocks(self.node_blocks.clone());
                }
                if let Some(tol) = self.cg_tolerance {
                    cg = cg.with_tolerance(tol);
                }
                Box::new(cg)
            }
            #[cfg(feature = "cholmod")]
            SolverKind::Cholmod => Box::new(fibercell_cholmod::Cholmod::new(self.ordering.clone())),
            #[cfg(not(feature = "cholmod"))]
            SolverKind::Cholmod => {
                return Err(Error::Solver(fibercell_solver::SolverError::Unavailable {
                    backend: "cholmod",
                    reason: "this build lacks the `cholmod` cargo feature (apt-get install libsuitesparse-dev libclang-dev, then build with --features cholmod)".into(),
                }))
            }
        })
    }
}
