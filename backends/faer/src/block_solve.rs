//! One right-hand side through the blocks of faer's Cholesky factor, independent subtrees of
//! the block tree on separate threads.
//!
//! A triangular solve with one right-hand side reads each block of L once per direction and is
//! bound by memory bandwidth, which one core does not saturate. The subtrees below the top
//! separators touch disjoint rows: forward, each thread eliminates its subtrees and collects
//! their updates of the top rows privately (summed afterwards), then the top blocks follow;
//! backward, the top blocks first, then the subtrees in parallel (they only read the top rows).

use crate::block_kernels::{backward_block, top_par, Shared, SolveSchedule};
use crate::block_tree::BlockTree;
use crate::dense_forward::DenseForward;
use crate::prefetch::prefetch_block;
use crate::symbolic::Symbolic;
use faer::Par;
use rayon::prelude::*;

/// Solves L Lᵀ x = b in place (one right-hand side, factor order).
pub(crate) fn solve_in_place(
    tree: &BlockTree,
    schedule: &SolveSchedule,
    symbolic: &Symbolic,
    values: &[f64],
    x: &mut [f64],
) {
    forward_in_place(tree, schedule, symbolic, values, x);
    backward_in_place(tree, schedule, symbolic, values, x);
}

/// x ← L⁻¹ x (factor order).
pub(crate) fn forward_in_place(
    tree: &BlockTree,
    schedule: &SolveSchedule,
    symbolic: &Symbolic,
    values: &[f64],
    x: &mut [f64],
) {
    DenseForward::new(tree, schedule, symbolic, values, x).run();
}

/// x ← L⁻ᵀ x (factor order): the top blocks, then the subtrees (reading the final top rows).
pub(crate) fn backward_in_place(
    tree: &BlockTree,
    schedule: &SolveSchedule,
    symbolic: &Symbolic,
    values: &[f64],
    x: &mut [f64],
) {
    let mut below = Vec::new();
    for &s in schedule.top.iter().rev() {
        let b = tree.block(symbolic, values, s);
        below.clear();
        below.extend(b.pattern.iter().map(|&row| x[row]));
        backward_block(
            &b,
            &mut x[b.begin..b.begin + b.width],
            &below,
            top_par(&b, schedule),
        );
    }
    let shared = Shared(x.as_mut_ptr());
    schedule.tasks.par_iter().for_each(|blocks| {
        let mut below = Vec::new();
        for (i, &s) in blocks.iter().enumerate().rev() {
            if i > 0 {
                prefetch_block(tree, values, blocks[i - 1]);
            }
            let b = tree.block(symbolic, values, s);
            below.clear();
            // SAFETY: the pattern rows are this task's (written by it before) or top rows
            // (final, only read now); the block's own rows are this task's.
            below.extend(b.pattern.iter().map(|&row| unsafe { *shared.at(row) }));
            let top = unsafe { std::slice::from_raw_parts_mut(shared.at(b.begin), b.width) };
            backward_block(&b, top, &below, Par::Seq);
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::block_kernels::BALANCE;
    use crate::block_tree::FactorView;
    use crate::test_matrices::grid_factor;
    use fibercell_solver::LinearSolver;

    /// The block solve on 1 thread and with subtrees on 2 and 3 threads gives faer's solution
    /// (1e-12) on a supernodal ND factor, with a backward error ≤ 1e-14.
    #[test]
    fn block_solve_on_one_to_three_threads_gives_faers_solution() {
        let (n, a, mut s) = grid_factor(16);
        let b: Vec<f64> = (0..n).map(|i| ((i * 53) % 29) as f64 - 14.0).collect();
        let mut want = [b.clone(), b.clone()].concat();
        s.solve_in_place(&mut want, 2).unwrap();
        let FactorView {
            symbolic,
            values,
            inv,
            scale,
        } = s.factor_view();
        let tree = BlockTree::of(symbolic);
        for threads in [1, 2, 3] {
            let schedule = SolveSchedule::with_threshold(&tree, threads, 0);
            assert_eq!(schedule.is_parallel(), threads > 1);
            if threads > 1 {
                assert_eq!(schedule.tasks.len(), threads);
                assert!(!schedule.top.is_empty());
                // The tasks' factor values are balanced to BALANCE of an even share.
                let loads: Vec<usize> = schedule
                    .tasks
                    .iter()
                    .map(|t| t.iter().map(|&s| tree.shapes[s].values.len()).sum())
                    .collect();
                let even = loads.iter().sum::<usize>() as f64 / threads as f64;
                let most = loads.iter().copied().max().unwrap_or(0) as f64;
                assert!(most <= BALANCE * even, "{threads} threads: loads {loads:?}");
            }
            let mut x = vec![0.0; n];
            for (old, &new) in inv.iter().enumerate() {
                x[new] = b[old] * scale[old];
            }
            solve_in_place(&tree, &schedule, symbolic, values, &mut x);
            let big = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let mut got = vec![0.0; n];
            for (old, &new) in inv.iter().enumerate() {
                got[old] = x[new] * scale[old];
                assert!(
                    (got[old] - want[old]).abs() <= 1e-12 * big,
                    "{threads} threads, row {old}"
                );
            }
            let e = fibercell_solver::backward_error(a.as_ref(), &got, &b);
            assert!(e <= 1e-14, "{threads} threads: backward error {e}");
        }
    }
}
