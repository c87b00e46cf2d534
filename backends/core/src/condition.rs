//! The 1-norm condition number of a factorized matrix, estimated from a few solves.

use crate::SolverError;

/// `solve(x, transposed)`: x ← A⁻¹x, or A⁻ᵀx when `transposed`.
pub type SolveWith<'a> = dyn FnMut(&mut [f64], bool) -> Result<(), SolverError> + 'a;

/// An estimate of ‖A⁻¹‖₁ (Higham 1988, Algorithm 4.1, as LAPACK's `dlacn2`): a lower bound
/// that is almost always within a factor 3, from at most five pairs of solves with A and Aᵀ
/// and one more with an alternating vector. `solve(x, transposed)` overwrites x with A⁻¹x (or
/// A⁻ᵀx). Infinite when a solve is not finite.
pub fn inverse_norm1_estimate(n: usize, solve: &mut SolveWith<'_>) -> Result<f64, SolverError> {
    if n == 0 {
        return Ok(0.0);
    }
    let norm1 = |v: &[f64]| v.iter().map(|x| x.abs()).sum::<f64>();
    let mut x = vec![1.0 / n as f64; n];
    let mut estimate = 0.0f64;
    let mut last_j = usize::MAX;
    for iteration in 0..5 {
        solve(&mut x, false)?;
        if x.iter().any(|v| !v.is_finite()) {
            return Ok(f64::INFINITY);
        }
        let y_norm = norm1(&x);
        if iteration > 0 && y_norm <= estimate {
            break;
        }
        estimate = y_norm;
        let mut z: Vec<f64> = x
            .iter()
            .map(|v| if *v >= 0.0 { 1.0 } else { -1.0 })
            .collect();
        solve(&mut z, true)?;
        let (j, zj) = z
            .iter()
            .enumerate()
            .fold((0, f64::NEG_INFINITY), |m, (k, v)| {
                if v.abs() > m.1 {
                    (k, v.abs())
                } else {
                    m
                }
            });
        if !zj.is_finite() {
            return Ok(f64::INFINITY);
        }
        if j == last_j {
            break;
        }
        last_j = j;
        x.iter_mut().for_each(|v| *v = 0.0);
        x[j] = 1.0;
    }
    // The alternating vector catches matrices where the iteration stalls.
    let mut alt: Vec<f64> = (0..n)
        .map(|i| {
            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
            sign * (1.0 + i as f64 / (n.max(2) - 1) as f64)
        })
        .collect();
    solve(&mut alt, false)?;
    let alt_estimate = 2.0 * norm1(&alt) / (3.0 * n as f64);
    if !alt_estimate.is_finite() {
        return Ok(f64::INFINITY);
    }
    Ok(estimate.max(alt_estimate))
}

/// ‖A‖₁, the largest column sum of |a_ij|.
pub fn norm1(a: crate::CscRef<'_>) -> f64 {
    (0..a.ncols())
        .map(|j| a.col(j).1.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}
