//! Conjugate gradients on a symmetric positive definite A preconditioned by the factorization of
//! a nearby matrix A₀ (the previous values of the same pattern). When A − A₀ has rank k — e.g. k
//! contact springs switched on or off — the preconditioned operator A₀⁻¹A is the identity plus a
//! rank-k term, so CG converges in at most k + 1 iterations in exact arithmetic, each costing one
//! pair of triangular solves and one product with A: far less than a refactorization while k is
//! small.

use crate::{norm_inf, vector_norm_inf, CscRef, LinearSolver, SolverError};

/// The outcome of [`pcg_with_factor`].
#[derive(Clone, Debug, PartialEq)]
pub struct FactorPcg {
    /// The solution (the last iterate when not converged).
    pub x: Vec<f64>,
    /// Iterations done (preconditioner applications after the first).
    pub iterations: usize,
    /// Whether the backward error reached the tolerance.
    pub converged: bool,
    /// Normwise backward error ‖Ax − b‖∞ / (‖A‖∞‖x‖∞ + ‖b‖∞) of the returned x, recomputed
    /// from the true residual.
    pub backward_error: f64,
}

/// Solves A x = b by CG preconditioned with `factor`, a solver already factorized on a matrix of
/// the same order (symmetric positive definite, like A). Stops when the normwise backward error
/// of the true residual is at most `tolerance`, or after `max_iterations`.
pub fn pcg_with_factor(
    factor: &mut dyn LinearSolver,
    a: CscRef<'_>,
    b: &[f64],
    tolerance: f64,
    max_iterations: usize,
) -> Result<FactorPcg, SolverError> {
    let n = a.ncols();
    <dyn LinearSolver>::check_rhs(n, b, 1)?;
    let norm_a = norm_inf(a);
    let inf = vector_norm_inf;
    let norm_b = inf(b);
    let dot = |u: &[f64], v: &[f64]| u.iter().zip(v).map(|(p, q)| p * q).sum::<f64>();
    let backward = |r: &[f64], x: &[f64]| {
        let d = norm_a * inf(x) + norm_b;
        if d > 0.0 {
            inf(r) / d
        } else {
            inf(r)
        }
    };
    // x₀ = A₀⁻¹ b: already exact when A = A₀.
    let mut x = b.to_vec();
    factor.solve_in_place(&mut x, 1)?;
    let mut ax = vec![0.0; n];
    a.mul_vec_symmetric_par(&x, &mut ax);
    let mut r: Vec<f64> = b.iter().zip(&ax).map(|(p, q)| p - q).collect();
    let mut iterations = 0;
    let mut err = backward(&r, &x);
    if !err.is_finite() {
        return Err(SolverError::NonFinite {
            what: "solution",
            index: x.iter().position(|v| !v.is_finite()).unwrap_or(0),
        });
    }
    let mut z = r.clone();
    let mut p = Vec::new();
    let mut rz_old = 0.0;
    let mut ap = vec![0.0; n];
    while err > tolerance && iterations < max_iterations {
        z.copy_from_slice(&r);
        factor.solve_in_place(&mut z, 1)?;
        let rz = dot(&r, &z);
        if iterations == 0 {
            p = z.clone();
        } else {
            let beta = rz / rz_old;
            p.iter_mut()
                .zip(&z)
                .for_each(|(pi, zi)| *pi = zi + beta * *pi);
        }
        rz_old = rz;
        a.mul_vec_symmetric_par(&p, &mut ap);
        let pap = dot(&p, &ap);
        if !(pap > 0.0) || !(rz > 0.0) {
            // A is not positive definite along p (or the residual vanished in the A₀⁻¹ norm).
            break;
        }
        let alpha = rz / pap;
        x.iter_mut().zip(&p).for_each(|(xi, pi)| *xi += alpha * pi);
        r.iter_mut()
            .zip(&ap)
            .for_each(|(ri, api)| *ri -= alpha * api);
        iterations += 1;
        err = backward(&r, &x);
    }
    // The recursive residual drifts from the true one: judge the true residual.
    a.mul_vec_symmetric_par(&x, &mut ax);
    let true_r: Vec<f64> = b.iter().zip(&ax).map(|(p, q)| p - q).collect();
    let err = backward(&true_r, &x);
    Ok(FactorPcg {
        converged: err <= tolerance,
        x,
        iterations,
        backward_error: err,
    })
}
