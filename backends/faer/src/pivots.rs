//! Reading the pivots back out of a faer Cholesky factor, to catch (near-)zero pivots that
//! faer accepts, and to count fill and flops.

use crate::supernodes::SupernodesRef;
use crate::symbolic::{Raw, Symbolic};

/// Each supernode as (first column, end column, rows of its dense block, first value index).
pub(crate) fn supernodes(
    s: SupernodesRef<'_>,
) -> impl Iterator<Item = (usize, usize, usize, usize)> + '_ {
    (0..s.n_supernodes()).map(move |k| {
        let (b, e) = (s.supernode_begin()[k], s.supernode_end()[k]);
        let below = s.col_ptr_for_row_idx()[k + 1] - s.col_ptr_for_row_idx()[k];
        (b, e, (e - b) + below, s.col_ptr_for_val()[k])
    })
}

/// Entries per column of L (diagonal included), in factor (permuted) order.
pub(crate) fn column_counts(symbolic: &Symbolic) -> Vec<usize> {
    match symbolic.raw() {
        Raw::Simplicial(s) => s.col_ptr().windows(2).map(|w| w[1] - w[0]).collect(),
        Raw::Supernodal(s) => supernodes(s)
            .flat_map(|(b, e, rows, _)| (0..e - b).map(move |c| rows - c))
            .collect(),
    }
}

/// nnz(L) and the flop count Σ c_j² of a left-looking Cholesky with column counts c_j.
pub(crate) fn fill_and_flops(symbolic: &Symbolic) -> (usize, f64) {
    let c = column_counts(symbolic);
    (
        c.iter().sum(),
        c.iter().map(|&x| (x as f64) * (x as f64)).sum(),
    )
}

/// The diagonal entries of the factor values (L_jj for LLᵀ, D_j for LDLᵀ), in factor order.
pub(crate) fn factor_diagonal(symbolic: &Symbolic, values: &[f64]) -> Vec<f64> {
    match symbolic.raw() {
        Raw::Simplicial(s) => s.col_ptr()[..s.ncols()]
            .iter()
            .map(|&p| values[p])
            .collect(),
        Raw::Supernodal(s) => supernodes(s)
            .flat_map(|(b, e, rows, start)| (0..e - b).map(move |c| values[start + c * rows + c]))
            .collect(),
    }
}

/// Whether faer chose the simplicial variant (its pivot error index is then one-based).
pub(crate) fn is_simplicial(symbolic: &Symbolic) -> bool {
    matches!(symbolic.raw(), Raw::Simplicial(_))
}
