//! Sparse LU through faer (COLAMD column ordering, partial pivoting), for nonsymmetric systems.
//!
//! faer does not flag a numerically zero pivot, and its pivots are not readable. After every
//! factorization a check solve x = A⁻¹(A·1) must be finite with a normwise backward error
//! ‖Ax − b‖∞/(‖A‖∞‖x‖∞ + ‖b‖∞) ≤ `max_backward_error` (default 1e-10), which a
//! backward-stable LU meets however ill-conditioned A is; otherwise A is
//! [`SolverError::Singular`]. The forward error |x − 1| is not a test: it is about κ(A)·ε,
//! which on valid cells of slender fibers with penalty contacts reaches 10⁻² (κ₁ ≈ 5·10¹⁶ on
//! the small non-woven cell, which Cholesky and CG solve to a backward error of 10⁻¹⁸).
//! Whether a solve can be trusted is judged like every other backend's, by the backward
//! error of its own solution ([`fibercell_solver::solve_checked`]). On request
//! ([`FaerLu::with_max_condition`]) the condition number κ₁(A) = ‖A‖₁‖A⁻¹‖₁ is estimated too
//! (Hager's method as refined by Higham, LAPACK's `dlacn2`: a few solves with A and Aᵀ) and a
//! matrix beyond the bound rejected.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::lu::{
    factorize_symbolic_lu, LuRef, LuSymbolicParams, NumericLu, SymbolicLu,
};
use faer::sparse::linalg::LuError;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Spec};
use fibercell_solver::{
    AnalyzeInfo, Capabilities, CscRef, LinearSolver, PatternFingerprint, SolveInfo, SolverError,
};

/// faer sparse LU for general square matrices.
pub struct FaerLu {
    par: Par,
    max_backward_error: f64,
    max_condition: Option<f64>,
    condition: Option<f64>,
    analysis: Option<(usize, PatternFingerprint, SymbolicLu<usize>)>,
    numeric: Option<NumericLu<usize, f64>>,
}

impl Default for FaerLu {
    fn default() -> Self {
        FaerLu {
            par: Par::rayon(0),
            max_backward_error: 1e-10,
            max_condition: None,
            condition: None,
            analysis: None,
            numeric: None,
        }
    }
}

impl FaerLu {
    /// A solver with all rayon threads and a check-solve backward error bound of 1e-10.
    pub fn new() -> Self {
        Self::default()
    }

    /// The largest accepted backward error of the check solve (default 1e-10).
    pub fn with_max_backward_error(mut self, tol: f64) -> Self {
        self.max_backward_error = tol;
        self
    }

    /// Estimate κ₁(A) after every factorization (about a dozen extra solves) and reject a
    /// matrix whose estimate is `kappa` or more.
    pub fn with_max_condition(mut self, kappa: f64) -> Self {
        self.max_condition = Some(kappa);
        self
    }

    /// The estimated κ₁ of the last factorized matrix, when [`FaerLu::with_max_condition`]
    /// asked for it.
    pub fn condition_estimate(&self) -> Option<f64> {
        self.condition
    }

    /// Solves with A (`transpose` false) or Aᵀ in place.
    fn solve_raw_with(
        &self,
        rhs: &mut [f64],
        nrhs: usize,
        transpose: bool,
    ) -> Result<(), SolverError> {
        let (an, numeric) = match (&self.analysis, &self.numeric) {
            (Some(a), Some(f)) => (a, f),
            _ => return Err(SolverError::OutOfOrder("solve", "factorize")),
        };
        let (n, _, symbolic) = an;
        let req = symbolic.solve_in_place_scratch::<f64>(nrhs, self.par);
        let mut buf = MemBuffer::try_new(req).map_err(|_| SolverError::OutOfMemory)?;
        let lu = LuRef::new_unchecked(symbolic, numeric);
        let rhs = MatMut::from_column_major_slice_mut(rhs, *n, nrhs);
        if transpose {
            lu.solve_transpose_in_place_with_conj(Conj::No, rhs, self.par, MemStack::new(&mut buf));
        } else {
            lu.solve_in_place_with_conj(Conj::No, rhs, self.par, MemStack::new(&mut buf));
        }
        Ok(())
    }

    fn solve_raw(&self, rhs: &mut [f64], nrhs: usize) -> Result<(), SolverError> {
        self.solve_raw_with(rhs, nrhs, false)
    }

