//! The pieces of a half solve on faer's Cholesky factor: the schedule of subtree tasks and top
//! blocks over the threads, and one block's forward and backward kernels.

use crate::block_tree::{Block, BlockTree, NONE};
use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::{Accum, MatMut, MatRef, Par};

/// Subtrees are split until the largest holds at most this share above an even one.
pub(crate) const BALANCE: f64 = 1.05;
/// At most this many blocks move to the top while balancing.
const MAX_SPLITS: usize = 512;
/// Blocks with at least this many values use faer's dense kernels (runtime-dispatched SIMD);
/// smaller ones the plain loops, whose call overhead is lower.
const DENSE_KERNEL_VALUES: usize = 1 << 10;
/// Top blocks with at least this many values run faer's kernels on all threads.
const PARALLEL_BLOCK_VALUES: usize = 1 << 20;
/// Factors with fewer values are solved on one thread.
const PARALLEL_VALUES: usize = 1 << 20;

/// Which blocks each thread eliminates.
pub(crate) struct SolveSchedule {
    /// Per thread: the blocks of its subtrees, ascending (children before parents).
    pub(crate) tasks: Vec<Vec<usize>>,
    /// The remaining blocks (ancestors of the tasks' subtrees), ascending.
    pub(crate) top: Vec<usize>,
    /// Per column of L: its index among the top blocks' columns, or `NONE`.
    top_index: Vec<usize>,
    /// Columns in the top blocks.
    top_rows: usize,
}

impl SolveSchedule {
    /// Whether the subtrees run on more than one thread.
    pub(crate) fn is_parallel(&self) -> bool {
        self.tasks.len() > 1
    }

    /// Per block of a tree with `blocks` blocks: the task whose subtrees hold it, or `NONE`
    /// for the top blocks (every block when the schedule is not parallel).
    pub(crate) fn task_of(&self, blocks: usize) -> Vec<usize> {
        let mut task_of = vec![NONE; blocks];
        for (t, task) in self.tasks.iter().enumerate() {
            for &s in task {
                task_of[s] = t;
            }
        }
        task_of
    }

    /// The number of tasks (threads) the subtrees are split into; 0 when not parallel.
    pub(crate) fn task_count(&self) -> usize {
        self.tasks.len()
    }

    /// Per task: the blocks of its subtrees, ascending.
    pub(crate) fn task_blocks(&self) -> &[Vec<usize>] {
        &self.tasks
    }

    /// The top blocks (every block when not parallel), ascending.
    pub(crate) fn top_blocks(&self) -> &[usize] {
        &self.top
    }

    /// Per column of L: its index among the top blocks' columns, or `NONE` (empty when not
    /// parallel).
    pub(crate) fn top_index(&self) -> &[usize] {
        &self.top_index
    }

    /// Columns in the top blocks (0 when not parallel).
    pub(crate) fn top_rows(&self) -> usize {
        self.top_rows
    }

    /// Balances the subtrees of `tree` over `threads` by the number of factor values.
    pub(crate) fn new(tree: &BlockTree, threads: usize) -> Self {
        Self::with_threshold(tree, threads, PARALLEL_VALUES)
    }

    /// The same, on one thread when the factor has fewer than `parallel_values` values.
    pub(crate) fn with_threshold(tree: &BlockTree, threads: usize, parallel_values: usize) -> Self {
        let blocks = tree.parent.len();
        let own: Vec<usize> = tree.shapes.iter().map(|b| b.values.len()).collect();
        let mut weight = own.clone();
        let mut children = vec![Vec::new(); blocks];
        for s in 0..blocks {
            let p = tree.parent[s];
            if p != NONE {
                weight[p] += weight[s];
                children[p].push(s);
            }
        }
        let total: usize = own.iter().sum();
        let mut top: Vec<usize> = Vec::new();
        let mut pool: Vec<usize> = (0..blocks).filter(|&s| tree.parent[s] == NONE).collect();
        if threads < 2 || total < parallel_values {
            return SolveSchedule {
                tasks: Vec::new(),
                top: (0..blocks).collect(),
                top_index: Vec::new(),
                top_rows: 0,
            };
        }
        // Split the largest subtree until the longest-processing-time-first assignment of the
        // pool is balanced (its largest load within BALANCE of an even share).
        for _ in 0..MAX_SPLITS {
            let pooled: usize = pool.iter().map(|&s| weight[s]).sum();
            let assigned = assign_longest_first(&mut pool, &weight, threads);
            if assigned.1.iter().copied().max().unwrap_or(0) as f64
                <= BALANCE * pooled as f64 / threads as f64
            {
                break;
            }
            let Some(at) = (0..pool.len()).max_by_key(|&k| weight[pool[k]]) else {
                break;
            };
            let largest = pool[at];
            if children[largest].is_empty() {
                break;
            }
            pool.swap_remove(at);
            top.push(largest);
            pool.extend(&children[largest]);
        }
        let (owner, _) = assign_longest_first(&mut pool, &weight, threads);
        let mut tasks: Vec<Vec<usize>> = vec![Vec::new(); threads];
        for (&root, &t) in pool.iter().zip(&owner) {
            let mut stack = vec![root];
            while let Some(s) = stack.pop() {
                tasks[t].push(s);
                stack.extend(&children[s]);
            }
        }
        tasks.retain(|t| !t.is_empty());
        tasks.iter_mut().for_each(|t| t.sort_unstable());
        top.sort_unstable();
        let mut top_index = vec![NONE; tree.block_of.len()];
        let mut top_rows = 0;
        for &s in &top {
            let b = &tree.shapes[s];
            for i in &mut top_index[b.begin..b.begin + b.width] {
                *i = top_rows;
                top_rows += 1;
            }
        }
        SolveSchedule {
            tasks,
            top,
            top_index,
            top_rows,
        }
    }
}

