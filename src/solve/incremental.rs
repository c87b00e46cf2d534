//! The incremental stick/slip solver (thesis §4.3 "Contact solution algorithm"): the load is
//! applied in N increments α_n = n/N; all closed contacts start in stick; inside each increment
//! the contact contributions are rebuilt for the current states, the system is solved, and every
//! contact is re-classified by a return mapping — open if it does not penetrate, stick if the
//! trial tangential force p_T (Eᵀ B q − s) lies within the friction bound (μN or G), otherwise
//! slip at the bound along the trial direction — until no state changes.
//!
//! A contact that changes its state or slip direction four times within one increment (the
//! discrete penalty problem can have no consistent state for it: e.g. closed it is pulled apart,
//! open it penetrates) is held in its state for the rest of the increment; the count is
//! reported per increment.
//!
//! The pattern (elements ∪ all candidate contact blocks) and each backend's symbolic analysis are
//! built once. The first symmetric factorization is the reference: later systems are its matrix
//! plus the changed contacts' blocks, assembled as such and solved as a low-rank correction of
//! it while that is cheaper than refactorizing (see [`IncrementalOptions::reuse_factor`]).
//! Otherwise systems with a Coulomb-sliding contact are nonsymmetric and go to LU, all others
//! to the chosen symmetric backend.

use super::affine_reference::AffineReferences;
use super::kept_contact_loads::KeptContactLoads;
use super::low_rank::{Capacitance, ContactChange, LowRankCorrection, Reference, SparseColumn};
use super::static_solve::{backward_tolerance, check_backward_error};
use super::{check_supported_with, IncrementTimings, SolveOptions, SolverConfig, SolverKind};
use crate::assembly::{
    color_blocks, element_stiffness, Assembler, DofMap, Pattern, SharedMut, NO_SLOT,
};
use crate::constraints::{internal_forces, Discretization, Reaction};
use crate::contact::{
    BlockCoefficients, BlockMatrix, BlockState, BlockVector, ContactPair, ContactSet, ContactSide,
    ContactState, Friction,
};
use crate::model::Model;
use crate::Error;
use fibercell_solver::{
    backward_from_product, norm_inf, relative_from_product, solve_checked, CscRef, LinearSolver,
    SolveInfo, SolveReport, SolverError,
};
use nalgebra::{DMatrix, Vector2, Vector3, Vector6};
use rayon::prelude::*;
use serde::Serialize;
use std::sync::OnceLock;

/// A callback told after every increment: (increments done, increments in all).
#[derive(Clone)]
pub struct Progress(pub std::sync::Arc<dyn Fn(usize, usize) + Send + Sync>);

impl std::fmt::Debug for Progress {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Progress(callback)")
    }
}

/// Options of [`solve_incremental`].
#[derive(Clone, Debug)]
pub struct IncrementalOptions {
    /// Number of load increments N ≥ 1.
    pub steps: usize,
    /// Backend and checks for the symmetric systems (Coulomb sliding always uses faer LU).
    pub solve: SolveOptions,
    /// Largest number of state iterations inside one increment.
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
    /// Columns of the low-rank correction kept on one reference factorization; one more
    /// refactorizes the current matrix as the new reference. S takes 8 bytes × this squared
    /// (default [`MAX_LOW_RANK_COLUMNS`], 512 MB).
    pub max_low_rank_columns: usize,
    /// A state iteration whose capacitance matrix is larger than this factorizes its matrix
    /// directly instead (the reference stays for the iterations after); `None` (default):
    /// decided by the measured costs, a low-rank solve while its capacitance factorization is
    /// predicted cheaper than a factorization. A bound makes the choice independent of the
    /// machine's timings.
    pub max_capacitance_order: Option<usize>,
    /// Stop after the increment during which this instant passes (default: none); the solution
    /// then holds fewer increments than the path. A time box, e.g. for a benchmark.
    pub deadline: Option<std::time::Instant>,
    /// Solve Coulomb sliding with its consistent tangent K_T^sl = μ p_N Bᵀd nᵀB (4.63), a
    /// nonsymmetric system for faer LU. Default false: each sliding contact's friction force
    /// is a load at the bound c + μ max(N, 0) of the state iteration's last normal force N,
    /// iterated until no bound moves by more than [`BOUND_TOLERANCE`] of itself (a fixed point
    /// on the bounds, as for Tresca friction with the bound updated), so every system stays
    /// symmetric for Cholesky and the low-rank corrections; at convergence both satisfy the
    /// same Coulomb law.
    pub consistent_coulomb_tangent: bool,
}

/// The relative change of a sliding Coulomb contact's bound c + μ max(N, 0) below which the
/// fixed point on the bounds has converged (see
/// [`IncrementalOptions::consistent_coulomb_tangent`]).
pub const BOUND_TOLERANCE: f64 = 1e-8;

/// State iterations of an increment after which the bounds of the Coulomb fixed point move by
/// half the step (see the update in the state iteration).
const BOUND_RELAXATION_AFTER: usize = 10;

/// State iterations of an increment with the Coulomb fixed point after which a sliding
/// contact's changes of direction or bound count as switches (see [`CHATTER_SWITCHES`]).
const SETTLING_ITERATIONS: usize = 20;

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
            consistent_coulomb_tangent: false,
        }
    }
}

/// One increment.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct IncrementRecord {
    /// Increment n (1-based).
    pub step: usize,
    /// Load factor α = n/N.
    pub alpha: f64,
    /// State iterations needed.
    pub iterations: usize,
    /// Numeric factorizations done in this increment.
    pub factorizations: usize,
    /// Solves done on an earlier factorization with the changed contacts as a low-rank
    /// correction instead of a new factorization (see [`IncrementalOptions::reuse_factor`]).
    pub factor_reuses: usize,
    /// Residual correction steps of those solves.
    pub reuse_iterations: usize,
    /// Contacts open, stuck and sliding at the end of the increment.
    pub open: usize,
    /// Stuck contacts.
    pub stick: usize,
    /// Sliding contacts.
    pub slip: usize,
    /// Applied nodal loads summed per DOF (Fx, Fy, Fz, Mx, My, Mz), times α.
    pub applied_load: [f64; 6],
    /// Support reactions summed per DOF.
    pub reaction: [f64; 6],
    /// For a periodic cell: the reactions of the six macroscopic drivers (stress resultants
    /// times the cell area).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub macro_reaction: Option<[f64; 6]>,
    /// Energy dissipated by sliding since the start, Σ F_t · Δs (J).
    pub dissipated: f64,
    /// Contacts that chattered (changed state or slip direction 4 times in this increment: the
    /// discrete penalty problem can have no consistent state for them) and were then held in
    /// their state for the rest of it.
    pub held: usize,
    /// Backend of the last solve.
    pub backend: String,
    /// Wall-clock seconds of the increment (not serialized: results files stay reproducible).
    #[serde(skip)]
    pub seconds: f64,
    /// Those seconds per stage (not serialized).
    #[serde(skip)]
    pub timings: IncrementTimings,
    /// Backward error of the last solve.
    pub backward_error: f64,
    /// Equilibrium residual ‖R‖₂ / (‖K q‖₂ + ‖α F‖₂) on the free DOFs at the converged state:
    /// R = α F − K q − f_c(q), the contact forces f_c those of the contact law itself (the
    /// return mapping's normal force, stick force or bound c + μ max(N, 0) along the slip
    /// direction, not the linearization the last system was assembled with), K q the
    /// elements' forces. About the solves' accuracy and the bounds' fixed-point tolerance.
    pub equilibrium_residual: f64,
    /// The energy of the increment's state (J): the work of the external forces so far, the
    /// elastic energy stored in the elements and contact springs, the energy of the
    /// stabilizing springs, and [`IncrementRecord::dissipated`].
    pub energy: EnergyBalance,
}

/// The energy balance of a stick/slip path: W_ext = E_el + E_stab + D up to the quadrature
/// of W_ext (the trapezoidal rule on each increment, exact where the response is linear in it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct EnergyBalance {
    /// Work of the external forces (loads and reactions, the macroscopic resultants of a cell)
    /// so far, by the trapezoidal rule over the increments: Σ ½ (f_{n−1} + f_n)·(q_n − q_{n−1}),
    /// f the generalized forces K q + f_c (at equilibrium the external ones).
    pub external_work: f64,
    /// Elastic energy: ½ qᵀ K q of the elements, and per closed contact ½ N²/p_N + ½ |F_t|²/p_T
    /// + ½ qᵀ K_R q of its springs.
    pub stored: f64,
    /// Energy of the stabilizing springs (0 without stabilization).
    pub stabilization: f64,
    /// |W_ext − E_el − E_stab − D| / W_ext (0 when no work was done).
    pub relative_error: f64,
}

/// One contact at the end of an increment.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ContactRecord {
    /// open, stick or slip.
    #[serde(serialize_with = "state_name")]
    pub state: ContactState,
    /// Current gap ḡ − nᵀ\[u\] (m; negative: penetration, which the penalty allows).
    pub gap: f64,
    /// Normal force N ≥ 0 (N).
    pub normal_force: f64,
    /// Tangential force vector in global coordinates (N).
    pub tangential_force: [f64; 3],
    /// Its magnitude (N).
    pub tangential_magnitude: f64,
    /// The friction bound μN or G at this state (N).
    pub friction_bound: f64,
    /// Tangential relative displacement of the contact points, global (m).
    pub relative_tangential: [f64; 3],
}

