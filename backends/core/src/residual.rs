//! Checked solves: relative residual ‖Ax − b‖/‖b‖ and finiteness of the solution.

use crate::csc::PRODUCT_CHUNK;
use crate::{CscRef, LinearSolver, SolveInfo, SolverError};
use rayon::prelude::*;

/// The outcome of a [`solve_checked`] call.
#[derive(Clone, Debug, PartialEq)]
pub struct SolveReport {
    /// Backend name.
    pub backend: &'static str,
    /// Largest relative residual ‖Ax − b‖₂/‖b‖₂ over the right-hand sides (0 for b = 0, x = 0).
    pub relative_residual: f64,
    /// Largest normwise backward error ‖Ax − b‖∞ / (‖A‖∞‖x‖∞ + ‖b‖∞): about 1e-16 for a
    /// backward-stable solve however ill-conditioned A is, about 1 for a meaningless one.
    pub backward_error: f64,
    /// What the backend reported.
    pub info: SolveInfo,
}

/// ‖Ax − b‖₂ / ‖b‖₂ (‖Ax‖₂ when b = 0).
pub fn relative_residual(a: CscRef<'_>, x: &[f64], b: &[f64]) -> f64 {
    let mut ax = vec![0.0; a.nrows()];
    a.mul_vec(x, &mut ax);
    relative_from_product(&ax, b)
}

/// ‖Ax − b‖₂ / ‖b‖₂ from the product `ax` = Ax.
pub fn relative_from_product(ax: &[f64], b: &[f64]) -> f64 {
    let r: f64 = ax
        .iter()
        .zip(b)
        .map(|(p, q)| (p - q) * (p - q))
        .sum::<f64>()
        .sqrt();
    relative_of(r, b)
}

/// ‖r‖₂ / ‖b‖₂ from ‖r‖₂ (‖r‖₂ when b = 0).
fn relative_of(r: f64, b: &[f64]) -> f64 {
    let nb: f64 = b.iter().map(|v| v * v).sum::<f64>().sqrt();
    if nb > 0.0 {
        r / nb
    } else {
        r
    }
}

/// ‖A‖∞, the largest absolute row sum of the stored entries (A given in full).
pub fn norm_inf(a: CscRef<'_>) -> f64 {
    let mut row_sums = vec![0.0; a.nrows()];
    for (&i, v) in a.row_idx().iter().zip(a.values()) {
        row_sums[i] += v.abs();
    }
    row_sums.iter().fold(0.0f64, |m, v| m.max(*v))
}

/// ‖A‖∞ of a **symmetric** A stored in full: its largest absolute column sum, columns in
/// parallel (each sum by one task: the result does not depend on threads).
pub fn norm_inf_symmetric_par(a: CscRef<'_>) -> f64 {
    use rayon::prelude::*;
    (0..a.ncols())
        .into_par_iter()
        .with_min_len(1024)
        .map(|j| a.col(j).1.iter().map(|v| v.abs()).sum::<f64>())
        .reduce(|| 0.0, f64::max)
}

