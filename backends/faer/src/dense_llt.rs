//! A dense LLᵀ on two threads for the widest supernodes' diagonal blocks.
//!
//! faer's dense Cholesky with `Par::rayon(2)` gains little from the second thread below a few
//! thousand columns (measured alone: 948 columns 54 → 49 GFLOP/s, 3,240 columns 58 → 91, against a
//! two-thread GEMM of ≈ 100). This one is the textbook right-looking blocked factorization (Golub &
//! Van Loan, Matrix Computations, §4.2): for each block column of [`BLOCK`] columns, the diagonal
//! block on one thread (faer's kernel), the block below it solved against its transpose with the
//! rows split over the two threads, and the trailing lower triangle updated by the block column's
//! rank-[`BLOCK`] product in two column ranges of equal work — the bulk of the flops, as a few
//! large products. The splits are two-way (`rayon::join`): the kernel calls it when the pool has
//! two threads, and faer's own kernel on more. [`lower_product`], the one-thread lower-trapezoid
//! product of these updates, is also each descendant's update of a supernode.

use faer::dyn_stack::MemStack;
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, LltError, LltRegularization};
use faer::linalg::matmul::{matmul, triangular};
use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::{Accum, MatMut, MatRef, Par, Spec};

/// Columns per block column: large enough that the trailing products run near the GEMM rate,
/// small enough that the diagonal blocks (one thread) stay a small part of the work.
pub(crate) const BLOCK: usize = 192;

/// Factorizes the lower triangle of the square `a` into L (L Lᵀ = a) in place on two threads;
/// the strict upper triangle is not read or written. `stack` holds faer's one-thread LLᵀ
/// scratch for [`BLOCK`] columns (`cholesky_in_place_scratch`). On a pivot that is not
/// positive, the column where faer's kernel stopped is the error and `a` is left
/// part-factorized.
pub(crate) fn llt_two_threads(mut a: MatMut<'_, f64>, stack: &mut MemStack) -> Result<(), usize> {
    let n = a.nrows();
    let mut k = 0;
    while k < n {
        let kb = BLOCK.min(n - k);
        let rest = a.rb_mut().submatrix_mut(k, k, n - k, n - k);
        let (mut a11, _, mut a21, a22) = rest.split_at_mut(kb, kb);
        llt(a11.rb_mut(), Par::Seq, stack).map_err(|index| k + index)?;
        if a21.nrows() > 0 {
            solve_below_two_threads(a11.rb(), a21.rb_mut());
            update_trailing(a21.rb(), a22);
        }
        k += kb;
    }
    Ok(())
}

/// faer's dense LLᵀ of the square `a` on `par`; the column of a pivot that is not positive
/// as the error.
pub(crate) fn llt(a: MatMut<'_, f64>, par: Par, stack: &mut MemStack) -> Result<(), usize> {
    let reg = LltRegularization::default();
    match cholesky_in_place(a, reg, par, stack, Spec::default()) {
        Err(LltError::NonPositivePivot { index }) => Err(index),
        Ok(_) => Ok(()),
    }
}

/// a21 ← a21 L11⁻ᵀ, the rows in two halves side by side.
pub(crate) fn solve_below_two_threads(l11: MatRef<'_, f64>, a21: MatMut<'_, f64>) {
    let half = a21.nrows() / 2;
    let (top, bottom) = a21.split_at_row_mut(half);
    rayon::join(
        || solve_lower_triangular_in_place(l11, top.transpose_mut(), Par::Seq),
        || solve_lower_triangular_in_place(l11, bottom.transpose_mut(), Par::Seq),
    );
}

/// The lower triangle of a22 −= a21 a21ᵀ in two column ranges of equal work: column j of a
/// trailing block of t columns holds t − j entries, so the first t (1 − 1/√2) columns hold
/// half of them.
fn update_trailing(a21: MatRef<'_, f64>, a22: MatMut<'_, f64>) {
    let t = a22.nrows();
    let split = ((t as f64) * (1.0 - std::f64::consts::FRAC_1_SQRT_2)).round() as usize;
    let (left, right) = a22.split_at_col_mut(split);
    let right = right.subrows_mut(split, t - split);
    rayon::join(
        || lower_product(left, a21, a21.subrows(0, split), Accum::Add),
        || {
            lower_product(
                right,
                a21.subrows(split, t - split),
                a21.subrows(split, t - split),
                Accum::Add,
            )
        },
    );
}

