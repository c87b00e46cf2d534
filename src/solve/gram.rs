//! The new columns of a Gram matrix Wᵀ W for one block of forward-solved columns, by panels:
//! each product starts at the first row its panel's columns can be nonzero in, and the product
//! of the new columns with themselves is formed once per pair of panels (a panel with itself:
//! its lower triangle) and mirrored.
//!
//! Blocks store their columns grouped by first nonzero row where that saves flops (the faer
//! backend's column layout), so the panels of a root separator's columns begin far down: on the
//! L bench cell at 1 % this halves the root's 3.8 GFLOP Gram product.

use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::{Accum, MatMut, MatRef, Par};
use rayon::prelude::*;

/// New columns per panel.
const PANEL: usize = 96;

/// One product of the blocked Gram: rows `from..` of W, a panel of earlier columns (`left`,
/// all old columns or a new panel) against a new panel (`right`).
struct Piece {
    left: std::ops::Range<usize>,
    right: std::ops::Range<usize>,
    from: usize,
}

/// Wᵀ W[:, old..] (all × new, column-major) for W = `w`: the old columns against
/// each panel of new ones, and the new panels pairwise (each pair once, mirrored), every
/// product from the first row where its right panel (or, for new pairs, either panel) can be
/// nonzero; the pieces on `threads` threads, one sequential kernel each (faer's parallel kernel
/// reached about half the rate on these shapes).
pub(crate) fn new_gram_columns(w: MatRef<'_, f64>, old: usize, threads: usize) -> Vec<f64> {
    let (rows, all) = (w.nrows(), w.ncols());
    let new = all - old;
    let mut product = vec![0.0; all * new];
    if new == 0 {
        return product;
    }
    // The first row each panel of new columns can be nonzero in.
    let panels: Vec<(std::ops::Range<usize>, usize)> = (old..all)
        .step_by(PANEL)
        .map(|start| {
            let range = start..(start + PANEL).min(all);
            let first = range
                .clone()
                .map(|c| (0..rows).position(|r| w[(r, c)] != 0.0).unwrap_or(rows))
                .min()
                .unwrap_or(rows);
            (range, first)
        })
        .collect();
    let mut pieces = Vec::new();
    for (j, (right, low_j)) in panels.iter().enumerate() {
        if old > 0 {
            pieces.push(Piece {
                left: 0..old,
                right: right.clone(),
                from: *low_j,
            });
        }
        for (left, low_i) in &panels[..=j] {
            pieces.push(Piece {
                left: left.clone(),
                right: right.clone(),
                from: *low_i.max(low_j),
            });
        }
    }
    // A panel against itself: its lower triangle only (mirrored below).
    let multiply = |p: &Piece| {
        let (m, n) = (p.left.len(), p.right.len());
        let mut out = vec![0.0; m * n];
        let tail = rows - p.from;
        let dst = MatMut::from_column_major_slice_mut(&mut out, m, n);
        let lhs = w.submatrix(p.from, p.left.start, tail, m).transpose();
        let rhs = w.submatrix(p.from, p.right.start, tail, n);
        if p.left == p.right {
            triangular::matmul(
                dst,
                BlockStructure::TriangularLower,
                Accum::Replace,
                lhs,
                BlockStructure::Rectangular,
                rhs,
                BlockStructure::Rectangular,
                1.0,
                Par::Seq,
            );
        } else {
            faer::linalg::matmul::matmul(dst, Accum::Replace, lhs, rhs, 1.0, Par::Seq);
        }
        out
    };
    let results: Vec<Vec<f64>> = if threads > 1 {
        pieces.par_iter().with_max_len(1).map(multiply).collect()
    } else {
        pieces.iter().map(multiply).collect()
    };
    for (p, out) in pieces.iter().zip(results) {
        let m = p.left.len();
        let diagonal = p.left == p.right;
        for (b, col) in out.chunks(m).enumerate() {
            let c = p.right.start + b - old;
            // A diagonal piece holds its lower triangle.
            let lowest = if diagonal { b } else { 0 };
            for (a, &v) in col.iter().enumerate().skip(lowest) {
                let row = p.left.start + a;
                product[c * all + row] = v;
                // The mirror of a pair of new columns.
                if row >= old {
                    product[(row - old) * all + p.right.start + b] = v;
                }
            }
        }
    }
    product
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `rows × all` values with each column's leading zeros as `zeros(c)`.
    fn with_leading_zeros(rows: usize, all: usize, zeros: impl Fn(usize) -> usize) -> Vec<f64> {
        (0..rows * all)
            .map(|i| {
                let (r, c) = (i % rows, i / rows);
                if r < zeros(c) {
                    0.0
                } else {
                    ((i * 7919) % 101) as f64 / 50.0 - 1.0
                }
            })
            .collect()
    }

    fn check(values: &[f64], rows: usize, all: usize, old: usize) {
        let w = MatRef::from_column_major_slice(values, rows, all);
        for threads in [1, 2, 3] {
            let product = new_gram_columns(w, old, threads);
            assert_eq!(product.len(), all * (all - old));
            for b in 0..all - old {
                for a in 0..all {
                    let want: f64 = (0..rows).map(|r| w[(r, a)] * w[(r, old + b)]).sum();
                    let got = product[b * all + a];
                    assert!(
                        (got - want).abs() <= 1e-13 * (1.0 + want.abs()),
                        "{rows}×{all}, old {old}, {threads} threads: ({a}, {b}) {got} vs {want}"
                    );
                }
            }
        }
    }

    /// The new columns of Wᵀ W on 1, 2 and 3 threads equal the entrywise dot products to 1e-13
    /// relative: small and several-panel shapes, with and without old columns, with columns
    /// grouped by leading zeros (as the faer backend stores them) and mixed.
    #[test]
    fn new_gram_columns_are_the_dot_products() {
        let dense = |_| 0;
        check(&with_leading_zeros(37, 11, dense), 37, 11, 4);
        check(&with_leading_zeros(37, 11, dense), 37, 11, 0);
        // Three groups of columns starting 0, 150 and 260 rows down, over several panels.
        let grouped = |c: usize| [0, 150, 260][(c * 3) / 400];
        for old in [0, 50, 230] {
            check(&with_leading_zeros(300, 400, grouped), 300, 400, old);
        }
        // Leading zeros in no order; an all-zero column.
        let mixed = |c: usize| if c == 7 { 300 } else { (c * 37) % 290 };
        check(&with_leading_zeros(300, 250, mixed), 300, 250, 20);
        let w = with_leading_zeros(3, 2, dense);
        let product = new_gram_columns(MatRef::from_column_major_slice(&w, 3, 2), 2, 2);
        assert!(product.is_empty());
    }
}
