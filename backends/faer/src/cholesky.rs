//! Sparse Cholesky through faer with the symbolic analysis kept across factorizations.
//!
//! The matrix is factorized in the symmetrically scaled form S A S with S = diag(a_jj)^(-1/2),
//! so every pivot can be judged relative to its own diagonal entry: a pivot below
//! `pivot_tolerance` is reported as [`SolverError::NotPositiveDefinite`] at the original column,
//! which is how a mechanism (a fiber held by nothing) shows up instead of a garbage solution.

use crate::block_kernels::SolveSchedule;
use crate::block_solve::{backward_in_place, forward_in_place, solve_in_place as block_solve};
use crate::block_solve_many::{solve_many_in_place, FactorBlocks};
use crate::block_tree::{BlockTree, FactorView};
use crate::permute;
use crate::pivots::{factor_diagonal, fill_and_flops, is_simplicial};
use crate::prefault::{PrefaultedValues, PREFAULT_BYTES};
use crate::supernodal_llt::{self, ScaledMatrix, ScratchPool, SupernodalPlan, TaskSizes};
use crate::supernodes::Supernodes;
use crate::symbolic::{internal, supernodal_fill, supernodal_of_node_tree, Raw, Symbolic};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::cholesky::llt::factor::{LltError, LltRegularization};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, supernodal, CholeskySymbolicParams, LdltRef, LltRef,
    SymbolicCholesky, SymmetricOrdering,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side, Spec};
use fibercell_solver::{
    compute_ordering, AnalyzeInfo, Capabilities, CscRef, DiagonalEntries, FillEstimate,
    FillOrdering, ForwardColumns, LinearSolver, LowerTriangle, NodeGraph, NodeTree,
    PatternFingerprint, Permutation, SolveInfo, SolverError,
};
use std::sync::{Arc, OnceLock};

/// LLᵀ or LDLᵀ (no square roots; same sparsity).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CholeskyVariant {
    /// L Lᵀ.
    #[default]
    Llt,
    /// L D Lᵀ with unit L.
    Ldlt,
}

/// faer sparse Cholesky for symmetric positive definite matrices (both triangles stored; each
/// entry is read once, from the lower triangle of A in the factor's order for the task-parallel
/// LLᵀ and of A itself for faer's kernels).
pub struct FaerCholesky {
    variant: CholeskyVariant,
    ordering: FillOrdering,
    pivot_tolerance: f64,
    par: Par,
    /// Shared with the solvers [`LinearSolver::share`] made (read-only).
    analysis: Option<Arc<Analysis>>,
    /// Shared likewise; a `factorize` reuses it only while no other solver holds it.
    factor: Option<Arc<Factor>>,
    /// Workspace of the numeric factorization, sized once per analysis; kept between
    /// factorizations up to [`KEPT_WORKSPACE_BYTES`].
    workspace: Option<Workspace>,
    /// The task-parallel LLᵀ's scratch, kept likewise.
    task_scratch: ScratchPool,
    /// One right-hand side in the factor's order, kept between solves.
    work: Vec<f64>,
    /// Factors of at least this many bytes get a prefaulted first buffer.
    prefault_bytes: usize,
    /// LLᵀ factors of at least this many entries take this crate's supernodes.
    own_supernodes_from: usize,
    /// The first factorization's value buffer, mapped since the analysis began.
    prefaulted: Option<PrefaultedValues>,
}

struct Analysis {
    n: usize,
    fingerprint: PatternFingerprint,
    /// The permutation of the factor (`fwd[new] = old`, `inv[old] = new`): faer factorizes
    /// with it, and a solve reads x[new] = b[fwd[new]].
    perm: Permutation,
    symbolic: Symbolic,
    /// The block tree of L for sparse forward solves.
    tree: BlockTree,
    /// Its blocks per thread for solves with one right-hand side.
    schedule: SolveSchedule,
    /// Which numeric kernel factorizes, with what it reads.
    kernel: Kernel,
    /// Where A's diagonal entries lie, found by the task kernel's first factorization and
    /// read by the next ones for the scale.
    diagonal: OnceLock<DiagonalEntries>,
}

impl Analysis {
    /// Whether an LLᵀ factor is solved by this crate's block solves: a factor split over the
    /// threads, and every factor on this crate's supernodes.
    fn block_solves(&self) -> bool {
        self.schedule.is_parallel() || self.symbolic.is_ours()
    }
}

/// The numeric kernel of an analysis.
enum Kernel {
    /// A supernodal LLᵀ: this crate's task-parallel kernel on its plan, gathering each
    /// supernode's columns from A itself.
    Tasks(SupernodalPlan),
    /// faer's kernel (LDLᵀ, a simplicial factor, a tree the plan cannot take) on a scaled
    /// copy of A's lower triangle of this pattern: in the factor's order for a supernodal
    /// factor (factorized as it is), else in A's (faer permutes it).
    Faer(LowerTriangle),
}

struct Factor {
    l_values: Vec<f64>,
    scale: Vec<f64>,
}

/// What a numeric factorization works in: faer's scratch and the scaled lower triangle it
/// factorizes.
struct Workspace {
    scratch: MemBuffer,
    lower_values: Vec<f64>,
}

impl Workspace {
    fn bytes(&self) -> usize {
        self.scratch.len() + self.lower_values.len() * size_of::<f64>()
    }
}

/// A factorization's workspace up to this size is kept for the next one; a larger one is
/// given back once the factor is made. On the L non-woven (n = 934,683) it is the scaled
/// lower triangle (0.12 GB) and faer's scratch — 0.37 GB before the triangle was kept in the
/// factor's order — which a kept workspace would hold through every low-rank solve in
/// between. Getting it again is estimated below 2 % of a factorization (page faults of the
/// fresh pages against 5·10¹⁰ flops in 4–6 s); it was not timed apart.
const KEPT_WORKSPACE_BYTES: usize = 64 << 20;

/// LLᵀ factors with at least this many entries, ordered on the node graph, take this crate's
/// supernodes ([`Supernodes::of_node_tree`]) instead of faer's supernodal step: their solves
/// are this crate's block solves anyway (`block_kernels::PARALLEL_VALUES`), and there faer's
/// step costs most (0.06–0.36 s on the L non-woven). Smaller factors keep faer's structure
/// for faer's solves, which are faster on a factor that fits in cache.
const OWN_SUPERNODES_FROM: usize = 1 << 20;

impl Default for FaerCholesky {
    fn default() -> Self {
        Self::new(CholeskyVariant::Llt, FillOrdering::Auto)
    }
}

