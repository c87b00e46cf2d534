//! What a stick/slip run is told: increments, backends, the contact treatment, and the
//! tolerances of its state iteration.

use super::super::SolveOptions;

/// A callback told after every increment: (increments done, increments in all, the record of
/// the increment just done: its iterations, factorizations, low-rank sizes, cutbacks, times).
#[derive(Clone)]
pub struct Progress(pub std::sync::Arc<ProgressFn>);

/// The function a [`Progress`] calls.
pub type ProgressFn = dyn Fn(usize, usize, &super::IncrementRecord) + Send + Sync;

impl std::fmt::Debug for Progress {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Progress(callback)")
    }
}

/// Options of [`solve_incremental`](super::solve_incremental).
#[derive(Clone, Debug)]
pub struct IncrementalOptions {
    /// Number of load increments N ≥ 1.
    pub steps: usize,
    /// Backend and checks for the symmetric systems (Coulomb sliding always uses faer LU).
    pub solve: SolveOptions,
    /// Largest number of state iterations inside one increment (default 50); the contacts
    /// still changing in the last are held in the states they were solved with.
    pub max_state_iterations: usize,
    /// Load factors of the increments (default: α_n = n/N, n = 1…N); any sequence, e.g. up to 1,
    /// back to 0 and up again for a load–unload–reload path. Overrides `steps`.
    pub path: Option<Vec<f64>>,
    /// Thesis Remark 4.38: every contact slides along the direction of its tangential relative
    /// displacement in a frictionless pre-run, instead of the trial direction of the return
    /// mapping (the default, and the more faithful treatment).
    pub fixed_slip_direction: bool,
    /// Called after every increment (e.g. to drive a progress bar).
    pub progress: Option<Progress>,
    /// Relative stiffness ε of the stabilizing springs (default 0: none). An open contact keeps
    /// ε (K_N + K_T^st + K_R) and a sliding one ε K_T^st, linear springs on the contact jump with
    /// no prestress. A fiber that loses all its closed contacts (a rattler) or whose contacts all
    /// slide one way is otherwise a mechanism and the system is singular; with ε ≈ 1e-8 it
    /// follows its neighbours and the springs carry forces of relative size ε, included in the
    /// reactions.
    pub stabilization: f64,
    /// A fixed contact topology: initially closed contacts never open (the normal spring is
    /// bilateral, N may be negative, a tension) and open ones never close; only stick and slip
    /// evolve, with a Coulomb bound μ max(N, 0). A model of bonded or consolidated mats, whose
    /// just-touching contacts would otherwise open under the smallest strain and chatter.
    pub bonded: bool,
    /// After the first factorization, solve on it: the contacts whose block changed since (a
    /// state, a slip direction or the tangent across it) are a low-rank correction U E Uᵀ in
    /// their jump rows, solved by the Sherman–Morrison–Woodbury formula with S = Uᵀ A₀⁻¹ U
    /// kept across iterations and increments (see `low_rank.rs`), while its dense capacitance
    /// factorization is predicted cheaper than refactorizing (measured times); the result is
    /// corrected with the residual of the assembled matrix until its backward error is 10⁵
    /// times below the accepted one, as accurate as a direct solve, else the matrix is
    /// refactorized and becomes the new reference (default true). Needs a direct symmetric
    /// backend; Coulomb sliding (a nonsymmetric E) is solved on the symmetric factorization.
    pub reuse_factor: bool,
    /// Columns of the low-rank correction kept on one reference factorization. Past it, the
    /// contacts whose load alone changed are left out of the correction (the assembled load is
    /// solved for instead); when the changed blocks alone need more, the current matrix is
    /// refactorized as the new reference. S takes 8 bytes × this squared (default
    /// [`MAX_LOW_RANK_COLUMNS`], 128 MiB).
    pub max_low_rank_columns: usize,
    /// A state iteration whose capacitance matrix is larger than this factorizes its matrix
    /// directly instead, as the new reference; `None` (default): decided by the measured
    /// costs, a low-rank solve while its capacitance factorization is predicted cheaper than
    /// a factorization, and a new reference once the capacitance factorizations on the
    /// current one have cost a factorization. A bound makes the choice independent of the
    /// machine's timings.
    pub max_capacitance_order: Option<usize>,
    /// Which increments keep their full outputs: displacements of every node and record of
    /// every contact (every increment keeps its summary and its contacts' states).
    pub history: History,
    /// Stop after the increment during which this instant passes (default: none); the solution
    /// then holds fewer increments than the path. A time box, e.g. for a benchmark.
    pub deadline: Option<std::time::Instant>,
    /// Solve Coulomb sliding with its consistent tangent K_T^sl = μ p_N Bᵀd nᵀB (4.63) for a
    /// contact in compression (in tension the bound c + μ max(N, 0) has no slope): Newton on
    /// the bounds, nonsymmetric systems solved as low-rank corrections of the symmetric
    /// reference factorization (each sliding block relative to stick has rank 2); where the
    /// reference cannot serve, that state iteration takes a symmetric fixed-point step whose
    /// factorization becomes the new reference, and only without factor reuse does a system
    /// go to faer LU. Default false: each sliding contact's friction force is a load at the
    /// bound c + μ max(N, 0) of the state iteration's last normal force N, iterated until no
    /// bound moves by more than [`BOUND_TOLERANCE`] of itself (a fixed point on the bounds, as
    /// for Tresca friction with the bound updated), so every system stays symmetric for
    /// Cholesky and the low-rank corrections; at convergence both satisfy the same Coulomb
    /// law (`tests/curve_consistent_tangent.rs`).
    pub consistent_coulomb_tangent: bool,
    /// Halvings of an increment that ends with contacts held off equilibrium (residual above
    /// [`EQUILIBRIUM_TOLERANCE`]) or without equilibrium: it is redone from its start as two
    /// halves, each of which may be halved again, down to 1/2^`max_cutbacks` of it (default
    /// [`MAX_CUTBACKS`]; 0: never, the held state is committed as it is).
    pub max_cutbacks: usize,
}

