//! The [`LinearSolver`] trait: analyze / factorize / solve.

use crate::{CscRef, ForwardColumns, SolverError, StopReason};

/// What a backend can do.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Capabilities {
    /// Only symmetric (positive definite) matrices.
    pub symmetric_only: bool,
    /// `analyze` is done once per pattern and reused by every `factorize`.
    pub reuses_symbolic: bool,
    /// An iterative method (the solve has a tolerance and may not converge).
    pub iterative: bool,
    /// Honours the requested fill-reducing [`crate::FillOrdering`].
    pub selectable_ordering: bool,
}

impl Capabilities {
    /// A direct sparse Cholesky solver with a selectable ordering.
    pub const DIRECT_SPD: Capabilities = Capabilities {
        symmetric_only: true,
        reuses_symbolic: true,
        iterative: false,
        selectable_ordering: true,
    };
}

/// What `analyze` found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AnalyzeInfo {
    /// Order of the matrix.
    pub n: usize,
    /// Stored entries of A (both triangles).
    pub nnz_a: usize,
    /// Entries of the factor L (or L + U) by its structure, when a direct method: the figure
    /// to compare orderings and backends by (CHOLMOD's `lnz`).
    pub nnz_factor: Option<usize>,
    /// Bytes of the factor's values as stored, when known: a supernodal factor also stores
    /// the explicit zeros of its relaxed supernodes.
    pub factor_bytes: Option<usize>,
    /// Floating point operations of one numeric factorization, when known.
    pub flops: Option<f64>,
    /// The ordering that was used.
    pub ordering: String,
}

/// What `solve_in_place` reports.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SolveInfo {
    /// Iterations (iterative methods; the largest over the right-hand sides).
    pub iterations: Option<usize>,
    /// The backend's own relative residual estimate (iterative methods).
    pub residual_estimate: Option<f64>,
    /// Why an iterative method stopped.
    pub stop: Option<StopReason>,
}