fn state_name<S: serde::Serializer>(s: &ContactState, ser: S) -> Result<S::Ok, S::Error> {
    ser.serialize_str(s.name())
}

/// Results of every increment.
#[derive(Clone, Debug)]
pub struct IncrementalSolution {
    /// The contact pairs.
    pub contacts: ContactSet,
    /// Per-increment summary.
    pub increments: Vec<IncrementRecord>,
    /// Per increment, every contact.
    pub contact_results: Vec<Vec<ContactRecord>>,
    /// Per increment, [ux, uy, uz, rx, ry, rz] of every node.
    pub displacements: Vec<Vec<[f64; 6]>>,
    /// Reactions at the end.
    pub reactions: Vec<Reaction>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Trial {
    state: ContactState,
    direction: Vector2<f64>,
    normal_force: f64,
    tangential: Vector2<f64>,
    bound: f64,
    relative: Vector2<f64>,
    penetration: f64,
    trial_norm: f64,
}

/// The contact law of a run: friction, and whether initially closed contacts are bonded
/// (never open).
#[derive(Clone, Copy, Debug)]
struct Law {
    friction: Friction,
    bonded: bool,
}

/// State switches of one contact within an increment after which it is held in its state.
const CHATTER_SWITCHES: usize = 4;

/// A sliding contact's direction has converged when the change |Δd| times its slip |u_t − s|
/// (the tangential displacement across the old direction the change stands for) is below this
/// fraction of the model size. Newton's iteration on the directions converges quadratically
/// down to roundoff, which on the benchmark's S cell reaches 1e-11 of the size for barely
/// sliding contacts: with 1e-12 or 1e-11 here some still chattered until held, with 1e-10
/// none, and the end resultant of the curve moved by less than 2e-10 of itself.
const SLIP_DIRECTION_TOLERANCE: f64 = 1e-10;

/// The backward error a factor-reuse CG solve must reach, relative to the accepted one of a
/// direct solve. The slip directions are read off the last digits of the tangential
/// displacements, so a CG solve must be as accurate as a direct one: at 1e-3 the directions of
/// barely sliding contacts wandered by 1e-3 between iterations (measured on the S cell).
const REUSE_ACCURACY: f64 = 1e-5;

/// The trial `t` of a contact held in `state` with slip direction `direction` (a contact that
/// chattered): forces consistent with that state (stick: the trial force; slip: the bound along
/// `direction`; open: none).
fn hold(mut t: Trial, state: ContactState, direction: Vector2<f64>) -> Trial {
    let trial = t.direction * t.trial_norm;
    match state {
        ContactState::Open => {
            t.normal_force = 0.0;
            t.tangential = Vector2::zeros();
        }
        ContactState::Stick => t.tangential = trial,
        ContactState::Slip => {
            t.direction = direction;
            t.tangential = direction * t.bound;
        }
    }
    t.state = state;
    t
}

/// Return mapping of one contact for the block displacement `q` and committed slip `s`.
/// `previous` is the state the system was solved with: within the tolerances (`length_tol` on
/// the penetration, a relative 1e-10 on the friction bound) a contact keeps it, so a contact
/// exactly at the switch point does not flip back and forth. A trial tangential force below
/// p_T · `length_tol` is roundoff: a closed contact keeps its state and slip direction (a
/// contact that carries nothing would otherwise slide in a direction set by noise).
fn classify(
    pair: &ContactPair,
    law: Law,
    q: &BlockVector,
    slip: &Vector2<f64>,
    previous: (ContactState, Vector2<f64>),
    length_tol: f64,
    fixed_direction: Option<Vector2<f64>>,
) -> Trial {
    let (previous, previous_direction) = previous;
    let friction = law.friction;
    let kin = pair.kinematics(q);
    let mut t = Trial {
        state: ContactState::Open,
        direction: Vector2::zeros(),
        normal_force: 0.0,
        tangential: Vector2::zeros(),
        bound: 0.0,
        relative: kin.tangential,
        penetration: kin.penetration,
        trial_norm: 0.0,
    };
    let closed_before = previous != ContactState::Open;
    let closes = if law.bonded {
        pair.gap <= 0.0
    } else if closed_before {
        kin.penetration > -length_tol
    } else {
        kin.penetration > length_tol
    };
    if !closes {
        return t;
    }
    t.normal_force = if law.bonded {
        pair.penalty_normal * kin.penetration
    } else {
        pair.penalty_normal * kin.penetration.max(0.0)
    };
    let trial = (kin.tangential - slip) * pair.penalty_tangent;
    let norm = trial.norm();
    t.trial_norm = norm;
    t.direction = if norm > 0.0 {
        trial / norm
    } else {
        Vector2::zeros()
    };
    t.bound = match friction {
        Friction::None => 0.0,
        Friction::Coulomb { mu, cohesion } => cohesion + mu * t.normal_force.max(0.0),
        Friction::Tresca { bound } => bound,
    };
    if closed_before && friction != Friction::None && norm <= pair.penalty_tangent * length_tol {
        t.state = previous;
        if previous == ContactState::Slip {
            t.direction = previous_direction;
            t.tangential = previous_direction * t.bound;
        } else {
            t.tangential = trial;
        }
        return t;
    }
    let margin = if previous == ContactState::Slip {
        1.0 - 1e-10
    } else {
        1.0 + 1e-10
    };
    if friction != Friction::None && norm <= t.bound * margin {
        t.state = ContactState::Stick;
        t.tangential = trial;
    } else if previous == ContactState::Slip
        && friction != Friction::None
        && t.direction.dot(&previous_direction) < 0.0
    {
        // A sliding contact cannot reverse without passing through stick: try stick first
        // (the solve under the old slip force says nothing about the elastic range).
        t.state = ContactState::Stick;
        t.tangential = trial;
    } else {
        t.state = ContactState::Slip;
        if let Some(d) = fixed_direction.filter(|d| d.norm() > 0.0) {
            t.direction = d;
        }
        t.tangential = t.direction * t.bound;
    }
    t
}

fn describe(model: &Model, set: &ContactSet, i: usize) -> String {
    let o = &set.origins[i];
    let side = |s: ContactSide| match s {
        ContactSide::Node(n) => format!("node {}", model.nodes[n].id),
        ContactSide::Point { element, xi } => {
            let e = model.elements()[element];
            format!(
                "fiber {} at nodes {}–{} ξ={xi:.3}",
                model.fibers[e.fiber].id, model.nodes[e.nodes[0]].id, model.nodes[e.nodes[1]].id
            )
        }
    };
    format!(
        "contact {} ({} / {})",
        i + 1,
        side(o.sides[0]),
        side(o.sides[1])
    )
}

/// The unscaled stabilizing spring of a contact in `state` (see
/// [`IncrementalOptions::stabilization`]): K_N + K_T^st + K_R when open, K_T^st when sliding.
fn stabilizer(pair: &ContactPair, state: ContactState) -> BlockMatrix {
    let (kt, _) = pair.stick(&Vector2::zeros());
    match state {
        ContactState::Open => pair.normal().0 + kt + pair.rotation(),
        _ => kt,
    }
}

/// [`stabilizer`]`(pair, state) q` from the jump basis G, Σₐ dₐ gₐ (gₐ · q) with the stick
/// coefficients d (open) or their tangential ones (sliding): the 30 × 30 block is never formed
/// (G D Gᵀ equals the assembled blocks, see `block_coefficients`).
fn stabilizer_force(pair: &ContactPair, state: ContactState, q: &BlockVector) -> BlockVector {
    let (pn, pt, pr) = (
        pair.penalty_normal,
        pair.penalty_tangent,
        pair.penalty_rotation,
    );
    let d = match state {
        ContactState::Open => [pn, pt, pt, pr, pr, pr],
        _ => [0.0, pt, pt, 0.0, 0.0, 0.0],
    };
    pair.jump_basis()
        .iter()
        .zip(d)
        .filter(|(_, da)| *da != 0.0)
        .fold(BlockVector::zeros(), |f, (ga, da)| {
            f + ga * (da * ga.dot(q))
        })
}

/// Columns of the low-rank correction kept on one factorization before refactorizing, by
/// default: S, their dense products, then takes 8 bytes × this squared (512 MB).
pub const MAX_LOW_RANK_COLUMNS: usize = 8192;

/// Correction steps x += W (b − A x) after a low-rank solve W ≈ A⁻¹ before it falls back to a
/// factorization (the correction subtracts stick springs far stiffer than the fibers, which
/// costs digits that one or two steps restore).
const MAX_REFINEMENTS: usize = 3;

/// What a factorization and the capacitance factorization cost in this run, measured: a
/// low-rank solve (the capacitance factorization and one solve with A₀, against a
/// factorization and one solve) is done while its capacitance factorization is predicted
/// cheaper than a factorization. New columns of U are not charged: each is computed once (a
/// solve among many right-hand sides) and serves every later solve on the same reference.
struct LowRankCost {
    factorize: Option<f64>,
    /// Flops per second of the capacitance factorization (2/3 R³ flops as an LU), last measured.
    lu_rate: f64,
}

impl LowRankCost {
    fn worth(&self, order: usize) -> bool {
        let lu = 2.0 / 3.0 * (order as f64).powi(3) / self.lu_rate;
        self.factorize.is_some_and(|f| lu <= f)
    }
}

/// A low-rank solve that reached `tolerance`: the solution, its backward error, its relative
/// residual ‖b − Ax‖₂/‖b‖₂ and the correction steps it took.
struct LowRankSolve {
    x: Vec<f64>,
    backward_error: f64,
    relative_residual: f64,
    refinements: usize,
}

/// The solve report of a checked low-rank solution.
fn low_rank_report(r: &LowRankSolve) -> SolveReport {
    SolveReport {
        backend: "low-rank",
        relative_residual: r.relative_residual,
        backward_error: r.backward_error,
        info: SolveInfo {
            iterations: Some(r.refinements),
            ..SolveInfo::default()
        },
    }
}

/// What a low-rank solution of one state iteration is checked against: the assembled matrix A
/// and load b, and the backward error to reach.
struct ResidualCheck<'a> {
    a: CscRef<'a>,
    symmetric: bool,
    b: &'a [f64],
    tolerance: f64,
}

