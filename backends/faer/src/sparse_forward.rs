//! Forward solves with sparse right-hand sides on faer's Cholesky factor, restricted to the
//! elimination-tree paths of the nonzeros (Gilbert–Peierls reach, by blocks of L).

use crate::block_kernels::SolveSchedule;
use crate::block_tree::{row_idx, BlockTree, FactorView, NONE};
use crate::column_layout::ColumnLayout;
use crate::dense_forward::{DenseForward, ForwardCursor};
use crate::symbolic::Symbolic;
use crate::top_columns::TopColumns;
use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::{Accum, MatMut, MatRef, Par};
use fibercell_solver::{ForwardBlock, ForwardColumns, SolverError};
use rayon::prelude::*;

/// Products of a block below which the dense kernels run single-threaded.
const PARALLEL_FLOPS: usize = 1 << 20;
/// Subtree tasks whose flops are within this factor of an even share keep each block on one
/// thread (on L at 1 %: the tasks' phase 51-53 → 46-50 ms).
const TASK_BALANCE: f64 = 1.1;

impl BlockTree {
    /// W = L⁻¹ P Ŝ B for the sparse columns `columns` (original row numbering) on `factor`,
    /// the subtrees of `schedule` on separate threads; with `rhs` (factor order) also its
    /// forward half `rhs` ← L⁻¹ `rhs`: in each block the columns read as one more column of
    /// their kernels (the block read once), the other blocks in between.
    pub(crate) fn forward(
        &self,
        factor: &FactorView<'_>,
        columns: &[Vec<(usize, f64)>],
        schedule: &SolveSchedule,
        par: Par,
        rhs: Option<&mut [f64]>,
    ) -> Result<ForwardColumns, SolverError> {
        let FactorView {
            symbolic,
            values,
            inv,
            scale,
        } = *factor;
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
        let layouts = self.column_layouts(symbolic, columns, inv, &touched, &members, &slot);
        // Per touched block: its columns in the order of its values.
        let stored: Vec<Vec<usize>> = touched
            .iter()
            .zip(&layouts)
            .map(|(&s, layout)| match layout {
                Some(l) => l.order.iter().map(|&c| members[s][c]).collect(),
                None => members[s].clone(),
            })
            .collect();
        let x_len: Vec<usize> = touched
            .iter()
            .map(|&s| self.shapes[s].width * members[s].len())
            .collect();
        // Room for a dense right-hand side's rows (see `Walk::eliminate`). Allocated zeroed
        // (`vec!`), so that large blocks' pages are zeroed where the walk first touches them,
        // on the threads, instead of written here.
        let spare = |s: usize| rhs.as_ref().map_or(0, |_| self.shapes[s].width);
        let mut x: Vec<Vec<f64>> = touched
            .iter()
            .zip(&x_len)
            .map(|(&s, &n)| {
                let mut xs = vec![0.0; n + spare(s)];
                xs.truncate(n);
                xs
            })
            .collect();
        for (j, col) in columns.iter().enumerate() {
            for &(i, v) in col {
                let p = inv[i];
                let s = self.block_of[p];
                let b = self.block(symbolic, values, s);
                let c = members[s].binary_search(&j).unwrap_or(0);
                let c = layouts[slot[s]].as_ref().map_or(c, |l| l.position[c]);
                x[slot[s]][c * b.width + p - b.begin] += v * scale[i];
            }
        }
        // Groups: the touched blocks of each task of `schedule` (disjoint subtrees, one thread
        // each) and the top ones, each ascending (children before parents). A block's
        // ancestors are in its own group or among the top blocks; a task adds to the top
        // blocks' columns through [`TopColumns`] (directly where it is the first task reaching
        // a column, else privately, summed before the top blocks follow).
        let task_of = schedule.task_of(self.parent.len());
        let top = schedule.task_count();
        let group_of: Vec<usize> = touched
            .iter()
            .map(|&s| match task_of[s] {
                NONE => top,
                t => t,
            })
            .collect();
        let mut lists: Vec<Vec<usize>> = vec![Vec::new(); top + 1];
        let mut index = vec![0; touched.len()];
        for (k, &g) in group_of.iter().enumerate() {
            index[k] = lists[g].len();
            lists[g].push(k);
        }
        let mut groups: Vec<Vec<Vec<f64>>> = lists
            .iter()
            .map(|list| list.iter().map(|&k| std::mem::take(&mut x[k])).collect())
            .collect();
        // The tasks' flops: when balanced, their blocks' columns stay on one thread (split
        // pieces each read the whole block, with fewer columns per product); else they are
        // split, and the idle thread takes pieces of the busy one's blocks.
        let flops: Vec<usize> = lists[..top]
            .iter()
            .map(|list| {
                list.iter()
                    .map(|&k| {
                        let b = &self.shapes[touched[k]];
                        (b.width + b.pattern.len()) * b.width * members[touched[k]].len()
                    })
                    .sum()
            })
            .collect();
        let walk = Walk {
            tree: self,
            symbolic,
            values,
            touched: &touched,
            members: &members,
            slot: &slot,
            group_of: &group_of,
            index: &index,
            layouts: &layouts,
            par,
            split_in_tasks: !balanced(&flops),
        };
        // The columns each task reaches, and the column held by each top block's storage
        // columns: a task adds to the top columns it owns directly, to others privately.
        let reached: Vec<Vec<bool>> = lists[..top]
            .iter()
            .map(|list| {
                let mut marks = vec![false; columns.len()];
                for &k in list {
                    members[touched[k]].iter().for_each(|&j| marks[j] = true);
                }
                marks
            })
            .collect();
        let widths: Vec<usize> = lists[top]
            .iter()
            .map(|&k| self.shapes[touched[k]].width)
            .collect();
        let storage: Vec<&[usize]> = lists[top].iter().map(|&k| &stored[k][..]).collect();
        let (tasks, top_group) = groups.split_at_mut(top);
        let mut access = TopColumns::split(&mut top_group[0], &widths, &storage, &reached);
        let mut dense = rhs.map(|x| DenseForward::new(self, schedule, symbolic, values, x));
        let mut cursors: Vec<Option<ForwardCursor<'_>>> = match dense.as_mut() {
            Some(d) => d.task_cursors().into_iter().map(Some).collect(),
            None => (0..top).map(|_| None).collect(),
        };
        tasks
            .par_iter_mut()
            .zip(&lists[..top])
            .zip(access.par_iter_mut())
            .zip(cursors.par_iter_mut())
            .enumerate()
            .for_each(|(g, (((mine, list), target), cursor))| {
                walk.eliminate(g, list, mine, Some(target), cursor.as_mut());
            });
        let updates: Vec<Vec<f64>> = cursors
            .into_iter()
            .flatten()
            .map(ForwardCursor::into_updates)
            .collect();
        TopColumns::join(access);
        let top_xs = &mut top_group[0];
        let mut top_cursor = dense.as_mut().map(|d| {
            d.add_updates(&updates);
            d.top_cursor()
        });
        walk.eliminate(top, &lists[top], top_xs, None, top_cursor.as_mut());
        for (list, group) in lists.iter().zip(groups) {
            for (&k, xk) in list.iter().zip(group) {
                x[k] = xk;
            }
        }
        let blocks = touched
            .iter()
            .zip(x)
            .zip(stored)
            .map(|((&s, values_s), columns)| ForwardBlock {
                block: s,
                first_row: self.shapes[s].begin,
                rows: self.shapes[s].width,
                columns,
                values: values_s,
            })
            .collect();
        Ok(ForwardColumns {
            ncols: columns.len(),
            blocks,
        })
    }

    /// Per touched block (`touched`, with `slot` its inverse): the storage order of its
    /// columns by the first row each can be nonzero in — the least of its own entries' rows
    /// and its touched children's first pattern rows (a descendant's pattern rows in a block
    /// are among those of the child it lies under) — where that saves flops.
    fn column_layouts(
        &self,
        symbolic: &Symbolic,
        columns: &[Vec<(usize, f64)>],
        inv: &[usize],
        touched: &[usize],
        members: &[Vec<usize>],
        slot: &[usize],
    ) -> Vec<Option<ColumnLayout>> {
        let mut first: Vec<Vec<usize>> = touched
            .iter()
            .map(|&s| {
                let (width, m) = (self.shapes[s].width, members[s].len());
                if ColumnLayout::may_pay(width, m) {
                    vec![width; m]
                } else {
                    Vec::new()
                }
            })
            .collect();
        for (j, col) in columns.iter().enumerate() {
            for &(i, _) in col {
                let p = inv[i];
                let s = self.block_of[p];
                let f = &mut first[slot[s]];
                if let (false, Ok(c)) = (f.is_empty(), members[s].binary_search(&j)) {
                    f[c] = f[c].min(p - self.shapes[s].begin);
                }
            }
        }
        let rows = row_idx(symbolic);
        for &c in touched {
            let s = self.parent[c];
            if s == NONE || first[slot[s]].is_empty() {
                continue;
            }
            // The child's first pattern row lies in its parent.
            let r = rows[self.shapes[c].pattern.start] - self.shapes[s].begin;
            let f = &mut first[slot[s]];
            let mut at = 0;
            for &j in &members[c] {
                while members[s][at] != j {
                    at += 1;
                }
                f[at] = f[at].min(r);
            }
        }
        touched
            .iter()
            .zip(first)
            .map(|(&s, f)| {
                let b = &self.shapes[s];
                (!f.is_empty())
                    .then(|| ColumnLayout::by_first_rows(&f, b.width, b.pattern.len()))
                    .flatten()
            })
            .collect()
    }
}

