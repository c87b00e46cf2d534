//! The block tree of faer's Cholesky factor: its supernodes (or single columns of a
//! simplicial factor), each block's parent, shape and values — what every half solve and the
//! sparse forward solves walk. The bottom of the solve modules: it uses none of them.

use crate::symbolic::{Raw, Symbolic};
use std::ops::Range;

/// No block (the parent of a root).
pub(crate) const NONE: usize = usize::MAX;

/// A numeric LLᵀ factor as the solves read it.
#[derive(Clone, Copy)]
pub(crate) struct FactorView<'a> {
    pub(crate) symbolic: &'a Symbolic,
    /// The values of L.
    pub(crate) values: &'a [f64],
    /// The inverse fill-reducing permutation, `inv[old] = new`.
    pub(crate) inv: &'a [usize],
    /// The scaling Ŝ.
    pub(crate) scale: &'a [f64],
}

/// The block tree of a factor: faer's supernodes, or single columns for a simplicial factor.
pub(crate) struct BlockTree {
    /// The block holding each column of L.
    pub(crate) block_of: Vec<usize>,
    /// Each block's parent (the block of its first off-diagonal row), `NONE` at a root.
    pub(crate) parent: Vec<usize>,
    /// Where each block lies.
    pub(crate) shapes: Vec<BlockShape>,
}

/// One block of L: first column, width, off-diagonal rows, values (rows × width, column-major,
/// the diagonal block on top).
pub(crate) struct Block<'a> {
    pub(crate) begin: usize,
    pub(crate) width: usize,
    pub(crate) pattern: &'a [usize],
    pub(crate) values: &'a [f64],
}

/// Where block `s` lies: first column, width, its off-diagonal rows (a range of the factor's
/// row indices) and its values.
#[derive(Clone, Debug)]
pub(crate) struct BlockShape {
    pub(crate) begin: usize,
    pub(crate) width: usize,
    pub(crate) pattern: Range<usize>,
    pub(crate) values: Range<usize>,
}

fn raw_shape(symbolic: &Symbolic, s: usize) -> BlockShape {
    match symbolic.raw() {
        Raw::Simplicial(f) => {
            let (p, q) = (f.col_ptr()[s], f.col_ptr()[s + 1]);
            BlockShape {
                begin: s,
                width: 1,
                pattern: p + 1..q,
                values: p..q,
            }
        }
        Raw::Supernodal(f) => {
            let begin = f.supernode_begin()[s];
            let first = f.col_ptr_for_row_idx()[s];
            BlockShape {
                begin,
                width: f.supernode_end()[s] - begin,
                pattern: first..first + f.pattern(s).len(),
                values: f.col_ptr_for_val()[s]..f.col_ptr_for_val()[s + 1],
            }
        }
    }
}

/// The row indices the block patterns index into.
pub(crate) fn row_idx(symbolic: &Symbolic) -> &[usize] {
    match symbolic.raw() {
        Raw::Simplicial(f) => f.row_idx(),
        Raw::Supernodal(f) => f.row_idx(),
    }
}

fn block_count(symbolic: &Symbolic) -> usize {
    match symbolic.raw() {
        Raw::Simplicial(f) => f.ncols(),
        Raw::Supernodal(f) => f.n_supernodes(),
    }
}

impl BlockTree {
    /// The tree of `symbolic` (its values are not read).
    pub(crate) fn of(symbolic: &Symbolic) -> Self {
        let n = symbolic.nrows();
        let blocks = block_count(symbolic);
        let mut block_of = vec![NONE; n];
        let shapes: Vec<BlockShape> = (0..blocks).map(|s| raw_shape(symbolic, s)).collect();
        for (s, b) in shapes.iter().enumerate() {
            block_of[b.begin..b.begin + b.width].fill(s);
        }
        let rows = row_idx(symbolic);
        // A block's parent holds its first row below the diagonal block: a supernode's rows
        // ascend, a simplicial column's are searched.
        let ascending = matches!(symbolic.raw(), Raw::Supernodal(_));
        let parent = shapes
            .iter()
            .map(|b| {
                let pattern = &rows[b.pattern.clone()];
                let first = if ascending {
                    pattern.first()
                } else {
                    pattern.iter().min()
                };
                first.map_or(NONE, |&r| block_of[r])
            })
            .collect();
        BlockTree {
            block_of,
            parent,
            shapes,
        }
    }

    /// Block `s` of the factor with values `values`.
    pub(crate) fn block<'a>(
        &self,
        symbolic: &'a Symbolic,
        values: &'a [f64],
        s: usize,
    ) -> Block<'a> {
        let b = &self.shapes[s];
        Block {
            begin: b.begin,
            width: b.width,
            pattern: &row_idx(symbolic)[b.pattern.clone()],
            values: &values[b.values.clone()],
        }
    }
}
