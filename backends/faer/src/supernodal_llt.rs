//! A supernodal LLᵀ that factorizes independent subtrees of the supernodal elimination tree on
//! separate threads (left-looking, on faer's symbolic structure and dense kernels).
//!
//! faer's own supernodal kernel walks the supernodes one after another and parallelizes only
//! inside the dense kernels of one supernode, which on fiber-network matrices are mostly too
//! small to split (a node's 6×6 block, a few neighbours). Here the tree is cut into *tasks*:
//! subtrees light enough to factorize on one thread, and the heavy supernodes above them, each
//! started once its children are done and factorized with every thread when its own work is
//! large. A supernode's numeric step is the textbook left-looking one (George & Liu;
//! CHOLMOD's supernodal numeric factorization): gather A's columns, subtract every descendant's
//! update L_d,bottom L_d,midᵀ, factorize the diagonal block and solve the rows below it.

use crate::dense_llt::{self, llt, llt_two_threads, lower_product, solve_below_two_threads};
use crate::supernodes::SupernodesRef;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::cholesky_in_place_scratch;
use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::reborrow::{IntoConst, Reborrow, ReborrowMut};
use faer::{Accum, MatMut, MatRef, Par, Spec};
use fibercell_solver::CscRef;
use std::marker::PhantomData;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

type Symbolic<'a> = SupernodesRef<'a>;

/// No parent (a root of the supernodal forest).
const NONE: usize = usize::MAX;

/// Where the tree is cut into tasks (work counted as Σ c_j² over columns j with c_j entries),
/// and which updates are one product.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TaskSizes {
    /// A subtree is one task when its work is below this or below 1/(16 × threads) of the
    /// whole: ≥ 0.1 ms at the ≈ 10 GFLOP/s of small supernodes, far above the microseconds of
    /// starting a task, and about 16 tasks per thread to balance.
    pub(crate) min_task: f64,
    /// A heavy supernode's own work above which its updates and dense kernels are split over
    /// the threads.
    pub(crate) parallel_node: f64,
    /// Updates whose top square costs at most this (m² k for m rows in the target's columns,
    /// k the descendant's width) are one full product, the square's upper half wasted,
    /// instead of a triangular and a rectangular one. faer's triangular product costs
    /// ≈ 0.3 µs more per call at these sizes, which the square's waste (m² k flops) is worth
    /// at ≈ 50 GFLOP/s: measured single products of 12–600 rows, `Par::Seq`, AVX-512.
    pub(crate) one_product_work: usize,
    /// A parallel supernode's diagonal block of at least this many columns is factorized by
    /// [`llt_two_threads`], a narrower one by faer's kernel on one thread. Measured alone,
    /// faer on one thread / faer on two / [`llt_two_threads`], GFLOP/s: 400 columns
    /// 45 / 30 / 41, 600: 52 / 42 / 56, 1,218: 58 / 70 / 86, 3,036: 57 / 93 / 106 (Intel VM,
    /// two-thread DGEMM ≈ 155).
    pub(crate) two_thread_llt: usize,
}

impl Default for TaskSizes {
    fn default() -> Self {
        TaskSizes {
            min_task: 1e6,
            parallel_node: 2e7,
            one_product_work: 1 << 14,
            two_thread_llt: 512,
        }
    }
}

/// The task structure of a supernodal factor, computed once per analysis.
pub(crate) struct SupernodalPlan {
    /// Each supernode's parent in the supernodal elimination tree.
    parent: Vec<usize>,
    /// The descendants that update each supernode (`updater_ptr[s]..updater_ptr[s + 1]` of
    /// `updaters`, ascending).
    updater_ptr: Vec<usize>,
    updaters: Vec<u32>,
    /// The tasks that start the factorization: the light subtrees whose parent is heavy or
    /// absent, each as its supernodes in ascending (a topological) order,
    /// `light_nodes[light_ptr[k]..light_ptr[k + 1]]`, its root last.
    light_ptr: Vec<usize>,
    light_nodes: Vec<u32>,
    /// Heavy supernodes: their number of children (light subtrees or heavy supernodes).
    heavy_children: Vec<usize>,
    heavy: Vec<bool>,
    /// For a supernode whose updates and dense kernels run on every thread, the column at
    /// which its updates split into two blocks of equal work ([`balanced_split`], ≥ 1); 0 for
    /// a supernode on one thread. Made once per analysis.
    parallel_split: Vec<u32>,
    /// [`TaskSizes::one_product_work`].
    one_product_work: usize,
    /// [`TaskSizes::two_thread_llt`].
    two_thread_llt: usize,
}