/// The relative change of a sliding Coulomb contact's bound c + μ max(N, 0) below which the
/// fixed point on the bounds has converged (see
/// [`IncrementalOptions::consistent_coulomb_tangent`]).
pub const BOUND_TOLERANCE: f64 = 1e-8;

/// The equilibrium residual ‖R‖/(‖K q‖ + ‖α F‖) with the law's contact forces, K q the
/// elements' nodal forces (stricter than the reported residual's scale), at or below which an
/// increment has converged, from state iteration `SETTLE_BY_EQUILIBRIUM_AFTER` on,
/// although sliding forces are still off the law by more than [`BOUND_TOLERANCE`] of their
/// bounds (see `classify_settled`).
pub const EQUILIBRIUM_TOLERANCE: f64 = 1e-8;

/// The strict equilibrium residual within which an increment whose residual has stopped
/// falling (not below half its best of the two state iterations before) has converged: the
/// round-off floor of large cells. On the L non-woven under e22 (seed 2) the fixed point on the
/// bounds reaches 1.0–1.4·10⁻⁸ by its seventh iteration from α = 0.9 on and stays there, while
/// thousands of bounds keep moving by more than [`BOUND_TOLERANCE`] from noise: increment 93
/// ran 50 iterations (49 factorizations, 202 s) and held 3,991 contacts at a reported residual
/// of 6.8·10⁻⁹. Twice [`EQUILIBRIUM_TOLERANCE`] keeps the reported residual, on a 3–4× larger
/// scale, below 10⁻⁸.
pub const STALLED_EQUILIBRIUM_TOLERANCE: f64 = 2.0 * EQUILIBRIUM_TOLERANCE;

/// The state iteration from which an increment may converge by its equilibrium residual.
pub(super) const SETTLE_BY_EQUILIBRIUM_AFTER: usize = 8;

/// The state iteration from which an increment may converge by an equilibrium residual ten
/// times below [`EQUILIBRIUM_TOLERANCE`], before [`SETTLE_BY_EQUILIBRIUM_AFTER`]. Without it
/// nearly every increment of the M and L non-wovens ran to the eighth iteration only to settle
/// there.
pub(super) const EARLY_SETTLE_AFTER: usize = 4;