/// The LLᵀ factor `f` of the analysis `an` as the solves read it.
fn factor_view<'a>(an: &'a Analysis, f: &'a Factor) -> FactorView<'a> {
    FactorView {
        symbolic: &an.symbolic,
        values: &f.l_values,
        inv: &an.perm.inv,
        scale: &f.scale,
    }
}

impl FaerCholesky {
    /// A solver with the given variant and ordering, relative pivot tolerance 1e-12 and all
    /// rayon threads.
    pub fn new(variant: CholeskyVariant, ordering: FillOrdering) -> Self {
        FaerCholesky {
            variant,
            ordering,
            pivot_tolerance: 1e-12,
            par: Par::rayon(0),
            analysis: None,
            factor: None,
            workspace: None,
            task_scratch: ScratchPool::default(),
            work: Vec::new(),
            prefault_bytes: PREFAULT_BYTES,
            own_supernodes_from: OWN_SUPERNODES_FROM,
            prefaulted: None,
        }
    }

    /// Prefaults the first factor's buffer from `bytes` of predicted values on (tests).
    #[cfg(test)]
    pub(crate) fn with_prefault_bytes(mut self, bytes: usize) -> Self {
        self.prefault_bytes = bytes;
        self
    }

    /// Builds this crate's supernodes for LLᵀ factors from `entries` of L on (tests).
    #[cfg(test)]
    pub(crate) fn with_own_supernodes_from(mut self, entries: usize) -> Self {
        self.own_supernodes_from = entries;
        self
    }

    /// Pivots of the diagonally scaled matrix below this are rejected (default 1e-12).
    pub fn with_pivot_tolerance(mut self, tol: f64) -> Self {
        self.pivot_tolerance = tol;
        self
    }

    /// Whether the current analysis chose faer's supernodal factor (tests).
    #[cfg(test)]
    pub(crate) fn is_supernodal(&self) -> Option<bool> {
        self.analysis.as_ref().map(|a| !is_simplicial(&a.symbolic))
    }

    /// The symbolic factor, L's values, the inverse permutation and the scaling (tests).
    #[cfg(test)]
    pub(crate) fn factor_view(&self) -> FactorView<'_> {
        let (an, f) = self.llt_parts().expect("an LLᵀ factor");
        factor_view(an, f)
    }

    /// The analysis and an LLᵀ factor, for the half and sparse solves.
    fn llt_parts(&self) -> Result<(&Analysis, &Factor), SolverError> {
        let (an, f) = match (&self.analysis, &self.factor) {
            (Some(a), Some(f)) => (a, f),
            _ => return Err(SolverError::OutOfOrder("solve", "factorize")),
        };
        if self.variant != CholeskyVariant::Llt {
            return Err(SolverError::Unavailable {
                backend: "faer-cholesky",
                reason: "half and sparse solves need the LLᵀ variant".into(),
            });
        }
        Ok((an, f))
    }

    /// `x` ← L⁻¹ P Ŝ x by `forward` on x in the factor's order (in the solver's work buffer),
    /// which may compute more; `x` is left as it was when `forward` fails.
    fn lower_half<T>(
        &mut self,
        x: &mut [f64],
        forward: impl FnOnce(&Analysis, &Factor, &mut [f64]) -> Result<T, SolverError>,
    ) -> Result<T, SolverError> {
        let mut y = std::mem::take(&mut self.work);
        let (an, f) = self.llt_parts()?;
        <dyn LinearSolver>::check_rhs(an.n, x, 1)?;
        let parallel = an.schedule.is_parallel();
        y.resize(an.n, 0.0);
        permute::into_factor_order(x, &f.scale, &an.perm.fwd, &mut y, parallel);
        let out = forward(an, f, &mut y);
        if out.is_ok() {
            permute::copy(&y, x, parallel);
        }
        self.work = y;
        out
    }

    /// Runs single-threaded.
    pub fn sequential(mut self) -> Self {
        self.par = Par::Seq;
        self
    }

    /// The fill-reducing permutation of `a` (checked here structurally symmetric), its name and,
    /// for an ordering made on the node graph (AMD, nested dissection, Auto: the one with
    /// fewer flops predicted there), the graph with the order's tree and fill — the factor's
    /// exact structure.
    fn permutation(
        &self,
        a: CscRef<'_>,
    ) -> Result<(Permutation, String, Option<NodeOrder>), SolverError> {
        match &self.ordering {
            o @ (FillOrdering::Auto | FillOrdering::Amd | FillOrdering::NestedDissection) => {
                let graph = NodeGraph::of(a)?;
                let ordered = graph.ordered(o)?;
                let name = match o {
                    FillOrdering::Auto => format!("auto→{}", ordered.chosen.name()),
                    o => o.name().to_string(),
                };
                let order = NodeOrder {
                    graph,
                    tree: ordered.tree,
                    fill: ordered.fill,
                };
                Ok((ordered.permutation, name, Some(order)))
            }
            o => {
                a.check_structurally_symmetric()?;
                Ok((compute_ordering(a, o)?, o.name().to_string(), None))
            }
        }
    }

    /// The symbolic factor of `a` under `perm`: where the ordering was made on the node graph
    /// and the factor is supernodal, this crate's supernodes for a large LLᵀ factor and faer's
    /// supernodal step on the node tree for the rest; else faer's own analysis.
    fn symbolic(
        &self,
        a: CscRef<'_>,
        perm: &Permutation,
        order: Option<&NodeOrder>,
    ) -> Result<Symbolic, SolverError> {
        if let Some(o) = order.filter(|o| supernodal_fill(&o.fill)) {
            let large = o.fill.nnz_l >= self.own_supernodes_from;
            return if self.variant == CholeskyVariant::Llt && large {
                Supernodes::of_node_tree(&o.graph, &o.tree).map(Symbolic::Nodes)
            } else {
                supernodal_of_node_tree(&o.graph, &o.tree).map(Symbolic::Supernodal)
            };
        }
        // faer reads the lower triangle of the pattern it is given (its entries with row ≥
        // column), so A's own pattern serves.
        let n = a.ncols();
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, a.col_ptr(), None, a.row_idx());
        self.symbolic_for(pattern, perm).map(Symbolic::Faer)
    }

    fn symbolic_for(
        &self,
        lower: SymbolicSparseColMatRef<'_, usize>,
        perm: &Permutation,
    ) -> Result<SymbolicCholesky<usize>, SolverError> {
        let n = perm.fwd.len();
        let p = PermRef::new_checked(&perm.fwd, &perm.inv, n);
        factorize_symbolic_cholesky(
            lower,
            Side::Lower,
            SymmetricOrdering::Custom(p),
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| SolverError::Backend {
            backend: "faer-cholesky",
            code: -1,
            message: format!("symbolic factorization failed: {e:?}"),
        })
    }
}