/// One block's kernel on columns `x` (the block's `top.nrows()` rows each) vanishing above
/// row `low`: the rows from `low` solved against the block's triangle `top`, `out` set to the
/// product of its rows below, `bottom`, with them. With `dense`, the last column is a dense
/// right-hand side: its rows above `low` are solved first and their part of the product
/// added after, so that the block is read once for all.
fn eliminate_columns(
    top: MatRef<'_, f64>,
    bottom: MatRef<'_, f64>,
    x: &mut [f64],
    out: &mut [f64],
    low: usize,
    dense: bool,
) {
    let (w, p) = (top.nrows(), bottom.nrows());
    let k = x.len() / w;
    let lead = dense && low > 0;
    if lead {
        let (head, tail) = x[(k - 1) * w..].split_at_mut(low);
        let mut head = MatMut::from_column_major_slice_mut(head, low, 1);
        solve_lower_triangular_in_place(top.submatrix(0, 0, low, low), head.rb_mut(), Par::Seq);
        matmul(
            MatMut::from_column_major_slice_mut(tail, w - low, 1),
            Accum::Add,
            top.submatrix(low, 0, w - low, low),
            head.rb(),
            -1.0,
            Par::Seq,
        );
    }
    let mut all = MatMut::from_column_major_slice_mut(x, w, k);
    let mut x = all.rb_mut().subrows_mut(low, w - low);
    solve_lower_triangular_in_place(
        top.submatrix(low, low, w - low, w - low),
        x.rb_mut(),
        Par::Seq,
    );
    if p > 0 {
        let mut out = MatMut::from_column_major_slice_mut(out, p, k);
        matmul(
            out.rb_mut(),
            Accum::Replace,
            bottom.subcols(low, w - low),
            x.rb(),
            1.0,
            Par::Seq,
        );
        if lead {
            matmul(
                out.subcols_mut(k - 1, 1),
                Accum::Add,
                bottom.subcols(0, low),
                all.rb().submatrix(0, k - 1, low, 1),
                1.0,
                Par::Seq,
            );
        }
    }
}