/// A sparse linear solver with separate symbolic, numeric and solve phases.
///
/// Call order: `analyze` once per sparsity pattern, then `factorize` whenever the values change
/// (same pattern), then `solve_in_place` for any number of right-hand sides.
pub trait LinearSolver: Send {
    /// Short name, e.g. `"faer-cholesky"`.
    fn name(&self) -> &'static str;
    /// What the backend can do.
    fn capabilities(&self) -> Capabilities;
    /// FillOrdering and symbolic factorization; only the pattern of `a` is used.
    fn analyze(&mut self, a: CscRef<'_>) -> Result<AnalyzeInfo, SolverError>;
    /// Numeric factorization of `a`, whose pattern must be the analysed one.
    fn factorize(&mut self, a: CscRef<'_>) -> Result<(), SolverError>;
    /// Solves A X = B in place; `rhs` holds `nrhs` columns of length n, column after column.
    fn solve_in_place(&mut self, rhs: &mut [f64], nrhs: usize) -> Result<SolveInfo, SolverError>;
    /// Another solver on this one's analysis and current factorization, read-only, with
    /// workspaces of its own: its solves give what this one's give, bit for bit, and several
    /// may solve at once on different threads (many material points on one reference
    /// factorization). A `factorize` on it (or on this one) makes that solver's own numeric
    /// factor and leaves the other's as it was; `analyze` makes its own analysis. `None`
    /// (the default) where a backend cannot share its factors: the caller factorizes its own.
    fn share(&self) -> Option<Box<dyn LinearSolver>> {
        None
    }

    /// Turns the current factorization of A into one of A + W Wᵀ (`update`) or A − W Wᵀ
    /// (downdate) without refactorizing, W an n × k matrix (e.g. the square roots of k contact
    /// springs switched on or off); later solves use it until the next `factorize`. Backends
    /// without a low-rank modification return [`SolverError::Unavailable`] (the default).
    fn update_factor(&mut self, w: CscRef<'_>, update: bool) -> Result<(), SolverError> {
        let _ = (w, update);
        Err(SolverError::Unavailable {
            backend: self.name(),
            reason: "no low-rank update or downdate of the factor".into(),
        })
    }

    /// The forward half W = L⁻¹ P Ŝ B of a solve for the sparse columns B (`columns[j]` lists
    /// column j's (row, value) entries, rows distinct) with the current symmetric factorization
    /// A = Ŝ⁻¹ Pᵀ L Lᵀ P Ŝ⁻¹, so that Bᵀ A⁻¹ B = Wᵀ W at the cost of the elimination-tree paths
    /// of B's nonzeros instead of two full triangular solves per column. Backends without it
    /// return [`SolverError::Unavailable`] (the default).
    fn forward_solve_sparse(
        &mut self,
        columns: &[Vec<(usize, f64)>],
    ) -> Result<ForwardColumns, SolverError> {
        let _ = columns;
        Err(SolverError::Unavailable {
            backend: self.name(),
            reason: "no sparse forward solve".into(),
        })
    }

    /// [`LinearSolver::forward_solve_sparse`] for `columns` together with the forward half of
    /// one dense right-hand side, `x` ← L⁻¹ P Ŝ x as [`LinearSolver::solve_lower_in_place`]:
    /// a backend may read each block of L once for both (a low-rank solve's new columns and
    /// its right-hand side). `x` is left as it was on an error. Default: the two in turn.
    fn forward_solve_sparse_and_lower(
        &mut self,
        columns: &[Vec<(usize, f64)>],
        x: &mut [f64],
    ) -> Result<ForwardColumns, SolverError> {
        let w = self.forward_solve_sparse(columns)?;
        self.solve_lower_in_place(x)?;
        Ok(w)
    }

    /// The forward half of a solve with the symmetric factorization A = Ŝ⁻¹ Pᵀ L Lᵀ P Ŝ⁻¹ for
    /// one right-hand side: `x` ← L⁻¹ P Ŝ x, in the factor's row order (see
    /// [`LinearSolver::solve_upper_in_place`]; the same space as
    /// [`LinearSolver::forward_solve_sparse`]'s blocks). Default: [`SolverError::Unavailable`].
    fn solve_lower_in_place(&mut self, x: &mut [f64]) -> Result<(), SolverError> {
        let _ = x;
        Err(SolverError::Unavailable {
            backend: self.name(),
            reason: "no half solves".into(),
        })
    }

    /// The backward half: `y` (factor order) ← Ŝ Pᵀ L⁻ᵀ y, so that the two halves in turn are
    /// a solve with A. Default: [`SolverError::Unavailable`].
    fn solve_upper_in_place(&mut self, y: &mut [f64]) -> Result<(), SolverError> {
        let _ = y;
        Err(SolverError::Unavailable {
            backend: self.name(),
            reason: "no half solves".into(),
        })
    }
}

impl dyn LinearSolver {
    /// Checks that `rhs` holds `nrhs` columns of length `n`.
    pub fn check_rhs(n: usize, rhs: &[f64], nrhs: usize) -> Result<(), SolverError> {
        if rhs.len() != n * nrhs {
            return Err(SolverError::DimensionMismatch(format!(
                "right-hand side has {} values, expected {n} × {nrhs}",
                rhs.len()
            )));
        }
        if let Some(i) = rhs.iter().position(|v| !v.is_finite()) {
            return Err(SolverError::NonFinite {
                what: "right-hand side",
                index: i,
            });
        }
        Ok(())
    }

    /// `check_matrix` plus a symmetric pattern: what every symmetric backend checks in
    /// `analyze` before it orders (a single triangle would otherwise be ordered and factorized
    /// as if it were the whole matrix).
    pub fn check_symmetric_matrix(a: CscRef<'_>) -> Result<(), SolverError> {
        Self::check_matrix(a, None)?;
        a.check_structurally_symmetric()
    }

    /// Checks that the matrix is square, of order `n` when given, with finite values.
    pub fn check_matrix(a: CscRef<'_>, n: Option<usize>) -> Result<(), SolverError> {
        Self::check_order(a, n)?;
        match Self::non_finite_error(a) {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// The error for the matrix's first NaN or infinite value, if it has one (what
    /// `check_matrix` reports): for a backend that reads every value anyway and looks for the
    /// first only once it met one.
    pub fn non_finite_error(a: CscRef<'_>) -> Option<SolverError> {
        a.first_non_finite().map(|index| SolverError::NonFinite {
            what: "matrix",
            index,
        })
    }

    /// Checks that the matrix is square and of order `n` when given (the values unread).
    pub fn check_order(a: CscRef<'_>, n: Option<usize>) -> Result<(), SolverError> {
        if a.nrows() != a.ncols() {
            return Err(SolverError::DimensionMismatch(format!(
                "matrix is {}×{}, not square",
                a.nrows(),
                a.ncols()
            )));
        }
        if let Some(n) = n {
            if a.ncols() != n {
                return Err(SolverError::DimensionMismatch(format!(
                    "matrix has order {}, analysed order was {n}",
                    a.ncols()
                )));
            }
        }
        Ok(())
    }
}
