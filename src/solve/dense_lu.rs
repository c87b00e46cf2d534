//! A dense LU factorization with partial pivoting kept in the matrix it factorizes.
//!
//! faer's `PartialPivLu::new` copies its input and then splits the factors into two matrices of
//! the full order, so a capacitance matrix of order R held 3 R² doubles while it was factorized
//! and 2 R² while it was kept. Capacitances reach orders of thousands (7,456 on the L
//! non-woven's curve, 0.44 GB per copy); this keeps R² throughout, with faer's own kernels.
//! The LU serves changes that add springs (slip → stick, the consistent Coulomb tangent); those
//! that only remove them are factorized by Cholesky in place (`low_rank.rs`).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::perm::Perm;
use faer::reborrow::Reborrow;
use faer::{MatMut, MatRef};

/// P A = L U of a square matrix, L unit lower and U upper triangular, both in the one
/// column-major buffer that held A.
pub struct DenseLu {
    lu: Vec<f64>,
    order: usize,
    /// P, checked once when the factors are made.
    perm: Perm<usize>,
}

impl DenseLu {
    /// Factorizes the `order × order` column-major matrix `data` in place.
    ///
    /// # Panics
    /// When `data` does not hold `order²` values (a caller's error, not an input's).
    pub fn new(mut data: Vec<f64>, order: usize) -> Self {
        assert_eq!(data.len(), order * order, "an order × order matrix");
        let mut forward = vec![0usize; order];
        let mut inverse = vec![0usize; order];
        let par = faer::get_global_parallelism();
        let scratch =
            factor::lu_in_place_scratch::<usize, f64>(order, order, par, Default::default());
        factor::lu_in_place(
            MatMut::from_column_major_slice_mut(&mut data, order, order),
            &mut forward,
            &mut inverse,
            par,
            MemStack::new(&mut MemBuffer::new(scratch)),
            Default::default(),
        );
        let perm = Perm::new_checked(forward.into(), inverse.into(), order);
        DenseLu {
            lu: data,
            order,
            perm,
        }
    }

    /// Overwrites the column-major `order × k` right-hand sides `rhs` with A⁻¹ rhs (a
    /// singular A gives non-finite values, which the callers check).
    pub fn solve_in_place(&self, rhs: &mut [f64]) {
        let n = self.order;
        let k = rhs.len().checked_div(n).unwrap_or(0);
        assert_eq!(rhs.len(), n * k, "whole columns of right-hand sides");
        let lu = MatRef::from_column_major_slice(&self.lu, n, n);
        let par = faer::get_global_parallelism();
        let scratch = solve::solve_in_place_scratch::<usize, f64>(n, k, par);
        // The unit lower solve reads only the strictly lower triangle, the upper solve only
        // the upper one: both read the one buffer.
        solve::solve_in_place(
            lu,
            lu,
            self.perm.rb(),
            MatMut::from_column_major_slice_mut(rhs, n, k),
            par,
            MemStack::new(&mut MemBuffer::new(scratch)),
        );
    }

    /// The bytes it holds: the factors and the two permutations.
    pub fn memory_bytes(&self) -> usize {
        8 * self.lu.capacity() + 2 * size_of::<usize>() * self.order
    }
}

#[cfg(test)]
mod tests {
    use super::DenseLu;
    use faer::linalg::solvers::Solve;
    use faer::{Mat, MatRef};

    /// A nonsymmetric matrix whose first pivot is tiny (so partial pivoting must swap rows):
    /// the in-place factors solve it to round-off — the residual ‖b − A x‖∞ below 10⁻¹² of
    /// ‖A‖‖x‖ — and give faer's `PartialPivLu` solution bit for bit (the same kernels on the
    /// same values).
    #[test]
    fn in_place_factors_solve_like_faers_partial_pivoting_lu() {
        let n = 37;
        let a: Vec<f64> = (0..n * n)
            .map(|k| {
                let (i, j) = (k % n, k / n);
                let wave = ((7 * i + 3 * j) as f64).sin();
                if i == j {
                    if i == 0 {
                        1e-14
                    } else {
                        4.0 + wave
                    }
                } else {
                    wave / (1.0 + (i as f64 - j as f64).abs())
                }
            })
            .collect();
        let b: Vec<f64> = (0..2 * n).map(|i| (i as f64 * 0.37).cos()).collect();
        let mut x = b.clone();
        DenseLu::new(a.clone(), n).solve_in_place(&mut x);
        let am = MatRef::from_column_major_slice(&a, n, n);
        let mut y = Mat::from_fn(n, 2, |i, j| b[j * n + i]);
        am.partial_piv_lu().solve_in_place(y.as_mut());
        for j in 0..2 {
            let xs = &x[j * n..(j + 1) * n];
            for i in 0..n {
                assert_eq!(xs[i], y[(i, j)], "column {j} row {i}");
            }
            let norm_a = (0..n)
                .map(|i| (0..n).map(|l| a[l * n + i].abs()).sum::<f64>())
                .fold(0.0, f64::max);
            let norm_x = xs.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for i in 0..n {
                let ax: f64 = (0..n).map(|l| a[l * n + i] * xs[l]).sum();
                let r = (b[j * n + i] - ax).abs();
                assert!(r <= 1e-12 * norm_a * norm_x, "row {i}: residual {r:e}");
            }
        }
    }

    /// It keeps one matrix of the order: R² doubles and the permutations.
    #[test]
    fn it_holds_one_matrix_of_its_order() {
        let lu = DenseLu::new(vec![2.0, 1.0, 1.0, 3.0], 2);
        assert_eq!(lu.memory_bytes(), 8 * 4 + 4 * size_of::<usize>());
    }
}