/// Corrects `first`, a solution of A x = b by the low-rank correction `cap` of the reference
/// factorization `a0`, with the residual of the assembled A until the backward error is at
/// most the check's tolerance; `None` when [`MAX_REFINEMENTS`] steps do not get there (or the
/// capacitance matrix is singular).
fn refine_low_rank(
    low_rank: &LowRankCorrection,
    a0: &mut dyn LinearSolver,
    cap: &Capacitance,
    check: &ResidualCheck<'_>,
    first: Result<Vec<f64>, SolverError>,
) -> Result<Option<LowRankSolve>, SolverError> {
    let ResidualCheck {
        a,
        symmetric,
        b,
        tolerance,
    } = *check;
    let Ok(mut x) = first else {
        return Ok(None);
    };
    let mut ax = vec![0.0; b.len()];
    let mut norm_a = None;
    for refinements in 0..=MAX_REFINEMENTS {
        let norm_a = *norm_a.get_or_insert_with(|| {
            if symmetric {
                a.mul_vec_symmetric_norm_par(&x, &mut ax)
            } else {
                a.mul_vec(&x, &mut ax);
                norm_inf(a)
            }
        });
        if refinements > 0 {
            if symmetric {
                a.mul_vec_symmetric_par(&x, &mut ax);
            } else {
                a.mul_vec(&x, &mut ax);
            }
        }
        let backward_error = backward_from_product(norm_a, &ax, &x, b);
        if !backward_error.is_finite() {
            return Ok(None);
        }
        if backward_error <= tolerance {
            return Ok(Some(LowRankSolve {
                relative_residual: relative_from_product(&ax, b),
                x,
                backward_error,
                refinements,
            }));
        }
        if refinements == MAX_REFINEMENTS {
            break;
        }
        let r: Vec<f64> = b.iter().zip(&ax).map(|(p, q)| p - q).collect();
        let Ok(dx) = low_rank.solve(a0, cap, &r) else {
            return Ok(None);
        };
        x.iter_mut().zip(&dx).for_each(|(xi, d)| *xi += d);
    }
    Ok(None)
}

/// A contact as the reference factorization has it: block coefficients, what they and the
/// load were computed from, and the anchor of the k⊥ spring.
struct ReferenceBlock {
    stiffness: BlockCoefficients,
    state: BlockState,
    /// The contact's friction law in the reference (a Coulomb contact's bound there).
    friction: Friction,
    anchor: Vector2<f64>,
    /// The slip its load was computed at: the reference load b₀ keeps it, so that b₀ changes
    /// with α only (see [`AffineReferences`]); a contact whose slip moved since is a change.
    slip: Vector2<f64>,
}

/// Adds G ΔD Gᵀ, the change `e` of `pair`'s block coefficients, to its slots in `values`.
fn add_block_change(pair: &ContactPair, slots: &[u32], e: &BlockCoefficients, values: &mut [f64]) {
    let g = pair.jump_basis();
    let m = pair.size();
    for r in 0..m {
        let ge: [f64; 6] = std::array::from_fn(|b| (0..6).map(|a| g[a][r] * e[(a, b)]).sum());
        for c in 0..m {
            let s = slots[r * m + c];
            if s != NO_SLOT {
                values[s as usize] += (0..6).map(|b| ge[b] * g[b][c]).sum::<f64>();
            }
        }
    }
}

/// Brings `values` to A₀'s values (`reference_values`) plus the blocks of `changes` when
/// `behind`: the slots of the contacts changed since the reference (`changed`; every value
/// when unknown) restored, then the changes added. The stick/slip iteration calls it only where
/// the matrix is read, so iterations that neither check a residual nor factorize skip it.
fn catch_up_values(
    values: &mut [f64],
    behind: &mut bool,
    reference_values: &[f64],
    pattern: &Pattern,
    pairs: &[ContactPair],
    changes: Option<&[ContactChange]>,
    changed: &mut Option<Vec<usize>>,
) {
    let (true, Some(changes)) = (std::mem::take(behind), changes) else {
        return;
    };
    match changed.take() {
        Some(contacts) => {
            for i in contacts {
                for &slot in pattern.extra_slots(i) {
                    if slot != NO_SLOT {
                        values[slot as usize] = reference_values[slot as usize];
                    }
                }
            }
        }
        None => values.copy_from_slice(reference_values),
    }
    *changed = Some(changes.iter().map(|ch| ch.contact).collect());
    for ch in changes {
        add_block_change(
            &pairs[ch.contact],
            pattern.extra_slots(ch.contact),
            &ch.stiffness,
            values,
        );
    }
}

/// ‖f − α F‖₂ over the free DOFs of the generalized force vector `forces` (‖f‖₂ without
/// `load`, F given on the free DOFs).
fn free_norm(disc: &Discretization, forces: &[f64], load: Option<(&[f64], f64)>) -> f64 {
    forces
        .iter()
        .enumerate()
        .filter_map(|(g, f)| {
            let r = disc.reduced(g)?;
            Some(f - load.map_or(0.0, |(l, alpha)| alpha * l[r]))
        })
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt()
}

/// Whether a sliding contact's force in the solved system, the bound along the direction it
/// was assembled with (`direction`) plus the k⊥ spring stretched from its anchor
/// (`perpendicular`), differs from the law's, the bound along the trial direction, by more
/// than [`BOUND_TOLERANCE`] of the bound. The direction test of the state iteration measures
/// the change in displacement, which misses this where p_T (and with it k⊥) is large: on the
/// S cell a contact with k⊥ = 1.6·10⁷ N/m passed it with a spring force of 3.6·10⁻³ of its
/// bound, the equilibrium residual of the increment 5.6·10⁻⁴.
fn unsettled_force(t: &Trial, direction: Vector2<f64>, perpendicular: (f64, Vector2<f64>)) -> bool {
    if t.state != ContactState::Slip || !(t.bound > 0.0) {
        return false;
    }
    let (k_perp, anchor) = perpendicular;
    let across = Vector2::new(-direction[1], direction[0]);
    let spring = k_perp * across.dot(&(t.relative - anchor));
    let error = t.bound * (t.direction - direction).norm() + spring.abs();
    error > BOUND_TOLERANCE * t.bound
}

/// The rows of `pair`'s block on free DOFs: (row in the block, free DOF).
fn free_rows<'a>(
    pair: &'a ContactPair,
    disc: &'a Discretization,
) -> impl Iterator<Item = (usize, usize)> + 'a {
    (0..pair.size()).filter_map(move |r| {
        disc.reduced(6 * pair.jump.nodes[r / 6] + r % 6)
            .map(|i| (r, i))
    })
}

/// The column of U for basis row `k` of `pair`'s jump basis in the free DOFs.
fn low_rank_column(pair: &ContactPair, disc: &Discretization, k: usize) -> SparseColumn {
    let g = pair.jump_basis()[k];
    let mut col: SparseColumn = free_rows(pair, disc).map(|(r, i)| (i, g[r])).collect();
    col.sort_unstable_by_key(|e| e.0);
    col.dedup_by(|b, a| {
        if a.0 == b.0 {
            a.1 += b.1;
            true
        } else {
            false
        }
    });
    col.retain(|e| e.1 != 0.0);
    col
}

/// What an assembled matrix was built from: symmetry, states, slip directions, k⊥ of each contact.
type AssembledKey = (bool, Vec<ContactState>, Vec<Vector2<f64>>, Vec<f64>);

struct Backends {
    symmetric: Option<Box<dyn LinearSolver>>,
    general: Option<Box<dyn LinearSolver>>,
    /// The reference factorization A₀ of the low-rank solves, kept apart from `symmetric`
    /// so that direct solves in between do not discard the correction's columns.
    reference: Option<Box<dyn LinearSolver>>,
}

/// Runs the incremental stick/slip analysis of `model` (its supports, loads and contacts).
pub fn solve_incremental(
    model: &Model,
    opts: &IncrementalOptions,
) -> Result<IncrementalSolution, Error> {
    if model.cell.is_some() && model.supports.is_empty() {
        return Err(Error::CellWithoutSupports);
    }
    let set = ContactSet::build(model)?;
    run_incremental(model, &Discretization::supported(model), set, opts, None)
}

/// Called once with the run's first reference factorization when that is the all-stick matrix
/// (every closed contact in stick, every other open; open contacts carry their stabilizing
/// springs when [`IncrementalOptions::stabilization`] > 0): the factorized solver and the
/// matrix. The elasto-plastic curve solves its six elastic cell problems on it.
pub(crate) type OnAllStick<'h> =
    &'h mut dyn FnMut(&mut dyn LinearSolver, CscRef<'_>) -> Result<(), Error>;

