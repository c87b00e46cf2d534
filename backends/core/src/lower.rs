//! The lower triangle of a symmetric matrix in its own CSC arrays, and the symmetric diagonal
//! scaling S A S (S = diag(A)^-1/2) that lets Cholesky backends judge every pivot relative to
//! its own diagonal entry.

use crate::{CscRef, SolverError};

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

    /// Stored entries.
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// Writes `scale[j] = 1/√a_jj` and the lower values of S A S. A diagonal entry that is
    /// missing or not positive is [`SolverError::NotPositiveDefinite`] at its column.
    pub fn scaled_values(
        &self,
        a: CscRef<'_>,
        scale: &mut [f64],
        values: &mut [f64],
    ) -> Result<(), SolverError> {
        let n = self.col_ptr.len() - 1;
        for (j, s) in scale.iter_mut().enumerate().take(n) {
            let first = self.col_ptr[j];
            let ajj = if first < self.col_ptr[j + 1] && self.row_idx[first] == j {
                a.values()[self.src[first]]
            } else {
                0.0
            };
            if !(ajj > 0.0) {
                return Err(SolverError::NotPositiveDefinite {
                    column: j,
                    pivot: ajj,
                });
            }
            *s = 1.0 / ajj.sqrt();
        }
        for j in 0..n {
            for k in self.col_ptr[j]..self.col_ptr[j + 1] {
                values[k] = a.values()[self.src[k]] * scale[self.row_idx[k]] * scale[j];
            }
        }
        Ok(())
    }
}

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
    }
}
