//! Checked solves: relative residual ‖Ax − b‖/‖b‖ and finiteness of the solution.

use crate::{CscRef, LinearSolver, SolveInfo, SolverError};

/// The outcome of a [`solve_checked`] call.
#[derive(Clone, Debug, PartialEq)]
pub struct SolveReport {
    /// Backend name.
    pub backend: &'static str,
    /// Largest relative residual ‖Ax − b‖₂/‖b‖₂ over the right-hand sides (0 for b = 0, x = 0).
    pub relative_residual: f64,
    /// What the backend reported.
    pub info: SolveInfo,
}

/// ‖Ax − b‖₂ / ‖b‖₂ (‖Ax‖₂ when b = 0).
pub fn relative_residual(a: CscRef<'_>, x: &[f64], b: &[f64]) -> f64 {
    let mut ax = vec![0.0; a.nrows()];
    a.mul_vec(x, &mut ax);
    let r: f64 = ax.iter().zip(b).map(|(p, q)| (p - q) * (p - q)).sum::<f64>().sqrt();
    let nb: f64 = b.iter().map(|v| v * v).sum::<f64>().sqrt();
    if nb > 0.0 {
        r / nb
    } else {
        r
    }
}

/// Solves A X = B with a factorized `solver`, then checks the result: a non-finite solution is
/// [`SolverError::NonFinite`], and the relative residual of every column is computed and
/// reported. `b` holds `nrhs` columns of length n.
pub fn solve_checked(
    solver: &mut dyn LinearSolver,
    a: CscRef<'_>,
    b: &[f64],
    nrhs: usize,
) -> Result<(Vec<f64>, SolveReport), SolverError> {
    let n = a.ncols();
    <dyn LinearSolver>::check_rhs(n, b, nrhs)?;
    let mut x = b.to_vec();
    let info = solver.solve_in_place(&mut x, nrhs)?;
    if let Some(i) = x.iter().position(|v| !v.is_finite()) {
        return Err(SolverError::NonFinite {
            what: "solution",
            index: i % n.max(1),
        });
    }
    let relative_residual = (0..nrhs)
        .map(|k| {
            let cols = k * n..(k + 1) * n;
            relative_residual(a, &x[cols.clone()], &b[cols])
        })
        .fold(0.0, f64::max);
    Ok((
        x,
        SolveReport {
            backend: solver.name(),
            relative_residual,
            info,
        },
    ))
}
