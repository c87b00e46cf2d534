//! Sparse LU through faer (COLAMD column ordering, partial pivoting), for nonsymmetric systems.
//!
//! faer does not flag a numerically zero pivot; after every factorization a check solve with
//! b = A·1 must return the vector of ones to `singularity_tolerance`, otherwise the matrix is
//! reported [`SolverError::Singular`].

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
    singularity_tolerance: f64,
    analysis: Option<(usize, PatternFingerprint, SymbolicLu<usize>)>,
    numeric: Option<NumericLu<usize, f64>>,
}

impl Default for FaerLu {
    fn default() -> Self {
        FaerLu {
            par: Par::rayon(0),
            singularity_tolerance: 1e-6,
            analysis: None,
            numeric: None,
        }
    }
}

impl FaerLu {
    /// A solver with all rayon threads and a singularity tolerance of 1e-6.
    pub fn new() -> Self {
        Self::default()
    }

    /// Largest accepted error of the check solve A x = A·1 (default 1e-6).
    pub fn with_singularity_tolerance(mut self, tol: f64) -> Self {
        self.singularity_tolerance = tol;
        self
    }

    fn solve_raw(&self, rhs: &mut [f64], nrhs: usize) -> Result<(), SolverError> {
        let (an, numeric) = match (&self.analysis, &self.numeric) {
            (Some(a), Some(f)) => (a, f),
            _ => return Err(SolverError::OutOfOrder("solve", "factorize")),
        };
        let (n, _, symbolic) = an;
        let req = symbolic.solve_in_place_scratch::<f64>(nrhs, self.par);
        let mut buf = MemBuffer::try_new(req).map_err(|_| SolverError::OutOfMemory)?;
        let lu = LuRef::new_unchecked(symbolic, numeric);
        lu.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, *n, nrhs),
            self.par,
            MemStack::new(&mut buf),
        );
        Ok(())
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
        // Check solve: A x = A·1 must give x = 1.
        let ones = vec![1.0; n];
        let mut b = vec![0.0; n];
        a.mul_vec(&ones, &mut b);
        self.solve_raw(&mut b, 1)?;
        let err = b.iter().map(|x| (x - 1.0).abs()).fold(0.0, |m: f64, e| {
            if e.is_nan() {
                f64::INFINITY
            } else {
                m.max(e)
            }
        });
        if !(err <= self.singularity_tolerance) {
            self.numeric = None;
            return Err(SolverError::Singular {
                column: None,
                detail: format!(
                    "numerically zero pivot: the check solve A x = A·1 is off by {err:.3e}"
                ),
            });
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