impl SupernodalPlan {
    /// The plan of `sym`, or `None` when a supernode's parent does not come after it (which
    /// an elimination tree's numbering guarantees; the tasks rely on it) or the columns do
    /// not fit 32-bit indices.
    pub(crate) fn new(sym: Symbolic<'_>, threads: usize, sizes: TaskSizes) -> Option<Self> {
        let ns = sym.n_supernodes();
        if u32::try_from(sym.nrows()).is_err() {
            return None;
        }
        let block_of = block_of_columns(sym);
        let (parent, own) = tree(sym, &block_of);
        // A child's columns come before its parent's, so ascending order is a topological
        // order of every subtree.
        let mut subtree = own.clone();
        for s in 0..ns {
            if parent[s] != NONE {
                if parent[s] <= s {
                    return None;
                }
                subtree[parent[s]] += subtree[s];
            }
        }
        let (updater_ptr, updaters) = updaters(sym, &block_of);
        let total: f64 = own.iter().sum();
        let cut = if threads > 1 {
            (total / (16 * threads) as f64).max(sizes.min_task)
        } else {
            f64::INFINITY
        };
        let heavy: Vec<bool> = subtree.iter().map(|&w| w > cut).collect();
        let mut heavy_children = vec![0usize; ns];
        for &p in &parent {
            if p != NONE && heavy[p] {
                heavy_children[p] += 1;
            }
        }
        let (light_ptr, light_nodes) = light_tasks(&parent, &heavy);
        let parallel_split = (0..ns)
            .map(|s| {
                if threads > 1 && own[s] > sizes.parallel_node {
                    let list = &updaters[updater_ptr[s]..updater_ptr[s + 1]];
                    // Fits: the plan checked n ≤ u32::MAX.
                    balanced_split(sym, list, s) as u32
                } else {
                    0
                }
            })
            .collect();
        Some(SupernodalPlan {
            parent,
            updater_ptr,
            updaters,
            light_ptr,
            light_nodes,
            heavy_children,
            heavy,
            parallel_split,
            one_product_work: sizes.one_product_work,
            two_thread_llt: sizes.two_thread_llt,
        })
    }
}

/// The supernode of every column, in 32 bits (the plan checked that the columns fit): half
/// the pages and cache lines of `usize`, read once per row of every supernode's pattern.
fn block_of_columns(sym: Symbolic<'_>) -> Vec<u32> {
    let (begin, end) = (sym.supernode_begin(), sym.supernode_end());
    let mut block_of = vec![0u32; sym.nrows()];
    for s in 0..sym.n_supernodes() {
        block_of[begin[s]..end[s]].fill(s as u32);
    }
    block_of
}

/// Each supernode's parent (the supernode of its first off-diagonal row) and own work
/// Σ c_j² over its columns.
fn tree(sym: Symbolic<'_>, block_of: &[u32]) -> (Vec<usize>, Vec<f64>) {
    (0..sym.n_supernodes())
        .map(|s| {
            let pattern = sym.pattern(s);
            let width = sym.supernode_end()[s] - sym.supernode_begin()[s];
            let rows = (width + pattern.len()) as f64;
            let own: f64 = (0..width).map(|c| (rows - c as f64).powi(2)).sum();
            (pattern.first().map_or(NONE, |&r| block_of[r] as usize), own)
        })
        .unzip()
}

/// For every supernode s, the descendants d with a row in s's columns (ascending), in CSR
/// form: the supernodes that d's pattern touches.
fn updaters(sym: Symbolic<'_>, block_of: &[u32]) -> (Vec<usize>, Vec<u32>) {
    let ns = sym.n_supernodes();
    let touched = |d: usize| {
        let mut last = NONE;
        sym.pattern(d).iter().filter_map(move |&r| {
            let t = block_of[r] as usize;
            (t != last).then(|| {
                last = t;
                t
            })
        })
    };
    let mut ptr = vec![0usize; ns + 1];
    for d in 0..ns {
        for t in touched(d) {
            ptr[t + 1] += 1;
        }
    }
    for s in 0..ns {
        ptr[s + 1] += ptr[s];
    }
    let mut updaters = vec![0u32; ptr[ns]];
    let mut next = ptr.clone();
    for d in 0..ns {
        for t in touched(d) {
            // Fits: the plan checked n ≤ u32::MAX (and supernodes ≤ columns).
            updaters[next[t]] = d as u32;
            next[t] += 1;
        }
    }
    (ptr, updaters)
}

/// The light subtrees below heavy supernodes (or at the roots), each as its supernodes in
/// ascending order, in CSR form.
fn light_tasks(parent: &[usize], heavy: &[bool]) -> (Vec<usize>, Vec<u32>) {
    let ns = parent.len();
    // Each light supernode's task, named by the root of its light subtree.
    let mut task = vec![NONE; ns];
    for s in (0..ns).rev() {
        let p = parent[s];
        if !heavy[s] {
            task[s] = if p == NONE || heavy[p] { s } else { task[p] };
        }
    }
    let mut slot = vec![NONE; ns];
    let mut roots = 0;
    for s in 0..ns {
        if task[s] == s {
            slot[s] = roots;
            roots += 1;
        }
    }
    let mut ptr = vec![0usize; roots + 1];
    for &t in task.iter().filter(|&&t| t != NONE) {
        ptr[slot[t] + 1] += 1;
    }
    for k in 0..roots {
        ptr[k + 1] += ptr[k];
    }
    let mut nodes = vec![0u32; ptr[roots]];
    let mut next = ptr.clone();
    for (s, &t) in task.iter().enumerate().filter(|(_, &t)| t != NONE) {
        nodes[next[slot[t]]] = s as u32;
        next[slot[t]] += 1;
    }
    (ptr, nodes)
}

/// The values of L, written by one task per supernode and read by its ancestors' tasks.
struct SharedFactor<'a> {
    ptr: *mut f64,
    len: usize,
    _values: PhantomData<&'a mut [f64]>,
}

// SAFETY: access goes through `block` and `block_mut`, whose contracts exclude a read or write
// of a block while another task writes it.
unsafe impl Sync for SharedFactor<'_> {}
unsafe impl Send for SharedFactor<'_> {}

