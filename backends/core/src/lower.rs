//! The lower triangle of a symmetric matrix in its own CSC arrays, and the symmetric diagonal
//! scaling S A S (S = diag(A)^-1/2) that lets Cholesky backends judge every pivot relative to
//! its own diagonal entry.

use crate::{CscRef, SolverError};
use rayon::prelude::*;
use std::ops::Range;

/// Pattern of the lower triangle (diagonal included) with, for each entry, its index in the
/// full matrix's values — built once per pattern, so refills are a gather.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LowerTriangle {
    /// Column pointers (n + 1).
    pub col_ptr: Vec<usize>,
    /// Row indices, sorted within each column; the diagonal comes first when present.
    pub row_idx: Vec<usize>,
    src: Vec<usize>,
}

impl LowerTriangle {
    /// Extracts the lower-triangle pattern of `a`.
    pub fn of(a: CscRef<'_>) -> Self {
        let n = a.ncols();
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::with_capacity(a.nnz() / 2 + n);
        let mut src = Vec::with_capacity(a.nnz() / 2 + n);
        col_ptr.push(0);
        for j in 0..n {
            let start = a.col_ptr()[j];
            for (k, &i) in a.col(j).0.iter().enumerate() {
                if i >= j {
                    row_idx.push(i);
                    src.push(start + k);
                }
            }
            col_ptr.push(row_idx.len());
        }
        LowerTriangle {
            col_ptr,
            row_idx,
            src,
        }
    }

    /// The lower triangle of P A Pᵀ (`inv[old] = new`), rows sorted within each column, its
    /// entries still read from A: a factorization in that order then needs no permuted copy.
    pub fn permuted(&self, inv: &[usize]) -> Self {
        let n = self.col_ptr.len() - 1;
        let column_of = |i: usize, j: usize| inv[i].min(inv[j]);
        let mut col_ptr = vec![0usize; n + 1];
        for j in 0..n {
            for &i in &self.row_idx[self.col_ptr[j]..self.col_ptr[j + 1]] {
                col_ptr[column_of(i, j) + 1] += 1;
            }
        }
        for j in 0..n {
            col_ptr[j + 1] += col_ptr[j];
        }
        let nnz = self.nnz();
        let mut next = col_ptr[..n].to_vec();
        let (mut row_idx, mut src) = (vec![0usize; nnz], vec![0usize; nnz]);
        for j in 0..n {
            for k in self.col_ptr[j]..self.col_ptr[j + 1] {
                let i = self.row_idx[k];
                let c = &mut next[column_of(i, j)];
                row_idx[*c] = inv[i].max(inv[j]);
                src[*c] = self.src[k];
                *c += 1;
            }
        }
        drop(next);
        // Rows sorted within each column, each entry's source along: a column's pairs go
        // through a small buffer (no copy of the whole triangle as pairs).
        let mut pairs = Vec::new();
        for j in 0..n {
            let column = col_ptr[j]..col_ptr[j + 1];
            if row_idx[column.clone()].is_sorted() {
                continue;
            }
            pairs.clear();
            pairs.extend(
                row_idx[column.clone()]
                    .iter()
                    .copied()
                    .zip(src[column.clone()].iter().copied()),
            );
            pairs.sort_unstable();
            for (k, &(row, from)) in column.zip(&pairs) {
                row_idx[k] = row;
                src[k] = from;
            }
        }
        LowerTriangle {
            col_ptr,
            row_idx,
            src,
        }
    }

    /// Stored entries.
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// [`LowerTriangle::scaled_values`] for a triangle made by [`LowerTriangle::permuted`]
    /// with the inverse of `fwd` (`fwd[new] = old`): the lower values of P S A S Pᵀ, `scale` in
    /// A's order. An error names A's column.
    pub fn scaled_permuted_values(
        &self,
        a: CscRef<'_>,
        fwd: &[usize],
        scale: &mut [f64],
        values: &mut [f64],
    ) -> Result<(), SolverError> {
        self.scaled_in_order(a, |j| fwd[j], scale, values)
    }