    /// The check solve x = A⁻¹(A·1) of a fresh factorization of `a`: finite, with a backward
    /// error of at most `max_backward_error` (else the factorization is dropped).
    fn check_solve(&mut self, a: CscRef<'_>) -> Result<(), SolverError> {
        let n = a.ncols();
        let ones = vec![1.0; n];
        let mut b = vec![0.0; n];
        a.mul_vec(&ones, &mut b);
        let mut x = b.clone();
        self.solve_raw(&mut x, 1)?;
        let backward = if x.iter().all(|v| v.is_finite()) {
            fibercell_solver::backward_error(a, &x, &b)
        } else {
            f64::INFINITY
        };
        if backward <= self.max_backward_error {
            return Ok(());
        }
        self.numeric = None;
        Err(SolverError::Singular {
            column: None,
            detail: format!(
                "numerically zero pivot: the check solve A x = A·1 has backward error {backward:.3e} > {:.1e}",
                self.max_backward_error
            ),
        })
    }

    /// An estimate of ‖A⁻¹‖₁ from the current factorization
    /// ([`fibercell_solver::inverse_norm1_estimate`]).
    fn inverse_norm1_estimate(&self, n: usize) -> Result<f64, SolverError> {
        fibercell_solver::inverse_norm1_estimate(n, &mut |x, transposed| {
            self.solve_raw_with(x, 1, transposed)
        })
    }
}

impl LinearSolver for FaerLu {
    fn name(&self) -> &'static str {
        "faer-lu"
    }

    fn capabilities(&self) -> Capabilities {
        Capabilities {
            symmetric_only: false,
            reuses_symbolic: true,
            iterative: false,
            selectable_ordering: false,
        }
    }

    fn analyze(&mut self, a: CscRef<'_>) -> Result<AnalyzeInfo, SolverError> {
        <dyn LinearSolver>::check_matrix(a, None)?;
        self.numeric = None;
        let n = a.ncols();
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, a.col_ptr(), None, a.row_idx());
        let symbolic =
            factorize_symbolic_lu(pattern, LuSymbolicParams::default()).map_err(|e| {
                SolverError::Backend {
                    backend: "faer-lu",
                    code: -1,
                    message: format!("symbolic LU failed: {e:?}"),
                }
            })?;
        self.analysis = Some((n, a.fingerprint(), symbolic));
        Ok(AnalyzeInfo {
            n,
            nnz_a: a.nnz(),
            nnz_factor: None,
            factor_bytes: None,
            flops: None,
            ordering: "colamd".into(),
        })
    }

    fn factorize(&mut self, a: CscRef<'_>) -> Result<(), SolverError> {
        let (n, fp, symbolic) = self
            .analysis
            .as_ref()
            .ok_or(SolverError::OutOfOrder("factorize", "analyze"))?;
        <dyn LinearSolver>::check_matrix(a, Some(*n))?;
        if a.fingerprint() != *fp {
            return Err(SolverError::PatternChanged);
        }
        let n = *n;
        let mut numeric = self.numeric.take().unwrap_or_default();
        let req = symbolic.factorize_numeric_lu_scratch::<f64>(self.par, Spec::default());
        let mut buf = MemBuffer::try_new(req).map_err(|_| SolverError::OutOfMemory)?;
        let mat = SparseColMatRef::new(
            SymbolicSparseColMatRef::new_checked(n, n, a.col_ptr(), None, a.row_idx()),
            a.values(),
        );
        match symbolic.factorize_numeric_lu(
            &mut numeric,
            mat,
            self.par,
            MemStack::new(&mut buf),
            Spec::default(),
        ) {
            Ok(_) => {}
            Err(LuError::SymbolicSingular { index }) => {
                return Err(SolverError::Singular {
                    column: None,
                    detail: format!("structurally singular (no pivot at step {index})"),
                })
            }
            Err(LuError::Generic(e)) => {
                return Err(SolverError::Backend {
                    backend: "faer-lu",
                    code: -1,
                    message: format!("{e:?}"),
                })
            }
        }
        self.numeric = Some(numeric);
        self.check_solve(a)?;
        self.condition = None;
        if let Some(max) = self.max_condition {
            // ‖A‖₁: the largest absolute column sum.
            let norm_a = (0..n)
                .map(|j| a.col(j).1.iter().map(|v| v.abs()).sum::<f64>())
                .fold(0.0f64, f64::max);
            let kappa = norm_a * self.inverse_norm1_estimate(n)?;
            self.condition = Some(kappa);
            if !(kappa < max) {
                self.numeric = None;
                return Err(SolverError::Singular {
                    column: None,
                    detail: format!(
                        "estimated condition number κ₁ ≈ {kappa:.3e} ≥ the accepted {max:.1e}"
                    ),
                });
            }
        }
        Ok(())
    }

    fn solve_in_place(&mut self, rhs: &mut [f64], nrhs: usize) -> Result<SolveInfo, SolverError> {
        let n = self.analysis.as_ref().map(|a| a.0).unwrap_or(0);
        <dyn LinearSolver>::check_rhs(n, rhs, nrhs)?;
        self.solve_raw(rhs, nrhs)?;
        Ok(SolveInfo::default())
    }
}