/// Whether the largest of `loads` is within [`TASK_BALANCE`] of an even share.
fn balanced(loads: &[usize]) -> bool {
    let most = loads.iter().copied().max().unwrap_or(0) as f64;
    let even = loads.iter().sum::<usize>() as f64 / loads.len().max(1) as f64;
    most <= TASK_BALANCE * even
}

/// What eliminating the touched blocks of one group needs.
struct Walk<'a> {
    tree: &'a BlockTree,
    symbolic: &'a Symbolic,
    values: &'a [f64],
    /// The touched blocks, ascending.
    touched: &'a [usize],
    /// Per block: the columns that reach it, ascending.
    members: &'a [Vec<usize>],
    /// Per block: its position in `touched`, or `NONE`.
    slot: &'a [usize],
    /// Per touched block: its group (a task, or the top).
    group_of: &'a [usize],
    /// Per touched block: its position in its group.
    index: &'a [usize],
    /// Per touched block: the order of its stored columns when not ascending.
    layouts: &'a [Option<ColumnLayout>],
    par: Par,
    /// Whether the subtree tasks split a large block's columns over the threads.
    split_in_tasks: bool,
}

impl Walk<'_> {
    /// Eliminates the touched blocks `list` of group `group` (ascending), their solutions
    /// `mine` (in list order): each block's rows solved, its rows below subtracted from its
    /// ancestors' — in `mine`, or for top blocks of another group through `top_columns` (by
    /// their position among the top blocks). A dense right-hand side's `cursor` over the
    /// group's blocks advances alongside: to each touched block before it, past it with the
    /// block's columns (one more column of their kernels), and to the group's end.
    fn eliminate(
        &self,
        group: usize,
        list: &[usize],
        mine: &mut [Vec<f64>],
        mut top_columns: Option<&mut TopColumns<'_>>,
        mut cursor: Option<&mut ForwardCursor<'_>>,
    ) {
        let mut below = Vec::new();
        let mut position = Vec::new();
        for (i, &k) in list.iter().enumerate() {
            let s = self.touched[k];
            if let Some(c) = cursor.as_deref_mut() {
                c.advance_to(s);
            }
            let b = self.tree.block(self.symbolic, self.values, s);
            let m = self.members[s].len();
            let rows = b.width + b.pattern.len();
            let l = MatRef::from_column_major_slice(b.values, rows, b.width);
            let (top, bottom) = l.split_at_row(b.width);
            let (done, rest) = mine.split_at_mut(i + 1);
            let xs = &mut done[i];
            // A dense right-hand side rides along as one more column, stored last (its
            // storage has room for it): the block is read once for both.
            let fused = match cursor.as_deref_mut() {
                Some(c) => {
                    xs.extend_from_slice(c.rows_of(s));
                    true
                }
                None => false,
            };
            below.clear();
            below.resize(b.pattern.len() * (m + usize::from(fused)), 0.0);
            // Large blocks: the columns split over the threads, each solved and multiplied by
            // one thread's kernels (faer's parallel kernels reached half the rate here); in a
            // subtree task only when the tasks are unbalanced.
            let split = top_columns.is_none() || self.split_in_tasks;
            let threads = match self.par {
                Par::Rayon(t) if split && rows * b.width * m > PARALLEL_FLOPS => t.get().min(m),
                _ => 1,
            };
            let (w, p) = (b.width, b.pattern.len());
            let layout = self.layouts[k].as_ref();
            let one = [(0..m, 0)];
            let groups = layout.map_or(&one[..], |l| &l.groups[..]);
            // Work items: each group's columns in chunks (more than one chunk per thread when
            // groups differ in cost, each chunk its own task).
            let pieces = if groups.len() > 1 {
                2 * threads
            } else {
                threads
            };
            let mut items: Vec<(&mut [f64], &mut [f64], usize, bool)> = Vec::new();
            let (mut x_rest, mut out_rest) = (&mut xs[..], &mut below[..]);
            for (g, (range, low)) in groups.iter().enumerate() {
                let chunk = range.len().div_ceil(pieces.max(1)).max(1);
                let mut left = range.len();
                while left > 0 {
                    let c = chunk.min(left);
                    // The right-hand side joins the last chunk.
                    let dense = fused && g + 1 == groups.len() && c == left;
                    let taken = c + usize::from(dense);
                    let (x_now, x_next) = std::mem::take(&mut x_rest).split_at_mut(taken * w);
                    let (out_now, out_next) = std::mem::take(&mut out_rest).split_at_mut(taken * p);
                    items.push((x_now, out_now, *low, dense));
                    (x_rest, out_rest) = (x_next, out_next);
                    left -= c;
                }
            }
            if threads > 1 {
                items
                    .into_par_iter()
                    .with_max_len(1)
                    .for_each(|(x, out, low, dense)| {
                        eliminate_columns(top, bottom, x, out, low, dense)
                    });
            } else {
                items.into_iter().for_each(|(x, out, low, dense)| {
                    eliminate_columns(top, bottom, x, out, low, dense)
                });
            }
            if let Some(c) = cursor.as_deref_mut() {
                c.rows_of(s).copy_from_slice(&xs[m * w..]);
                c.eliminated(s, &below[m * p..]);
                xs.truncate(m * w);
            }
            if b.pattern.is_empty() {
                continue;
            }
            // Subtract from the ancestors' rows; this block's columns are among theirs. The
            // pattern is ascending: a run of rows per ancestor, column by column (contiguous
            // reads of `below`, ascending writes).
            let mut r0 = 0;
            while r0 < p {
                let t = self.tree.block_of[b.pattern[r0]];
                let end = self.tree.shapes[t].begin + self.tree.shapes[t].width;
                let r1 = r0 + b.pattern[r0..].partition_point(|&row| row < end);
                // Storage column of this block → storage column of the ancestor.
                let kt = self.slot[t];
                let ancestor = self.layouts[kt].as_ref();
                position.clear();
                position.resize(m, 0);
                let mut at = 0;
                for (c, &j) in self.members[s].iter().enumerate() {
                    while self.members[t][at] != j {
                        at += 1;
                    }
                    position[layout.map_or(c, |l| l.position[c])] =
                        ancestor.map_or(at, |l| l.position[at]);
                }
                let bt = &self.tree.shapes[t];
                let rows = &b.pattern[r0..r1];
                let (first, len) = (rows[0] - bt.begin, r1 - r0);
                // Ascending and distinct: contiguous exactly when the last row is len − 1 on.
                let contiguous = rows[len - 1] - rows[0] == len - 1;
                let subtract = |out: &mut [f64], c: usize| {
                    let from = &below[c * p + r0..c * p + r1];
                    if contiguous {
                        out[first..first + len]
                            .iter_mut()
                            .zip(from)
                            .for_each(|(o, v)| *o -= v);
                    } else {
                        for (&row, v) in rows.iter().zip(from) {
                            out[row - bt.begin] -= v;
                        }
                    }
                };
                if self.group_of[kt] == group {
                    let xt = &mut rest[self.index[kt] - i - 1];
                    for (c, &at) in position.iter().enumerate() {
                        subtract(&mut xt[at * bt.width..(at + 1) * bt.width], c);
                    }
                } else {
                    // The top group's ancestors are top blocks.
                    let Some(top) = top_columns.as_deref_mut() else {
                        unreachable!("an ancestor outside the top group")
                    };
                    for (c, &at) in position.iter().enumerate() {
                        subtract(top.column(self.index[kt], at), c);
                    }
                }
                r0 = r1;
            }
        }
        if let Some(c) = cursor {
            c.finish();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{BlockTree, NONE};
    use crate::test_matrices::{grid, grid_factor};
    use crate::{CholeskyVariant, FaerCholesky};
    use faer::Par;
    use fibercell_solver::{FillOrdering, ForwardColumns, LinearSolver, SolverError};

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
            for ordering in [FillOrdering::Natural, FillOrdering::NestedDissection] {
                let a = grid(k);
                let n = k * k * k;
                let mut s = FaerCholesky::new(CholeskyVariant::Llt, ordering.clone());
                s.analyze(a.as_ref()).unwrap();
                s.factorize(a.as_ref()).unwrap();
                if ordering == FillOrdering::NestedDissection {
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
                if supernodal && ordering == FillOrdering::NestedDissection {
                    assert!(w.nnz() < b.len() * n / 4, "{} of {}", w.nnz(), b.len() * n);
                }
            }
        }
    }

    /// With the subtrees of the block tree on 2 and 3 tasks (their updates of the top blocks
    /// direct or private by column) the sparse forward solve gives the one-group result: the same blocks
    /// and columns, values to 1e-12.
    #[test]
    fn sparse_forward_solve_on_subtree_tasks_matches_one_group() {
        use crate::block_kernels::SolveSchedule;
        let (n, _, s) = grid_factor(16);
        let factor = s.factor_view();
        let tree = BlockTree::of(factor.symbolic);
        let forward = |b: &[Vec<(usize, f64)>], schedule: &SolveSchedule| {
            tree.forward(&factor, b, schedule, Par::Seq, None).unwrap()
        };
        let one_group = SolveSchedule::with_threshold(&tree, 1, 0);
        for threads in [2, 3] {
            let schedule = SolveSchedule::with_threshold(&tree, threads, 0);
            assert_eq!(schedule.task_count(), threads);
            let task_of = schedule.task_of(tree.parent.len());
            let task = |i: usize| task_of[tree.block_of[factor.inv[i]]];
            // Besides the usual columns, one in a single task's subtrees and one with a row in
            // every task's, whatever the ordering: both kinds of top columns occur, reached
            // by one task only (written directly) and by several (the later tasks' parts
            // private).
            let first_row_of = |t: usize| (0..n).find(|&i| task(i) == t).expect("task's row");
            let mut b = columns(n);
            b.push(vec![(first_row_of(0), 1.5)]);
            b.push(
                (0..threads)
                    .map(|t| (first_row_of(t), 1.0 + t as f64))
                    .collect(),
            );
            let reaching: Vec<usize> = b
                .iter()
                .map(|col| {
                    let mut tasks: Vec<usize> = col
                        .iter()
                        .map(|&(i, _)| task(i))
                        .filter(|&t| t != NONE)
                        .collect();
                    tasks.sort_unstable();
                    tasks.dedup();
                    tasks.len()
                })
                .collect();
            assert!(
                reaching.contains(&1) && reaching.contains(&threads),
                "{threads} tasks: {reaching:?}"
            );
            let got = forward(&b, &schedule);
            assert_same_forward(&got, &forward(&b, &one_group), &format!("{threads} tasks"));
        }
    }

    /// With the subtrees on two tasks and two threads the forward solve matches the
    /// sequential one, for columns spread over the cell and for columns all in one task's
    /// subtrees (unbalanced: that task's large blocks split over the threads).
    #[test]
    fn sparse_forward_solve_on_tasks_with_and_without_splits_matches_sequential() {
        use crate::block_kernels::SolveSchedule;
        let (n, _, s) = grid_factor(20);
        let factor = s.factor_view();
        let tree = BlockTree::of(factor.symbolic);
        let one = SolveSchedule::with_threshold(&tree, 1, 0);
        let tasks = SolveSchedule::with_threshold(&tree, 2, 0);
        let task_of = tasks.task_of(tree.parent.len());
        let task = |i: usize| task_of[tree.block_of[factor.inv[i]]];
        let spread = spread_columns(n);
        let first: Vec<usize> = (0..n).filter(|&i| task(i) == 0).collect();
        let one_task: Vec<Vec<(usize, f64)>> = (0..160)
            .map(|j| vec![(first[(j * 7919) % first.len()], 1.0 + j as f64)])
            .collect();
        for (name, b) in [("spread", &spread), ("one task", &one_task)] {
            let seq = tree.forward(&factor, b, &one, Par::Seq, None).unwrap();
            if name == "one task" {
                // A block of task 0 large enough to split.
                assert!(seq.blocks.iter().any(|blk| {
                    let rows = blk.rows
                        + tree
                            .block(factor.symbolic, factor.values, blk.block)
                            .pattern
                            .len();
                    task_of[blk.block] == 0
                        && rows * blk.rows * blk.columns.len() > super::PARALLEL_FLOPS
                }));
            }
            let par = tree
                .forward(&factor, b, &tasks, Par::rayon(2), None)
                .unwrap();
            assert_same_forward(&par, &seq, name);
        }
    }

    /// 47 columns of two entries each, spread over the `n` rows.
    fn spread_columns(n: usize) -> Vec<Vec<(usize, f64)>> {
        (0..47)
            .map(|j| {
                vec![
                    ((j * 7919) % n, 1.0 + j as f64),
                    ((j * 104_729 + 11) % n, -0.5),
                ]
            })
            .collect()
    }

    /// `got` has the blocks and columns of `want`, values to 1e-12 of the largest.
    fn assert_same_forward(got: &ForwardColumns, want: &ForwardColumns, label: &str) {
        assert_eq!(got.blocks.len(), want.blocks.len(), "{label}");
        let big = want
            .blocks
            .iter()
            .flat_map(|blk| &blk.values)
            .fold(0.0f64, |m, v| m.max(v.abs()));
        for (g, w) in got.blocks.iter().zip(&want.blocks) {
            assert_eq!((g.block, &g.columns), (w.block, &w.columns), "{label}");
            for (x, y) in g.values.iter().zip(&w.values) {
                assert!((x - y).abs() <= 1e-12 * big, "{label}: {x} vs {y}");
            }
        }
    }

    /// The forward half of a dense right-hand side taken along with sparse columns is the
    /// plain forward half (to 1e-13 of its largest entry: on touched blocks it is one more
    /// column of the columns' kernels, elsewhere the same block operations; bit for bit with
    /// no columns), and the columns' values are as without it: on one group, on 2 and 3 subtree tasks (sequential
    /// and on two threads), with no columns, and through the trait, whose error on a bad
    /// column leaves the right-hand side as it was.
    #[test]
    fn forward_solve_with_a_dense_right_hand_side_matches_the_two_apart() {
        use crate::block_kernels::SolveSchedule;
        use crate::block_solve::forward_in_place;
        let (n, _, mut s) = grid_factor(20);
        let b = spread_columns(n);
        let rhs: Vec<f64> = (0..n).map(|i| ((i * 37) % 23) as f64 - 11.0).collect();
        // The largest difference and the largest entry of `want`.
        let off = |x: &[f64], want: &[f64]| {
            let big = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let off = x
                .iter()
                .zip(want)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            (off, big)
        };
        {
            let factor = s.factor_view();
            let tree = BlockTree::of(factor.symbolic);
            for threads in [1, 2, 3] {
                let schedule = SolveSchedule::with_threshold(&tree, threads, 0);
                let mut want = rhs.clone();
                forward_in_place(&tree, &schedule, factor.symbolic, factor.values, &mut want);
                for par in [Par::Seq, Par::rayon(2)] {
                    let label = format!("{threads} tasks, {par:?}");
                    let alone = tree.forward(&factor, &b, &schedule, par, None).unwrap();
                    for columns in [&b[..], &[]] {
                        let mut x = rhs.clone();
                        let w = tree
                            .forward(&factor, columns, &schedule, par, Some(&mut x))
                            .unwrap();
                        let (off, big) = off(&x, &want);
                        assert!(
                            off <= 1e-13 * big && (!columns.is_empty() || x == want),
                            "{label}, {} columns: off by {off:e} of {big:e}",
                            columns.len()
                        );
                        if columns.is_empty() {
                            assert!(w.blocks.is_empty());
                        } else {
                            assert_same_forward(&w, &alone, &label);
                        }
                    }
                }
            }
        }
        let mut want = rhs.clone();
        s.solve_lower_in_place(&mut want).unwrap();
        let mut x = rhs.clone();
        let w = s.forward_solve_sparse_and_lower(&b, &mut x).unwrap();
        let (off, big) = off(&x, &want);
        assert!(off <= 1e-13 * big, "trait: off by {off:e} of {big:e}");
        assert_same_forward(&w, &s.forward_solve_sparse(&b).unwrap(), "trait");
        let mut x = rhs.clone();
        let bad = s.forward_solve_sparse_and_lower(&[vec![(n, 1.0)]], &mut x);
        assert!(matches!(bad, Err(SolverError::DimensionMismatch(_))));
        assert!(x == rhs);
    }

    /// The block kernel on columns vanishing above a row, with and without a dense last
    /// column, equals a plain dense forward elimination of each column (1e-13 of the largest
    /// entry): a 9-wide block with 5 rows below, columns zero above row 4.
    #[test]
    fn block_kernel_takes_a_dense_last_column_from_the_top() {
        let (w, p, k, low) = (9, 5, 4, 4);
        let ld = w + p;
        let l: Vec<f64> = (0..ld * w)
            .map(|i| {
                let (r, c) = (i % ld, i / ld);
                match r.cmp(&c) {
                    std::cmp::Ordering::Less => 0.0,
                    std::cmp::Ordering::Equal => 2.0 + r as f64 / 3.0,
                    std::cmp::Ordering::Greater => ((r * 7 + c * 3) % 11) as f64 / 5.0 - 1.0,
                }
            })
            .collect();
        let l = faer::MatRef::from_column_major_slice(&l, ld, w);
        let (top, bottom) = l.split_at_row(w);
        let mut x: Vec<f64> = (0..w * k)
            .map(|i| {
                if i % w < low {
                    0.0
                } else {
                    ((i * 5) % 7) as f64 - 3.0
                }
            })
            .collect();
        // The dense column: nonzero from the top.
        x[(k - 1) * w..]
            .iter_mut()
            .enumerate()
            .for_each(|(r, v)| *v = r as f64 - 4.5);
        // Plain column-by-column elimination.
        let mut want_x = x.clone();
        let mut want_out = vec![0.0; p * k];
        for c in 0..k {
            let col = &mut want_x[c * w..(c + 1) * w];
            for j in 0..w {
                col[j] /= top[(j, j)];
                for i in j + 1..w {
                    col[i] -= top[(i, j)] * col[j];
                }
                for i in 0..p {
                    want_out[c * p + i] += bottom[(i, j)] * col[j];
                }
            }
        }
        for (dense, columns) in [(true, k), (false, k - 1)] {
            let mut got_x = x[..columns * w].to_vec();
            let mut got_out = vec![f64::NAN; p * columns];
            super::eliminate_columns(top, bottom, &mut got_x, &mut got_out, low, dense);
            let big = want_x
                .iter()
                .chain(&want_out)
                .fold(0.0f64, |m, v| m.max(v.abs()));
            for (g, r) in got_x
                .iter()
                .zip(&want_x)
                .chain(got_out.iter().zip(&want_out))
            {
                assert!((g - r).abs() <= 1e-13 * big, "dense {dense}: {g} vs {r}");
            }
        }
    }

    /// Loads within 10 % of an even share are balanced; one task with all of them is not.
    #[test]
    fn task_balance_rule() {
        assert!(super::balanced(&[105, 95]));
        assert!(!super::balanced(&[120, 80]));
        assert!(!super::balanced(&[100, 0]));
        assert!(super::balanced(&[]));
    }

    /// Blocks large enough to split their columns over threads (the top separators of a 20³
    /// grid with 47 columns) give the sequential result to 1e-12, on 2 and 3 threads.
    #[test]
    fn sparse_forward_solve_with_columns_split_over_threads_matches_sequential() {
        use crate::block_kernels::SolveSchedule;
        let (n, _, s) = grid_factor(20);
        let factor = s.factor_view();
        let tree = BlockTree::of(factor.symbolic);
        let b = spread_columns(n);
        let schedule = SolveSchedule::with_threshold(&tree, 1, 0);
        let seq = tree
            .forward(&factor, &b, &schedule, Par::Seq, None)
            .unwrap();
        // The split must happen somewhere: a block of at least 2²⁰ products.
        assert!(seq.blocks.iter().any(|blk| {
            let rows = tree.shapes[blk.block].width
                + tree
                    .block(factor.symbolic, factor.values, blk.block)
                    .pattern
                    .len();
            rows * blk.rows * blk.columns.len() > super::PARALLEL_FLOPS
        }));
        for threads in [2, 3] {
            let par = tree
                .forward(&factor, &b, &schedule, Par::rayon(threads), None)
                .unwrap();
            assert_same_forward(&par, &seq, &format!("{threads} threads"));
        }
    }

    /// A solve with one right-hand side agrees with one with two to 1e-12 and is backward
    /// stable (backward error ≤ 1e-14).
    #[test]
    fn single_right_hand_side_solve_matches_two() {
        for k in [4, 16] {
            for ordering in [FillOrdering::Natural, FillOrdering::NestedDissection] {
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

    /// Columns spread over a 20³ grid reach the top separators through children whose
    /// patterns start at different rows: some blocks store them grouped by their first
    /// possibly nonzero row and skip the zeros above. Every block's values still equal the
    /// dense lower solve of each column (1e-12), sequential and split over 2 threads; a dense
    /// right-hand side taken along (in such a block one more column, solved from the top)
    /// gets its plain forward half (1e-13 of its largest entry) and leaves the columns as
    /// they were.
    #[test]
    fn forward_solve_with_columns_grouped_by_first_row_matches_dense_lower_solves() {
        use crate::block_kernels::SolveSchedule;
        use crate::block_solve::forward_in_place;
        let (n, _, mut s) = grid_factor(20);
        let b: Vec<Vec<(usize, f64)>> = (0..96)
            .map(|j| vec![((j * 7919) % n, 1.0 + j as f64 / 7.0)])
            .collect();
        let lower: Vec<Vec<f64>> = b
            .iter()
            .map(|col| {
                let mut dense = vec![0.0; n];
                for &(i, v) in col {
                    dense[i] = v;
                }
                s.solve_lower_in_place(&mut dense).unwrap();
                dense
            })
            .collect();
        let factor = s.factor_view();
        let tree = BlockTree::of(factor.symbolic);
        let schedule = SolveSchedule::with_threshold(&tree, 2, 0);
        // In the factor's row order.
        let rhs: Vec<f64> = (0..n).map(|i| ((i * 37) % 23) as f64 - 11.0).collect();
        let mut half = rhs.clone();
        forward_in_place(&tree, &schedule, factor.symbolic, factor.values, &mut half);
        let big = half.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for par in [Par::Seq, Par::rayon(2)] {
            let w = tree.forward(&factor, &b, &schedule, par, None).unwrap();
            let mut x = rhs.clone();
            let along = tree
                .forward(&factor, &b, &schedule, par, Some(&mut x))
                .unwrap();
            for (g, r) in x.iter().zip(&half) {
                assert!((g - r).abs() <= 1e-13 * big, "{par:?}: {g} vs {r}");
            }
            assert_same_forward(&along, &w, "with a right-hand side");
            assert!(
                w.blocks
                    .iter()
                    .any(|blk| blk.columns.windows(2).any(|p| p[0] > p[1])),
                "no block grouped its columns"
            );
            for blk in &w.blocks {
                for (c, &j) in blk.columns.iter().enumerate() {
                    let want = &lower[j][blk.first_row..blk.first_row + blk.rows];
                    let big = lower[j].iter().fold(1e-300f64, |m, v| m.max(v.abs()));
                    let got = &blk.values[c * blk.rows..(c + 1) * blk.rows];
                    for (g, r) in got.iter().zip(want) {
                        assert!((g - r).abs() <= 1e-12 * big, "{par:?}: column {j}");
                    }
                }
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
            let mut s = FaerCholesky::new(CholeskyVariant::Llt, FillOrdering::NestedDissection);
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
                    if let Some(c) = blk.columns.iter().position(|&c| c == j) {
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
        let mut s = FaerCholesky::new(CholeskyVariant::Llt, FillOrdering::Amd);
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
        let mut l = FaerCholesky::new(CholeskyVariant::Ldlt, FillOrdering::Amd);
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