    /// Writes `scale[j] = 1/√a_jj` and the lower values of S A S. A diagonal entry that is
    /// missing or not positive is [`SolverError::NotPositiveDefinite`] at its column.
    pub fn scaled_values(
        &self,
        a: CscRef<'_>,
        scale: &mut [f64],
        values: &mut [f64],
    ) -> Result<(), SolverError> {
        self.scaled_in_order(a, |j| j, scale, values)
    }

    /// values = S A S for the columns `cols` (`values` holding exactly their entries), halved
    /// over the threads down to runs of 2¹⁶ entries.
    fn scale_columns(&self, cols: Range<usize>, scale: &[f64], a: &[f64], values: &mut [f64]) {
        let first = self.col_ptr[cols.start];
        if values.len() > 1 << 16 && cols.len() > 1 {
            let mid = cols.start + cols.len() / 2;
            let (left, right) = values.split_at_mut(self.col_ptr[mid] - first);
            rayon::join(
                || self.scale_columns(cols.start..mid, scale, a, left),
                || self.scale_columns(mid..cols.end, scale, a, right),
            );
            return;
        }
        for j in cols {
            let sj = scale[j];
            for k in self.col_ptr[j]..self.col_ptr[j + 1] {
                values[k - first] = a[self.src[k]] * scale[self.row_idx[k]] * sj;
            }
        }
    }

    /// The scaled values of a triangle whose index `j` is A's index `old(j)`.
    fn scaled_in_order(
        &self,
        a: CscRef<'_>,
        old: impl Fn(usize) -> usize + Sync,
        scale: &mut [f64],
        values: &mut [f64],
    ) -> Result<(), SolverError> {
        let local = diagonal_scale(a, |column| search_diagonal(a, column), old, scale)?;
        self.scale_columns(0..local.len(), &local, a.values(), values);
        Ok(())
    }
}

/// The scale S = diag(A)^(-1/2) of P A Pᵀ (`fwd[new] = old`), read from A's diagonal:
/// written in A's order to `scale`, returned in the new order. A diagonal entry that is
/// missing or not positive is [`SolverError::NotPositiveDefinite`] at A's column.
pub fn permuted_diagonal_scale(
    a: CscRef<'_>,
    fwd: &[usize],
    scale: &mut [f64],
) -> Result<Vec<f64>, SolverError> {
    diagonal_scale(a, |column| search_diagonal(a, column), |j| fwd[j], scale)
}

/// Where each column's diagonal entry lies in A's values, for one pattern: a factorization
/// that refactorizes the same pattern reads its scale from them instead of searching every
/// column again (on L seed 1: 23–25 ms of searches, waiting on memory, against ≈ 5 ms).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DiagonalEntries {
    /// The entry's index in A's values, or [`DiagonalEntries::NONE`] without one.
    at: Vec<usize>,
}

impl DiagonalEntries {
    /// A column without a diagonal entry.
    const NONE: usize = usize::MAX;

    /// The diagonal entries of `a`'s pattern (on the threads).
    pub fn of(a: CscRef<'_>) -> Self {
        let at = (0..a.ncols())
            .into_par_iter()
            .with_min_len(SCALE_CHUNK)
            .map(|column| {
                let (rows, _) = a.col(column);
                rows.binary_search(&column)
                    .map_or(Self::NONE, |k| a.col_ptr()[column] + k)
            })
            .collect();
        DiagonalEntries { at }
    }

    /// [`permuted_diagonal_scale`] for a matrix of the pattern these entries were found in
    /// (the caller's check; another pattern of the same order gives a wrong scale, never an
    /// out-of-bounds read, and one of another order the error of its first column).
    pub fn permuted_scale(
        &self,
        a: CscRef<'_>,
        fwd: &[usize],
        scale: &mut [f64],
    ) -> Result<Vec<f64>, SolverError> {
        if self.at.len() != a.ncols() {
            return Err(SolverError::DimensionMismatch(format!(
                "diagonal entries of order {}, matrix of order {}",
                self.at.len(),
                a.ncols()
            )));
        }
        let values = a.values();
        let ajj = |column: usize| values.get(self.at[column]).copied().unwrap_or(0.0);
        diagonal_scale(a, ajj, |j| fwd[j], scale)
    }
}

