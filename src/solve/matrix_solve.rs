//! Any sparse matrix through the solver layer, timed: what `fibercell solve-matrix` runs on a
//! Matrix Market file, so the backends can be compared on matrices from anywhere.

use super::SolverConfig;
use crate::Error;
use fibercell_solver::{solve_checked, CscRef};
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
    /// Stored entries of the matrix (both triangles).
    pub nnz: usize,
    /// Entries of the factor, when a direct method.
    pub nnz_factor: Option<usize>,
    /// Flops of one numeric factorization, when known.
    pub flops: Option<f64>,
    /// Iterations, for CG.
    pub iterations: Option<usize>,
    /// Seconds of the symbolic analysis (ordering included).
    pub analyze_seconds: f64,
    /// Seconds of the numeric factorization.
    pub factorize_seconds: f64,
    /// Seconds of the solve and its residual check.
    pub solve_seconds: f64,
    /// ‖Ax − b‖₂/‖b‖₂.
    pub relative_residual: f64,
    /// ‖Ax − b‖∞/(‖A‖∞‖x‖∞ + ‖b‖∞).
    pub backward_error: f64,
    /// max |x − 1| when no right-hand side was given (b = A·1, so x = 1 exactly).
    pub error_against_ones: Option<f64>,
}

/// Analyzes, factorizes and solves A x = b with the backend of `config`; `b` defaults to A·1,
/// whose exact solution is the vector of ones.
pub fn solve_matrix(
    a: CscRef<'_>,
    b: Option<&[f64]>,
    config: &SolverConfig,
) -> Result<(Vec<f64>, MatrixSolveReport), Error> {
    let n = a.ncols();
    let ones_rhs;
    let rhs = match b {
        Some(b) => b,
        None => {
            let mut v = vec![0.0; a.nrows()];
            a.mul_vec(&vec![1.0; n], &mut v);
            ones_rhs = v;
            &ones_rhs
        }
    };
    let mut solver = config.build()?;
    let t = Instant::now();
    let info = solver.analyze(a)?;
    let analyze_seconds = t.elapsed().as_secs_f64();
    let t = Instant::now();
    solver.factorize(a)?;
    let factorize_seconds = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let (x, report) = solve_checked(solver.as_mut(), a, rhs, 1)?;
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
            nnz: a.nnz(),
            nnz_factor: info.nnz_factor,
            flops: info.flops,
            iterations: report.info.iterations,
            analyze_seconds,
            factorize_seconds,
            solve_seconds,
            relative_residual: report.relative_residual,
            backward_error: report.backward_error,
            error_against_ones,
        },
    ))
}
