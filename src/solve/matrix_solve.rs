//! Any sparse matrix through the solver layer, timed: what `fibercell solve-matrix` runs on a
//! Matrix Market file, so the backends can be compared on matrices from anywhere.

use super::SolverConfig;
use crate::Error;
use fibercell_solver::{median, solve_checked, CscRef, SolverError};
use serde::Serialize;
use std::time::Instant;

/// What [`solve_matrix`] did and how well.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MatrixSolveReport {
    /// Backend.
    pub backend: String,
    /// The ordering the backend used.
    pub ordering: String,
    /// Order of the matrix.
    pub n: usize,
    /// Right-hand sides solved.
    pub columns: usize,
    /// Stored entries of the matrix (both triangles).
    pub nnz: usize,
    /// Entries of the factor by its structure, when a direct method.
    pub nnz_factor: Option<usize>,
    /// Bytes of the factor's values as stored (relaxed supernodes' zeros included), when known.
    pub factor_bytes: Option<usize>,
    /// Flops of one numeric factorization, when known.
    pub flops: Option<f64>,
    /// Iterations, for CG.
    pub iterations: Option<usize>,
    /// Runs of the analysis and of the factorization whose median is reported.
    pub repeats: usize,
    /// Seconds of the symbolic analysis (ordering included): the median of `repeats`.
    pub analyze_seconds: f64,
    /// Seconds of the numeric factorization: the median of `repeats` on the last analysis
    /// (the first allocates the factor, the others reuse it as a solver loop does).
    pub factorize_seconds: f64,
    /// Seconds of the solve and its residual check.
    pub solve_seconds: f64,
    /// ‖Ax − b‖₂/‖b‖₂, the largest over the columns.
    pub relative_residual: f64,
    /// ‖Ax − b‖∞/(‖A‖∞‖x‖∞ + ‖b‖∞), the largest over the columns.
    pub backward_error: f64,
    /// max |x − 1| when no right-hand side was given (b = A·1, so x = 1 exactly).
    pub error_against_ones: Option<f64>,
}

/// Analyzes, factorizes and solves A X = B with the backend of `config`: `b` holds one or
/// more columns of length n, column after column (X is returned the same way), and defaults to
/// A·1, whose exact solution is the vector of ones. The analysis and the factorization run
/// `repeats` times (at least once) and their medians are reported.
pub fn solve_matrix(
    a: CscRef<'_>,
    b: Option<&[f64]>,
    config: &SolverConfig,
    repeats: usize,
) -> Result<(Vec<f64>, MatrixSolveReport), Error> {
    let repeats = repeats.max(1);
    let n = a.ncols();
    let ones_rhs;
    let rhs = match b {
        Some(b) if b.is_empty() || n == 0 || b.len() % n != 0 => {
            return Err(SolverError::DimensionMismatch(format!(
                "the right-hand sides hold {} values, not one or more columns of {n}",
                b.len()
            ))
            .into())
        }
        Some(b) => b,
        None => {
            let mut v = vec![0.0; a.nrows()];
            a.mul_vec(&vec![1.0; n], &mut v);
            ones_rhs = v;
            &ones_rhs
        }
    };
    let mut solver = config.build()?;
    let mut analyze = Vec::with_capacity(repeats);
    let mut info = None;
    for _ in 0..repeats {
        let t = Instant::now();
        info = Some(solver.analyze(a)?);
        analyze.push(t.elapsed().as_secs_f64());
    }
    let info = info.expect("at least one analysis");
    let mut factorize = Vec::with_capacity(repeats);
    for _ in 0..repeats {
        let t = Instant::now();
        solver.factorize(a)?;
        factorize.push(t.elapsed().as_secs_f64());
    }
    let t = Instant::now();
    let columns = rhs.len().checked_div(n).unwrap_or(1);
    let (x, report) = solve_checked(solver.as_mut(), a, rhs, columns)?;
    let solve_seconds = t.elapsed().as_secs_f64();
    let error_against_ones = b
        .is_none()
        .then(|| x.iter().fold(0.0f64, |m, v| m.max((v - 1.0).abs())));
    Ok((
        x,
        MatrixSolveReport {
            backend: report.backend.to_string(),
            ordering: info.ordering,
            n,
            columns,
            nnz: a.nnz(),
            nnz_factor: info.nnz_factor,
            factor_bytes: info.factor_bytes,
            flops: info.flops,
            iterations: report.info.iterations,
            repeats,
            analyze_seconds: median(analyze),
            factorize_seconds: median(factorize),
            solve_seconds,
            relative_residual: report.relative_residual,
            backward_error: report.backward_error,
            error_against_ones,
        },
    ))
}

/// The largest backward error a [`MatrixSolver`] solve accepts.
pub const MATRIX_SOLVE_BACKWARD_ERROR: f64 = 1e-8;

/// A backend with its last matrix, for callers with their own matrices (the Python and C
/// bindings): factorize any number of matrices — the symbolic analysis runs again only when
/// the pattern changes — and solve any number of right-hand sides, each checked by its
/// normwise backward error.
pub struct MatrixSolver {
    solver: Box<dyn fibercell_solver::LinearSolver>,
    matrix: Option<fibercell_solver::CscMatrix>,
}

impl MatrixSolver {
    /// The backend of `config`.
    pub fn new(config: &SolverConfig) -> Result<Self, Error> {
        Ok(MatrixSolver {
            solver: config.build()?,
            matrix: None,
        })
    }