impl<'a> SharedFactor<'a> {
    fn new(values: &'a mut [f64]) -> Self {
        SharedFactor {
            ptr: values.as_mut_ptr(),
            len: values.len(),
            _values: PhantomData,
        }
    }

    /// The values `range`, to write.
    ///
    /// # Safety
    /// No other task reads or writes `range` while the borrow lives (bounds are checked).
    #[allow(clippy::mut_from_ref)]
    unsafe fn block_mut(&self, range: std::ops::Range<usize>) -> &mut [f64] {
        assert!(range.start <= range.end && range.end <= self.len);
        // SAFETY: in bounds; exclusivity is the caller's contract.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(range.start), range.len()) }
    }

    /// The values `range`, to read.
    ///
    /// # Safety
    /// No task writes `range` while the borrow lives (bounds are checked).
    unsafe fn block(&self, range: std::ops::Range<usize>) -> &[f64] {
        assert!(range.start <= range.end && range.end <= self.len);
        // SAFETY: in bounds; no concurrent writer is the caller's contract.
        unsafe { std::slice::from_raw_parts(self.ptr.add(range.start), range.len()) }
    }
}

/// Scratch of one task: the row positions of the supernode being factorized, the update
/// buffers, the dense Cholesky's stack.
#[derive(Default)]
struct Scratch {
    /// Each row's position in the supernode being factorized (its columns, then its
    /// pattern); written for that supernode's rows before it is gathered, of length n.
    position: Vec<u32>,
    buffers: UpdateBuffers,
    stack: Option<MemBuffer>,
    stack_dim: usize,
}

impl Scratch {
    /// The stack of faer's dense LLᵀ for a diagonal block of `width` columns (enough for
    /// [`llt_two_threads`]'s blocks too), grown when too small. faer asks for one column of
    /// `width` whatever the threads.
    fn stack_for(&mut self, width: usize) -> &mut MemStack {
        let width = width.max(dense_llt::BLOCK);
        if self.stack.is_none() || self.stack_dim < width {
            let req = cholesky_in_place_scratch::<f64>(width, Par::Seq, Spec::default());
            self.stack = Some(MemBuffer::new(req));
            self.stack_dim = width;
        }
        MemStack::new(self.stack.as_mut().expect("allocated above"))
    }
}

/// The scratch of a factorization's tasks, kept for the next factorization. Made anew each
/// time, L seed 1's four (50 MB: two position arrays of 3.7 MB, product buffers of up to
/// 19 MB) faulted 3,700 fresh pages in every factorization.
#[derive(Default)]
pub(crate) struct ScratchPool(Vec<Scratch>);

impl ScratchPool {
    /// Bytes held.
    pub(crate) fn bytes(&self) -> usize {
        self.0
            .iter()
            .map(|s| {
                4 * s.position.capacity()
                    + 8 * (s.buffers.local.capacity() + s.buffers.update.capacity())
                    + s.stack.as_ref().map_or(0, |b| b.len())
            })
            .sum()
    }
}

/// What one descendant's update works in: its rows' positions and the product block.
#[derive(Default)]
struct UpdateBuffers {
    local: Vec<usize>,
    update: Vec<f64>,
}

/// A read in the factor's order and scaled (S A S) where a supernode gathers it: column j of
/// the permuted lower triangle is A's column `fwd[j]`, its rows renumbered by `inv` and
/// those above j dropped (A stores both triangles), so no permuted copy of A exists.
#[derive(Clone, Copy)]
pub(crate) struct ScaledMatrix<'a> {
    /// A, with both triangles.
    pub(crate) a: CscRef<'a>,
    /// The factor's permutation, `fwd[new] = old` and `inv[old] = new`.
    pub(crate) fwd: &'a [usize],
    pub(crate) inv: &'a [usize],
    /// S in the factor's order.
    pub(crate) scale: &'a [f64],
}

impl ScaledMatrix<'_> {
    /// Adds column `j` (factor's order) of the lower triangle of P S A S Pᵀ into `dst`, the
    /// supernode's column that holds it, row i at `position[i]`; whether every value of A's
    /// column (both triangles) is finite. The gather is the only pass over A's values in a
    /// factorization, so it is where they are checked (on L seed 1 a separate pass took
    /// 14–16 ms of each factorization).
    fn add_column(&self, j: usize, position: &[u32], dst: &mut [f64]) -> bool {
        let (inv, scale) = (self.inv, self.scale);
        let sj = scale[j];
        let (rows, values) = self.a.col(self.fwd[j]);
        let mut finite = true;
        for (&r, &x) in rows.iter().zip(values) {
            finite &= x.is_finite();
            let i = inv[r];
            if i >= j {
                dst[position[i] as usize] += x * scale[i] * sj;
            }
        }
        finite
    }
}

/// A pivot of the scaled matrix at or below the tolerance: its column in the factor's order
/// and its value (0 when faer's dense kernel stopped at a non-positive one; NaN for a column
/// whose column of A holds a NaN or an infinity).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Pivot {
    pub(crate) index: usize,
    pub(crate) value: f64,
}

/// The failing pivot of the lowest column met by any task.
struct Failure {
    any: AtomicBool,
    first: Mutex<Option<Pivot>>,
}

impl Failure {
    fn record(&self, pivot: Pivot) {
        self.any.store(true, Ordering::Release);
        let mut f = self.first.lock().unwrap_or_else(|e| e.into_inner());
        if f.is_none_or(|g| pivot.index < g.index) {
            *f = Some(pivot);
        }
    }
}

