//! The forward half of a symmetric solve for sparse right-hand sides.

/// W = L⁻¹ P Ŝ B for sparse columns B and a symmetric factorization A = Ŝ⁻¹ Pᵀ L Lᵀ P Ŝ⁻¹
/// (Ŝ diagonal scaling, P a fill-reducing permutation), so that Bᵀ A⁻¹ B = Wᵀ W.
///
/// Column j of W is nonzero only on the rows of the blocks of L (supernodes, or single columns)
/// on the elimination-tree paths from B's nonzeros to the root: W is stored block by block,
/// each [`ForwardBlock`] holding the columns that reach it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ForwardColumns {
    /// Number of columns of B.
    pub ncols: usize,
    /// The blocks reached by at least one column, in increasing block order.
    pub blocks: Vec<ForwardBlock>,
}

/// The rows of W in one block of L.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ForwardBlock {
    /// The block's index in its factor.
    pub block: usize,
    /// Its first row in the factor's row order (it holds `first_row..first_row + rows`).
    pub first_row: usize,
    /// Its rows (columns of L).
    pub rows: usize,
    /// The columns of B that reach it, in the order of `values`: ascending, or grouped by the
    /// first row they can be nonzero in where a backend skips leading zero rows.
    pub columns: Vec<usize>,
    /// `rows × columns.len()` values, column-major.
    pub values: Vec<f64>,
}

impl ForwardColumns {
    /// Stored values.
    pub fn nnz(&self) -> usize {
        self.blocks.iter().map(|b| b.values.len()).sum()
    }

    /// The Gram matrix Wᵀ W (= Bᵀ A⁻¹ B), dense column-major `ncols × ncols`.
    pub fn gram(&self) -> Vec<f64> {
        let k = self.ncols;
        let mut g = vec![0.0; k * k];
        for b in &self.blocks {
            let col = |c: usize| &b.values[c * b.rows..(c + 1) * b.rows];
            for (cj, &j) in b.columns.iter().enumerate() {
                for (ci, &i) in b.columns.iter().enumerate() {
                    g[j * k + i] += col(ci).iter().zip(col(cj)).map(|(x, y)| x * y).sum::<f64>();
                }
            }
        }
        g
    }
}