/// The equilibrium residual of an early settlement (see [`EARLY_SETTLE_AFTER`]): at
/// [`EQUILIBRIUM_TOLERANCE`] itself the small stabilized non-woven's near-mechanism moved its
/// resultants by 1.4·10⁻⁵ between solve paths (`tests/curve_nonwoven_convergence.rs`).
pub(super) const EARLY_EQUILIBRIUM_TOLERANCE: f64 = 0.1 * EQUILIBRIUM_TOLERANCE;

/// State iterations of an increment after which the bounds of the Coulomb fixed point move by
/// half the step (see the update in the state iteration).
pub(super) const BOUND_RELAXATION_AFTER: usize = 10;

/// State iterations of an increment with the Coulomb fixed point after which a sliding
/// contact's changes of direction or bound count as switches (see [`CHATTER_SWITCHES`]).
pub(super) const SETTLING_ITERATIONS: usize = 20;

/// Which increments of a run keep their full outputs, [`IncrementalSolution::displacements`]
/// and [`IncrementalSolution::contact_results`], which on a large cell take more memory than
/// the factorization within a few hundred increments (the summaries and contact states of
/// every increment are always kept).
///
/// [`IncrementalSolution::displacements`]: super::IncrementalSolution::displacements
/// [`IncrementalSolution::contact_results`]: super::IncrementalSolution::contact_results
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum History {
    /// By job: every increment for `solve_incremental` (its files show each step), the last
    /// for `elasto_plastic_curve` (its points and switches need the summaries and states).
    #[default]
    Auto,
    /// Every increment.
    All,
    /// The last increment only; the earlier increments' vectors are left empty.
    Last,
}

impl History {
    /// Whether a run keeps every increment: all but `Last` (a curve turns `Auto` into `Last`
    /// before its run starts).
    pub fn keeps_all(self) -> bool {
        self != History::Last
    }
}

impl Default for IncrementalOptions {
    fn default() -> Self {
        IncrementalOptions {
            steps: 10,
            solve: SolveOptions::default(),
            max_state_iterations: 50,
            path: None,
            fixed_slip_direction: false,
            progress: None,
            stabilization: 0.0,
            bonded: false,
            reuse_factor: true,
            max_low_rank_columns: MAX_LOW_RANK_COLUMNS,
            max_capacitance_order: None,
            deadline: None,
            history: History::Auto,
            consistent_coulomb_tangent: false,
            max_cutbacks: MAX_CUTBACKS,
        }
    }
}

/// The most increments a run takes: its path, and every contact's record of every increment,
/// are kept in memory.
pub const MAX_INCREMENTS: usize = 1_000_000;

/// The most contact records (one per contact and increment, about 90 bytes each: 4.5 GB) a run
/// keeps; a run that would need more is refused before it starts.
pub const MAX_CONTACT_RECORDS: usize = 50_000_000;

/// The equilibrium residual above which an increment that held contacts is an error
/// ([`crate::Error::NoEquilibrium`]) rather than a result: held contacts leave residuals of
/// 10⁻⁶–10⁻⁴ where a few chatter on generated non-wovens, 1.5·10⁻² where one slides into a
/// near-mechanism held by stabilizing springs alone (`tests/curve_nonwoven_convergence.rs`),
/// 6·10⁻⁴ where a knit unloaded to zero strain holds its frictionless contacts, and 0.2–1
/// where the held state is a mechanism (a knitted cell with unilateral contacts, all of which
/// open or slide under shear: its resultants then grew to 10¹⁴³).
pub const MAX_HELD_RESIDUAL: f64 = 0.1;

/// The equilibrium residual above which an increment whose contacts all settled (none held)
/// is an error ([`crate::Error::RoundOff`]) rather than a result. Settled increments end at
/// 10⁻¹⁰–3·10⁻⁹ on every generated cell, at the round-off floor of 1–2·10⁻⁸ on the L
/// non-woven; above that the penalties' round-off shows: the crossing beams of
/// `tests/contact_validation.rs` reach 2.7·10⁻⁷ at 10⁷ × the default penalty (the force
/// 2·10⁻⁶ off its closed form), 7·10⁻⁶ at 10⁸, and 0.12 at 10¹² with the force 100 % off.
pub const MAX_SETTLED_RESIDUAL: f64 = 1e-6;