/// What every task reads: the symbolic factor, A's lower triangle in the factor's order, the
/// plan, the factor being written and the failure flag.
struct Context<'a> {
    sym: Symbolic<'a>,
    a: ScaledMatrix<'a>,
    pivot_tolerance: f64,
    plan: &'a SupernodalPlan,
    values: SharedFactor<'a>,
    pending: Vec<AtomicUsize>,
    failure: Failure,
    threads: usize,
    /// Scratch of finished tasks, for the next ones (the caller's pool, given back at the
    /// end).
    scratch: Mutex<Vec<Scratch>>,
}

/// Factorizes S A S (`a`) into `values` (faer's supernodal layout of `sym`) on `threads`
/// threads. A pivot L_jj² at or below `pivot_tolerance` (the scaled diagonal being 1) is the
/// error, the lowest such column found. The tasks take their scratch from `pool` and put it
/// back.
pub(crate) fn factorize_llt(
    values: &mut [f64],
    a: ScaledMatrix<'_>,
    pivot_tolerance: f64,
    sym: Symbolic<'_>,
    plan: &SupernodalPlan,
    threads: usize,
    pool: &mut ScratchPool,
) -> Result<(), Pivot> {
    assert_eq!(values.len(), sym.len_val());
    let ctx = Context {
        sym,
        a,
        pivot_tolerance,
        plan,
        values: SharedFactor::new(values),
        pending: plan
            .heavy_children
            .iter()
            .map(|&c| AtomicUsize::new(c))
            .collect(),
        failure: Failure {
            any: AtomicBool::new(false),
            first: Mutex::new(None),
        },
        threads,
        scratch: Mutex::new(std::mem::take(&mut pool.0)),
    };
    if threads <= 1 {
        let mut scratch = ctx.take_scratch();
        for s in 0..sym.n_supernodes() {
            if let Err(k) = ctx.node(s, Par::Seq, &mut scratch) {
                ctx.failure.record(k);
                break;
            }
        }
        ctx.put_scratch(scratch);
    } else {
        rayon::scope(|scope| {
            for k in 0..plan.light_ptr.len() - 1 {
                let ctx = &ctx;
                let nodes = &plan.light_nodes[plan.light_ptr[k]..plan.light_ptr[k + 1]];
                scope.spawn(move |scope| ctx.light_task(scope, nodes));
            }
            for s in 0..sym.n_supernodes() {
                if plan.heavy[s] && plan.heavy_children[s] == 0 {
                    let ctx = &ctx;
                    scope.spawn(move |scope| ctx.heavy_task(scope, s));
                }
            }
        });
    }
    pool.0 = ctx.scratch.into_inner().unwrap_or_else(|e| e.into_inner());
    let first = ctx
        .failure
        .first
        .into_inner()
        .unwrap_or_else(|e| e.into_inner());
    match first {
        Some(pivot) => Err(pivot),
        None => Ok(()),
    }
}

