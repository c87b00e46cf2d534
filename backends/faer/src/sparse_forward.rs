//! Forward solves with sparse right-hand sides on faer's Cholesky factor, restricted to the
//! elimination-tree paths of the nonzeros (Gilbert–Peierls reach, by blocks of L).

use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymbolicCholeskyRaw};
use faer::{Accum, MatMut, MatRef, Par};
use fibercell_solver::{ForwardBlock, ForwardColumns, SolverError};
use std::ops::Range;

pub(crate) const NONE: usize = usize::MAX;

/// Products of a block below which the dense kernels run single-threaded.
const PARALLEL_FLOPS: usize = 1 << 20;

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
    pattern: Range<usize>,
    pub(crate) values: Range<usize>,
}

fn raw_shape(symbolic: &SymbolicCholesky<usize>, s: usize) -> BlockShape {
    match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(f) => {
            let (p, q) = (f.col_ptr()[s], f.col_ptr()[s + 1]);
            BlockShape {
                begin: s,
                width: 1,
                pattern: p + 1..q,
                values: p..q,
            }
        }
        SymbolicCholeskyRaw::Supernodal(f) => {
            let begin = f.supernode_begin()[s];
            let first = f.col_ptr_for_row_idx()[s];
            BlockShape {
                begin,
                width: f.supernode_end()[s] - begin,
                pattern: first..first + f.supernode(s).pattern().len(),
                values: f.col_ptr_for_val()[s]..f.col_ptr_for_val()[s + 1],
            }
        }
    }
}

/// The row indices the block patterns index into.
fn row_idx(symbolic: &SymbolicCholesky<usize>) -> &[usize] {
    match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(f) => f.row_idx(),
        SymbolicCholeskyRaw::Supernodal(f) => f.row_idx(),
    }
}

fn block_count(symbolic: &SymbolicCholesky<usize>) -> usize {
    match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(f) => f.ncols(),
        SymbolicCholeskyRaw::Supernodal(f) => f.n_supernodes(),
    }
}