/// An ordering made on the node graph: the graph, the order's elimination tree and its fill.
struct NodeOrder {
    graph: NodeGraph,
    tree: NodeTree,
    fill: FillEstimate,
}

/// Factor values × right-hand sides below which a solve stays on the calling thread (about
/// 100 µs of work; waking another thread costs microseconds).
const PARALLEL_SOLVE_VALUES: usize = 1 << 18;

/// The task-parallel supernodal LLᵀ of S A S into `f`, A's columns gathered where each
/// supernode reads them.
fn factorize_with_tasks(
    an: &Analysis,
    plan: &SupernodalPlan,
    a: CscRef<'_>,
    mut f: Factor,
    pivot_tolerance: f64,
    par: Par,
    pool: &mut ScratchPool,
) -> Result<Factor, SolverError> {
    let Some(sn) = an.symbolic.supernodal() else {
        return Err(SolverError::Backend {
            backend: "faer-cholesky",
            code: -3,
            message: "a task plan without a supernodal factor (an internal error)".into(),
        });
    };
    // The pattern is the analysis's (its fingerprint was checked).
    let diagonal = an.diagonal.get_or_init(|| DiagonalEntries::of(a));
    let scale = diagonal.permuted_scale(a, &an.perm.fwd, &mut f.scale)?;
    let scaled = ScaledMatrix {
        a,
        fwd: &an.perm.fwd,
        inv: &an.perm.inv,
        scale: &scale,
    };
    supernodal_llt::factorize_llt(
        &mut f.l_values,
        scaled,
        pivot_tolerance,
        sn,
        plan,
        threads(par),
        pool,
    )
    .map_err(|p| pivot_error(an.perm.fwd[p.index], p.value))?;
    Ok(f)
}

/// Threads of `par`.
fn threads(par: Par) -> usize {
    match par {
        Par::Seq => 1,
        Par::Rayon(t) => t.get(),
    }
}