/// A's entry (column, column), or 0 when the pattern has none.
fn search_diagonal(a: CscRef<'_>, column: usize) -> f64 {
    let (rows, values) = a.col(column);
    // Rows are strictly ascending (a checked pattern).
    rows.binary_search(&column).map_or(0.0, |k| values[k])
}

/// `scale[old(j)] = 1/√a_jj`, A's entry at (old(j), old(j)) as `ajj` reads it, and the same in
/// the order of j (returned). `old` maps 0..n onto A's n columns (a permutation).
///
/// A's diagonal is read in its order of storage and the scale gathered afterwards: read in
/// the new order, each column's search missed the cache (7 of M's 85 ms of factorization).
/// Both passes run on the threads in runs of [`SCALE_CHUNK`] columns: on one thread the
/// searches waited on memory for 42–48 ms of each L factorization. A bad diagonal is
/// reported at the lowest such column of A.
fn diagonal_scale(
    a: CscRef<'_>,
    ajj: impl Fn(usize) -> f64 + Sync,
    old: impl Fn(usize) -> usize + Sync,
    scale: &mut [f64],
) -> Result<Vec<f64>, SolverError> {
    let n = a.ncols();
    let bad = scale[..n]
        .par_chunks_mut(SCALE_CHUNK)
        .enumerate()
        .find_map_first(|(c, chunk)| {
            for (k, s) in chunk.iter_mut().enumerate() {
                let column = c * SCALE_CHUNK + k;
                let ajj = ajj(column);
                if !(ajj > 0.0) {
                    return Some((column, ajj));
                }
                *s = 1.0 / ajj.sqrt();
            }
            None
        });
    if let Some((column, pivot)) = bad {
        return Err(SolverError::NotPositiveDefinite { column, pivot });
    }
    let scale = &scale[..n];
    Ok((0..n)
        .into_par_iter()
        .with_min_len(SCALE_CHUNK)
        .map(|j| scale[old(j)])
        .collect())
}