/// Sorts `pool` by decreasing weight and gives each subtree to the least loaded of `threads`
/// (longest processing time first): the thread of each pool entry and the loads.
fn assign_longest_first(
    pool: &mut [usize],
    weight: &[usize],
    threads: usize,
) -> (Vec<usize>, Vec<usize>) {
    pool.sort_by_key(|&s| std::cmp::Reverse(weight[s]));
    let mut load = vec![0usize; threads];
    let owner = pool
        .iter()
        .map(|&root| {
            let t = (0..threads).min_by_key(|&t| load[t]).unwrap_or(0);
            load[t] += weight[root];
            t
        })
        .collect();
    (owner, load)
}

/// The solution vector shared by the threads, each writing its own rows only.
#[derive(Clone, Copy)]
pub(crate) struct Shared(pub(crate) *mut f64);
// SAFETY: the threads of the solves touch disjoint rows (see there).
unsafe impl Send for Shared {}
unsafe impl Sync for Shared {}

impl Shared {
    /// Pointer to row `i` (a method, so closures capture the `Send` wrapper).
    pub(crate) fn at(self, i: usize) -> *mut f64 {
        self.0.wrapping_add(i)
    }
}

/// Σ aᵢ bᵢ with four partial sums (vectorizable).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    let (ac, bc) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = ac
        .remainder()
        .iter()
        .zip(bc.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in ac.zip(bc) {
        for k in 0..4 {
            acc[k] += x[k] * y[k];
        }
    }
    acc.iter().sum::<f64>() + tail
}

/// Forward elimination of one block: its rows `top` solved in place, `below` set to what its
/// pattern rows lose.
pub(crate) fn forward_block(b: &Block<'_>, top: &mut [f64], below: &mut Vec<f64>, par: Par) {
    let ld = b.width + b.pattern.len();
    below.clear();
    below.resize(b.pattern.len(), 0.0);
    if b.values.len() >= DENSE_KERNEL_VALUES {
        let x = MatMut::from_column_major_slice_mut(top, b.width, 1);
        let below = MatMut::from_column_major_slice_mut(below, b.pattern.len(), 1);
        forward_dense(b, x, below, par);
        return;
    }
    for c in 0..b.width {
        let col = &b.values[c * ld..(c + 1) * ld];
        let xc = top[c] / col[c];
        top[c] = xc;
        for (t, l) in top[c + 1..].iter_mut().zip(&col[c + 1..b.width]) {
            *t -= l * xc;
        }
        for (t, l) in below.iter_mut().zip(&col[b.width..]) {
            *t += l * xc;
        }
    }
}

/// Back substitution of one block: its rows `top` from the final values `below` of its
/// pattern rows.
pub(crate) fn backward_block(b: &Block<'_>, top: &mut [f64], below: &[f64], par: Par) {
    let ld = b.width + b.pattern.len();
    if b.values.len() >= DENSE_KERNEL_VALUES {
        let x = MatMut::from_column_major_slice_mut(top, b.width, 1);
        let below = MatRef::from_column_major_slice(below, b.pattern.len(), 1);
        backward_dense(b, x, below, par);
        return;
    }
    for c in (0..b.width).rev() {
        let col = &b.values[c * ld..(c + 1) * ld];
        let sum = dot(&col[c + 1..b.width], &top[c + 1..]) + dot(&col[b.width..], below);
        top[c] = (top[c] - sum) / col[c];
    }
}

/// The forward step of one block by faer's kernels on the block's rows `x` (width × k, any
/// layout): x ← L₁₁⁻¹ x and `below` ← L₂₁ x, what its pattern rows lose.
pub(crate) fn forward_dense(
    b: &Block<'_>,
    mut x: MatMut<'_, f64>,
    below: MatMut<'_, f64>,
    par: Par,
) {
    let ld = b.width + b.pattern.len();
    let (l_top, l_bottom) =
        MatRef::from_column_major_slice(b.values, ld, b.width).split_at_row(b.width);
    solve_lower_triangular_in_place(l_top, x.rb_mut(), par);
    matmul(below, Accum::Replace, l_bottom, x.rb(), 1.0, par);
}

/// The backward step of one block by faer's kernels: x ← L₁₁⁻ᵀ (x − L₂₁ᵀ below), `below` the
/// final values of its pattern rows.
pub(crate) fn backward_dense(
    b: &Block<'_>,
    mut x: MatMut<'_, f64>,
    below: MatRef<'_, f64>,
    par: Par,
) {
    let ld = b.width + b.pattern.len();
    let (l_top, l_bottom) =
        MatRef::from_column_major_slice(b.values, ld, b.width).split_at_row(b.width);
    matmul(
        x.rb_mut(),
        Accum::Add,
        l_bottom.transpose(),
        below,
        -1.0,
        par,
    );
    solve_upper_triangular_in_place(l_top.transpose(), x, par);
}

/// The threads of a top block's kernels: those of `schedule` for the largest blocks (each
/// read once per solve, bandwidth-bound on one core).
pub(crate) fn top_par(b: &Block<'_>, schedule: &SolveSchedule) -> Par {
    let threads = schedule.task_count();
    if threads > 1 && b.values.len() >= PARALLEL_BLOCK_VALUES {
        Par::rayon(threads)
    } else {
        Par::Seq
    }
}