/// The column groups of `x` (n rows, `per_group` columns each) through `solve`, side by side
/// when `parallel`, each with its own `scratch(columns)` workspace.
fn solve_groups(
    x: &mut [f64],
    (n, per_group): (usize, usize),
    parallel: bool,
    scratch: impl Fn(usize) -> StackReq + Sync,
    solve: impl Fn(MatMut<'_, f64>, &mut MemStack) + Sync,
) -> Result<(), SolverError> {
    let group = |block: &mut [f64]| -> Result<(), SolverError> {
        let k = block.len() / n;
        let mut buf = MemBuffer::try_new(scratch(k)).map_err(|_| SolverError::OutOfMemory)?;
        solve(
            MatMut::from_column_major_slice_mut(block, n, k),
            MemStack::new(&mut buf),
        );
        Ok(())
    };
    if parallel {
        use rayon::prelude::*;
        x.par_chunks_mut(per_group * n).try_for_each(group)
    } else {
        group(x)
    }
}

fn pivot_error(column: usize, pivot: f64) -> SolverError {
    SolverError::NotPositiveDefinite { column, pivot }
}

impl LinearSolver for FaerCholesky {
    fn name(&self) -> &'static str {
        "faer-cholesky"
    }

    fn capabilities(&self) -> Capabilities {
        Capabilities::DIRECT_SPD
    }

    fn analyze(&mut self, a: CscRef<'_>) -> Result<AnalyzeInfo, SolverError> {
        self.factor = None;
        self.analysis = None;
        self.workspace = None;
        self.task_scratch = ScratchPool::default();
        self.prefaulted = None;
        let n = a.ncols();
        // Every ordering's L holds A's lower triangle and the whole diagonal: at least
        // (nnz(A) + n) / 2 values, mapped from now on (dropped, so stopped, on an error).
        let prefault = PrefaultedValues::start((a.nnz() + n) / 2, self.prefault_bytes);
        // The pattern's symmetry is checked with the ordering (on the nodes where it is made
        // on the node graph). The values' check and the pattern's fingerprint read other
        // arrays on the thread that the ordering's sequential steps leave idle (on L: the
        // pre-elimination, METIS's top separator, the order's tree, 0.16 s; the two took 0.03 s
        // before and after it).
        let (order, (checked, fingerprint)) = rayon::join(
            || self.permutation(a),
            || (<dyn LinearSolver>::check_matrix(a, None), a.fingerprint()),
        );
        checked?;
        let (perm, name, order) = order?;
        let fill = order.as_ref().map(|o| o.fill);
        if let (Some(p), Some(f)) = (&prefault, fill) {
            p.aim(f.nnz_l);
        }
        let symbolic = self.symbolic(a, &perm, order.as_ref())?;
        if let Some(p) = &prefault {
            p.aim(symbolic.len_val());
        }
        drop(order);
        // faer's supernodes store explicit zeros where they were relaxed; nnz(L) and the
        // flops are the structure's (from the node graph, else faer's column counts).
        let (nnz_l, flops) = fill.map_or_else(|| fill_and_flops(&symbolic), |f| (f.nnz_l, f.flops));
        let info = AnalyzeInfo {
            n,
            nnz_a: a.nnz(),
            nnz_factor: Some(nnz_l),
            factor_bytes: Some(8 * symbolic.len_val()),
            flops: Some(flops),
            ordering: name,
        };
        // faer's own symbolic factor keeps the permutation it was given (or none for the
        // identity), so the factor's order is `perm` for every kind.
        if let Symbolic::Faer(s) = &symbolic {
            debug_assert!(match s.perm() {
                Some(p) => p.arrays().0 == perm.fwd.as_slice(),
                None => perm.fwd.iter().enumerate().all(|(new, &old)| new == old),
            });
        }
        // The block tree and its solve schedule beside the task plan (on L 9–16 ms and 17–22 ms).
        let threads = threads(self.par);
        let ((tree, schedule), plan) = rayon::join(
            || {
                let tree = BlockTree::of(&symbolic);
                let schedule = SolveSchedule::new(&tree, threads);
                (tree, schedule)
            },
            || match (self.variant, symbolic.raw()) {
                (CholeskyVariant::Llt, Raw::Supernodal(sn)) => {
                    SupernodalPlan::new(sn, threads, TaskSizes::default())
                }
                _ => None,
            },
        );
        if plan.is_none() && symbolic.is_ours() {
            // Only past 2³² columns, which no factor in memory reaches.
            return Err(internal("no task plan for this crate's supernodes"));
        }
        let kernel = match plan {
            Some(plan) => Kernel::Tasks(plan),
            None if is_simplicial(&symbolic) => Kernel::Faer(LowerTriangle::of(a)),
            None => Kernel::Faer(LowerTriangle::of(a).permuted(&perm.inv)),
        };
        self.analysis = Some(Arc::new(Analysis {
            n,
            fingerprint,
            perm,
            schedule,
            tree,
            symbolic,
            kernel,
            diagonal: OnceLock::new(),
        }));
        self.prefaulted = prefault;
        Ok(info)
    }

    fn factorize(&mut self, a: CscRef<'_>) -> Result<(), SolverError> {
        let an = self
            .analysis
            .as_ref()
            .ok_or(SolverError::OutOfOrder("factorize", "analyze"))?;
        // The task kernel checks the values where it gathers them.
        match an.kernel {
            Kernel::Tasks(_) => <dyn LinearSolver>::check_order(a, Some(an.n))?,
            Kernel::Faer(_) => <dyn LinearSolver>::check_matrix(a, Some(an.n))?,
        }
        if a.fingerprint() != an.fingerprint {
            return Err(SolverError::PatternChanged);
        }
        let n = an.n;
        // Reuse the buffers of the previous factorization when no shared solver holds them.
        let mut f = match self.factor.take().and_then(|f| Arc::try_unwrap(f).ok()) {
            Some(f) => f,
            None => Factor {
                l_values: self.prefaulted.take().map_or_else(
                    || vec![0.0; an.symbolic.len_val()],
                    |p| p.take(an.symbolic.len_val()),
                ),
                scale: vec![0.0; n],
            },
        };
        let lower = match &an.kernel {
            Kernel::Faer(lower) => lower,
            Kernel::Tasks(plan) => {
                let mut pool = std::mem::take(&mut self.task_scratch);
                let f =
                    factorize_with_tasks(an, plan, a, f, self.pivot_tolerance, self.par, &mut pool);
                if pool.bytes() <= KEPT_WORKSPACE_BYTES {
                    self.task_scratch = pool;
                }
                // Any failure may come from a value that is not finite (the kernel stops at
                // the first it meets, or at a pivot it spoilt, or the scale at a diagonal):
                // the first such value is the error, as `check_matrix` reports it.
                let f = f.map_err(|e| <dyn LinearSolver>::non_finite_error(a).unwrap_or(e))?;
                self.factor = Some(Arc::new(f));
                return Ok(());
            }
        };
        let mut ws = match self.workspace.take() {
            Some(ws) => ws,
            None => {
                let req = match (self.variant, an.symbolic.faer_supernodal()) {
                    (CholeskyVariant::Llt, Some(sn)) => {
                        supernodal::factorize_supernodal_numeric_llt_scratch::<usize, f64>(
                            sn,
                            self.par,
                            Spec::default(),
                        )
                    }
                    (CholeskyVariant::Ldlt, Some(sn)) => {
                        supernodal::factorize_supernodal_numeric_ldlt_scratch::<usize, f64>(
                            sn,
                            self.par,
                            Spec::default(),
                        )
                    }
                    (CholeskyVariant::Llt, _) => an
                        .symbolic
                        .faer()?
                        .factorize_numeric_llt_scratch::<f64>(self.par, Spec::default()),
                    (CholeskyVariant::Ldlt, _) => an
                        .symbolic
                        .faer()?
                        .factorize_numeric_ldlt_scratch::<f64>(self.par, Spec::default()),
                };
                Workspace {
                    scratch: MemBuffer::try_new(req).map_err(|_| SolverError::OutOfMemory)?,
                    lower_values: vec![0.0; lower.nnz()],
                }
            }
        };
        let supernodal = an.symbolic.faer_supernodal();
        if supernodal.is_some() {
            lower.scaled_permuted_values(a, &an.perm.fwd, &mut f.scale, &mut ws.lower_values)?;
        } else {
            lower.scaled_values(a, &mut f.scale, &mut ws.lower_values)?;
        }
        let lower = SparseColMatRef::new(
            SymbolicSparseColMatRef::new_checked(n, n, &lower.col_ptr, None, &lower.row_idx),
            &ws.lower_values,
        );
        let sym = &an.symbolic;
        let first_pivot_index = |index: usize| {
            let k = if is_simplicial(sym) {
                index.saturating_sub(1)
            } else {
                index
            };
            an.perm.fwd[k.min(n.saturating_sub(1))]
        };
        let stack = MemStack::new(&mut ws.scratch);
        match self.variant {
            CholeskyVariant::Llt => {
                let reg = LltRegularization::default();
                let r = match supernodal {
                    // In the factor's order already: no permuted copy of A.
                    Some(sn) => supernodal::factorize_supernodal_numeric_llt(
                        &mut f.l_values,
                        lower,
                        reg,
                        sn,
                        self.par,
                        stack,
                        Spec::default(),
                    )
                    .map(|_| ()),
                    None => sym
                        .faer()?
                        .factorize_numeric_llt(
                            &mut f.l_values,
                            lower,
                            Side::Lower,
                            reg,
                            self.par,
                            stack,
                            Spec::default(),
                        )
                        .map(|_| ()),
                };
                if let Err(LltError::NonPositivePivot { index }) = r {
                    return Err(pivot_error(first_pivot_index(index), 0.0));
                }
            }
            CholeskyVariant::Ldlt => {
                let reg = LdltRegularization::default();
                let r = match supernodal {
                    Some(sn) => supernodal::factorize_supernodal_numeric_ldlt(
                        &mut f.l_values,
                        lower,
                        reg,
                        sn,
                        self.par,
                        stack,
                        Spec::default(),
                    )
                    .map(|_| ()),
                    None => sym
                        .faer()?
                        .factorize_numeric_ldlt(
                            &mut f.l_values,
                            lower,
                            Side::Lower,
                            reg,
                            self.par,
                            stack,
                            Spec::default(),
                        )
                        .map(|_| ()),
                };
                if let Err(e) = r {
                    let faer::linalg::cholesky::ldlt::factor::LdltError::ZeroPivot { index } = e;
                    return Err(pivot_error(first_pivot_index(index), 0.0));
                }
            }
        }
        if ws.bytes() <= KEPT_WORKSPACE_BYTES {
            self.workspace = Some(ws);
        }
        // faer accepts tiny positive pivots: judge them relative to the (unit) scaled diagonal.
        let diag = factor_diagonal(sym, &f.l_values);
        for (k, d) in diag.iter().enumerate() {
            let pivot = match self.variant {
                CholeskyVariant::Llt => d * d,
                CholeskyVariant::Ldlt => *d,
            };
            if !(pivot > self.pivot_tolerance) {
                return Err(pivot_error(an.perm.fwd[k], pivot));
            }
        }
        self.factor = Some(Arc::new(f));
        Ok(())
    }

    fn share(&self) -> Option<Box<dyn LinearSolver>> {
        Some(Box::new(FaerCholesky {
            variant: self.variant,
            ordering: self.ordering.clone(),
            pivot_tolerance: self.pivot_tolerance,
            par: self.par,
            analysis: self.analysis.clone(),
            factor: self.factor.clone(),
            workspace: None,
            task_scratch: ScratchPool::default(),
            work: Vec::new(),
            prefault_bytes: self.prefault_bytes,
            own_supernodes_from: self.own_supernodes_from,
            prefaulted: None,
        }))
    }

    fn solve_in_place(&mut self, rhs: &mut [f64], nrhs: usize) -> Result<SolveInfo, SolverError> {
        let (an, f) = match (&self.analysis, &self.factor) {
            (Some(a), Some(f)) => (a, f),
            _ => return Err(SolverError::OutOfOrder("solve", "factorize")),
        };
        let n = an.n;
        <dyn LinearSolver>::check_rhs(n, rhs, nrhs)?;
        if n == 0 {
            return Ok(SolveInfo::default());
        }
        if nrhs == 1 && self.variant == CholeskyVariant::Llt && an.block_solves() {
            // One right-hand side on a factor large enough to split over the threads: our
            // block solve (faer's runs at a quarter of the bandwidth; on a factor that fits in
            // cache faer's kernels are faster).
            let mut x = std::mem::take(&mut self.work);
            x.resize(n, 0.0);
            permute::into_factor_order(rhs, &f.scale, &an.perm.fwd, &mut x, true);
            block_solve(&an.tree, &an.schedule, &an.symbolic, &f.l_values, &mut x);
            permute::from_factor_order(&x, &f.scale, &an.perm.inv, rhs, true);
            self.work = x;
            return Ok(SolveInfo::default());
        }
        if self.variant == CholeskyVariant::Llt && an.block_solves() {
            // Several right-hand sides on a factor split over the threads: all columns through
            // each block at once (faer's solve reads the factor once per column group). The
            // buffer is not kept: shared solvers of many material points would each hold one.
            let mut x = vec![0.0; n * nrhs];
            permute::many_into_factor_order(rhs, nrhs, &f.scale, &an.perm.fwd, &mut x);
            let blocks = FactorBlocks {
                tree: &an.tree,
                schedule: &an.schedule,
                symbolic: &an.symbolic,
                values: &f.l_values,
            };
            solve_many_in_place(blocks, &mut x, nrhs);
            permute::many_from_factor_order(&x, nrhs, &f.scale, &an.perm.inv, rhs);
            return Ok(SolveInfo::default());
        }
        // Several right-hand sides: column groups solved side by side, one per thread (faer's
        // supernodal solve gains little from more columns at a time or from a parallel kernel);
        // on the calling thread alone when the solves are too small to hand to another.
        let threads = if f.l_values.len() * nrhs < PARALLEL_SOLVE_VALUES {
            1
        } else {
            threads(self.par)
        };
        let groups = threads.min(nrhs).max(1);
        let (par, per_group) = if groups > 1 {
            (Par::Seq, nrhs.div_ceil(groups))
        } else if threads == 1 {
            (Par::Seq, nrhs)
        } else {
            (self.par, nrhs)
        };
        let variant = self.variant;
        match an.symbolic.faer_supernodal() {
            Some(sn) => {
                // faer's supernodal solve in the factor's order: columns permuted and scaled
                // into a copy, solved, and back.
                let mut x = vec![0.0; n * nrhs];
                let parallel = threads > 1;
                for (b, y) in rhs.chunks(n).zip(x.chunks_mut(n)) {
                    permute::into_factor_order(b, &f.scale, &an.perm.fwd, y, parallel);
                }
                let values = &f.l_values[..];
                solve_groups(
                    &mut x,
                    (n, per_group),
                    groups > 1,
                    |k| sn.solve_in_place_scratch::<f64>(k, par),
                    |mat, stack| match variant {
                        CholeskyVariant::Llt => supernodal::SupernodalLltRef::new(sn, values)
                            .solve_in_place_with_conj(Conj::No, mat, par, stack),
                        CholeskyVariant::Ldlt => supernodal::SupernodalLdltRef::new(sn, values)
                            .solve_in_place_with_conj(Conj::No, mat, par, stack),
                    },
                )?;
                for (y, b) in x.chunks(n).zip(rhs.chunks_mut(n)) {
                    permute::from_factor_order(y, &f.scale, &an.perm.inv, b, parallel);
                }
            }
            None => {
                let sym = an.symbolic.faer()?;
                for col in rhs.chunks_mut(n) {
                    col.iter_mut().zip(&f.scale).for_each(|(x, s)| *x *= s);
                }
                let values = &f.l_values[..];
                solve_groups(
                    rhs,
                    (n, per_group),
                    groups > 1,
                    |k| sym.solve_in_place_scratch::<f64>(k, par),
                    |mat, stack| match variant {
                        CholeskyVariant::Llt => LltRef::new(sym, values).solve_in_place_with_conj(
                            Conj::No,
                            mat,
                            par,
                            stack,
                        ),
                        CholeskyVariant::Ldlt => LdltRef::new(sym, values)
                            .solve_in_place_with_conj(Conj::No, mat, par, stack),
                    },
                )?;
                for col in rhs.chunks_mut(n) {
                    col.iter_mut().zip(&f.scale).for_each(|(x, s)| *x *= s);
                }
            }
        }
        Ok(SolveInfo::default())
    }

    fn solve_lower_in_place(&mut self, x: &mut [f64]) -> Result<(), SolverError> {
        self.lower_half(x, |an, f, y| {
            forward_in_place(&an.tree, &an.schedule, &an.symbolic, &f.l_values, y);
            Ok(())
        })
    }

    fn solve_upper_in_place(&mut self, y: &mut [f64]) -> Result<(), SolverError> {
        let mut x = std::mem::take(&mut self.work);
        let (an, f) = self.llt_parts()?;
        <dyn LinearSolver>::check_rhs(an.n, y, 1)?;
        let parallel = an.schedule.is_parallel();
        backward_in_place(&an.tree, &an.schedule, &an.symbolic, &f.l_values, y);
        x.resize(an.n, 0.0);
        permute::from_factor_order(y, &f.scale, &an.perm.inv, &mut x, parallel);
        permute::copy(&x, y, parallel);
        self.work = x;
        Ok(())
    }

    fn forward_solve_sparse(
        &mut self,
        columns: &[Vec<(usize, f64)>],
    ) -> Result<ForwardColumns, SolverError> {
        let (an, f) = self.llt_parts()?;
        an.tree
            .forward(&factor_view(an, f), columns, &an.schedule, self.par, None)
    }

    fn forward_solve_sparse_and_lower(
        &mut self,
        columns: &[Vec<(usize, f64)>],
        x: &mut [f64],
    ) -> Result<ForwardColumns, SolverError> {
        let par = self.par;
        self.lower_half(x, |an, f, y| {
            let factor = factor_view(an, f);
            an.tree
                .forward(&factor, columns, &an.schedule, par, Some(y))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_matrices::{blocked_network, grid, grid_factor};
    use fibercell_solver::CscMatrix;

    /// The solution of `solver` for `b`, one right-hand side.
    fn solved(solver: &mut dyn LinearSolver, b: &[f64]) -> Vec<f64> {
        let mut x = b.to_vec();
        solver.solve_in_place(&mut x, 1).unwrap();
        x
    }

    /// ‖A x − b‖∞ / ‖b‖∞.
    fn relative_residual(a: &CscMatrix, x: &[f64], b: &[f64]) -> f64 {
        let a = a.as_ref();
        let mut r: Vec<f64> = b.iter().map(|v| -v).collect();
        for (j, xj) in x.iter().enumerate() {
            let (rows, values) = a.col(j);
            for (&i, v) in rows.iter().zip(values) {
                r[i] += v * xj;
            }
        }
        let norm = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        norm(&r) / norm(b)
    }

    /// On a network of mixed node widths the analysis takes the node tree's supernodal
    /// structure, and one, three and five right-hand sides (faer's supernodal solve in the
    /// factor's order) solve A x = b for LLᵀ and LDLᵀ, column for column alike.
    #[test]
    fn the_node_tree_structure_factorizes_and_solves() {
        let a = blocked_network(400);
        let n = a.as_ref().ncols();
        for variant in [CholeskyVariant::Llt, CholeskyVariant::Ldlt] {
            let mut s = FaerCholesky::new(variant, FillOrdering::Auto);
            s.analyze(a.as_ref()).unwrap();
            let an = s.analysis.as_ref().unwrap();
            assert!(
                matches!(an.symbolic, Symbolic::Supernodal(_)),
                "{variant:?}"
            );
            s.factorize(a.as_ref()).unwrap();
            for k in [1, 3, 5] {
                let b: Vec<f64> = (0..n * k).map(|i| ((i * 37) % 101) as f64 - 50.0).collect();
                let mut x = b.clone();
                s.solve_in_place(&mut x, k).unwrap();
                for (c, (xc, bc)) in x.chunks(n).zip(b.chunks(n)).enumerate() {
                    let r = relative_residual(&a, xc, bc);
                    assert!(r < 1e-12, "{variant:?}, {k} columns, column {c}: {r:e}");
                    let one = solved(&mut s, bc);
                    let diff = one
                        .iter()
                        .zip(xc)
                        .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
                    let scale = one.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                    assert!(
                        diff <= 1e-12 * scale,
                        "{variant:?}, {k} columns, column {c}"
                    );
                }
            }
        }
    }

    /// The task kernel checks A's values where it gathers them: a NaN or an infinity in
    /// either triangle or on the diagonal is reported at its index as `check_matrix` reports
    /// it (the lowest of two), not as the pivot it spoils, and the next factorization of
    /// the finite values solves as the first did, bit for bit.
    #[test]
    fn the_task_kernel_reports_the_first_non_finite_value() {
        let (n, a, mut s) = grid_factor(16);
        let an = s.analysis.as_ref().unwrap();
        assert!(matches!(an.kernel, Kernel::Tasks(_)));
        let before = solved(&mut s, &vec![1.0; n]);
        let csc = a.as_ref();
        let entry = |i: usize, j: usize| {
            (csc.col_ptr()[j]..csc.col_ptr()[j + 1])
                .find(|&k| csc.row_idx()[k] == i)
                .unwrap()
        };
        let (upper, lower, diagonal) = (entry(3, 259), entry(510, 494), entry(777, 777));
        for bad in [
            vec![(upper, f64::NAN)],
            vec![(lower, f64::INFINITY)],
            vec![(diagonal, f64::NAN)],
            vec![(diagonal, f64::NEG_INFINITY), (upper, f64::NAN)],
        ] {
            let mut b = a.clone();
            for &(k, v) in &bad {
                b.values_mut()[k] = v;
            }
            let first = bad.iter().map(|&(k, _)| k).min().unwrap();
            match s.factorize(b.as_ref()) {
                Err(SolverError::NonFinite {
                    what: "matrix",
                    index,
                }) => assert_eq!(index, first, "{bad:?}"),
                other => panic!("{bad:?}: {other:?}"),
            }
            s.factorize(a.as_ref()).unwrap();
            let x = solved(&mut s, &vec![1.0; n]);
            assert!(x
                .iter()
                .zip(&before)
                .all(|(p, q)| p.to_bits() == q.to_bits()));
        }
    }

    /// The task kernel's later factorizations read the scale at the diagonal entries the
    /// first one found: with a diagonal raised unevenly (so that S A S changes), the
    /// refactorized solver solves as a fresh one, bit for bit.
    #[test]
    fn a_refactorization_reads_the_new_diagonal() {
        let (n, a, mut s) = grid_factor(16);
        assert!(s.analysis.as_ref().unwrap().diagonal.get().is_some());
        let mut b = a.clone();
        let csc = a.as_ref();
        for j in 0..n {
            let k = (csc.col_ptr()[j]..csc.col_ptr()[j + 1])
                .find(|&k| csc.row_idx()[k] == j)
                .unwrap();
            b.values_mut()[k] *= 1.0 + (j % 3) as f64;
        }
        s.factorize(b.as_ref()).unwrap();
        let mut fresh = FaerCholesky::new(CholeskyVariant::Llt, FillOrdering::NestedDissection);
        fresh.analyze(b.as_ref()).unwrap();
        fresh.factorize(b.as_ref()).unwrap();
        let rhs: Vec<f64> = (0..n).map(|i| (i % 7) as f64 - 3.0).collect();
        let (x, y) = (solved(&mut s, &rhs), solved(&mut fresh, &rhs));
        assert!(x.iter().zip(&y).all(|(p, q)| p.to_bits() == q.to_bits()));
        assert!(relative_residual(&b, &x, &rhs) < 1e-8);
    }

    /// The values' check runs beside the ordering and still comes first: a NaN in a pattern
    /// that is one triangle only is reported as the NaN, and the failed analysis keeps
    /// nothing; a finite one-triangle pattern is refused by the ordering's check.
    #[test]
    fn a_non_finite_value_is_reported_before_the_pattern() {
        let t = [(0, 0, 2.0), (1, 0, 1.0), (1, 1, f64::NAN)];
        let a = CscMatrix::from_triplets(2, 2, &t).unwrap();
        for ordering in [FillOrdering::Auto, FillOrdering::Natural] {
            let mut s = FaerCholesky::new(CholeskyVariant::Llt, ordering.clone());
            let e = s.analyze(a.as_ref());
            assert!(
                matches!(
                    e,
                    Err(SolverError::NonFinite {
                        what: "matrix",
                        index: 2
                    })
                ),
                "{ordering:?}: {e:?}"
            );
            assert!(s.analysis.is_none() && s.prefaulted.is_none());
            let finite = CscMatrix::from_triplets(2, 2, &t[..2]).unwrap();
            let e = s.analyze(finite.as_ref());
            assert!(
                matches!(e, Err(SolverError::NotStructurallySymmetric { .. })),
                "{ordering:?}: {e:?}"
            );
        }
    }

    /// A large LLᵀ factor (here forced on small ones) takes this crate's supernodes; its
    /// analysis reports what faer's structure gives, its factor is faer's structure's bit for
    /// bit, and every solve — one and several right-hand sides, the two halves, sparse
    /// forward columns — agrees with the solves on faer's structure, on two threads and on
    /// one (where the block solves run without a parallel schedule).
    #[test]
    fn own_supernodes_factorize_and_solve_as_faers() {
        let close = |p: &[f64], q: &[f64], what: &str| {
            let scale = q.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let diff = p
                .iter()
                .zip(q)
                .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
            assert!(diff <= 1e-12 * scale, "{what}: {diff:e} of {scale:e}");
        };
        for (name, a) in [("network", blocked_network(3000)), ("grid", grid(14))] {
            let n = a.as_ref().ncols();
            for sequential in [false, true] {
                let what = format!("{name}, sequential {sequential}");
                let make = |from: usize| {
                    let s = FaerCholesky::new(CholeskyVariant::Llt, FillOrdering::Auto)
                        .with_own_supernodes_from(from);
                    if sequential {
                        s.sequential()
                    } else {
                        s
                    }
                };
                let (mut ours, mut theirs) = (make(0), make(usize::MAX));
                let info = ours.analyze(a.as_ref()).unwrap();
                assert_eq!(info, theirs.analyze(a.as_ref()).unwrap(), "{what}");
                ours.factorize(a.as_ref()).unwrap();
                theirs.factorize(a.as_ref()).unwrap();
                let is_ours = |s: &FaerCholesky| s.analysis.as_ref().unwrap().symbolic.is_ours();
                assert!(is_ours(&ours) && !is_ours(&theirs), "{what}");
                assert_eq!(
                    ours.factor_view().values,
                    theirs.factor_view().values,
                    "{what}"
                );
                for k in [1, 3] {
                    let b: Vec<f64> = (0..n * k).map(|i| ((i * 37) % 101) as f64 - 50.0).collect();
                    let (mut x, mut y) = (b.clone(), b.clone());
                    ours.solve_in_place(&mut x, k).unwrap();
                    theirs.solve_in_place(&mut y, k).unwrap();
                    close(&x, &y, &format!("{what}, {k} columns"));
                    for (xc, bc) in x.chunks(n).zip(b.chunks(n)) {
                        // The grid's scales span four decades: 1e-11 with either structure.
                        let r = relative_residual(&a, xc, bc);
                        assert!(r < 1e-10, "{what}, {k} columns: {r:e}");
                    }
                }
                let b: Vec<f64> = (0..n).map(|i| ((i * 29) % 97) as f64 - 48.0).collect();
                let (mut x, mut y) = (b.clone(), b.clone());
                ours.solve_lower_in_place(&mut x).unwrap();
                theirs.solve_lower_in_place(&mut y).unwrap();
                close(&x, &y, &format!("{what}, lower half"));
                ours.solve_upper_in_place(&mut x).unwrap();
                theirs.solve_upper_in_place(&mut y).unwrap();
                close(&x, &y, &format!("{what}, upper half"));
                let columns = vec![vec![(3, 1.0), (40, -2.0)], vec![(n - 1, 0.5)]];
                close(
                    &ours.forward_solve_sparse(&columns).unwrap().gram(),
                    &theirs.forward_solve_sparse(&columns).unwrap().gram(),
                    &format!("{what}, sparse forward"),
                );
            }
        }
    }

    /// `solve_checked_into` gives `solve_checked`'s solutions and report, bit for bit, in a
    /// given buffer whatever it held and however long it was (shorter, equal, longer than the
    /// right-hand sides), and it still refuses a right-hand side of the wrong length.
    #[test]
    fn a_given_solution_buffer_changes_nothing_but_where_the_solution_lives() {
        use fibercell_solver::{solve_checked, solve_checked_into};
        let a = blocked_network(300);
        let n = a.as_ref().ncols();
        let mut s = FaerCholesky::new(CholeskyVariant::Llt, FillOrdering::Auto);
        s.analyze(a.as_ref()).unwrap();
        s.factorize(a.as_ref()).unwrap();
        for k in [1, 7] {
            let b: Vec<f64> = (0..n * k).map(|i| ((i * 29) % 97) as f64 - 48.0).collect();
            let (want, report) = solve_checked(&mut s, a.as_ref(), &b, k).unwrap();
            assert!(report.backward_error < 1e-14, "{k}: {report:?}");
            for len in [0, n * k, 3 * n * k + 5] {
                let buffer = vec![f64::NAN; len];
                let (got, r) = solve_checked_into(&mut s, a.as_ref(), &b, buffer, k).unwrap();
                assert_eq!(got.len(), n * k);
                assert!(got
                    .iter()
                    .zip(&want)
                    .all(|(p, q)| p.to_bits() == q.to_bits()));
                assert_eq!(r, report, "{k} columns, buffer of {len}");
            }
            let short = &b[..n * k - 1];
            let e = solve_checked_into(&mut s, a.as_ref(), short, Vec::new(), k);
            assert!(matches!(e, Err(SolverError::DimensionMismatch(_))), "{e:?}");
        }
    }

    /// nnz(L) is the factor's structure (its entries on and below the diagonal that are not
    /// exactly zero: a relaxed supernode's explicit zeros receive no update and stay 0.0), the
    /// stored bytes its values with those zeros, as CHOLMOD counts `lnz` and `xsize`.
    #[test]
    fn nnz_counts_the_structure_and_bytes_the_stored_values() {
        let a = grid(14);
        let mut s = FaerCholesky::new(CholeskyVariant::Llt, FillOrdering::NestedDissection);
        let info = s.analyze(a.as_ref()).unwrap();
        s.factorize(a.as_ref()).unwrap();
        assert_eq!(s.is_supernodal(), Some(true));
        let view = s.factor_view();
        let Raw::Supernodal(sn) = view.symbolic.raw() else {
            unreachable!("checked supernodal")
        };
        let (mut structural, mut lower) = (0, 0);
        for (b, e, rows, start) in crate::pivots::supernodes(sn) {
            for c in 0..e - b {
                let column = &view.values[start + c * rows + c..start + (c + 1) * rows];
                structural += column.iter().filter(|&&v| v != 0.0).count();
                lower += column.len();
            }
        }
        assert_eq!(info.nnz_factor, Some(structural));
        assert_eq!(info.factor_bytes, Some(8 * view.values.len()));
        assert!(
            lower > structural,
            "no relaxed zeros: the test shows nothing"
        );
    }

    /// A factorization into the prefaulted buffer (every analysis given one, the helper
    /// stopped at once or after it mapped the whole factor) equals one into a fresh buffer
    /// bit for bit, again after a refactorization; a failed analysis keeps no buffer.
    #[test]
    fn the_prefaulted_buffer_holds_the_same_factor() {
        let a = grid(14);
        let factor = |bytes: usize, wait: bool| {
            let mut s = FaerCholesky::new(CholeskyVariant::Llt, FillOrdering::NestedDissection)
                .with_prefault_bytes(bytes);
            s.analyze(a.as_ref()).unwrap();
            assert_eq!(s.prefaulted.is_some(), bytes == 0);
            if wait {
                std::thread::sleep(std::time::Duration::from_millis(30));
            }
            s.factorize(a.as_ref()).unwrap();
            assert!(s.prefaulted.is_none());
            let first = s.factor_view().values.to_vec();
            s.factorize(a.as_ref()).unwrap();
            assert_eq!(first, s.factor_view().values);
            first
        };
        let fresh = factor(usize::MAX, false);
        assert_eq!(factor(0, false), fresh);
        assert_eq!(factor(0, true), fresh);
        let mut s = FaerCholesky::default().with_prefault_bytes(0);
        let one_triangle =
            CscMatrix::from_triplets(2, 2, &[(0, 0, 2.0), (1, 0, 1.0), (1, 1, 2.0)]).unwrap();
        assert!(s.analyze(one_triangle.as_ref()).is_err());
        assert!(s.prefaulted.is_none());
    }

    /// A shared solver solves bit for bit as its origin (one and several right-hand sides,
    /// the two halves, sparse forward columns), from two threads at once; a factorization of
    /// other values on either side leaves the other's factor as it was.
    #[test]
    fn shared_solvers_solve_alike_and_factorize_apart() {
        let (n, a, mut origin) = grid_factor(12);
        let b: Vec<f64> = (0..n).map(|i| ((i * 37) % 23) as f64 - 11.0).collect();
        let expected = solved(&mut origin, &b);
        let mut shared = origin.share().expect("faer Cholesky shares");
        assert_eq!(solved(shared.as_mut(), &b), expected);
        let mut two = [b.clone(), b.clone()].concat();
        shared.solve_in_place(&mut two, 2).unwrap();
        let mut two_origin = [b.clone(), b.clone()].concat();
        origin.solve_in_place(&mut two_origin, 2).unwrap();
        assert_eq!(two, two_origin);
        let (mut lower, mut lower_origin) = (b.clone(), b.clone());
        shared.solve_lower_in_place(&mut lower).unwrap();
        origin.solve_lower_in_place(&mut lower_origin).unwrap();
        assert_eq!(lower, lower_origin);
        let columns = vec![vec![(3, 1.0), (40, -2.0)], vec![(n - 1, 0.5)]];
        let (w, w_origin) = (
            shared.forward_solve_sparse(&columns).unwrap(),
            origin.forward_solve_sparse(&columns).unwrap(),
        );
        assert_eq!(w.gram(), w_origin.gram());
        // Two threads solving on one factor at once.
        let mut other = origin.share().expect("shares");
        let (x1, x2) = rayon::join(
            || solved(shared.as_mut(), &b),
            || solved(other.as_mut(), &b),
        );
        assert_eq!((&x1, &x2), (&expected, &expected));
        // Doubled values on the shared side: its solution halves, the origin's stays.
        let mut doubled = a.clone();
        doubled.values_mut().iter_mut().for_each(|v| *v *= 2.0);
        shared.factorize(doubled.as_ref()).unwrap();
        let half = solved(shared.as_mut(), &b);
        let big = expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(half
            .iter()
            .zip(&expected)
            .all(|(h, e)| (2.0 * h - e).abs() <= 1e-12 * big));
        assert_eq!(solved(&mut origin, &b), expected);
        // And the origin refactorized with other values: the other shared solver keeps the old.
        origin.factorize(doubled.as_ref()).unwrap();
        assert_eq!(solved(other.as_mut(), &b), expected);
        // A share of an analysis without a factor factorizes on the shared analysis.
        let mut analyzed = FaerCholesky::default();
        analyzed.analyze(grid(12).as_ref()).unwrap();
        let mut late = analyzed.share().expect("shares");
        late.factorize(a.as_ref()).unwrap();
        assert!(solved(late.as_mut(), &b)
            .iter()
            .zip(&expected)
            .all(|(x, e)| (x - e).abs() <= 1e-12 * big));
    }
}