/// The elastic part on a discretization: element blocks on generalized nodes.
struct Elastic {
    /// Generalized nodes and T of every element (None: the element's own nodes, T = I).
    maps: Vec<Option<(Vec<usize>, DMatrix<f64>)>>,
    /// The discretization is the identity (a supported structure).
    identity: bool,
    /// Every element's Tᵀ K T, kept after first use when they take at most
    /// [`ELEMENT_CACHE_BYTES`] (the internal forces of every increment's commit need them).
    cache: OnceLock<Option<Vec<DMatrix<f64>>>>,
}

/// Largest memory the element matrices of the commit are kept in.
const ELEMENT_CACHE_BYTES: usize = 512 << 20;

impl Elastic {
    fn new(model: &Model, disc: &Discretization) -> Self {
        let identity = disc.is_identity();
        Elastic {
            maps: model
                .elements()
                .iter()
                .map(|e| {
                    if identity {
                        None
                    } else {
                        disc.non_identity_block(&e.nodes)
                    }
                })
                .collect(),
            identity,
            cache: OnceLock::new(),
        }
    }

    /// Every element's Tᵀ K T when they fit in [`ELEMENT_CACHE_BYTES`].
    fn cached(&self, model: &Model) -> Option<&[DMatrix<f64>]> {
        self.cache
            .get_or_init(|| {
                let bytes: usize = (0..self.maps.len())
                    .map(|e| 8 * (6 * self.block_nodes(model, e)).pow(2))
                    .sum();
                (bytes <= ELEMENT_CACHE_BYTES)
                    .then(|| self.matrices(model).map(|(_, k)| k).collect())
            })
            .as_deref()
    }

    /// `f(e, Tᵀ K T)` for every element in order, from the cache when it fits.
    fn for_each_matrix(&self, model: &Model, mut f: impl FnMut(usize, &DMatrix<f64>)) {
        match self.cached(model) {
            Some(all) => all.iter().enumerate().for_each(|(e, k)| f(e, k)),
            None => self.matrices(model).for_each(|(e, k)| f(e, &k)),
        }
    }

    /// Nodes of element e's block.
    fn block_nodes(&self, model: &Model, e: usize) -> usize {
        match &self.maps[e] {
            Some((g, _)) => g.len(),
            None => model.elements()[e].nodes.len(),
        }
    }

    /// The generalized nodes of element e's block.
    fn gnodes_of<'a>(&'a self, model: &'a Model, e: usize) -> &'a [usize] {
        match &self.maps[e] {
            Some((g, _)) => g,
            None => &model.elements()[e].nodes,
        }
    }

    /// Tᵀ K T of element e on its generalized nodes.
    fn matrix(&self, model: &Model, e: usize) -> DMatrix<f64> {
        let k = element_stiffness(model, e);
        let k = DMatrix::from_fn(12, 12, |r, c| k[(r, c)]);
        match &self.maps[e] {
            Some((_, t)) => t.transpose() * k * t,
            None => k,
        }
    }

    /// (element, Tᵀ K T) of every element in order, computed in parallel chunks.
    fn matrices<'a>(
        &'a self,
        model: &'a Model,
    ) -> impl Iterator<Item = (usize, DMatrix<f64>)> + 'a {
        const CHUNK: usize = 4096;
        (0..self.maps.len()).step_by(CHUNK).flat_map(move |start| {
            let end = (start + CHUNK).min(self.maps.len());
            let mats: Vec<DMatrix<f64>> = (start..end)
                .into_par_iter()
                .map(|e| self.matrix(model, e))
                .collect();
            (start..end).zip(mats)
        })
    }

    fn fill(
        &self,
        model: &Model,
        pattern: &Pattern,
        values: &mut [f64],
        mode: crate::assembly::FillMode,
    ) -> Result<(), Error> {
        if self.identity {
            Assembler::new(model).fill(model, pattern, values, mode)?;
            return Ok(());
        }
        values.iter_mut().for_each(|v| *v = 0.0);
        self.for_each_matrix(model, |e, k| {
            let m = k.nrows();
            let slots = pattern.element_slots(e);
            for r in 0..m {
                for c in 0..m {
                    let s = slots[r * m + c];
                    if s != NO_SLOT {
                        values[s as usize] += k[(r, c)];
                    }
                }
            }
        });
        Ok(())
    }

    /// F_f − K_fc u_c at α = 1, with the nodal loads mapped onto generalized nodes.
    /// The nodal loads F of the model on the free DOFs (α = 1).
    fn applied(model: &Model, disc: &Discretization) -> Vec<f64> {
        let mut rhs = vec![0.0; disc.n_free()];
        for l in &model.loads {
            let (gnodes, t) = disc.block(&[l.node]);
            for c in 0..t.ncols() {
                if let Some(r) = disc.reduced(6 * gnodes[c / 6] + c % 6) {
                    rhs[r] += t[(l.dof.index(), c)] * l.value;
                }
            }
        }
        rhs
    }

    /// The load of the linear system for α = 1: F and the products of the elements with the
    /// prescribed DOFs.
    fn rhs(&self, model: &Model, disc: &Discretization) -> Vec<f64> {
        let mut rhs = Self::applied(model, disc);
        for e in 0..self.maps.len() {
            let gnodes = self.gnodes_of(model, e);
            let prescribed = |c: usize| {
                let g = 6 * gnodes[c / 6] + c % 6;
                disc.reduced(g)
                    .is_none()
                    .then(|| disc.prescribed_value(g))
                    .filter(|v| *v != 0.0)
            };
            if !(0..6 * gnodes.len()).any(|c| prescribed(c).is_some()) {
                continue;
            }
            let k = self.matrix(model, e);
            for r in 0..k.nrows() {
                if let Some(i) = disc.reduced(6 * gnodes[r / 6] + r % 6) {
                    for c in 0..k.ncols() {
                        if let Some(v) = prescribed(c) {
                            rhs[i] -= k[(r, c)] * v;
                        }
                    }
                }
            }
        }
        rhs
    }

    /// Generalized internal forces K q for the full generalized vector q.
    fn internal(&self, model: &Model, q: &[f64]) -> Vec<f64> {
        if self.identity {
            return internal_forces(model, &q[..6 * model.nodes.len()]);
        }
        // Column by column, a node's six rows at a time (contiguous in K and in `out`).
        let add = |out: &mut [f64], e: usize, k: &DMatrix<f64>| {
            let gnodes = self.gnodes_of(model, e);
            for (c, column) in k.as_slice().chunks_exact(k.nrows()).enumerate() {
                let qc = q[6 * gnodes[c / 6] + c % 6];
                if qc == 0.0 {
                    continue;
                }
                for (&g, rows) in gnodes.iter().zip(column.chunks_exact(6)) {
                    for (o, v) in out[6 * g..6 * g + 6].iter_mut().zip(rows) {
                        *o += v * qc;
                    }
                }
            }
        };
        match self.cached(model) {
            // One slice of the elements per thread, each into its own vector, summed.
            Some(all) => {
                let chunk = all.len().div_ceil(rayon::current_num_threads()).max(1);
                let parts: Vec<Vec<f64>> = all
                    .par_chunks(chunk)
                    .enumerate()
                    .map(|(p, ks)| {
                        let mut out = vec![0.0; q.len()];
                        for (i, k) in ks.iter().enumerate() {
                            add(&mut out, p * chunk + i, k);
                        }
                        out
                    })
                    .collect();
                let mut parts = parts.into_iter();
                let mut out = parts.next().unwrap_or_else(|| vec![0.0; q.len()]);
                for part in parts {
                    out.iter_mut().zip(&part).for_each(|(o, v)| *o += v);
                }
                out
            }
            None => {
                let mut out = vec![0.0; q.len()];
                self.matrices(model).for_each(|(e, k)| add(&mut out, e, &k));
                out
            }
        }
    }
}

