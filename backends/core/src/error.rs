//! Typed errors of the solver layer.

use std::fmt;

/// Why an iterative solver stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// The relative residual reached the tolerance.
    Converged,
    /// The iteration limit was reached first.
    MaxIterations,
    /// pᵀAp ≤ 0: the matrix is not positive definite (or the search direction vanished).
    Breakdown,
    /// A NaN or infinity appeared in the iteration.
    NonFinite,
}

impl fmt::Display for StopReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            StopReason::Converged => "converged",
            StopReason::MaxIterations => "iteration limit reached",
            StopReason::Breakdown => "breakdown (pᵀAp ≤ 0: matrix not positive definite)",
            StopReason::NonFinite => "non-finite value in the iteration",
        })
    }
}

/// Everything that can go wrong in the solver layer.
///
/// Column indices are those of the matrix handed to the solver (before any fill-reducing
/// permutation); callers map them back to their own unknowns (fibercell: node and DOF).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SolverError {
    /// A Cholesky pivot was not positive, or smaller than the pivot tolerance relative to its
    /// diagonal entry.
    #[error("matrix is not positive definite at column {column} (relative pivot {pivot:.3e})")]
    NotPositiveDefinite {
        /// Column (unknown) at which the factorization broke down.
        column: usize,
        /// The pivot relative to the diagonal entry of that column.
        pivot: f64,
    },
    /// The matrix is (numerically) singular.
    #[error("matrix is singular{}: {detail}", column.map(|c| format!(" at column {c}")).unwrap_or_default())]
    Singular {
        /// The column where it was detected, when known.
        column: Option<usize>,
        /// How it was detected.
        detail: String,
    },
    /// An iterative solver did not reach its tolerance.
    #[error("no convergence after {iterations} iterations: relative residual {residual:.3e} > tolerance {tolerance:.1e} ({reason})")]
    NoConvergence {
        /// Iterations performed.
        iterations: usize,
        /// Relative residual reached.
        residual: f64,
        /// Requested tolerance.
        tolerance: f64,
        /// Why it stopped.
        reason: StopReason,
    },
    /// `factorize` got a matrix whose sparsity pattern differs from the analysed one.
    #[error("the sparsity pattern changed since analyze (call analyze again)")]
    PatternChanged,
    /// `factorize` or `solve` was called before the phase it depends on.
    #[error("{0} called before {1}")]
    OutOfOrder(&'static str, &'static str),
    /// Sizes do not fit together.
    #[error("dimension mismatch: {0}")]
    DimensionMismatch(String),
    /// The CSC arrays are not a valid matrix.
    #[error("invalid sparse matrix: {0}")]
    InvalidMatrix(String),
    /// A NaN or infinity in the input or the output.
    #[error("non-finite value in the {what} at index {index}")]
    NonFinite {
        /// "matrix", "right-hand side" or "solution".
        what: &'static str,
        /// Position (value index for the matrix, row for vectors).
        index: usize,
    },
    /// A symmetric backend or ordering got a matrix whose pattern is not symmetric: entry
    /// (`row`, `column`) is stored but (`column`, `row`) is not — typically one triangle of a
    /// symmetric matrix (a symmetric Matrix Market file, `scipy.sparse.tril`).
    #[error("the sparsity pattern is not symmetric: entry ({row}, {column}) is stored but ({column}, {row}) is not; symmetric matrices must store both triangles (expand a single triangle with CscMatrix::symmetric_from_triangle)")]
    NotStructurallySymmetric {
        /// Row of the unmatched entry.
        row: usize,
        /// Column of the unmatched entry.
        column: usize,
    },
    /// The backend only handles symmetric matrices.
    #[error("backend {0} needs a symmetric matrix")]
    NotSymmetric(&'static str),
    /// The backend was not compiled in or cannot run here.
    #[error("backend {backend} is not available: {reason}")]
    Unavailable {
        /// Backend name.
        backend: &'static str,
        /// Why (e.g. the cargo feature to enable).
        reason: String,
    },
    /// A backend library reported an error code.
    #[error("{backend} failed with code {code}: {message}")]
    Backend {
        /// Backend name.
        backend: &'static str,
        /// The library's status code.
        code: i64,
        /// The library's message.
        message: String,
    },
    /// An allocation failed.
    #[error("out of memory")]
    OutOfMemory,
}