impl BlockTree {
    /// The tree of `symbolic` (its values are not read).
    pub(crate) fn of(symbolic: &SymbolicCholesky<usize>) -> Self {
        let n = symbolic.nrows();
        let blocks = block_count(symbolic);
        let mut block_of = vec![NONE; n];
        let shapes: Vec<BlockShape> = (0..blocks).map(|s| raw_shape(symbolic, s)).collect();
        for (s, b) in shapes.iter().enumerate() {
            block_of[b.begin..b.begin + b.width].fill(s);
        }
        let rows = row_idx(symbolic);
        let parent = shapes
            .iter()
            .map(|b| {
                rows[b.pattern.clone()]
                    .iter()
                    .min()
                    .map_or(NONE, |&r| block_of[r])
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
        symbolic: &'a SymbolicCholesky<usize>,
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

    /// W = L⁻¹ P Ŝ B for the sparse columns `columns` (original row numbering), `inv` the
    /// inverse permutation (`inv[old] = new`), `scale` Ŝ.
    pub(crate) fn forward(
        &self,
        symbolic: &SymbolicCholesky<usize>,
        values: &[f64],
        inv: &[usize],
        scale: &[f64],
        columns: &[Vec<(usize, f64)>],
        par: Par,
    ) -> Result<ForwardColumns, SolverError> {
        let n = self.block_of.len();
        // The reach: every block on a path from a column's nonzeros to the root.
        let mut members: Vec<Vec<usize>> = vec![Vec::new(); self.parent.len()];
        let mut stamp = vec![NONE; self.parent.len()];
        for (j, col) in columns.iter().enumerate() {
            for &(i, v) in col {
                if i >= n || !v.is_finite() {
                    return Err(SolverError::DimensionMismatch(format!(
                        "sparse column {j}: entry ({i}, {v}) outside the order {n} or not finite"
                    )));
                }
                let mut s = self.block_of[inv[i]];
                while s != NONE && stamp[s] != j {
                    stamp[s] = j;
                    members[s].push(j);
                    s = self.parent[s];
                }
            }
        }
        let touched: Vec<usize> = (0..members.len())
            .filter(|&s| !members[s].is_empty())
            .collect();
        // Position of each touched block in `touched`.
        let mut slot = vec![NONE; members.len()];
        for (k, &s) in touched.iter().enumerate() {
            slot[s] = k;
        }
        let mut x: Vec<Vec<f64>> = touched
            .iter()
            .map(|&s| vec![0.0; self.block(symbolic, values, s).width * members[s].len()])
            .collect();
        for (j, col) in columns.iter().enumerate() {
            for &(i, v) in col {
                let p = inv[i];
                let s = self.block_of[p];
                let b = self.block(symbolic, values, s);
                let c = members[s].binary_search(&j).unwrap_or(0);
                x[slot[s]][c * b.width + p - b.begin] += v * scale[i];
            }
        }
        let mut below = Vec::new();
        let mut position = Vec::new();
        for (k, &s) in touched.iter().enumerate() {
            let b = self.block(symbolic, values, s);
            let m = members[s].len();
            let rows = b.width + b.pattern.len();
            let l = MatRef::from_column_major_slice(b.values, rows, b.width);
            let (top, bottom) = l.split_at_row(b.width);
            let (done, rest) = x.split_at_mut(k + 1);
            let xs = &mut done[k];
            let kernel_par = if rows * b.width * m > PARALLEL_FLOPS {
                par
            } else {
                Par::Seq
            };
            solve_lower_triangular_in_place(
                top,
                MatMut::from_column_major_slice_mut(xs, b.width, m),
                kernel_par,
            );
            if b.pattern.is_empty() {
                continue;
            }
            below.clear();
            below.resize(b.pattern.len() * m, 0.0);
            matmul(
                MatMut::from_column_major_slice_mut(&mut below, b.pattern.len(), m),
                Accum::Replace,
                bottom,
                MatRef::from_column_major_slice(xs, b.width, m),
                1.0,
                kernel_par,
            );
            // Subtract from the ancestors' rows; this block's columns are among theirs.
            let mut last = NONE;
            for (r, &row) in b.pattern.iter().enumerate() {
                let t = self.block_of[row];
                if t != last {
                    last = t;
                    position.clear();
                    let mut at = 0;
                    for &j in &members[s] {
                        while members[t][at] != j {
                            at += 1;
                        }
                        position.push(at);
                    }
                }
                let bt = self.block(symbolic, values, t);
                let xt = &mut rest[slot[t] - k - 1];
                let local = row - bt.begin;
                for (c, &at) in position.iter().enumerate() {
                    xt[at * bt.width + local] -= below[c * b.pattern.len() + r];
                }
            }
        }
        let blocks = touched
            .iter()
            .zip(x)
            .map(|(&s, values_s)| ForwardBlock {
                block: s,
                first_row: self.shapes[s].begin,
                rows: self.shapes[s].width,
                columns: std::mem::take(&mut members[s]),
                values: values_s,
            })
            .collect();
        Ok(ForwardColumns {
            ncols: columns.len(),
            blocks,
        })
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use crate::{CholeskyVariant, FaerCholesky};
    use fibercell_solver::{CscMatrix, LinearSolver, Ordering, SolverError};

    /// A k³ grid Laplacian with edge weights and diagonal scales spread over four decades.
    pub(crate) fn grid(k: usize) -> CscMatrix {
        let id = |x: usize, y: usize, z: usize| (x * k + y) * k + z;
        let weight = |a: usize, b: usize| 1.0 + ((a * 7919 + b * 104_729) % 97) as f64 / 10.0;
        let scale = |a: usize| 10f64.powi((a % 5) as i32 - 2);
        let mut t = Vec::new();
        let mut diag = vec![0.1; k * k * k];
        for x in 0..k {
            for y in 0..k {
                for z in 0..k {
                    let a = id(x, y, z);
                    for b in [
                        (x + 1 < k).then(|| id(x + 1, y, z)),
                        (y + 1 < k).then(|| id(x, y + 1, z)),
                        (z + 1 < k).then(|| id(x, y, z + 1)),
                    ]
                    .into_iter()
                    .flatten()
                    {
                        let w = weight(a, b);
                        t.push((a, b, -w * scale(a) * scale(b)));
                        t.push((b, a, -w * scale(a) * scale(b)));
                        diag[a] += w;
                        diag[b] += w;
                    }
                }
            }
        }
        for (a, d) in diag.iter().enumerate() {
            t.push((a, a, d * scale(a) * scale(a)));
        }
        CscMatrix::from_triplets(k * k * k, k * k * k, &t).unwrap()
    }

    /// Sparse columns: single entries, a repeated column, entries far apart.
    fn columns(n: usize) -> Vec<Vec<(usize, f64)>> {
        vec![
            vec![(0, 1.0)],
            vec![(n / 2, -2.0), (n / 2 + 1, 0.5)],
            vec![(n - 1, 3.0), (1, 1.0), (n / 3, -1.0)],
            vec![(n / 2, -2.0), (n / 2 + 1, 0.5)],
            vec![(7 % n, 0.25)],
            vec![],
        ]
    }

    /// Bᵀ A⁻¹ B by full solves.
    fn gram_by_solves(s: &mut FaerCholesky, n: usize, b: &[Vec<(usize, f64)>]) -> Vec<f64> {
        let k = b.len();
        let mut x = vec![0.0; n * k];
        for (j, col) in b.iter().enumerate() {
            for &(i, v) in col {
                x[j * n + i] = v;
            }
        }
        s.solve_in_place(&mut x, k).unwrap();
        let mut g = vec![0.0; k * k];
        for j in 0..k {
            for (i, col) in b.iter().enumerate() {
                g[j * k + i] = col.iter().map(|&(r, v)| v * x[j * n + r]).sum();
            }
        }
        g
    }

    #[test]
    fn gram_of_sparse_forward_solves_is_b_transpose_a_inverse_b() {
        for (k, supernodal) in [(4, false), (16, true)] {
            for ordering in [Ordering::Natural, Ordering::NestedDissection] {
                let a = grid(k);
                let n = k * k * k;
                let mut s = FaerCholesky::new(CholeskyVariant::Llt, ordering.clone());
                s.analyze(a.as_ref()).unwrap();
                s.factorize(a.as_ref()).unwrap();
                if ordering == Ordering::NestedDissection {
                    assert_eq!(s.is_supernodal(), Some(supernodal), "k = {k}");
                }
                let b = columns(n);
                let w = s.forward_solve_sparse(&b).unwrap();
                let got = w.gram();
                let want = gram_by_solves(&mut s, n, &b);
                let big = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                for (g, r) in got.iter().zip(&want) {
                    assert!(
                        (g - r).abs() <= 1e-10 * big,
                        "k {k} {ordering:?}: {g} vs {r}"
                    );
                }
                // The empty column reaches nothing; on the large grid with nested dissection a
                // column reaches a small part of the factor.
                assert!(w.blocks.iter().all(|blk| !blk.columns.contains(&5)));
                if supernodal && ordering == Ordering::NestedDissection {
                    assert!(w.nnz() < b.len() * n / 4, "{} of {}", w.nnz(), b.len() * n);
                }
            }
        }
    }

    /// A solve with one right-hand side agrees with one with two to 1e-12 and is backward
    /// stable (backward error ≤ 1e-14).
    #[test]
    fn single_right_hand_side_solve_matches_two() {
        for k in [4, 16] {
            for ordering in [Ordering::Natural, Ordering::NestedDissection] {
                let a = grid(k);
                let n = k * k * k;
                let mut s = FaerCholesky::new(CholeskyVariant::Llt, ordering.clone());
                s.analyze(a.as_ref()).unwrap();
                s.factorize(a.as_ref()).unwrap();
                let b: Vec<f64> = (0..n).map(|i| ((i * 37) % 23) as f64 - 11.0).collect();
                let mut one = b.clone();
                s.solve_in_place(&mut one, 1).unwrap();
                let mut two = [b.clone(), b.clone()].concat();
                s.solve_in_place(&mut two, 2).unwrap();
                let big = two.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                for (x, y) in one.iter().zip(&two) {
                    assert!(
                        (x - y).abs() <= 1e-12 * big,
                        "k {k} {ordering:?}: {x} vs {y}"
                    );
                }
                let r = fibercell_solver::backward_error(a.as_ref(), &one, &b);
                assert!(r <= 1e-14, "k {k} {ordering:?}: backward error {r}");
            }
        }
    }

    /// The half solves: the lower half of a dense column equals its sparse forward solve on
    /// the blocks it reaches and vanishes elsewhere; lower then upper is a solve (1e-12).
    #[test]
    fn half_solves_match_the_sparse_forward_solve_and_compose_to_a_solve() {
        for k in [4, 16] {
            let a = grid(k);
            let n = k * k * k;
            let mut s = FaerCholesky::new(CholeskyVariant::Llt, Ordering::NestedDissection);
            s.analyze(a.as_ref()).unwrap();
            s.factorize(a.as_ref()).unwrap();
            let b = columns(n);
            let w = s.forward_solve_sparse(&b).unwrap();
            for (j, col) in b.iter().enumerate() {
                let mut dense = vec![0.0; n];
                for &(i, v) in col {
                    dense[i] = v;
                }
                let mut full = dense.clone();
                s.solve_in_place(&mut full, 1).unwrap();
                s.solve_lower_in_place(&mut dense).unwrap();
                let big = dense.iter().fold(1e-300f64, |m, v| m.max(v.abs()));
                let mut seen = vec![false; n];
                for blk in &w.blocks {
                    if let Ok(c) = blk.columns.binary_search(&j) {
                        let got = &blk.values[c * blk.rows..(c + 1) * blk.rows];
                        for (r, g) in got.iter().enumerate() {
                            let want = dense[blk.first_row + r];
                            assert!((g - want).abs() <= 1e-12 * big, "k {k} col {j}");
                            seen[blk.first_row + r] = true;
                        }
                    }
                }
                assert!(dense.iter().zip(&seen).all(|(v, s)| *s || *v == 0.0));
                s.solve_upper_in_place(&mut dense).unwrap();
                let big = full.iter().fold(1e-300f64, |m, v| m.max(v.abs()));
                for (x, y) in dense.iter().zip(&full) {
                    assert!((x - y).abs() <= 1e-12 * big, "k {k} col {j}");
                }
            }
        }
    }

    #[test]
    fn sparse_forward_solve_rejects_bad_columns_and_ldlt() {
        let a = grid(4);
        let mut s = FaerCholesky::new(CholeskyVariant::Llt, Ordering::Amd);
        assert!(matches!(
            s.forward_solve_sparse(&[vec![(0, 1.0)]]),
            Err(SolverError::OutOfOrder(..))
        ));
        s.analyze(a.as_ref()).unwrap();
        s.factorize(a.as_ref()).unwrap();
        for bad in [vec![(64, 1.0)], vec![(3, f64::NAN)]] {
            assert!(matches!(
                s.forward_solve_sparse(&[bad]),
                Err(SolverError::DimensionMismatch(_))
            ));
        }
        let mut l = FaerCholesky::new(CholeskyVariant::Ldlt, Ordering::Amd);
        l.analyze(a.as_ref()).unwrap();
        l.factorize(a.as_ref()).unwrap();
        assert!(matches!(
            l.forward_solve_sparse(&[vec![(0, 1.0)]]),
            Err(SolverError::Unavailable { .. })
        ));
        assert!(matches!(
            l.solve_lower_in_place(&mut [0.0; 64]),
            Err(SolverError::Unavailable { .. })
        ));
    }
}
