//! Several right-hand sides through the blocks of faer's Cholesky factor at once, independent
//! subtrees on separate threads, as [`crate::block_solve`] does for one.
//!
//! The k columns are interleaved (row i's k values side by side), so each block of L is read
//! once per direction for all of them and a row's values share a cache line. faer's own solve
//! of several columns runs a column group per thread, each group reading the whole factor.

use crate::block_kernels::{backward_dense, forward_dense, top_par, Shared, SolveSchedule};
use crate::block_tree::{Block, BlockTree, NONE};
use crate::symbolic::Symbolic;
use faer::{MatMut, MatRef, Par};
use rayon::prelude::*;

/// Blocks with at least this many values × columns use faer's dense kernels; smaller ones the
/// plain loops, whose call overhead is lower.
const DENSE_KERNEL_WORK: usize = 1 << 11;

/// The factor and its schedule, as the half solves read them.
#[derive(Clone, Copy)]
pub(crate) struct FactorBlocks<'a> {
    pub(crate) tree: &'a BlockTree,
    pub(crate) schedule: &'a SolveSchedule,
    pub(crate) symbolic: &'a Symbolic,
    pub(crate) values: &'a [f64],
}

/// Solves L Lᵀ X = B in place; `x` holds the k columns interleaved (`x[i·k + c]`), factor order.
pub(crate) fn solve_many_in_place(f: FactorBlocks<'_>, x: &mut [f64], k: usize) {
    forward_many(f, x, k);
    backward_many(f, x, k);
}

/// X ← L⁻¹ X: the subtree tasks in parallel (their updates of the top rows kept privately,
/// then summed), then the top blocks.
fn forward_many(f: FactorBlocks<'_>, x: &mut [f64], k: usize) {
    let top_index = f.schedule.top_index();
    let top_rows = f.schedule.top_rows();
    let shared = Shared(x.as_mut_ptr());
    let updates: Vec<Vec<f64>> = f
        .schedule
        .task_blocks()
        .par_iter()
        .map(|blocks| {
            let mut update = vec![0.0; top_rows * k];
            let mut below = Vec::new();
            for &s in blocks {
                let b = f.tree.block(f.symbolic, f.values, s);
                // SAFETY: a task's blocks and the rows below them that are not top rows lie in
                // its subtrees, which no other task writes; top rows go to `update`.
                let own =
                    unsafe { std::slice::from_raw_parts_mut(shared.at(b.begin * k), b.width * k) };
                forward_block_many(&b, own, &mut below, k, Par::Seq);
                for (&row, lost) in b.pattern.iter().zip(below.chunks(k)) {
                    let target = match top_index[row] {
                        // SAFETY: as above, a row of this task's subtrees.
                        NONE => unsafe { std::slice::from_raw_parts_mut(shared.at(row * k), k) },
                        t => &mut update[t * k..(t + 1) * k],
                    };
                    target.iter_mut().zip(lost).for_each(|(v, l)| *v -= l);
                }
            }
            update
        })
        .collect();
    for update in &updates {
        for &s in f.schedule.top_blocks() {
            let b = &f.tree.shapes[s];
            let t = top_index[b.begin] * k;
            let rows = b.begin * k..(b.begin + b.width) * k;
            x[rows.clone()]
                .iter_mut()
                .zip(&update[t..t + rows.len()])
                .for_each(|(v, u)| *v += u);
        }
    }
    let mut below = Vec::new();
    for &s in f.schedule.top_blocks() {
        let b = f.tree.block(f.symbolic, f.values, s);
        let own = &mut x[b.begin * k..(b.begin + b.width) * k];
        forward_block_many(&b, own, &mut below, k, top_par(&b, f.schedule));
        for (&row, lost) in b.pattern.iter().zip(below.chunks(k)) {
            x[row * k..(row + 1) * k]
                .iter_mut()
                .zip(lost)
                .for_each(|(v, l)| *v -= l);
        }
    }
}

/// X ← L⁻ᵀ X: the top blocks, then the subtrees in parallel (they only read the top rows).
fn backward_many(f: FactorBlocks<'_>, x: &mut [f64], k: usize) {
    let (mut below, mut sum) = (Vec::new(), Vec::new());
    for &s in f.schedule.top_blocks().iter().rev() {
        let b = f.tree.block(f.symbolic, f.values, s);
        gather(&mut below, b.pattern, k, |row| &x[row * k..(row + 1) * k]);
        let own = &mut x[b.begin * k..(b.begin + b.width) * k];
        backward_block_many(&b, own, &below, k, top_par(&b, f.schedule), &mut sum);
    }
    let shared = Shared(x.as_mut_ptr());
    f.schedule.task_blocks().par_iter().for_each(|blocks| {
        let (mut below, mut sum) = (Vec::new(), Vec::new());
        for &s in blocks.iter().rev() {
            let b = f.tree.block(f.symbolic, f.values, s);
            // SAFETY: the pattern rows are this task's (final, written by it before) or top
            // rows (final, only read now); the block's own rows are this task's.
            gather(&mut below, b.pattern, k, |row| unsafe {
                std::slice::from_raw_parts(shared.at(row * k), k)
            });
            let own =
                unsafe { std::slice::from_raw_parts_mut(shared.at(b.begin * k), b.width * k) };
            backward_block_many(&b, own, &below, k, Par::Seq, &mut sum);
        }
    });
}