/// Columns per task of [`diagonal_scale`]: ≈ 0.1 ms of searches, far above a task's start.
const SCALE_CHUNK: usize = 1 << 13;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CscMatrix;

    #[test]
    fn scaled_lower_triangle_has_unit_diagonal() {
        let a = CscMatrix::from_triplets(
            3,
            3,
            &[
                (0, 0, 4.0),
                (1, 0, 2.0),
                (0, 1, 2.0),
                (1, 1, 9.0),
                (2, 2, 16.0),
                (2, 1, 3.0),
                (1, 2, 3.0),
            ],
        )
        .unwrap();
        let l = LowerTriangle::of(a.as_ref());
        assert_eq!(l.col_ptr, vec![0, 2, 4, 5]);
        let (mut s, mut v) = (vec![0.0; 3], vec![0.0; l.nnz()]);
        l.scaled_values(a.as_ref(), &mut s, &mut v).unwrap();
        assert_eq!(s, vec![0.5, 1.0 / 3.0, 0.25]);
        assert_eq!(v, vec![1.0, 2.0 / 6.0, 1.0, 3.0 / 12.0, 1.0]);
        // Permuted by fwd = [2, 0, 1]: the lower triangle of P S A S Pᵀ, rows sorted.
        let (fwd, inv) = ([2, 0, 1], [1, 2, 0]);
        let p = l.permuted(&inv);
        let mut pv = vec![0.0; p.nnz()];
        let mut ps = vec![0.0; 3];
        p.scaled_permuted_values(a.as_ref(), &fwd, &mut ps, &mut pv)
            .unwrap();
        assert_eq!(ps, s);
        assert_eq!(p.col_ptr, vec![0, 2, 4, 5]);
        assert_eq!(p.row_idx, vec![0, 2, 1, 2, 2]);
        // (new 0 = old 2): a22 = 1, a21 → (new 2, new 0); (new 1 = old 0): a00, a10 → (2, 1).
        assert_eq!(pv, vec![1.0, 3.0 / 12.0, 1.0, 2.0 / 6.0, 1.0]);
        // The scale alone from A's diagonal, in both orders.
        let mut by_old = vec![0.0; 3];
        let local = permuted_diagonal_scale(a.as_ref(), &fwd, &mut by_old).unwrap();
        assert_eq!(by_old, s);
        assert_eq!(local, vec![0.25, 0.5, 1.0 / 3.0]);
        let bad = CscMatrix::from_triplets(2, 2, &[(0, 0, 1.0), (1, 0, 1.0), (0, 1, 1.0)]).unwrap();
        let l = LowerTriangle::of(bad.as_ref());
        let e = l
            .scaled_values(bad.as_ref(), &mut [0.0; 2], &mut [0.0; 2])
            .unwrap_err();
        assert_eq!(
            e,
            SolverError::NotPositiveDefinite {
                column: 1,
                pivot: 0.0
            }
        );
        let e = permuted_diagonal_scale(bad.as_ref(), &[1, 0], &mut [0.0; 2]).unwrap_err();
        assert_eq!(
            e,
            SolverError::NotPositiveDefinite {
                column: 1,
                pivot: 0.0
            }
        );
    }

    /// Over several runs of [`SCALE_CHUNK`] columns (dealt to the threads): the scale of a
    /// diagonal matrix is 1/√d in both orders, and of two bad diagonals, one missing in the
    /// second run and one negative in the third, the lower column is the one reported;
    /// alike through [`DiagonalEntries`].
    #[test]
    fn the_scale_in_runs_reports_the_lowest_bad_column() {
        let n = 3 * SCALE_CHUNK + 5;
        let d = |j: usize| (j % 7 + 1) as f64;
        let diagonal: Vec<(usize, usize, f64)> = (0..n).map(|j| (j, j, d(j))).collect();
        let a = CscMatrix::from_triplets(n, n, &diagonal).unwrap();
        let fwd: Vec<usize> = (0..n).rev().collect();
        let mut by_old = vec![0.0; n];
        let local = permuted_diagonal_scale(a.as_ref(), &fwd, &mut by_old).unwrap();
        for j in 0..n {
            assert_eq!(by_old[j], 1.0 / d(j).sqrt());
            assert_eq!(local[j], 1.0 / d(n - 1 - j).sqrt());
        }
        let (missing, negative) = (SCALE_CHUNK + 7, 2 * SCALE_CHUNK + 3);
        let mut bad: Vec<(usize, usize, f64)> = diagonal
            .into_iter()
            .filter(|&(j, _, _)| j != missing)
            .collect();
        bad[negative - 1].2 = -2.0;
        bad.push((missing + 1, missing, 1.0));
        let b = CscMatrix::from_triplets(n, n, &bad).unwrap();
        let e = permuted_diagonal_scale(b.as_ref(), &fwd, &mut by_old).unwrap_err();
        let expected = SolverError::NotPositiveDefinite {
            column: missing,
            pivot: 0.0,
        };
        assert_eq!(e, expected);
        // The same through the diagonal entries found once: the scale of new values on A's
        // pattern, the error on B's, and a matrix of another order refused.
        let entries = DiagonalEntries::of(a.as_ref());
        let mut twice = a.clone();
        twice.values_mut().iter_mut().for_each(|v| *v *= 4.0);
        let mut by_old_twice = vec![0.0; n];
        let halved = entries
            .permuted_scale(twice.as_ref(), &fwd, &mut by_old_twice)
            .unwrap();
        assert!(halved.iter().zip(&local).all(|(h, l)| *h == l / 2.0));
        let e = DiagonalEntries::of(b.as_ref())
            .permuted_scale(b.as_ref(), &fwd, &mut by_old)
            .unwrap_err();
        assert_eq!(e, expected);
        let small = CscMatrix::from_triplets(2, 2, &[(0, 0, 1.0), (1, 1, 1.0)]).unwrap();
        assert!(matches!(
            entries.permuted_scale(small.as_ref(), &[0, 1], &mut [0.0; 2]),
            Err(SolverError::DimensionMismatch(_))
        ));
    }
}