impl<'a> Context<'a> {
    /// A light subtree (its supernodes, root last) on this thread, then its parent when it was
    /// the last child to finish.
    fn light_task<'s>(&'s self, scope: &rayon::Scope<'s>, nodes: &'s [u32]) {
        let mut scratch = self.take_scratch();
        for &s in nodes {
            if self.failure.any.load(Ordering::Acquire) {
                return;
            }
            if let Err(k) = self.node(s as usize, Par::Seq, &mut scratch) {
                self.failure.record(k);
                return;
            }
        }
        self.put_scratch(scratch);
        if let Some(&root) = nodes.last() {
            self.finished(scope, root as usize);
        }
    }

    /// The heavy supernode `s` (its children are done).
    fn heavy_task<'s>(&'s self, scope: &rayon::Scope<'s>, s: usize) {
        if self.failure.any.load(Ordering::Acquire) {
            return;
        }
        let par = if self.plan.parallel_split[s] > 0 {
            Par::rayon(self.threads)
        } else {
            Par::Seq
        };
        let mut scratch = self.take_scratch();
        if let Err(k) = self.node(s, par, &mut scratch) {
            self.failure.record(k);
            return;
        }
        self.put_scratch(scratch);
        self.finished(scope, s);
    }

    fn take_scratch(&self) -> Scratch {
        let mut pool = self.scratch.lock().unwrap_or_else(|e| e.into_inner());
        pool.pop().unwrap_or_default()
    }

    fn put_scratch(&self, scratch: Scratch) {
        let mut pool = self.scratch.lock().unwrap_or_else(|e| e.into_inner());
        pool.push(scratch);
    }

    /// Counts `s` off its parent's children and starts the parent after the last one.
    fn finished<'s>(&'s self, scope: &rayon::Scope<'s>, s: usize) {
        let p = self.plan.parent[s];
        // AcqRel: the parent's task sees every child's writes to the factor.
        if p != NONE && self.pending[p].fetch_sub(1, Ordering::AcqRel) == 1 {
            scope.spawn(move |scope| self.heavy_task(scope, p));
        }
    }

    /// The value range and shape (columns, rows) of supernode `s`.
    fn shape(&self, s: usize) -> (std::ops::Range<usize>, usize, usize, &'a [usize]) {
        let sym = self.sym;
        let (b, e) = (sym.supernode_begin()[s], sym.supernode_end()[s]);
        let pattern = sym.pattern(s);
        let values = sym.col_ptr_for_val()[s]..sym.col_ptr_for_val()[s + 1];
        (values, e - b, e - b + pattern.len(), pattern)
    }

    /// Supernode `s`: gather A, subtract the descendants' updates, factorize.
    fn node(&self, s: usize, par: Par, scratch: &mut Scratch) -> Result<(), Pivot> {
        let (range, width, rows, pattern) = self.shape(s);
        let begin = self.sym.supernode_begin()[s];
        // SAFETY: supernode s is written by this task only, and read by its ancestors' tasks,
        // which start after this one ends.
        let ls = unsafe { self.values.block_mut(range) };
        let position = &mut scratch.position;
        position.resize(self.sym.nrows(), 0);
        // Fits: the plan checked n ≤ u32::MAX.
        for (k, r) in (begin..begin + width)
            .chain(pattern.iter().copied())
            .enumerate()
        {
            position[r] = k as u32;
        }
        if par == Par::Seq || width < 2 {
            self.gather(ls, rows, begin, &scratch.position)?;
        } else {
            // The halves of the columns side by side: L's root clears and gathers 74 MB.
            let half = width / 2;
            let (left, right) = ls.split_at_mut(half * rows);
            let position = &scratch.position;
            let (first, second) = rayon::join(
                || self.gather(left, rows, begin, position),
                || self.gather(right, rows, begin + half, position),
            );
            first.and(second)?;
        }
        let mut l = MatMut::from_column_major_slice_mut(ls, rows, width);
        let (position, buffers) = (&scratch.position, &mut scratch.buffers);
        if par == Par::Seq || width < 2 {
            self.updates(l.rb_mut(), s, 0..width, position, buffers);
        } else {
            // Two column blocks of equal update work, each updated by every descendant on its
            // own thread.
            let split = self.plan.parallel_split[s] as usize;
            let (left, right) = l.rb_mut().split_at_col_mut(split);
            let mut other = self.take_scratch();
            rayon::join(
                || self.updates(left, s, 0..split, position, buffers),
                || self.updates(right, s, split..width, position, &mut other.buffers),
            );
            self.put_scratch(other);
        }
        let top = self.dense_step(l, par, scratch).map_err(|index| Pivot {
            index: begin + index,
            value: 0.0,
        })?;
        // faer accepts tiny positive pivots: judge them against the (unit) scaled diagonal.
        for c in 0..width {
            let pivot = top[(c, c)] * top[(c, c)];
            if !(pivot > self.pivot_tolerance) {
                return Err(Pivot {
                    index: begin + c,
                    value: pivot,
                });
            }
        }
        Ok(())
    }

    /// The dense step of a supernode held in `l` (its rows × its columns, updated): the
    /// diagonal block factorized and the rows below it solved against its transpose. On two
    /// threads a wide diagonal block goes to [`llt_two_threads`] and the rows below are solved
    /// in two halves; on more, faer's kernels take every thread. The diagonal block, or the
    /// column of a pivot that is not positive.
    fn dense_step<'l>(
        &self,
        l: MatMut<'l, f64>,
        par: Par,
        scratch: &mut Scratch,
    ) -> Result<MatRef<'l, f64>, usize> {
        let width = l.ncols();
        let (mut top, bottom) = l.split_at_row_mut(width);
        let two = self.threads == 2 && par != Par::Seq;
        let stack = scratch.stack_for(width);
        if two && width >= self.plan.two_thread_llt {
            llt_two_threads(top.rb_mut(), stack)?;
        } else {
            llt(top.rb_mut(), if two { Par::Seq } else { par }, stack)?;
        }
        if two {
            solve_below_two_threads(top.rb(), bottom);
        } else {
            solve_lower_triangular_in_place(top.rb(), bottom.transpose_mut(), par);
        }
        Ok(top.into_const())
    }

    /// Clears `block`, a supernode's columns from column `first` on (`rows` values each), and
    /// gathers A's columns into them, each row at its `position`.
    fn gather(
        &self,
        block: &mut [f64],
        rows: usize,
        first: usize,
        position: &[u32],
    ) -> Result<(), Pivot> {
        block.fill(0.0);
        for (j, column) in block.chunks_exact_mut(rows).enumerate() {
            // A's entries lie in the factor's pattern.
            if !self.a.add_column(first + j, position, column) {
                return Err(Pivot {
                    index: first + j,
                    value: f64::NAN,
                });
            }
        }
        Ok(())
    }

    /// Subtracts every descendant's update from the columns `cols` of supernode `s`, held in
    /// `l` (all of s's rows, those columns).
    fn updates(
        &self,
        mut l: MatMut<'_, f64>,
        s: usize,
        cols: Range<usize>,
        position: &[u32],
        buffers: &mut UpdateBuffers,
    ) {
        let (up, down) = (self.plan.updater_ptr[s], self.plan.updater_ptr[s + 1]);
        for &d in &self.plan.updaters[up..down] {
            self.update(l.rb_mut(), s, d as usize, cols.clone(), position, buffers);
        }
    }

    /// Subtracts descendant `d`'s update L_d,below L_d,midᵀ from the columns `cols` of
    /// supernode `s`, held in `l`.
    fn update(
        &self,
        l: MatMut<'_, f64>,
        s: usize,
        d: usize,
        cols: Range<usize>,
        position: &[u32],
        buffers: &mut UpdateBuffers,
    ) {
        let (range, d_width, d_rows, d_pattern) = self.shape(d);
        let begin = self.sym.supernode_begin()[s];
        // The rows of d in s's columns `cols`, and below them.
        let (p0, m) = rows_from(d_pattern, begin + cols.start..begin + cols.end);
        let rows = &d_pattern[p0..];
        if m == 0 {
            return;
        }
        // Their positions in s (d's pattern from s on lies in s's columns and pattern).
        let local = &mut buffers.local;
        local.clear();
        local.extend(rows.iter().map(|&r| position[r] as usize));
        // SAFETY: d is a descendant of s, whose task ended before this one started.
        let ld =
            MatRef::from_column_major_slice(unsafe { self.values.block(range) }, d_rows, d_width);
        let below = ld.subrows(d_width + p0, rows.len());
        let mid = below.subrows(0, m);
        let n = rows.len();
        let contiguous = local[n - 1] - local[0] + 1 == n;
        // A small top square goes with the rows below it in one product (see
        // [`TaskSizes::one_product_work`]); the scatter takes its lower trapezoid.
        let one_product = m * m * d_width <= self.plan.one_product_work;
        if contiguous && !one_product {
            let dst = l.submatrix_mut(local[0], local[0] - cols.start, n, m);
            lower_product(dst, below, mid, Accum::Add);
            return;
        }
        if buffers.update.len() < n * m {
            buffers.update.resize(n * m, 0.0);
        }
        let w = MatMut::from_column_major_slice_mut(&mut buffers.update[..n * m], n, m);
        if one_product {
            matmul(w, Accum::Replace, below, mid.transpose(), -1.0, Par::Seq);
        } else {
            lower_product(w, below, mid, Accum::Replace);
        }
        // Scatter the lower trapezoid of the product: column j of it goes to s's column
        // local[j], its rows i ≥ j to rows local[i].
        let w = &buffers.update[..n * m];
        let stride = l.col_stride() as usize;
        let (lrows, lcols) = (l.nrows(), l.ncols());
        let dst = l.as_ptr_mut();
        assert!(local[n - 1] < lrows && local[m - 1] - cols.start < lcols);
        if contiguous {
            let first = local[0];
            for j in 0..m {
                let col = (local[j] - cols.start) * stride;
                // SAFETY: rows first + j..first + n of that column are in l (checked above:
                // first + n − 1 = local[n − 1]), and l is column-major with this stride.
                let target =
                    unsafe { std::slice::from_raw_parts_mut(dst.add(first + j + col), n - j) };
                for (t, &x) in target.iter_mut().zip(&w[j + j * n..(j + 1) * n]) {
                    *t += x;
                }
            }
            return;
        }
        for j in 0..m {
            let col = (local[j] - cols.start) * stride;
            for i in j..n {
                // SAFETY: local is ascending, local[n - 1] < rows of l and local[m - 1] is in
                // its columns (checked above), and l is column-major with this stride.
                unsafe { *dst.add(local[i] + col) += w[i + j * n] };
            }
        }
    }
}