/// `below` ← the k values of each pattern row, interleaved.
fn gather<'x>(below: &mut Vec<f64>, pattern: &[usize], k: usize, row: impl Fn(usize) -> &'x [f64]) {
    below.clear();
    below.reserve(pattern.len() * k);
    for &r in pattern {
        below.extend_from_slice(row(r));
    }
}

/// Forward elimination of one block for k interleaved columns: its rows `top` (width × k)
/// solved in place, `below` set to what its pattern rows lose (pattern × k).
fn forward_block_many(b: &Block<'_>, top: &mut [f64], below: &mut Vec<f64>, k: usize, par: Par) {
    let ld = b.width + b.pattern.len();
    below.clear();
    below.resize(b.pattern.len() * k, 0.0);
    if b.values.len() * k >= DENSE_KERNEL_WORK {
        let x = MatMut::from_row_major_slice_mut(top, b.width, k);
        let below = MatMut::from_row_major_slice_mut(below, b.pattern.len(), k);
        forward_dense(b, x, below, par);
        return;
    }
    for c in 0..b.width {
        let col = &b.values[c * ld..(c + 1) * ld];
        let (done, rest) = top.split_at_mut((c + 1) * k);
        let xc = &mut done[c * k..];
        xc.iter_mut().for_each(|v| *v /= col[c]);
        for (t, &l) in rest.chunks_mut(k).zip(&col[c + 1..b.width]) {
            t.iter_mut().zip(xc.iter()).for_each(|(t, x)| *t -= l * x);
        }
        for (t, &l) in below.chunks_mut(k).zip(&col[b.width..]) {
            t.iter_mut().zip(xc.iter()).for_each(|(t, x)| *t += l * x);
        }
    }
}

/// Back substitution of one block for k interleaved columns: its rows `top` from the final
/// values `below` of its pattern rows (`sum`: scratch).
fn backward_block_many(
    b: &Block<'_>,
    top: &mut [f64],
    below: &[f64],
    k: usize,
    par: Par,
    sum: &mut Vec<f64>,
) {
    let ld = b.width + b.pattern.len();
    if b.values.len() * k >= DENSE_KERNEL_WORK {
        let x = MatMut::from_row_major_slice_mut(top, b.width, k);
        let below = MatRef::from_row_major_slice(below, b.pattern.len(), k);
        backward_dense(b, x, below, par);
        return;
    }
    for c in (0..b.width).rev() {
        let col = &b.values[c * ld..(c + 1) * ld];
        sum.clear();
        sum.resize(k, 0.0);
        let (head, rest) = top.split_at_mut((c + 1) * k);
        for (t, &l) in rest.chunks(k).zip(&col[c + 1..b.width]) {
            sum.iter_mut().zip(t).for_each(|(s, t)| *s += l * t);
        }
        for (t, &l) in below.chunks(k).zip(&col[b.width..]) {
            sum.iter_mut().zip(t).for_each(|(s, t)| *s += l * t);
        }
        head[c * k..]
            .iter_mut()
            .zip(sum.iter())
            .for_each(|(x, s)| *x = (*x - s) / col[c]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::block_tree::FactorView;
    use crate::test_matrices::grid_factor;
    use fibercell_solver::LinearSolver;

    /// k = 1, 3 and 7 columns through the blocks at once, on one thread and with subtrees on
    /// two and three, give faer's solution (1e-12) on a supernodal ND factor whose blocks take
    /// both the plain loops and faer's kernels.
    #[test]
    fn several_columns_on_one_to_three_threads_give_faers_solution() {
        let (n, a, mut s) = grid_factor(16);
        let cases: Vec<(usize, Vec<f64>, Vec<f64>)> = [1, 3, 7]
            .into_iter()
            .map(|k| {
                let b: Vec<f64> = (0..k * n).map(|i| ((i * 53) % 29) as f64 - 14.0).collect();
                let mut want = b.clone();
                s.solve_in_place(&mut want, k).unwrap();
                (k, b, want)
            })
            .collect();
        let FactorView {
            symbolic,
            values,
            inv,
            scale,
        } = s.factor_view();
        let tree = BlockTree::of(symbolic);
        let sizes: Vec<usize> = tree.shapes.iter().map(|b| b.values.len()).collect();
        assert!(sizes.iter().any(|&v| 3 * v < DENSE_KERNEL_WORK));
        assert!(sizes.iter().any(|&v| 3 * v >= DENSE_KERNEL_WORK));
        for (k, b, want) in cases {
            let big = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for threads in [1, 2, 3] {
                let schedule = SolveSchedule::with_threshold(&tree, threads, 0);
                assert_eq!(schedule.is_parallel(), threads > 1);
                let mut x = vec![0.0; k * n];
                for (old, &new) in inv.iter().enumerate() {
                    for c in 0..k {
                        x[new * k + c] = b[c * n + old] * scale[old];
                    }
                }
                let f = FactorBlocks {
                    tree: &tree,
                    schedule: &schedule,
                    symbolic,
                    values,
                };
                solve_many_in_place(f, &mut x, k);
                for (old, &new) in inv.iter().enumerate() {
                    for c in 0..k {
                        let got = x[new * k + c] * scale[old];
                        assert!(
                            (got - want[c * n + old]).abs() <= 1e-12 * big,
                            "k {k}, {threads} threads, row {old}, column {c}"
                        );
                    }
                }
            }
            let e = fibercell_solver::backward_error(a.as_ref(), &want[..n], &b[..n]);
            assert!(e <= 1e-14, "k {k}: backward error {e}");
        }
    }
}