    /// The backend's name.
    pub fn backend(&self) -> &'static str {
        self.solver.name()
    }

    /// The order of the last factorized matrix (`None` before the first).
    pub fn order(&self) -> Option<usize> {
        self.matrix.as_ref().map(|m| m.as_ref().nrows())
    }

    /// Analyzes `a` when its pattern differs from the last matrix's, and factorizes it.
    pub fn factorize(&mut self, a: fibercell_solver::CscMatrix) -> Result<(), Error> {
        let same_pattern = self.matrix.as_ref().is_some_and(|m| {
            let (m, a) = (m.as_ref(), a.as_ref());
            m.nrows() == a.nrows() && m.col_ptr() == a.col_ptr() && m.row_idx() == a.row_idx()
        });
        // A failed factorization leaves no matrix to solve with.
        self.matrix = None;
        if !same_pattern {
            self.solver.analyze(a.as_ref())?;
        }
        self.solver.factorize(a.as_ref())?;
        self.matrix = Some(a);
        Ok(())
    }

    /// x with A x = b for the last factorized A, and its backward error ‖Ax − b‖∞/(‖A‖∞‖x‖∞ +
    /// ‖b‖∞); an error above [`MATRIX_SOLVE_BACKWARD_ERROR`] (a singular matrix, or one that
    /// breaks the backend's assumptions) is refused.
    pub fn solve(&mut self, b: &[f64]) -> Result<(Vec<f64>, f64), Error> {
        let a = self
            .matrix
            .as_ref()
            .ok_or_else(|| Error::InvalidOption("solve before factorize: no matrix".into()))?;
        if b.len() != a.as_ref().nrows() {
            return Err(Error::InvalidOption(format!(
                "right-hand side of length {} for a matrix of order {}",
                b.len(),
                a.as_ref().nrows()
            )));
        }
        let (x, report) = solve_checked(self.solver.as_mut(), a.as_ref(), b, 1)?;
        let e = report.backward_error;
        if !(e <= MATRIX_SOLVE_BACKWARD_ERROR) {
            return Err(Error::InvalidOption(format!(
                "the solve's backward error is {e:e}: the matrix is singular or breaks the \
                 backend's assumptions (try the faer-lu backend)"
            )));
        }
        Ok((x, e))
    }
}

#[cfg(test)]
mod matrix_solver_tests {
    use super::*;
    use crate::solve::SolverKind;
    use fibercell_solver::CscMatrix;

    /// [[4,1,0],[1,3,1],[0,1,2]] scaled by `s`, both triangles.
    fn tridiagonal(s: f64) -> CscMatrix {
        let v = [4.0, 1.0, 1.0, 3.0, 1.0, 1.0, 2.0].map(|x| x * s);
        CscMatrix::new(
            3,
            3,
            vec![0, 2, 5, 7],
            vec![0, 1, 0, 1, 2, 1, 2],
            v.to_vec(),
        )
        .unwrap()
    }

    /// `solve_matrix` solves several right-hand sides at once, column after column: B = A X
    /// for X = [(1, 2, 3), (−1, 0, 2)] gives X back to 1e-13; values that are not whole
    /// columns of 3 are a dimension error, not a solve of the first column.
    #[test]
    fn solve_matrix_takes_whole_columns_of_right_hand_sides() {
        let a = tridiagonal(1.0);
        let b = [6.0, 10.0, 8.0, -4.0, 1.0, 4.0];
        let config = SolverConfig::default();
        let (x, r) = solve_matrix(a.as_ref(), Some(&b), &config, 1).unwrap();
        assert_eq!(r.columns, 2);
        for (got, want) in x.iter().zip([1.0, 2.0, 3.0, -1.0, 0.0, 2.0]) {
            assert!((got - want).abs() <= 1e-13, "{x:?}");
        }
        assert!(r.error_against_ones.is_none());
        for wrong in [&b[..4], &[][..]] {
            match solve_matrix(a.as_ref(), Some(wrong), &config, 1) {
                Err(Error::Solver(SolverError::DimensionMismatch(m))) => {
                    assert!(m.contains("columns of 3"), "{m}")
                }
                other => panic!("{} values: {other:?}", wrong.len()),
            }
        }
    }

    /// Refactorized values give the new solution (A x = (6, 10, 8) s: x = (1, 2, 3)); a
    /// singular matrix, a wrong length and a solve before any factorization are errors.
    #[test]
    fn a_matrix_solver_refactorizes_and_refuses_what_it_cannot_solve() {
        for kind in [SolverKind::FaerCholesky, SolverKind::FaerLu] {
            let mut s = MatrixSolver::new(&SolverConfig::new(kind)).unwrap();
            assert!(s.solve(&[1.0; 3]).is_err(), "{kind}: no matrix yet");
            for scale in [1.0, 2.0] {
                s.factorize(tridiagonal(scale)).unwrap();
                let b = [6.0, 10.0, 8.0].map(|x| x * scale);
                let (x, e) = s.solve(&b).unwrap();
                assert!(e <= 1e-15, "{kind}: backward error {e}");
                for (i, xi) in x.iter().enumerate() {
                    assert!((xi - (i + 1) as f64).abs() <= 1e-13, "{kind}: {x:?}");
                }
            }
            assert_eq!(s.order(), Some(3));
            assert!(s.solve(&[1.0; 2]).is_err(), "{kind}: wrong length");
            let singular =
                CscMatrix::new(2, 2, vec![0, 2, 4], vec![0, 1, 0, 1], vec![1.0; 4]).unwrap();
            let refused = s
                .factorize(singular)
                .and_then(|_| s.solve(&[1.0, 2.0]).map(|_| ()));
            assert!(refused.is_err(), "{kind}: a singular matrix was solved");
            assert_eq!(
                s.order(),
                None,
                "{kind}: a failed factorization keeps no matrix"
            );
        }
    }
}