/// dst = (or +=, by `accum`) −below · midᵀ on this thread, `mid` being `below`'s first rows:
/// the top square only on and below its diagonal.
pub(crate) fn lower_product(
    dst: MatMut<'_, f64>,
    below: MatRef<'_, f64>,
    mid: MatRef<'_, f64>,
    accum: Accum,
) {
    let m = mid.nrows();
    if m == 0 {
        return;
    }
    let (top, bottom) = dst.split_at_row_mut(m);
    triangular::matmul(
        top,
        triangular::BlockStructure::TriangularLower,
        accum,
        mid,
        triangular::BlockStructure::Rectangular,
        mid.transpose(),
        triangular::BlockStructure::Rectangular,
        -1.0,
        Par::Seq,
    );
    matmul(
        bottom,
        accum,
        below.subrows(m, below.nrows() - m),
        mid.transpose(),
        -1.0,
        Par::Seq,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::dyn_stack::MemBuffer;
    use faer::linalg::cholesky::llt::factor::cholesky_in_place_scratch;
    use faer::Mat;

    fn stack() -> MemBuffer {
        MemBuffer::new(cholesky_in_place_scratch::<f64>(
            BLOCK,
            Par::Seq,
            Spec::default(),
        ))
    }

    /// A symmetric positive definite matrix: a diagonally dominant one with smooth off-diagonal
    /// entries (its lower triangle; the upper holds a marker that must not be read).
    fn spd(n: usize) -> Mat<f64> {
        Mat::from_fn(n, n, |i, j| {
            if i < j {
                f64::NAN
            } else if i == j {
                n as f64 + 1.0
            } else {
                1.0 / (1.0 + (i - j) as f64) + 0.01 * ((i * 7 + j * 3) % 5) as f64
            }
        })
    }

    /// Orders around the block size and across several blocks: L Lᵀ reproduces the matrix's
    /// lower triangle to rounding (‖·‖ relative 1e-13; the factor is well conditioned), and
    /// the upper triangle keeps its NaN markers.
    #[test]
    fn the_factor_reproduces_the_matrix() {
        for n in [1, 5, BLOCK - 1, BLOCK, BLOCK + 1, 3 * BLOCK + 17] {
            let a = spd(n);
            let mut l = a.clone();
            let mut buf = stack();
            llt_two_threads(l.as_mut(), MemStack::new(&mut buf)).unwrap();
            for j in 0..n {
                for i in 0..j {
                    assert!(l[(i, j)].is_nan(), "n {n}: upper ({i}, {j}) written");
                }
            }
            let lower = Mat::from_fn(n, n, |i, j| if i >= j { l[(i, j)] } else { 0.0 });
            let product = &lower * lower.transpose();
            let mut worst = 0.0f64;
            for j in 0..n {
                for i in j..n {
                    worst = worst.max((product[(i, j)] - a[(i, j)]).abs() / a[(j, j)]);
                }
            }
            assert!(worst < 1e-13, "n {n}: {worst:e}");
        }
    }

    /// A matrix whose leading minors are positive up to order p and not at order p + 1 (in
    /// the second block column) reports column p.
    #[test]
    fn a_pivot_that_is_not_positive_is_reported_at_its_column() {
        let n = 2 * BLOCK + 5;
        let p = BLOCK + 7;
        let mut a = spd(n);
        // The pivot at p is then 0 − Σ_k<p l_pk² < 0.
        a[(p, p)] = 0.0;
        let mut buf = stack();
        let e = llt_two_threads(a.as_mut(), MemStack::new(&mut buf));
        assert_eq!(e, Err(p));
    }
}