/// Where a descendant's ascending `pattern` reaches the target columns `columns` (its first
/// row there or below), and how many of its rows from there lie in them.
fn rows_from(pattern: &[usize], columns: Range<usize>) -> (usize, usize) {
    let first = pattern.partition_point(|&r| r < columns.start);
    let m = pattern[first..].partition_point(|&r| r < columns.end);
    (first, m)
}

/// The column at which the updates of supernode `s` by its descendants `updaters` split into
/// two halves of equal work, to within one column's (in 1..width, for a width of 2 or more):
/// a descendant of width k whose rows from s's first column on number n puts n − q entries,
/// k multiply-adds each, into the column of its q-th row. (Halves of equal area left the
/// updates of L seed 1's root at 0.085 s on one thread and 0.15–0.2 s on the other; now
/// 0.115–0.135 s each.)
fn balanced_split(sym: Symbolic<'_>, updaters: &[u32], s: usize) -> usize {
    let (begin, end) = (sym.supernode_begin()[s], sym.supernode_end()[s]);
    let mut work = vec![0.0f64; end - begin];
    for &d in updaters {
        let d = d as usize;
        let k = sym.supernode_end()[d] - sym.supernode_begin()[d];
        let pattern = sym.pattern(d);
        let (p0, m) = rows_from(pattern, begin..end);
        let rows = &pattern[p0..];
        for (q, &r) in rows[..m].iter().enumerate() {
            work[r - begin] += ((rows.len() - q) * k) as f64;
        }
    }
    // The first column that takes the left block past half its work ends the left block
    // (or starts the right one, whichever is nearer even).
    let half = work.iter().sum::<f64>() / 2.0;
    let mut done = 0.0;
    let mut split = work.len();
    for (c, w) in work.iter().enumerate() {
        if done + w >= half {
            split = if done + w - half <= half - done {
                c + 1
            } else {
                c
            };
            break;
        }
        done += w;
    }
    split.clamp(1, work.len().saturating_sub(1).max(1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_matrices::grid;
    use faer::linalg::cholesky::llt::factor::{LltError, LltRegularization};
    use faer::sparse::linalg::cholesky::{
        factorize_symbolic_cholesky, supernodal, supernodal::SymbolicSupernodalCholesky,
        CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
    };
    use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
    use faer::Side;
    use fibercell_solver::{permuted_diagonal_scale, CscMatrix, LowerTriangle};

    /// A matrix with its lower triangle in the factor's order (AMD, supernodal), the scale in
    /// that order and the scaled values as a copy for faer's kernel.
    struct Case {
        a: CscMatrix,
        lower: LowerTriangle,
        fwd: Vec<usize>,
        inv: Vec<usize>,
        scale: Vec<f64>,
        scaled: Vec<f64>,
        sym: SymbolicCholesky<usize>,
    }

    impl Case {
        fn new(a: CscMatrix) -> Self {
            let n = a.as_ref().ncols();
            let full = LowerTriangle::of(a.as_ref());
            let pattern =
                SymbolicSparseColMatRef::new_checked(n, n, &full.col_ptr, None, &full.row_idx);
            let params = CholeskySymbolicParams {
                supernodal_flop_ratio_threshold:
                    faer::sparse::linalg::SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            };
            let sym =
                factorize_symbolic_cholesky(pattern, Side::Lower, SymmetricOrdering::Amd, params)
                    .unwrap();
            let (fwd, inv) = sym.perm().unwrap().arrays();
            let lower = full.permuted(inv);
            let mut by_old = vec![0.0; n];
            let mut scaled = vec![0.0; lower.nnz()];
            lower
                .scaled_permuted_values(a.as_ref(), fwd, &mut by_old, &mut scaled)
                .unwrap();
            let scale = permuted_diagonal_scale(a.as_ref(), fwd, &mut by_old).unwrap();
            let (fwd, inv) = (fwd.to_vec(), inv.to_vec());
            Case {
                a,
                lower,
                fwd,
                inv,
                scale,
                scaled,
                sym,
            }
        }

        fn faer_supernodal(&self) -> &SymbolicSupernodalCholesky<usize> {
            match self.sym.raw() {
                SymbolicCholeskyRaw::Supernodal(sn) => sn,
                SymbolicCholeskyRaw::Simplicial(_) => panic!("forced supernodal"),
            }
        }

        fn supernodal(&self) -> Symbolic<'_> {
            SupernodesRef::of_faer(self.faer_supernodal())
        }

        /// faer's sequential supernodal kernel on the scaled copy.
        fn faer_llt(&self) -> Result<Vec<f64>, LltError> {
            let sn = self.faer_supernodal();
            let n = sn.nrows();
            let lower = &self.lower;
            let a = SparseColMatRef::new(
                SymbolicSparseColMatRef::new_checked(n, n, &lower.col_ptr, None, &lower.row_idx),
                &self.scaled[..],
            );
            let mut l = vec![0.0; sn.len_val()];
            let req = supernodal::factorize_supernodal_numeric_llt_scratch::<usize, f64>(
                sn,
                Par::Seq,
                Spec::default(),
            );
            let mut mem = MemBuffer::new(req);
            supernodal::factorize_supernodal_numeric_llt(
                &mut l,
                a,
                LltRegularization::default(),
                sn,
                Par::Seq,
                MemStack::new(&mut mem),
                Spec::default(),
            )?;
            Ok(l)
        }

        /// This module's kernel, reading A scaled.
        fn ours(&self, threads: usize, sizes: TaskSizes) -> Result<Vec<f64>, Pivot> {
            self.ours_with(threads, sizes, &mut ScratchPool::default())
        }

        /// The same, the tasks' scratch taken from and put back into `pool`.
        fn ours_with(
            &self,
            threads: usize,
            sizes: TaskSizes,
            pool: &mut ScratchPool,
        ) -> Result<Vec<f64>, Pivot> {
            let sn = self.supernodal();
            let plan =
                SupernodalPlan::new(sn, threads, sizes).expect("an elimination tree's numbering");
            let a = ScaledMatrix {
                a: self.a.as_ref(),
                fwd: &self.fwd,
                inv: &self.inv,
                scale: &self.scale,
            };
            let mut l = vec![0.0; sn.len_val()];
            factorize_llt(&mut l, a, 1e-12, sn, &plan, threads, pool)?;
            Ok(l)
        }
    }

    /// Cuts small enough that a 10³ grid has light subtrees, heavy supernodes and supernodes
    /// whose updates are split over two threads, whose diagonal blocks go to
    /// [`llt_two_threads`].
    const TINY: TaskSizes = TaskSizes {
        min_task: 1e3,
        parallel_node: 1e4,
        one_product_work: 1 << 14,
        two_thread_llt: 8,
    };

    /// The same, every diagonal block on one thread.
    const TINY_ONE_THREAD_LLT: TaskSizes = TaskSizes {
        two_thread_llt: usize::MAX,
        ..TINY
    };

    /// The default sizes with every update one product, or none.
    fn products(one_product_work: usize) -> TaskSizes {
        TaskSizes {
            one_product_work,
            ..TaskSizes::default()
        }
    }

    #[test]
    fn every_schedule_gives_faers_factor() {
        let case = Case::new(grid(10));
        let reference = case.faer_llt().unwrap();
        let scale = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (threads, sizes) in [
            (1, TaskSizes::default()),
            (2, TaskSizes::default()),
            (2, TINY),
            (2, TINY_ONE_THREAD_LLT),
            (3, TINY),
            (1, products(0)),
            (1, products(usize::MAX)),
            (2, products(usize::MAX)),
        ] {
            let l = case.ours(threads, sizes).unwrap();
            // Same operations in another order of the sums: agreement to rounding.
            let diff = l
                .iter()
                .zip(&reference)
                .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
            assert!(
                diff <= 1e-13 * scale,
                "threads {threads} {sizes:?}: {diff:e} of {scale:e}"
            );
        }
        let plan = SupernodalPlan::new(case.supernodal(), 2, TINY).unwrap();
        assert!(plan.heavy.iter().any(|&h| h) && plan.light_ptr.len() > 2);
        assert!(plan.parallel_split.iter().any(|&p| p > 0));
    }

    /// A value that is not finite in the last column, which a parallel root gathers in the
    /// second half of its columns, is reported at that column: an upper-triangle entry, so
    /// nothing but the gather's check sees it (the factor would come out finite).
    #[test]
    fn a_nan_in_a_parallel_supernodes_second_half_is_reported() {
        let mut case = Case::new(grid(10));
        let n = case.fwd.len();
        let plan = SupernodalPlan::new(case.supernodal(), 2, TINY).unwrap();
        let root = case.supernodal().n_supernodes() - 1;
        assert!(plan.parallel_split[root] > 0, "the root is not parallel");
        let column = case.fwd[n - 1];
        let a = case.a.as_ref();
        let k = (a.col_ptr()[column]..a.col_ptr()[column + 1])
            .find(|&k| a.row_idx()[k] != column)
            .unwrap();
        case.a.values_mut()[k] = f64::NAN;
        for (threads, sizes) in [(2, TINY), (1, TaskSizes::default())] {
            match case.ours(threads, sizes) {
                Err(p) => {
                    assert_eq!(p.index, n - 1, "threads {threads}");
                    assert!(p.value.is_nan());
                }
                Ok(_) => panic!("threads {threads}: a NaN went unreported"),
            }
        }
    }

    /// A parallel supernode's two column blocks carry equal update work, counted here entry by
    /// entry: descendant d of width k puts k multiply-adds into every entry (i, j) of its
    /// product with j in s's columns and i at or below j. The halves differ by at most one
    /// column's work.
    #[test]
    fn the_parallel_updates_split_into_equal_work() {
        let case = Case::new(grid(10));
        let sym = case.supernodal();
        let plan = SupernodalPlan::new(sym, 2, TINY).unwrap();
        let mut tested = 0;
        for s in (0..sym.n_supernodes()).filter(|&s| plan.parallel_split[s] > 0) {
            let (begin, end) = (sym.supernode_begin()[s], sym.supernode_end()[s]);
            let mut work = vec![0usize; end - begin];
            for &d in &plan.updaters[plan.updater_ptr[s]..plan.updater_ptr[s + 1]] {
                let d = d as usize;
                let k = sym.supernode_end()[d] - sym.supernode_begin()[d];
                let rows: Vec<usize> = sym
                    .pattern(d)
                    .iter()
                    .copied()
                    .filter(|&r| r >= begin)
                    .collect();
                for (b, &j) in rows.iter().enumerate().filter(|(_, &j)| j < end) {
                    for _ in &rows[b..] {
                        work[j - begin] += k;
                    }
                }
            }
            if end - begin < 2 || work.iter().all(|&w| w == 0) {
                continue;
            }
            let split = plan.parallel_split[s] as usize;
            let (left, right): (usize, usize) =
                (work[..split].iter().sum(), work[split..].iter().sum());
            let widest = *work.iter().max().unwrap();
            assert!(
                left.abs_diff(right) <= widest,
                "supernode {s}: {left} against {right} (columns at most {widest})"
            );
            tested += 1;
        }
        assert!(tested > 0);
    }

    /// A pool kept from a factorization of another matrix (a larger grid: longer position
    /// arrays, larger buffers, stale values in both) gives the same factor bit for bit as
    /// fresh scratch, and holds the scratch afterwards.
    #[test]
    fn a_kept_scratch_pool_gives_the_same_factor() {
        let mut pool = ScratchPool::default();
        Case::new(grid(12)).ours_with(2, TINY, &mut pool).unwrap();
        assert!(pool.bytes() > 0);
        let case = Case::new(grid(10));
        for threads in [1, 2] {
            let fresh = case.ours(threads, TINY).unwrap();
            let kept = case.ours_with(threads, TINY, &mut pool).unwrap();
            assert!(fresh
                .iter()
                .zip(&kept)
                .all(|(x, y)| x.to_bits() == y.to_bits()));
            assert!(pool.bytes() > 0);
        }
    }

    #[test]
    fn a_failing_pivot_is_reported_at_its_column() {
        // An indefinite matrix: the grid with one diagonal entry a thousandth of its row's
        // off-diagonal sum (positive, so the scaling passes).
        let mut a = grid(6);
        let old = 100;
        let k = (a.as_ref().col_ptr()[old]..a.as_ref().col_ptr()[old + 1])
            .find(|&k| a.as_ref().row_idx()[k] == old)
            .unwrap();
        a.values_mut()[k] *= 1e-3;
        let case = Case::new(a);
        let expected = match case.faer_llt() {
            Err(LltError::NonPositivePivot { index }) => index,
            Ok(_) => panic!("faer factorized an indefinite matrix"),
        };
        for (threads, sizes) in [
            (1, TaskSizes::default()),
            (2, TINY),
            (2, TINY_ONE_THREAD_LLT),
        ] {
            match case.ours(threads, sizes) {
                Err(p) => assert_eq!(p.index, expected, "threads {threads}"),
                Ok(_) => panic!("threads {threads}: factorized an indefinite matrix"),
            }
        }
    }
}
