//! The backends the mechanics can use, by name.

use crate::Error;
use fibercell_solver::{LinearSolver, Ordering};
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

/// Builds a backend. `node_blocks` are the first reduced DOFs of each node (the CG
/// preconditioner's blocks).
pub fn make_solver(
    kind: SolverKind,
    ordering: &Ordering,
    node_blocks: Vec<usize>,
) -> Result<Box<dyn LinearSolver>, Error> {
    Ok(match kind {
        SolverKind::FaerCholesky => Box::new(fibercell_faer::FaerCholesky::new(
            fibercell_faer::CholeskyVariant::Llt,
            ordering.clone(),
        )),
        SolverKind::FaerLu => Box::new(fibercell_faer::FaerLu::new()),
        SolverKind::Cg => Box::new(fibercell_cg::ConjugateGradient::new().with_blocks(node_blocks)),
        #[cfg(feature = "cholmod")]
        SolverKind::Cholmod => Box::new(fibercell_cholmod::Cholmod::new(ordering.clone())),
        #[cfg(not(feature = "cholmod"))]
        SolverKind::Cholmod => {
            return Err(Error::Solver(fibercell_solver::SolverError::Unavailable {
                backend: "cholmod",
                reason: "this build lacks the `cholmod` cargo feature (apt-get install libsuitesparse-dev libclang-dev, then build with --features cholmod)".into(),
            }))
        }
    })
}