/// The incremental analysis on any discretization (supported structure or periodic cell).
pub(crate) fn run_incremental(
    model: &Model,
    disc: &Discretization,
    set: ContactSet,
    opts: &IncrementalOptions,
    mut on_all_stick: Option<OnAllStick<'_>>,
) -> Result<IncrementalSolution, Error> {
    let path: Vec<f64> = match &opts.path {
        Some(p) => p.clone(),
        None => (1..=opts.steps)
            .map(|n| n as f64 / opts.steps as f64)
            .collect(),
    };
    if path.is_empty() {
        return Err(Error::InvalidOption(
            "the number of increments must be at least 1".into(),
        ));
    }
    if let Some(a) = path.iter().find(|a| !a.is_finite()) {
        return Err(Error::InvalidOption(format!(
            "load factor {a} is not finite"
        )));
    }
    if opts.max_state_iterations == 0 {
        return Err(Error::InvalidOption(
            "max_state_iterations must be at least 1".into(),
        ));
    }
    let friction = model
        .contact
        .as_ref()
        .map_or(Friction::None, |c| c.friction);
    let bonded = opts.bonded || model.contact.as_ref().is_some_and(|c| c.bonded);
    // Coulomb sliding by a fixed point on the bounds (see
    // IncrementalOptions::consistent_coulomb_tangent): each contact's bound c + μ max(N, 0) at
    // the last classification, the load its sliding force is assembled with.
    let bound_fixed_point = matches!(friction, Friction::Coulomb { mu, .. } if mu > 0.0)
        && !opts.consistent_coulomb_tangent;
    let mut bounds: Vec<f64> = match friction {
        Friction::Coulomb { cohesion, .. } => vec![cohesion; set.pairs.len()],
        _ => Vec::new(),
    };
    let fixed: Vec<Option<Vector2<f64>>> =
        if opts.fixed_slip_direction && friction != Friction::None {
            let mut frictionless = model.clone();
            if let Some(c) = frictionless.contact.as_mut() {
                c.friction = Friction::None;
            }
            let pre = run_incremental(
                &frictionless,
                disc,
                set.clone(),
                &IncrementalOptions {
                    fixed_slip_direction: false,
                    deadline: None,
                    ..opts.clone()
                },
                None,
            )?;
            let last = pre.contact_results.last().cloned().unwrap_or_default();
            set.pairs
                .iter()
                .zip(&last)
                .map(|(p, r)| {
                    let g = Vector3::from(r.relative_tangential);
                    let d = Vector2::new(p.tangents[0].dot(&g), p.tangents[1].dot(&g));
                    (d.norm() > 0.0).then(|| d / d.norm())
                })
                .collect()
        } else {
            vec![None; set.pairs.len()]
        };
    // Contact jumps on generalized nodes: B T.
    let pairs: Vec<ContactPair> = set.pairs.iter().map(|p| disc.contact_pair(p)).collect();
    let elastic = Elastic::new(model, disc);
    let mut blocks: Vec<Vec<usize>> = (0..model.elements().len())
        .map(|e| elastic.gnodes_of(model, e).to_vec())
        .collect();
    blocks.extend(pairs.iter().map(|p| p.jump.nodes.clone()));
    let block_refs: Vec<&[usize]> = blocks.iter().map(|b| &b[..]).collect();
    let pattern = Pattern::from_blocks(
        disc.reduced_indices(),
        disc.n_free(),
        &block_refs,
        model.elements().len(),
    )?;
    let mut k_elastic = vec![0.0; pattern.nnz()];
    elastic.fill(model, &pattern, &mut k_elastic, opts.solve.fill)?;
    // Contacts by color: no two of a color share a generalized node (the driver, which has no
    // rows, aside), so a color's contacts are scattered in parallel.
    let contact_colors = color_blocks(
        disc.n_gnodes(),
        pairs.iter().map(|p| &p.jump.nodes[..]),
        disc.driver(),
    );
    let rhs_full = elastic.rhs(model, disc);
    let applied_free = Elastic::applied(model, disc);
    let n_free = disc.n_free();
    let mut applied_full = [0.0; 6];
    for l in &model.loads {
        applied_full[l.dof.index()] += l.value;
    }
    let mut backends = Backends {
        symmetric: None,
        general: None,
        reference: None,
    };
    // Low-rank solves need a direct symmetric backend.
    let solver_config = opts.solve.solver_config(disc.node_block_starts());
    let low_rank_possible = opts.reuse_factor
        && solver_config
            .build()
            .is_ok_and(|s| !s.capabilities().iterative);
    // Set when the correction outgrew its columns or missed its accuracy: the next symmetric
    // factorization becomes the new reference.
    let mut refresh_reference = false;
    let locate = |e: SolverError| disc.locate(model, e);

    // Contact states: closed pairs start in stick (thesis step 1), others open.
    let initial = |p: &ContactPair| {
        if p.gap <= 0.0 {
            if friction == Friction::None {
                ContactState::Slip
            } else {
                ContactState::Stick
            }
        } else {
            ContactState::Open
        }
    };
    let mut states: Vec<ContactState> = pairs.iter().map(initial).collect();
    let mut directions: Vec<Vector2<f64>> = vec![Vector2::zeros(); pairs.len()];
    let mut slips: Vec<Vector2<f64>> = vec![Vector2::zeros(); pairs.len()];
    // Consistent tangent across the slip direction: (k⊥, anchor) per contact.
    let mut perpendicular: Vec<(f64, Vector2<f64>)> = vec![(0.0, Vector2::zeros()); pairs.len()];
    // What the current factorization was built from (None: nothing factorized yet).
    let mut factorized: Option<AssembledKey> = None;

    let length_tol = 1e-12 * model.size();
    let direction_tol = SLIP_DIRECTION_TOLERANCE * model.size();
    let mut values = k_elastic.clone();
    let mut q = vec![0.0; 6 * disc.n_gnodes()];
    let mut out = IncrementalSolution {
        contacts: set.clone(),
        increments: Vec::with_capacity(path.len()),
        contact_results: Vec::with_capacity(path.len()),
        displacements: Vec::with_capacity(path.len()),
        reactions: Vec::new(),
    };
    let gather = |q: &[f64], nodes: &[usize]| {
        let mut v = BlockVector::zeros();
        for (k, &n) in nodes.iter().enumerate() {
            for d in 0..6 {
                v[6 * k + d] = q[6 * n + d];
            }
        }
        v
    };

    let stabilization = opts.stabilization;
    if !(stabilization.is_finite() && stabilization >= 0.0) {
        return Err(Error::InvalidOption(format!(
            "stabilization = {stabilization} must be finite and ≥ 0"
        )));
    }
    let mut dissipated = 0.0;
    // W_ext so far, and the generalized forces and displacements of the last increment.
    let mut external_work = 0.0;
    let mut previous = (
        vec![0.0; 6 * disc.n_gnodes()],
        vec![0.0; 6 * disc.n_gnodes()],
    );
    // CG iterations preconditioned by the previous factorization allowed per solve (0: none).
    let mut low_rank_cost = LowRankCost {
        factorize: None,
        lu_rate: 1e10,
    };
    // The block coefficients of every contact in the last symmetric factorization (the
    // reference A₀ of the low-rank solves), and the correction accumulated on it.
    let mut reference: Option<Vec<ReferenceBlock>> = None;
    // A₀⁻¹ b₀ for this increment, b₀ the load with every contact as in the reference (its
    // state, slip direction and slip there).
    let mut reference_solution: Option<Reference>;
    let mut low_rank = LowRankCorrection::new(n_free, pairs.len());
    // The references of earlier increments' b₀ on it, when b₀ is affine in α.
    let mut affine = AffineReferences::default();
    let mut reference_values = vec![0.0; pattern.nnz()];
    // When `values` is `reference_values` plus the blocks of these contacts only: restoring
    // their slots is enough to start the next iteration from the reference.
    let mut changed_since_reference: Option<Vec<usize>> = None;
    // Per contact, its block columns on prescribed DOFs (their products go to the load).
    let prescribed: Vec<Vec<usize>> = pairs
        .iter()
        .map(|p| {
            (0..p.size())
                .filter(|&c| disc.reduced(6 * p.jump.nodes[c / 6] + c % 6).is_none())
                .collect()
        })
        .collect();
    // The loads of the contacts without prescribed DOFs in their base states (open as open, the
    // others stuck) with the slips they were summed at: kept across increments and updated at
    // the contacts whose base state or slip changed (few per increment), instead of summed anew.
    let mut contact_base_load: Option<KeptContactLoads> = None;
    let block_state = |states: &[ContactState],
                       directions: &[Vector2<f64>],
                       perpendicular: &[(f64, Vector2<f64>)],
                       i: usize| BlockState {
        state: states[i],
        direction: directions[i],
        k_perp: perpendicular[i].0,
    };
    for (step, &alpha) in (1..).zip(&path) {
        let increment_start = std::time::Instant::now();
        // New α and committed slips: a new reference load.
        reference_solution = None;
        // The contacts' states in it (open as open, all others as stuck) at the first
        // load-only assembly of this increment, and α F + their loads.
        let mut base_load: Option<(Vec<ContactState>, Vec<f64>)> = None;
        // Per contact γ = Gᵀ α ū on its prescribed DOFs: its block's products with them are
        // the load −G D γ.
        let prescribed_jump: Vec<Vector6<f64>> = pairs
            .iter()
            .zip(&prescribed)
            .map(|(p, cols)| {
                if cols.is_empty() {
                    return Vector6::zeros();
                }
                let g = p.jump_basis();
                Vector6::from_fn(|b, _| {
                    cols.iter()
                        .map(|&c| {
                            let gdof = 6 * p.jump.nodes[c / 6] + c % 6;
                            g[b][c] * alpha * disc.prescribed_value(gdof)
                        })
                        .sum()
                })
            })
            .collect();
        let mut factorizations = 0;
        let mut factor_reuses = 0;
        let mut reuse_iterations_done = 0;
        let mut converged = None;
        // State switches per contact in this increment (chatter detection).
        let mut switches = vec![0usize; pairs.len()];
        let mut timings = IncrementTimings::default();
        let lap = IncrementTimings::lap;
        let mut clock = increment_start;
        for iteration in 1..=opts.max_state_iterations {
            // The friction law contact i is assembled with.
            let friction_of = |i: usize| -> Friction {
                if bound_fixed_point {
                    Friction::Tresca { bound: bounds[i] }
                } else {
                    friction
                }
            };
            let mut refactorized = false;
            // Assemble K + K_N + K_T and α F + F_N + F_T for the current states: once a
            // symmetric factorization is the reference, its values plus the blocks of the
            // contacts that changed since (G ΔD Gᵀ), else element and contact blocks anew.
            let changes: Option<Vec<ContactChange>> = reference.as_ref().map(|reference| {
                (0..pairs.len())
                    .into_par_iter()
                    .with_min_len(256)
                    .filter_map(|i| {
                        let current = block_state(&states, &directions, &perpendicular, i);
                        let r = &reference[i];
                        let stiffness =
                            pairs[i].block_coefficients(&current, friction_of(i), stabilization)
                                - r.stiffness;
                        let load = pairs[i].load_coefficients(
                            &current,
                            &perpendicular[i].1,
                            &slips[i],
                            friction_of(i),
                        ) - pairs[i]
                            .load_coefficients(&r.state, &r.anchor, &r.slip, r.friction)
                            - stiffness * prescribed_jump[i];
                        let change = ContactChange {
                            contact: i,
                            stiffness,
                            load,
                        };
                        change.is_change().then_some(change)
                    })
                    .collect()
            });
            // With a reference, the values follow the changes only where the matrix is read
            // (a residual check or a factorization): until then `values_behind`.
            let mut values_behind = changes.is_some();
            if changes.is_none() {
                changed_since_reference = None;
                values.copy_from_slice(&k_elastic);
            }
            let write_values = changes.is_none();
            let mut rhs: Vec<f64> = rhs_full.iter().map(|v| alpha * v).collect();
            let closed: Vec<&[usize]> = (0..pairs.len())
                .filter(|&i| states[i] != ContactState::Open)
                .map(|i| &set.pairs[i].jump.nodes[..])
                .collect();
            let nonsymmetric = opts.consistent_coulomb_tangent
                && matches!(friction, Friction::Coulomb { mu, .. } if mu > 0.0)
                && states.contains(&ContactState::Slip);
            // K_N + K_T^sl (+ the consistent tangent k⊥ across the slip direction) + K_R
            // (+ ε K_T^st) and its load, of a sliding contact.
            let sliding_block = |i: usize| -> (BlockMatrix, BlockVector) {
                let pair = &pairs[i];
                let (mut k, mut f) = pair.normal();
                let (ks, fs) = pair.slip(friction_of(i), &directions[i]);
                k += ks + pair.rotation();
                f += fs;
                if perpendicular[i].0 > 0.0 {
                    let (kp, fp) = pair.slip_perpendicular(
                        &directions[i],
                        perpendicular[i].0,
                        &perpendicular[i].1,
                    );
                    k += kp;
                    f += fp;
                }
                if stabilization > 0.0 {
                    k += stabilizer(pair, ContactState::Slip) * stabilization;
                }
                (k, f)
            };
            // Contact i's load in `state`, times `sign`, into `rhs`, and with `values` its
            // block into the matrix: the caller keeps concurrent calls on distinct nodes.
            let contact_into = |i: usize,
                                state: ContactState,
                                sign: f64,
                                rhs: &SharedMut<f64>,
                                values: Option<&SharedMut<f64>>| {
                let pair = &pairs[i];
                let m = pair.size();
                let slots = pattern.extra_slots(i);
                let gdof = |r: usize| 6 * pair.jump.nodes[r / 6] + r % 6;
                let scatter = |k: &dyn Fn(usize, usize) -> f64, f: &BlockVector| {
                    for r in 0..m {
                        let Some(ir) = disc.reduced(gdof(r)) else {
                            continue;
                        };
                        // SAFETY: row r is a free DOF of a node no concurrent call holds, and
                        // so are the slots of row r.
                        let rhs_r = unsafe { rhs.get(ir) };
                        *rhs_r += sign * f[r];
                        if let Some(values) = values {
                            for c in 0..m {
                                let s = slots[r * m + c];
                                if s != NO_SLOT {
                                    // SAFETY: as above.
                                    unsafe { *values.get(s as usize) += k(r, c) };
                                }
                            }
                        }
                        for &c in &prescribed[i] {
                            *rhs_r -= sign * k(r, c) * alpha * disc.prescribed_value(gdof(c));
                        }
                    }
                };
                match state {
                    // Stuck contacts, the most, entry by entry: K_N + K_T^st + K_R.
                    ContactState::Stick => {
                        scatter(&pair.closed_stiffness(true), &pair.stick_load(&slips[i]))
                    }
                    // ε (K_N + K_T^st + K_R), the open contact's stabilizer.
                    ContactState::Open if stabilization > 0.0 => {
                        let k = pair.closed_stiffness(true);
                        scatter(&|r, c| stabilization * k(r, c), &BlockVector::zeros())
                    }
                    ContactState::Open => {}
                    ContactState::Slip => {
                        let (k, f) = sliding_block(i);
                        scatter(&|r, c| k[(r, c)], &f)
                    }
                }
            };
            // Color by color in parallel (sums independent of the number of threads).
            // (`None`: the contact is left out.)
            let by_colors = |state: &(dyn Fn(usize) -> Option<ContactState> + Sync),
                             rhs: &mut [f64],
                             values: Option<&mut [f64]>| {
                let shared_rhs = SharedMut::new(rhs);
                let shared_values = values.map(SharedMut::new);
                for color in &contact_colors {
                    color.par_iter().with_min_len(16).for_each(|&i| {
                        if let Some(state) = state(i) {
                            contact_into(i, state, 1.0, &shared_rhs, shared_values.as_ref())
                        }
                    });
                }
            };
            if write_values {
                // The contact blocks and loads for the current states.
                by_colors(&|i| Some(states[i]), &mut rhs, Some(&mut values));
            } else {
                // Only the load: once per increment every contact stuck, or open if it is open
                // now (α and the slips are fixed within it), then the contacts in another state
                // swapped in.
                let (base_states, base) = base_load.get_or_insert_with(|| {
                    let states: Vec<ContactState> = states
                        .iter()
                        .map(|&s| match s {
                            ContactState::Open => ContactState::Open,
                            _ => ContactState::Stick,
                        })
                        .collect();
                    // The contacts without prescribed DOFs: their kept sum, updated where the
                    // base state or the slip changed (an open contact's load is zero, a stuck
                    // one's its stick load).
                    let free = |i: usize| prescribed[i].is_empty();
                    let kept = contact_base_load.get_or_insert_with(|| {
                        let mut sum = vec![0.0; rhs.len()];
                        by_colors(&|i| free(i).then_some(states[i]), &mut sum, None);
                        KeptContactLoads::new(&states, &slips, sum)
                    });
                    kept.update(&states, &slips, free, |i, state, slip, sign, out| {
                        if state != ContactState::Stick {
                            return;
                        }
                        let f = pairs[i].stick_load(slip);
                        for (r, ir) in free_rows(&pairs[i], disc) {
                            out[ir] += sign * f[r];
                        }
                    });
                    let mut base: Vec<f64> =
                        rhs.iter().zip(kept.sum()).map(|(r, k)| r + k).collect();
                    // The contacts on prescribed DOFs, whose loads follow α.
                    by_colors(&|i| (!free(i)).then_some(states[i]), &mut base, None);
                    (states, base)
                });
                rhs.copy_from_slice(base);
                let shared_rhs = SharedMut::new(&mut rhs);
                for i in (0..pairs.len()).filter(|&i| states[i] != base_states[i]) {
                    if !prescribed[i].is_empty() {
                        contact_into(i, base_states[i], -1.0, &shared_rhs, None);
                        contact_into(i, states[i], 1.0, &shared_rhs, None);
                        continue;
                    }
                    let base_state = BlockState {
                        state: base_states[i],
                        direction: Vector2::zeros(),
                        k_perp: 0.0,
                    };
                    // No prescribed DOFs: the load alone, G (φ − φ_base) (see
                    // ContactPair::load_coefficients), without the block.
                    let pair = &pairs[i];
                    let (anchor, slip) = (&perpendicular[i].1, &slips[i]);
                    let current = block_state(&states, &directions, &perpendicular, i);
                    let phi = pair.load_coefficients(&current, anchor, slip, friction_of(i))
                        - pair.load_coefficients(&base_state, anchor, slip, friction_of(i));
                    let mut f = BlockVector::zeros();
                    for (ga, pa) in pair.jump_basis().iter().zip(phi.iter()) {
                        f += ga * *pa;
                    }
                    for (r, ir) in free_rows(pair, disc) {
                        // SAFETY: one contact at a time.
                        unsafe { *shared_rhs.get(ir) += f[r] };
                    }
                }
            }
            if disc.is_identity() {
                check_supported_with(model, &closed)?;
            }
            lap(&mut timings.assemble, &mut clock);
            // After the first factorization, solve on it with the changed contacts as a low-rank
            // correction while that is cheaper than refactorizing (see LowRankCost).
            let mut reused = None;
            // A low-rank solution not yet checked against the assembled matrix, with its
            // capacitance: the residual check and correction wait until the contact states are
            // consistent with it (the states in between only steer the iteration, and the
            // converged solution is checked as every other).
            let mut unchecked: Option<Capacitance> = None;
            let tolerance = REUSE_ACCURACY * backward_tolerance(&opts.solve);
            // The iteration's matrix, its values brought up to date first.
            macro_rules! current_matrix {
                () => {{
                    catch_up_values(
                        &mut values,
                        &mut values_behind,
                        &reference_values,
                        &pattern,
                        &pairs,
                        changes.as_deref(),
                        &mut changed_since_reference,
                    );
                    pattern.matrix(&values)?
                }};
            }
            // The residual check of a low-rank solution against it.
            macro_rules! residual_check {
                () => {
                    ResidualCheck {
                        a: current_matrix!(),
                        symmetric: !nonsymmetric,
                        b: &rhs,
                        tolerance,
                    }
                };
            }
            if let (Some(changes), Some(a0), true) = (
                changes.as_ref(),
                backends.reference.as_mut(),
                n_free > 0 && !refresh_reference,
            ) {
                let (order, new) = low_rank.size_of(changes);
                let affordable = match opts.max_capacitance_order {
                    Some(max) => order <= max,
                    None => low_rank_cost.worth(order),
                };
                if low_rank.len() + new > opts.max_low_rank_columns {
                    refresh_reference = true;
                } else if affordable {
                    let column = |c: usize, k: usize| low_rank_column(&pairs[c], disc, k);
                    let x0 = match reference_solution.take() {
                        Some(x0) => {
                            low_rank
                                .extend(a0.as_mut(), changes, column)
                                .map_err(locate)?;
                            x0
                        }
                        // b₀ = b − U Δχ, the load with every contact as in the reference: from
                        // the references of two earlier increments when affine in α, else its
                        // forward half along with the new columns' forward solves.
                        None => {
                            let mut solved_b0 = None;
                            let x0 = low_rank
                                .extend_with_reference(
                                    a0.as_mut(),
                                    changes,
                                    column,
                                    |low_rank| {
                                        let load = low_rank.active_load(changes);
                                        let shift = low_rank.spread(changes, &load);
                                        rhs.iter().zip(&shift).map(|(b, s)| b - s).collect()
                                    },
                                    |low_rank, b0| {
                                        let known = affine.predict(alpha, b0, low_rank);
                                        if known.is_none() {
                                            solved_b0 = Some(b0.to_vec());
                                        }
                                        known
                                    },
                                )
                                .map_err(locate)?;
                            if let Some(b0) = solved_b0 {
                                affine.record(alpha, b0, &x0);
                            }
                            x0
                        }
                    };
                    let started = std::time::Instant::now();
                    let cap = low_rank.capacitance(changes);
                    if order > 0 {
                        low_rank_cost.lu_rate = (2.0 / 3.0 * (order as f64).powi(3)
                            / started.elapsed().as_secs_f64().max(1e-9))
                        .max(1e8);
                    }
                    let load = low_rank.active_load(changes);
                    let first = low_rank.solve_from(a0.as_mut(), &cap, &x0, &load);
                    reference_solution = Some(x0);
                    match first {
                        // Checked once its states are consistent (see `unchecked`); not in
                        // the last iteration allowed, which has no next one to fall back to.
                        Ok(x)
                            if iteration < opts.max_state_iterations
                                && x.iter().all(|v| v.is_finite()) =>
                        {
                            reused = Some(LowRankSolve {
                                x,
                                backward_error: f64::NAN,
                                relative_residual: f64::NAN,
                                refinements: 0,
                            });
                            unchecked = Some(cap);
                        }
                        first => {
                            let check = residual_check!();
                            reused = refine_low_rank(&low_rank, a0.as_mut(), &cap, &check, first)
                                .map_err(locate)?;
                        }
                    }
                    refresh_reference = reused.is_none();
                    lap(&mut timings.factor_reuse, &mut clock);
                }
            }
            let (x, mut report) = if let Some(r) = reused {
                factor_reuses += 1;
                reuse_iterations_done += r.refinements;
                let report = unchecked.is_none().then(|| low_rank_report(&r));
                (r.x, report)
            } else {
                // The first symmetric factorization, or the next after the correction outgrew its
                // columns or its accuracy, becomes the reference (in its own solver).
                let a = current_matrix!();
                let make_reference = !nonsymmetric
                    && low_rank_possible
                    && n_free > 0
                    && (reference.is_none() || refresh_reference);
                let (slot, kind) = if nonsymmetric {
                    (&mut backends.general, SolverKind::FaerLu)
                } else if make_reference {
                    (&mut backends.reference, opts.solve.solver)
                } else {
                    (&mut backends.symmetric, opts.solve.solver)
                };
                if slot.is_none() {
                    let mut s = SolverConfig {
                        kind,
                        ..solver_config.clone()
                    }
                    .build()?;
                    s.analyze(a).map_err(locate)?;
                    *slot = Some(s);
                }
                let solver = slot
                    .as_mut()
                    .ok_or(Error::Solver(SolverError::OutOfOrder("solve", "analyze")))?;
                let key = (
                    nonsymmetric,
                    states.clone(),
                    directions.clone(),
                    perpendicular.iter().map(|p| p.0).collect::<Vec<f64>>(),
                );
                lap(&mut timings.factorize, &mut clock);
                if make_reference || factorized.as_ref() != Some(&key) {
                    let started = std::time::Instant::now();
                    solver.factorize(a).map_err(locate)?;
                    factorizations += 1;
                    if !nonsymmetric {
                        low_rank_cost.factorize = Some(started.elapsed().as_secs_f64());
                    }
                    if !make_reference {
                        factorized = Some(key);
                    } else {
                        refresh_reference = false;
                        reference = Some(
                            (0..pairs.len())
                                .map(|i| {
                                    let state =
                                        block_state(&states, &directions, &perpendicular, i);
                                    ReferenceBlock {
                                        stiffness: pairs[i].block_coefficients(
                                            &state,
                                            friction_of(i),
                                            stabilization,
                                        ),
                                        state,
                                        friction: friction_of(i),
                                        anchor: perpendicular[i].1,
                                        slip: slips[i],
                                    }
                                })
                                .collect(),
                        );
                        refactorized = true;
                        reference_values.copy_from_slice(&values);
                        changed_since_reference = Some(Vec::new());
                        low_rank.reset();
                        affine.clear();
                        // The initial states are all-stick unless frictionless (sliding).
                        if let Some(hook) = on_all_stick.take() {
                            if friction != Friction::None
                                && states.iter().zip(&pairs).all(|(s, p)| *s == initial(p))
                            {
                                hook(solver.as_mut(), a)?;
                            }
                        }
                    }
                    lap(&mut timings.factorize, &mut clock);
                }
                if n_free == 0 {
                    (Vec::new(), None)
                } else {
                    let (x, r) = solve_checked(solver.as_mut(), a, &rhs, 1).map_err(locate)?;
                    if refactorized {
                        // The reference's own load: A₀⁻¹ b₀ of this increment.
                        reference_solution = Some(Reference::Full(x.clone()));
                    }
                    (x, Some(r))
                }
            };
            let mut bwd = report.as_ref().map_or(0.0, |r| r.backward_error);
            check_backward_error(&opts.solve, bwd, &format!("increment {step}"))?;
            lap(&mut timings.solve, &mut clock);
            q = disc.generalized(&x, alpha);
            // Return mapping of every contact: the trials and the contacts whose state or slip
            // direction they change.
            // A contact's state changed, or its slip direction by |Δd| · |u_t − s| above the
            // tolerance (see SLIP_DIRECTION_TOLERANCE).
            let switched =
                |t: &Trial, (state, direction): (ContactState, Vector2<f64>), pt: f64| {
                    t.state != state
                        || (t.state == ContactState::Slip
                            && friction != Friction::None
                            && t.trial_norm / pt * (t.direction - direction).norm() > direction_tol)
                };
            let classify_all = |q: &[f64]| -> (Vec<Trial>, Vec<usize>) {
                let trials: Vec<Trial> = pairs
                    .par_iter()
                    .with_min_len(256)
                    .enumerate()
                    .map(|(i, p)| {
                        classify(
                            p,
                            Law { friction, bonded },
                            &gather(q, &p.jump.nodes),
                            &slips[i],
                            (states[i], directions[i]),
                            length_tol,
                            fixed[i],
                        )
                    })
                    .collect();
                let trials: Vec<Trial> = trials
                    .into_iter()
                    .enumerate()
                    .map(|(i, t)| {
                        if switches[i] >= CHATTER_SWITCHES {
                            hold(t, states[i], directions[i])
                        } else {
                            t
                        }
                    })
                    .collect();
                // A slip direction has changed when |Δd| · |u_t − s| exceeds the tolerance (see
                // SLIP_DIRECTION_TOLERANCE).
                // ... and a sliding Coulomb contact's bound when it moved (the fixed point on
                // the bounds).
                let changed: Vec<usize> = (0..pairs.len())
                    .filter(|&i| {
                        let t = &trials[i];
                        switched(t, (states[i], directions[i]), pairs[i].penalty_tangent)
                            || (switches[i] < CHATTER_SWITCHES
                                && unsettled_force(t, directions[i], perpendicular[i]))
                            || (bound_fixed_point
                                && t.state == ContactState::Slip
                                && switches[i] < CHATTER_SWITCHES
                                && (t.bound - bounds[i]).abs()
                                    > BOUND_TOLERANCE * t.bound.max(bounds[i]))
                    })
                    .collect();
                (trials, changed)
            };
            let (mut trials, mut changed) = classify_all(&q);
            if let (true, Some(cap)) = (changed.is_empty(), unchecked.take()) {
                lap(&mut timings.classify, &mut clock);
                let a0 = backends
                    .reference
                    .as_mut()
                    .ok_or(Error::Solver(SolverError::OutOfOrder("solve", "factorize")))?;
                let check = residual_check!();
                let checked =
                    refine_low_rank(&low_rank, a0.as_mut(), &cap, &check, Ok(x)).map_err(locate)?;
                lap(&mut timings.factor_reuse, &mut clock);
                let Some(r) = checked else {
                    // Not accurate enough: the same states again, on a new reference.
                    refresh_reference = true;
                    continue;
                };
                reuse_iterations_done += r.refinements;
                bwd = r.backward_error;
                check_backward_error(&opts.solve, bwd, &format!("increment {step}"))?;
                report = Some(low_rank_report(&r));
                if r.refinements > 0 {
                    q = disc.generalized(&r.x, alpha);
                    (trials, changed) = classify_all(&q);
                }
            }
            if changed.is_empty() {
                lap(&mut timings.classify, &mut clock);
                converged = Some((iteration, trials, report.map(|r| (r.backend, bwd))));
                break;
            }
            if iteration == opts.max_state_iterations {
                return Err(Error::ContactNotConverged {
                    step,
                    iterations: iteration,
                    contacts: changed.iter().map(|&i| describe(model, &set, i)).collect(),
                });
            }
            for &i in &changed {
                // With the Coulomb fixed point the slip directions and bounds settle together,
                // linearly: their changes count as switches only after SETTLING_ITERATIONS, a
                // change of state always. A contact that does not settle is then held like a
                // chattering one.
                let counts = if bound_fixed_point {
                    trials[i].state != states[i] || iteration > SETTLING_ITERATIONS
                } else {
                    switched(
                        &trials[i],
                        (states[i], directions[i]),
                        pairs[i].penalty_tangent,
                    )
                };
                if counts {
                    switches[i] += 1;
                }
                states[i] = trials[i].state;
                directions[i] = trials[i].direction;
            }
            if bound_fixed_point {
                // The fixed point converges linearly with μ times the coupling of a contact's
                // normal force to its own friction force; where that coupling is strong the
                // plain update oscillates, so later iterations take half the step.
                let step = if iteration > BOUND_RELAXATION_AFTER {
                    0.5
                } else {
                    1.0
                };
                for (b, t) in bounds.iter_mut().zip(&trials) {
                    if t.state == ContactState::Slip {
                        *b += step * (t.bound - *b);
                    }
                }
            }
            for (i, t) in trials.iter().enumerate() {
                // Newton's next iterate linearizes every sliding contact at this trial: its
                // direction too, however small the change (the spring k⊥ is anchored here).
                if t.state == ContactState::Slip && states[i] == ContactState::Slip {
                    directions[i] = t.direction;
                }
                perpendicular[i] = if t.state == ContactState::Slip && t.trial_norm > 0.0 {
                    (
                        pairs[i].penalty_tangent * t.bound / t.trial_norm,
                        t.relative,
                    )
                } else {
                    (0.0, Vector2::zeros())
                };
            }
            lap(&mut timings.classify, &mut clock);
        }
        let Some((iterations, trials, report)) = converged else {
            return Err(Error::InvalidOption("no state iteration ran".into()));
        };
        // Commit the slip history and record the increment.
        let mut records = Vec::with_capacity(pairs.len());
        let mut forces = elastic.internal(model, &q);
        let element_forces_norm = free_norm(disc, &forces, None);
        let mut stored: f64 = 0.5 * q.iter().zip(&forces).map(|(a, b)| a * b).sum::<f64>();
        let mut stabilization_energy = 0.0;
        // Per contact, in parallel: its new slip, dissipation, generalized forces and record;
        // then applied in contact order (the same sums as one pass).
        let committed: Vec<_> = pairs
            .par_iter()
            .with_min_len(256)
            .zip(&trials)
            .zip(&slips)
            .map(|((pair, t), slip)| {
                let (new_slip, dissipation) = match t.state {
                    ContactState::Open => (Some(t.relative), 0.0),
                    ContactState::Slip => {
                        let new = t.relative - t.tangential / pair.penalty_tangent;
                        (Some(new), t.tangential.dot(&(new - slip)))
                    }
                    ContactState::Stick => (None, 0.0),
                };
                let ft: Vector3<f64> =
                    pair.tangents[0] * t.tangential[0] + pair.tangents[1] * t.tangential[1];
                let force = pair.normal * t.normal_force + ft;
                let mut fq = pair.jump.b.transpose() * force;
                let q_block = gather(&q, &pair.jump.nodes);
                // The springs' elastic energy: normal, tangential, rotational; the stabilizer's.
                let mut energy = (0.0, 0.0);
                if t.state != ContactState::Open {
                    let rotation = pair.jump.r.transpose() * pair.rotation_moment(&q_block);
                    energy.0 = 0.5 * t.normal_force * t.normal_force / pair.penalty_normal
                        + 0.5 * t.tangential.norm_squared() / pair.penalty_tangent
                        + 0.5 * q_block.dot(&rotation);
                    fq += rotation;
                }
                if stabilization > 0.0 && t.state != ContactState::Stick {
                    let f = stabilizer_force(pair, t.state, &q_block) * stabilization;
                    energy.1 = 0.5 * q_block.dot(&f);
                    fq += f;
                }
                let record = ContactRecord {
                    state: t.state,
                    gap: -t.penetration,
                    normal_force: t.normal_force,
                    tangential_force: [ft[0], ft[1], ft[2]],
                    tangential_magnitude: ft.norm(),
                    friction_bound: t.bound,
                    relative_tangential: {
                        let g = pair.tangents[0] * t.relative[0] + pair.tangents[1] * t.relative[1];
                        [g[0], g[1], g[2]]
                    },
                };
                (new_slip, dissipation, fq, record, energy)
            })
            .collect();
        for (i, (new_slip, dissipation, fq, record, energy)) in committed.into_iter().enumerate() {
            if let Some(new) = new_slip {
                slips[i] = new;
            }
            dissipated += dissipation;
            stored += energy.0;
            stabilization_energy += energy.1;
            for (k, &n) in pairs[i].jump.nodes.iter().enumerate() {
                for d in 0..6 {
                    forces[6 * n + d] += fq[6 * k + d];
                }
            }
            records.push(record);
        }
        // W_ext by the trapezoidal rule over this increment.
        external_work += 0.5
            * forces
                .iter()
                .zip(&previous.0)
                .zip(q.iter().zip(&previous.1))
                .map(|((f, f0), (x, x0))| (f + f0) * (x - x0))
                .sum::<f64>();
        let energy = EnergyBalance {
            external_work,
            stored,
            stabilization: stabilization_energy,
            relative_error: if external_work.abs() > 0.0 {
                (external_work - stored - stabilization_energy - dissipated).abs()
                    / external_work.abs()
            } else {
                0.0
            },
        };
        previous = (forces.clone(), q.clone());
        let load_norm = alpha * applied_free.iter().map(|v| v * v).sum::<f64>().sqrt();
        let equilibrium_residual = free_norm(disc, &forces, Some((&applied_free, alpha)))
            / (element_forces_norm + load_norm).max(f64::MIN_POSITIVE);
        let mut reaction = [0.0; 6];
        let mut reactions = Vec::with_capacity(model.supports.len());
        for s in &model.supports {
            let g = DofMap::global(s.node, s.dof);
            let load: f64 = model
                .loads
                .iter()
                .filter(|l| l.node == s.node && l.dof == s.dof)
                .map(|l| alpha * l.value)
                .sum();
            let value = forces[g] - load;
            reaction[s.dof.index()] += value;
            reactions.push(Reaction {
                node: s.node,
                dof: s.dof,
                value,
            });
        }
        let macro_reaction = disc
            .driver()
            .map(|d| [0, 1, 2, 3, 4, 5].map(|k| forces[6 * d + k]));
        let count = |s: ContactState| records.iter().filter(|r| r.state == s).count();
        let (backend, bwd) = report.unwrap_or(("none", 0.0));
        out.increments.push(IncrementRecord {
            step,
            alpha,
            iterations,
            factorizations,
            open: count(ContactState::Open),
            stick: count(ContactState::Stick),
            slip: count(ContactState::Slip),
            applied_load: applied_full.map(|v| alpha * v),
            reaction,
            macro_reaction,
            dissipated,
            factor_reuses,
            reuse_iterations: reuse_iterations_done,
            held: switches.iter().filter(|&&n| n >= CHATTER_SWITCHES).count(),
            backend: backend.to_string(),
            seconds: increment_start.elapsed().as_secs_f64(),
            timings: {
                lap(&mut timings.commit, &mut clock);
                timings
            },
            backward_error: bwd,
            equilibrium_residual,
            energy,
        });
        out.contact_results.push(records);
        out.displacements.push(disc.physical(&q));
        out.reactions = reactions;
        if let Some(p) = &opts.progress {
            (p.0)(step, path.len());
        }
        if opts
            .deadline
            .is_some_and(|d| std::time::Instant::now() >= d)
        {
            break;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::ContactSet;
    use crate::generate::crossing_grid;

    /// The stabilizing force from the jump basis equals the 30 × 30 stabilizer times q (open
    /// and sliding), to rounding, on every contact of a crossing grid.
    #[test]
    fn stabilizer_force_is_the_stabilizer_block_times_q() {
        let model = Model::from_description(&crossing_grid(3, 2, 1e-3, 1e-4)).unwrap();
        let set = ContactSet::build(&model).unwrap();
        assert!(!set.pairs.is_empty());
        let q = BlockVector::from_fn(|r, _| ((r * 37) % 11) as f64 * 1e-5 - 4e-5);
        for pair in &set.pairs {
            for state in [ContactState::Open, ContactState::Slip] {
                let want = stabilizer(pair, state) * q;
                let got = stabilizer_force(pair, state, &q);
                let scale = stabilizer(pair, ContactState::Open).amax() * q.amax();
                assert!((got - want).amax() <= 1e-12 * scale, "{state:?}");
            }
        }
    }
}