/// The default of [`IncrementalOptions::max_cutbacks`]: down to 1/16 of an increment.
pub const MAX_CUTBACKS: usize = 4;

/// State switches of one contact within an increment after which it is held in its state.
pub(super) const CHATTER_SWITCHES: usize = 4;

/// A sliding contact's direction has converged when the change |Δd| times its slip |u_t − s|
/// (the tangential displacement across the old direction the change stands for) is below this
/// fraction of the model size. Newton's iteration on the directions converges quadratically
/// down to roundoff, which on the benchmark's S cell reaches 1e-11 of the size for barely
/// sliding contacts: with 1e-12 or 1e-11 here some still chattered until held, with 1e-10
/// none, and the end resultant of the curve moved by less than 2e-10 of itself.
pub(super) const SLIP_DIRECTION_TOLERANCE: f64 = 1e-10;

/// The farthest a sliding contact's slip direction may have turned from the reference's,
/// |d − d_f|, for its block to keep the reference's tangent (see
/// `contact_states::FrozenTangent`).
pub(super) const FROZEN_TURN: f64 = 0.01;

/// The largest relative change of k⊥ from the reference's for a sliding contact's block to
/// keep the reference's tangent.
pub(super) const FROZEN_STIFFNESS_CHANGE: f64 = 0.1;

/// State iterations of an increment whose solves may keep a reference's tangent: the
/// modified Newton iteration converges linearly, and where it is slow (measured on the L
/// non-woven: 50 iterations and every sliding contact held, where Newton takes 8) the
/// consistent tangent takes over.
pub(super) const FROZEN_ITERATIONS: usize = 6;

/// The backward error a factor-reuse CG solve must reach, relative to the accepted one of a
/// direct solve. The slip directions are read off the last digits of the tangential
/// displacements, so a CG solve must be as accurate as a direct one: at 1e-3 the directions of
/// barely sliding contacts wandered by 1e-3 between iterations (measured on the S cell).
pub(super) const REUSE_ACCURACY: f64 = 1e-5;

/// How far a low-rank solve's backward error may stay above that of the reference
/// factorization's own direct solve. [`REUSE_ACCURACY`] alone accepted low-rank solves 300–500
/// times less accurate than the direct ones: on the L non-woven (seed 3) unloaded under e11,
/// from the reversal on, the correction adds the stick springs of thousands of contacts that
/// slid in the reference, its solves were accepted at backward errors of 5·10⁻¹⁷–1.4·10⁻¹⁶
/// against 2·10⁻¹⁹ for Cholesky, and the strict equilibrium residual rose from 5·10⁻⁹ to
/// 0.8–1.8·10⁻⁷ (reported 1.7–5·10⁻⁸), with stalls and cutbacks. The M non-woven's low-rank
/// solves reach 10⁻¹⁹ in their first step. A solve that stops short of it after
/// [`MAX_REFINEMENTS`] steps is kept if it meets [`REUSE_ACCURACY`], and the next solve
/// refactorizes: a fresh reference for the states the correction had drifted to.
pub(super) const LOW_RANK_MATCH: f64 = 10.0;

/// Columns of the low-rank correction kept on one factorization before refactorizing, by
/// default: S, their dense products, then takes 8 bytes × this squared (128 MiB), and the
/// capacitance factorization as much again at most.
pub const MAX_LOW_RANK_COLUMNS: usize = 4096;

/// A direct symmetric factorization is kept beside the reference A₀ (whose low-rank columns
/// later iterations with fewer changes reuse) only while a factor has at most this many bytes;
/// a larger one becomes the new reference instead, so that a large cell's run holds one
/// factor: on the L non-woven a factor is 0.8 GB, and from the crossover on (increment 79 of
/// its e11 curve) the reference's 7,400 columns served no further solve while the factor
/// beside them took the run from 4.5 to 6.1 GB. The M non-woven's factor is 91 MB.
pub(super) const MAX_BESIDE_FACTOR_BYTES: usize = 256 << 20;

/// Correction steps x += W (b − A x) after a low-rank solve W ≈ A⁻¹ before it falls back to a
/// factorization (the correction subtracts stick springs far stiffer than the fibers, which
/// costs digits that one or two steps restore).
pub(super) const MAX_REFINEMENTS: usize = 3;