/// ‖v‖∞ (0 for an empty vector).
pub fn vector_norm_inf(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Normwise backward error ‖Ax − b‖∞ / (‖A‖∞‖x‖∞ + ‖b‖∞) (0 when all vanish).
pub fn backward_error(a: CscRef<'_>, x: &[f64], b: &[f64]) -> f64 {
    let mut ax = vec![0.0; a.nrows()];
    a.mul_vec(x, &mut ax);
    backward_from_product(norm_inf(a), &ax, x, b)
}

/// The backward error ‖Ax − b‖∞ / (‖A‖∞‖x‖∞ + ‖b‖∞) from the product `ax` = Ax and ‖A‖∞.
pub fn backward_from_product(norm_a: f64, ax: &[f64], x: &[f64], b: &[f64]) -> f64 {
    let r = ax
        .iter()
        .zip(b)
        .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
    backward_of(norm_a, r, x, b)
}

/// The backward error from ‖A‖∞ and ‖Ax − b‖∞ (`r`).
fn backward_of(norm_a: f64, r: f64, x: &[f64], b: &[f64]) -> f64 {
    let denom = norm_a * vector_norm_inf(x) + vector_norm_inf(b);
    if denom > 0.0 {
        r / denom
    } else {
        r
    }
}

/// Solves A X = B with a factorized `solver`, then checks the result: a non-finite solution is
/// [`SolverError::NonFinite`], and the relative residual of every column is computed and
/// reported. `b` holds `nrhs` columns of length n. For a symmetric-only backend `a` is taken
/// to be symmetric, as its analysis required, and its columns are read as rows.
pub fn solve_checked(
    solver: &mut dyn LinearSolver,
    a: CscRef<'_>,
    b: &[f64],
    nrhs: usize,
) -> Result<(Vec<f64>, SolveReport), SolverError> {
    solve_checked_into(solver, a, b, Vec::new(), nrhs)
}

/// [`solve_checked`] with the solution written into `buffer` (its contents are replaced; it
/// grows if it is shorter than `b`). A buffer whose pages are already mapped — written on a
/// thread that would otherwise idle, say — keeps the first touch of n·nrhs new values off the
/// solve.
pub fn solve_checked_into(
    solver: &mut dyn LinearSolver,
    a: CscRef<'_>,
    b: &[f64],
    buffer: Vec<f64>,
    nrhs: usize,
) -> Result<(Vec<f64>, SolveReport), SolverError> {
    let n = a.ncols();
    <dyn LinearSolver>::check_rhs(n, b, nrhs)?;
    let mut x = buffer;
    x.clear();
    x.extend_from_slice(b);
    let info = solver.solve_in_place(&mut x, nrhs)?;
    if let Some(i) = x.iter().position(|v| !v.is_finite()) {
        return Err(SolverError::NonFinite {
            what: "solution",
            index: i % n.max(1),
        });
    }
    let symmetric = solver.capabilities().symmetric_only;
    let (relative, backward) = if symmetric && nrhs > 1 {
        // A symmetric backend's matrix (its pattern checked symmetric by the analysis): the
        // residuals of all columns in one pass over A, without storing A X.
        symmetric_residuals(a, &x, b, nrhs)
    } else {
        let (norm_a, ax) = if symmetric {
            let mut ax = vec![0.0; n * nrhs];
            let norm = a.mul_many_symmetric_norm_par(&x, nrhs, &mut ax);
            (norm, ax)
        } else {
            rayon::join(|| norm_inf(a), || products(a, &x, nrhs))
        };
        residuals_from_products(norm_a, &ax, &x, b, nrhs)
    };
    Ok((
        x,
        SolveReport {
            backend: solver.name(),
            relative_residual: relative,
            backward_error: backward,
            info,
        },
    ))
}

/// The largest relative residual and backward error over the `nrhs` columns, from the
/// products `ax` and ‖A‖∞.
fn residuals_from_products(
    norm_a: f64,
    ax: &[f64],
    x: &[f64],
    b: &[f64],
    nrhs: usize,
) -> (f64, f64) {
    let n = x.len() / nrhs.max(1);
    (0..nrhs)
        .into_par_iter()
        .map(|k| {
            let cols = k * n..(k + 1) * n;
            let (ax, x, b) = (&ax[cols.clone()], &x[cols.clone()], &b[cols]);
            (
                relative_from_product(ax, b),
                backward_from_product(norm_a, ax, x, b),
            )
        })
        .reduce(|| (0.0, 0.0), |p, q| (p.0.max(q.0), p.1.max(q.1)))
}

/// [`residuals_from_products`] for a **symmetric** A, with A X formed chunk by chunk of rows
/// ([`CscRef::fold_many_symmetric_par`]) and reduced at once: per chunk and column Σ rᵢ² and
/// max |rᵢ|, summed in chunk order, so the result does not depend on the threads.
fn symmetric_residuals(a: CscRef<'_>, x: &[f64], b: &[f64], nrhs: usize) -> (f64, f64) {
    let n = a.ncols();
    let chunks = n.div_ceil(PRODUCT_CHUNK);
    let states = vec![vec![(0.0f64, 0.0f64); nrhs]; chunks];
    let (norm_a, parts) = a.fold_many_symmetric_par(x, nrhs, states, |part, i, c0, sums| {
        for (c, &s) in sums.iter().enumerate() {
            let r = s - b[(c0 + c) * n + i];
            let (squares, largest) = &mut part[c0 + c];
            *squares += r * r;
            *largest = largest.max(r.abs());
        }
    });
    (0..nrhs)
        .into_par_iter()
        .map(|c| {
            let cols = c * n..(c + 1) * n;
            let (squares, largest) = parts
                .iter()
                .fold((0.0, 0.0f64), |(s, m), p| (s + p[c].0, m.max(p[c].1)));
            (
                relative_of(squares.sqrt(), &b[cols.clone()]),
                backward_of(norm_a, largest, &x[cols.clone()], &b[cols]),
            )
        })
        .reduce(|| (0.0, 0.0), |p, q| (p.0.max(q.0), p.1.max(q.1)))
}

/// A X for the `nrhs` columns of `x` (length n each), the columns on all threads, each by
/// [`CscRef::mul_vec`] (so the result does not depend on the threads).
fn products(a: CscRef<'_>, x: &[f64], nrhs: usize) -> Vec<f64> {
    let (m, n) = (a.nrows(), a.ncols());
    let mut ax = vec![0.0; m * nrhs];
    if m == 0 || n == 0 {
        return ax;
    }
    ax.par_chunks_mut(m)
        .zip(x.par_chunks(n))
        .for_each(|(y, x)| a.mul_vec(x, y));
    ax
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CscMatrix;

    /// The residuals reduced chunk by chunk from the fused symmetric product are those of the
    /// stored products (relative 1e-12: the sums of squares are grouped differently) for 2, 3
    /// and 9 columns (one group of eight and one of one) on a symmetric matrix of three
    /// chunks and a part, and identical on one, two and three threads.
    #[test]
    fn fused_symmetric_residuals_are_the_residuals_of_the_products() {
        let n = 3 * PRODUCT_CHUNK + 77;
        let mut t = Vec::new();
        for i in 0..n {
            t.push((i, i, 4.0 + (i % 7) as f64));
            for (d, v) in [(1, -1.0), (1100, 0.25)] {
                if i + d < n {
                    t.push((i + d, i, v));
                    t.push((i, i + d, v));
                }
            }
        }
        let a = CscMatrix::from_triplets(n, n, &t).unwrap();
        let a = a.as_ref();
        for k in [2, 3, 9] {
            let x: Vec<f64> = (0..n * k).map(|i| ((i * 17) % 13) as f64 - 6.0).collect();
            let b: Vec<f64> = (0..n * k).map(|i| ((i * 7) % 11) as f64 - 5.0).collect();
            let ax = products(a, &x, k);
            let (rel, bwd) = residuals_from_products(norm_inf(a), &ax, &x, &b, k);
            assert!(rel > 0.1 && bwd > 1e-3, "k {k}: {rel}, {bwd}");
            let mut got = Vec::new();
            for threads in [1, 2, 3] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                got.push(pool.install(|| symmetric_residuals(a, &x, &b, k)));
            }
            assert!(got.iter().all(|&g| g == got[0]), "k {k}: {got:?}");
            let (r, e) = got[0];
            assert!((r - rel).abs() <= 1e-12 * rel, "k {k}: {r} vs {rel}");
            assert!((e - bwd).abs() <= 1e-12 * bwd, "k {k}: {e} vs {bwd}");
        }
    }

    /// The product of five right-hand sides with a nonsymmetric 3×3 matrix is the product
    /// worked by hand, on one, two and three threads.
    #[test]
    fn products_of_several_columns_are_each_columns_product_on_any_threads() {
        // A = [[2, 0, 1], [0, 3, 0], [4, 0, 5]], stored column by column.
        let a = CscMatrix::from_triplets(
            3,
            3,
            &[
                (0, 0, 2.0),
                (2, 0, 4.0),
                (1, 1, 3.0),
                (0, 2, 1.0),
                (2, 2, 5.0),
            ],
        )
        .unwrap();
        // Column k of X is (k, 1, −k); A X's column k is (2k − k, 3, 4k − 5k) = (k, 3, −k).
        let x: Vec<f64> = (0..5).flat_map(|k| [k as f64, 1.0, -(k as f64)]).collect();
        let want: Vec<f64> = (0..5).flat_map(|k| [k as f64, 3.0, -(k as f64)]).collect();
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let got = pool.install(|| products(a.as_ref(), &x, 5));
            assert_eq!(got, want, "{threads} threads");
        }
    }
}
