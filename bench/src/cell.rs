//! The stages of one benchmark cell: generation, contact search, pattern, value fill, every
//! applicable backend's symbolic analysis, numeric factorization and solve, the solve after a
//! few contact switches on the previous factor (CG, the low-rank correction, CHOLMOD's
//! downdate), the six elastic cell problems and an elasto-plastic curve.

use super::machine::peak_memory_bytes;
use super::BenchOptions;
use fibercell::cell::pair_boundary_nodes;
use fibercell::contact::{find_candidates, ContactSet};
use fibercell::generate::{nonwoven, nonwoven_preset};
use fibercell::homogenize::{
    elasto_plastic_curve, homogenize_elastic, ContactStiffness, CurveOptions, PeriodicSystem,
};
use fibercell::model::{FrictionSpec, Model};
use fibercell::solve::bench_internals::{ContactChange, LowRankCorrection, SparseColumn};
use fibercell::solve::{IncrementalOptions, SolveOptions, SolverConfig, SolverKind};
use fibercell::Error;
use fibercell_solver::{backward_error, median, pcg_with_factor, CscRef, FillOrdering};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Repeats at least of the stages that take milliseconds (contact search, value fills), whose
/// medians over a few runs still follow the noise of a shared machine.
const SHORT_STAGE_REPEATS: usize = 15;
/// Fewest runs of the first and next low-rank solves after switches (fractions of a second on
/// L, with a spread of ±20 % between runs on the VMs measured).
const LOW_RANK_REPEATS: usize = 7;

/// Median of `repeats` timings of `f` (seconds), with the last result.
fn median_of<T>(
    repeats: usize,
    mut f: impl FnMut() -> Result<T, Error>,
) -> Result<(f64, T), Error> {
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let t = Instant::now();
        last = Some(f()?);
        times.push(t.elapsed().as_secs_f64());
    }
    let out = last.ok_or_else(|| Error::InvalidOption("no repeat ran".into()))?;
    Ok((median(times), out))
}

/// One backend on the cell-problem matrix.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BackendBench {
    /// Backend and requested ordering, e.g. "faer-cholesky/auto".
    pub name: String,
    /// The ordering the backend reports it used.
    pub ordering: String,
    /// Symbolic analysis (s).
    pub analyze: f64,
    /// Numeric factorization, median (s).
    pub factorize: f64,
    /// One solve with one right-hand side, median (s).
    pub solve: f64,
    /// Entries of L.
    pub nnz_l: Option<usize>,
    /// Bytes the factor's values take as stored (faer's supernodes keep square diagonal
    /// blocks and the zeros of relaxed supernodes, so more than 8 · nnz(L)).
    #[serde(default)]
    pub factor_bytes: Option<usize>,
    /// Flops of one factorization, as the backend counts them.
    pub flops: Option<f64>,
    /// Factorization GFLOP/s.
    pub gflops: Option<f64>,
    /// Factorization GFLOP/s as a fraction of the all-thread DGEMM peak.
    pub fraction_of_dgemm: Option<f64>,
    /// Bytes of L read twice (forward and backward) per second in the solve, as a fraction of
    /// the triad bandwidth.
    pub solve_fraction_of_bandwidth: Option<f64>,
}

/// The solve after k contacts switched stick → sliding on the factor of the unswitched matrix
/// (CG preconditioned with it, its low-rank correction, CHOLMOD's downdate), against a
/// refactorization.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ReuseBench {
    /// Contacts switched.
    pub switched: usize,
    /// As a fraction of the closed contacts.
    pub fraction: f64,
    /// CG iterations to a backward error of 1e-13.
    pub iterations: usize,
    /// Whether it got there within the time of two refactorizations (at most 500 iterations).
    pub converged: bool,
    /// Seconds of the preconditioned CG solve.
    pub seconds: f64,
    /// Its cost relative to faer's refactorization plus solve (`refactorization_seconds`).
    pub ratio_to_refactorization: f64,
    /// The denominator of the faer ratios: a numeric refactorization plus one solve on the
    /// same solver (s). Since reports of 2026-11-25 the median of those timed one right before
    /// each of the row's low-rank first solves (paired, so that the VM's speed drifting
    /// between stages does not enter the ratios); before, the median of at least three after
    /// a first, once for all rows. Absent in reports written before that, whose ratios divided
    /// by the first factorization of a fresh solver.
    #[serde(default)]
    pub refactorization_seconds: Option<f64>,
    /// The same for CHOLMOD, the denominator of its ratios (s). Absent without the cholmod
    /// feature.
    #[serde(default)]
    pub cholmod_refactorization_seconds: Option<f64>,
    /// CHOLMOD's downdate of its factor by the switched contacts' stick springs (rank 2k,
    /// [`fibercell::homogenize::StickSystem::stick_spring_columns`]) plus one solve (s), the
    /// first after a factorization: it includes copying the supernodal factor into a
    /// simplicial LDLᵀ. Absent without the cholmod feature.
    #[serde(default)]
    pub updown_seconds: Option<f64>,
    /// That relative to CHOLMOD's refactorization plus solve.
    #[serde(default)]
    pub updown_ratio: Option<f64>,
    /// Normwise backward error of that solve on the switched matrix (the larger with the
    /// next one's on the original matrix).
    #[serde(default)]
    pub updown_backward_error: Option<f64>,
    /// The next modification of the same factor, the update that switches the contacts back,
    /// plus one solve (s): the cost once the factor is simplicial.
    #[serde(default)]
    pub updown_next_seconds: Option<f64>,
    /// That relative to CHOLMOD's refactorization plus solve.
    #[serde(default)]
    pub updown_next_ratio: Option<f64>,
    /// The low-rank (Woodbury) solve on faer's factor of the unswitched matrix, as the
    /// incremental solver does it: the 2k columns of S = Uᵀ A₀⁻¹ U (sparse forward solves), the
    /// factorization of the capacitance matrix and the solve (s); the median of `repeats` runs
    /// (at least seven) from no columns. Absent in reports written before.
    #[serde(default)]
    pub low_rank_seconds: Option<f64>,
    /// The next low-rank solve on the same columns as in a stick/slip iteration, whose load
    /// changed within them: the LU and one solve, from A₀⁻¹ b₀ known (s; median).
    #[serde(default)]
    pub low_rank_next_seconds: Option<f64>,
    /// The first low-rank solve's stages (s): the new columns of S (sparse forward solves,
    /// with the right-hand side's forward half along since reports of 2026-11-25; before, in
    /// the solve), the capacitance factorization, and the solve (the products with W, the
    /// capacitance solve and a backward half with A₀'s factor), of the median run. Absent in
    /// reports written before.
    #[serde(default)]
    pub low_rank_stages: Option<[f64; 3]>,
    /// Normwise backward error of the first low-rank solve on the switched matrix (the largest
    /// of the runs).
    #[serde(default)]
    pub low_rank_backward_error: Option<f64>,
    /// The first and the next low-rank solve relative to faer's refactorization plus solve.
    #[serde(default)]
    pub low_rank_ratios: Option<[f64; 2]>,
}

/// A factorized solver and the seconds of a refactorization plus one solve on it.
type TimedSolver = (Box<dyn fibercell_solver::LinearSolver>, f64);

/// Seconds of a numeric refactorization of `a` plus one solve of `rhs` on `solver`, which has
/// factorized once: the median of `repeats` (at least three), as the stick/slip loop
/// refactorizes on the same solver.
fn refactorization(
    solver: &mut dyn fibercell_solver::LinearSolver,
    a: CscRef<'_>,
    rhs: &[f64],
    repeats: usize,
) -> Result<f64, Error> {
    let times = (0..repeats.max(3))
        .map(|_| refactorize_once(solver, a, rhs))
        .collect::<Result<Vec<f64>, Error>>()?;
    Ok(median(times))
}

/// Seconds of one numeric refactorization of `a` plus one solve of `rhs` on `solver`.
fn refactorize_once(
    solver: &mut dyn fibercell_solver::LinearSolver,
    a: CscRef<'_>,
    rhs: &[f64],
) -> Result<f64, Error> {
    let t = Instant::now();
    solver.factorize(a)?;
    let mut x = rhs.to_vec();
    solver.solve_in_place(&mut x, 1)?;
    Ok(t.elapsed().as_secs_f64())
}

/// CHOLMOD (when built with it) factorized on the unswitched matrix `a0`, with its
/// [`refactorization`] time.
fn updown_solver(
    a0: CscRef<'_>,
    rhs: &[f64],
    repeats: usize,
) -> Result<Option<TimedSolver>, Error> {
    let mut solver = match SolverConfig::new(SolverKind::Cholmod).build() {
        Ok(s) => s,
        Err(Error::Solver(fibercell_solver::SolverError::Unavailable { .. })) => return Ok(None),
        Err(e) => return Err(e),
    };
    solver.analyze(a0)?;
    solver.factorize(a0)?;
    let seconds = refactorization(solver.as_mut(), a0, rhs, repeats)?;
    Ok(Some((solver, seconds)))
}

/// The incremental elasto-plastic curve.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CurveBench {
    /// Which curve: "default" (the generated cell as it is, Coulomb friction with the bond's
    /// cohesion, no option) or "mild" (Tresca, bonded, stabilized: the curve of earlier
    /// reports, kept for continuity).
    #[serde(default = "mild_name")]
    pub name: String,
    /// The friction law and options it ran with.
    #[serde(default)]
    pub physics: String,
    /// Increments.
    pub steps: usize,
    /// Macroscopic ε11 at the end.
    pub strain: f64,
    /// Tresca bound of the contacts (N); 0 for the default curve.
    pub tresca_bound: f64,
    /// Increments done: fewer than `steps` when the time limit stopped the curve.
    pub completed: usize,
    /// Whole curve including its all-stick elastic homogenization (s).
    pub total: f64,
    /// `total` with the missing increments at the mean time of the completed ones (s); equals
    /// `total` when every increment ran.
    pub projected_total: f64,
    /// Median increment (s).
    pub increment_median: f64,
    /// Slowest increment (s).
    pub increment_max: f64,
    /// State iterations in all.
    pub state_iterations: usize,
    /// Numeric factorizations in all.
    pub factorizations: usize,
    /// Solves on an earlier factorization with a low-rank correction (see
    /// [`fibercell::solve::IncrementalOptions::reuse_factor`]).
    pub factor_reuses: usize,
    /// Residual correction steps of those solves (absent in reports written before).
    #[serde(default)]
    pub correction_steps: usize,
    /// Largest capacitance order of a low-rank solve (columns of the correction in play).
    #[serde(default)]
    pub low_rank_largest_order: usize,
    /// Most columns of U kept on one reference factorization.
    #[serde(default)]
    pub low_rank_most_columns: usize,
    /// The capacitance order at which a low-rank solve is predicted to cost a factorization
    /// (from the run's measured times, at its end); larger corrections refactorize.
    #[serde(default)]
    pub crossover_order: Option<usize>,
    /// Contacts sliding at the end.
    pub sliding_at_end: usize,
    /// Contacts held after chattering (summed over increments).
    pub held: usize,
    /// Largest equilibrium residual ‖R‖/‖F‖ of an increment.
    #[serde(default)]
    pub max_equilibrium_residual: f64,
    /// Work of the stabilizing springs as a share of the dissipated energy at the end.
    #[serde(default)]
    pub stabilization_share: f64,
    /// Seconds of the completed increments per stage: assemble, factorize, factor reuse,
    /// solve, classify, commit ([`fibercell::solve::IncrementTimings::NAMES`]); absent in reports
    /// written before it was measured.
    #[serde(default)]
    pub stages: Option<[f64; 6]>,
    /// The error, when the curve failed.
    pub error: Option<String>,
    /// The most bytes the low-rank correction held in any increment (columns of U, their
    /// forward solves, S and a capacitance factorization; absent in reports before it).
    #[serde(default)]
    pub low_rank_bytes: Option<usize>,
    /// Bytes of the run's per-increment outputs at its end (every increment's displacements
    /// and contact records; absent in reports before it).
    #[serde(default)]
    pub output_bytes: Option<usize>,
}

fn mild_name() -> String {
    "mild".into()
}

/// Which curve to run: name, the friction to impose (None: the model's own), bonded,
/// stabilization, and the ε11 reached.
struct CurveCase {
    name: &'static str,
    tresca_bound: Option<f64>,
    bonded: bool,
    stabilization: f64,
    strain: f64,
}

/// Every stage of one cell.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CellBench {
    /// S, M or L.
    pub cell: String,
    /// Fibers deposited.
    pub fibers: usize,
    /// Elements (= segments searched).
    pub elements: usize,
    /// Closed contacts entering the cell problems.
    pub contacts: usize,
    /// Free DOFs of the cell problem.
    pub dofs: usize,
    /// Stored entries of K (both triangles).
    pub nnz_k: usize,
    /// Generation (s).
    pub generation: f64,
    /// Broad and narrow phase of the contact search with periodic images (s).
    pub contact_search: f64,
    /// Segments searched per second.
    pub segments_per_second: f64,
    /// The whole contact set: search, merge, kinematics, penalties (s).
    pub contact_set: f64,
    /// Pairing, contacts and percolation check of the cell system (s).
    pub setup: f64,
    /// The sparsity pattern and slot maps (s).
    pub pattern: f64,
    /// Value fill of the elements into a zeroed buffer, median (s).
    pub fill_elements: f64,
    /// Elements filled per second.
    pub elements_per_second: f64,
    /// Value fill of the closed contacts into a zeroed buffer, median (s).
    pub fill_contacts: f64,
    /// Contact pairs filled per second.
    pub pairs_per_second: f64,
    /// Fill bytes written (values, 8 per scattered entry) per second as a fraction of the
    /// triad bandwidth.
    pub fill_fraction_of_bandwidth: f64,
    /// Each applicable backend.
    pub backends: Vec<BackendBench>,
    /// Solves after contact switches without refactorizing.
    pub reuse: Vec<ReuseBench>,
    /// The six elastic cell problems (and Θ) end to end, median (s).
    pub six_cell_problems: f64,
    /// Their stages (of the median run).
    pub six_cell_problem_stages: fibercell::homogenize::HomogenizeTimings,
    /// The default elasto-plastic curve (None when skipped).
    pub curve: Option<CurveBench>,
    /// The mild-strain Tresca curve of earlier reports (None when skipped).
    #[serde(default)]
    pub mild_curve: Option<CurveBench>,
    /// Peak resident memory of the process after this cell (bytes).
    pub peak_memory: Option<u64>,
    /// Bytes of the large structures of the cell problems (absent in reports before them).
    #[serde(default)]
    pub memory: Option<MemoryBench>,
}

/// The backends that apply: faer Cholesky with each ordering, CHOLMOD (with the feature) with
/// its default and with the same nested dissection as faer. Block-Jacobi CG needs tens of
/// thousands of iterations on slender-fiber systems: it enters as the factor-preconditioned
/// solve after contact switches instead ([`ReuseBench`]).
fn backends() -> Vec<(String, SolverKind, FillOrdering)> {
    let mut v = vec![
        (
            "faer-cholesky/auto".to_string(),
            SolverKind::FaerCholesky,
            FillOrdering::Auto,
        ),
        (
            "faer-cholesky/amd".into(),
            SolverKind::FaerCholesky,
            FillOrdering::Amd,
        ),
        (
            "faer-cholesky/nd".into(),
            SolverKind::FaerCholesky,
            FillOrdering::NestedDissection,
        ),
    ];
    if cfg!(feature = "cholmod") {
        v.push((
            "cholmod/default".into(),
            SolverKind::Cholmod,
            FillOrdering::Auto,
        ));
        v.push((
            "cholmod/nd".into(),
            SolverKind::Cholmod,
            FillOrdering::NestedDissection,
        ));
    }
    v
}

fn bench_backend(
    name: &str,
    kind: SolverKind,
    ordering: &FillOrdering,
    a: CscRef<'_>,
    rhs: &[f64],
    repeats: usize,
    machine: &super::Machine,
) -> Result<BackendBench, Error> {
    let mut solver = SolverConfig {
        kind,
        ordering: ordering.clone(),
        ..SolverConfig::default()
    }
    .build()?;
    let t = Instant::now();
    let info = solver.analyze(a)?;
    let analyze = t.elapsed().as_secs_f64();
    let (factorize, _) = median_of(repeats, || Ok(solver.factorize(a)?))?;
    let (solve, _) = median_of(repeats, || {
        let mut x = rhs.to_vec();
        Ok(solver.solve_in_place(&mut x, 1)?)
    })?;
    let direct = !solver.capabilities().iterative;
    let gflops = info.flops.filter(|_| direct).map(|f| f / factorize / 1e9);
    Ok(BackendBench {
        name: name.to_string(),
        ordering: info.ordering.clone(),
        analyze,
        factorize: if direct { factorize } else { 0.0 },
        solve,
        nnz_l: info.nnz_factor,
        factor_bytes: info.factor_bytes,
        flops: info.flops,
        gflops,
        fraction_of_dgemm: gflops.map(|g| g / machine.dgemm_gflops_all),
        solve_fraction_of_bandwidth: info
            .nnz_factor
            .filter(|_| direct)
            .map(|l| 2.0 * 12.0 * l as f64 / solve / 1e9 / machine.bandwidth_gbs),
    })
}

/// The contacts `list` switched stick → sliding as the low-rank correction A₀ − W Wᵀ (W their
/// stick-spring columns, E = −I) of the factorization `a0` of the unswitched matrix `base`.
/// Runs `repeats` times (at least [`LOW_RANK_REPEATS`]), each from no columns: a
/// refactorization of `base` plus a solve, then the first solve (the columns with the
/// right-hand side's forward half, the capacitance, the rest of the solve), then the next
/// solve on the same columns with the load changed within them (capacitance, one backward
/// half). Returns the median refactorization, the first solve and its stages from the run of
/// median total, the median next solve, and the first solves' largest backward error on the
/// switched matrix `a`.
fn low_rank_switch(
    sys: &PeriodicSystem,
    a0: &mut dyn fibercell_solver::LinearSolver,
    base: CscRef<'_>,
    a: CscRef<'_>,
    rhs: &[f64],
    list: &[usize],
    repeats: usize,
) -> Result<LowRankSwitch, Error> {
    let w = sys.stick_spring_matrix(list)?;
    let w = w.as_ref();
    // Contact j owns the columns 2j, 2j + 1 of W, as basis rows 1 and 2 (the tangents).
    let column = |j: usize, k: usize| -> SparseColumn {
        let (rows, vals) = w.col(2 * j + k - 1);
        rows.iter().copied().zip(vals.iter().copied()).collect()
    };
    let mut stiffness = fibercell::contact::BlockCoefficients::zeros();
    stiffness[(1, 1)] = -1.0;
    stiffness[(2, 2)] = -1.0;
    let changes: Vec<ContactChange> = (0..list.len())
        .map(|contact| ContactChange {
            contact,
            stiffness,
            load: nalgebra::Vector6::zeros(),
        })
        .collect();
    let mut firsts: Vec<(f64, [f64; 3])> = Vec::new();
    let mut nexts = Vec::new();
    let mut error = 0.0f64;
    let mut refactorizations = Vec::new();
    for _ in 0..repeats.max(LOW_RANK_REPEATS) {
        // It ends with a solve, as the next solves of the runs before do.
        refactorizations.push(refactorize_once(a0, base, rhs)?);
        let mut low_rank = LowRankCorrection::new(a.ncols(), list.len());
        let t = Instant::now();
        // The columns' forward solves take the right-hand side's forward half along.
        let reference =
            low_rank.extend_with_reference(a0, &changes, column, |_| rhs.to_vec(), |_, _| None)?;
        let columns = t.elapsed().as_secs_f64();
        let cap = low_rank.capacitance(&changes);
        let capacitance = t.elapsed().as_secs_f64() - columns;
        let x = low_rank.solve_from_taken(a0, &cap, reference, &vec![0.0; cap.loads()])?;
        let first = t.elapsed().as_secs_f64();
        firsts.push((first, [columns, capacitance, first - columns - capacitance]));
        error = error.max(backward_error(a, &x, rhs));
        // The next solve as in a stick/slip iteration: the load changed within the switched
        // contacts' columns, solved from A₀⁻¹ b₀ of the increment (known) with one solve.
        let x0 = low_rank.reference(a0, rhs.to_vec())?;
        let load = vec![1.0; cap.loads()];
        let t = Instant::now();
        let cap = low_rank.capacitance(&changes);
        low_rank.solve_from(a0, &cap, &x0, &load)?;
        nexts.push(t.elapsed().as_secs_f64());
    }
    firsts.sort_by(|p, q| p.0.total_cmp(&q.0));
    let (first, stages) = firsts[firsts.len() / 2];
    Ok(LowRankSwitch {
        refactorization: median(refactorizations),
        first,
        next: median(nexts),
        stages,
        error,
    })
}

/// What [`low_rank_switch`] measured (s) and the first solve's backward error.
struct LowRankSwitch {
    /// The median refactorization plus solve, one timed right before each first solve.
    refactorization: f64,
    first: f64,
    next: f64,
    stages: [f64; 3],
    error: f64,
}

/// Solves after switching k contacts, for k at the given fractions of the contacts, against
/// refactorizations plus solve on the same solver timed alongside the low-rank first solves
/// (see [`low_rank_switch`]); CG stops once it has spent about two refactorizations (a
/// [`refactorization`] measured first).
fn bench_reuse(
    sys: &PeriodicSystem,
    model: &Model,
    rhs: &[f64],
    fractions: &[f64],
    repeats: usize,
) -> Result<Vec<ReuseBench>, Error> {
    let base = sys.assemble(model);
    let a0 = sys.pattern.matrix(&base.values)?;
    let mut factor = SolverConfig::new(SolverKind::FaerCholesky).build()?;
    factor.analyze(a0)?;
    factor.factorize(a0)?;
    let t_solve = Instant::now();
    let mut x = rhs.to_vec();
    factor.solve_in_place(&mut x, 1)?;
    let solve = t_solve.elapsed().as_secs_f64();
    let refactor = refactorization(factor.as_mut(), a0, rhs, repeats)?;
    // Past twice a refactorization's time the crossover is behind: stop CG there.
    let max_iterations = ((2.0 * refactor / solve.max(1e-9)).ceil() as usize).clamp(10, 500);
    let mut updown = updown_solver(a0, rhs, repeats)?;
    let n_contacts = sys.n_contacts();
    let mut out = Vec::new();
    for &fraction in fractions {
        let k = ((fraction * n_contacts as f64).round() as usize).max(1);
        // Every (n/k)-th contact slides: spread over the cell.
        let stride = (n_contacts / k).max(1);
        let switched = |i: usize| i.is_multiple_of(stride) && i / stride < k;
        let mut values = sys.zero_values();
        sys.add_elements(model, &mut values);
        sys.add_contacts(&mut values, |i| {
            if switched(i) {
                ContactStiffness::Sliding
            } else {
                ContactStiffness::Stick
            }
        });
        let a = sys.pattern.matrix(&values.values)?;
        let t = Instant::now();
        let r = pcg_with_factor(factor.as_mut(), a, rhs, 1e-13, max_iterations)?;
        let seconds = t.elapsed().as_secs_f64();
        let list: Vec<usize> = (0..n_contacts).filter(|&i| switched(i)).collect();
        let low_rank = low_rank_switch(sys, factor.as_mut(), a0, a, rhs, &list, repeats)?;
        // The row's faer ratios divide by the refactorizations paired with its first solves.
        let refactor = low_rank.refactorization;
        let mut measured = None;
        let cholmod_refactor = updown.as_ref().map_or(f64::NAN, |u| u.1);
        if let Some((solver, _)) = updown.as_mut() {
            let w = sys.stick_spring_matrix(&list)?;
            solver.factorize(a0)?;
            let t = Instant::now();
            solver.update_factor(w.as_ref(), false)?;
            let mut x = rhs.to_vec();
            solver.solve_in_place(&mut x, 1)?;
            let seconds = t.elapsed().as_secs_f64();
            let error = backward_error(a, &x, rhs);
            let t = Instant::now();
            solver.update_factor(w.as_ref(), true)?;
            let mut x = rhs.to_vec();
            solver.solve_in_place(&mut x, 1)?;
            let next = t.elapsed().as_secs_f64();
            let error = error.max(backward_error(a0, &x, rhs));
            measured = Some((seconds, error, next));
        }
        out.push(ReuseBench {
            switched: k,
            fraction: k as f64 / n_contacts.max(1) as f64,
            iterations: r.iterations,
            converged: r.converged,
            seconds,
            ratio_to_refactorization: seconds / refactor,
            refactorization_seconds: Some(refactor),
            cholmod_refactorization_seconds: updown.as_ref().map(|u| u.1),
            updown_seconds: measured.map(|m| m.0),
            updown_ratio: measured.map(|m| m.0 / cholmod_refactor),
            updown_backward_error: measured.map(|m| m.1),
            updown_next_seconds: measured.map(|m| m.2),
            updown_next_ratio: measured.map(|m| m.2 / cholmod_refactor),
            low_rank_seconds: Some(low_rank.first),
            low_rank_next_seconds: Some(low_rank.next),
            low_rank_stages: Some(low_rank.stages),
            low_rank_backward_error: Some(low_rank.error),
            low_rank_ratios: Some([low_rank.first / refactor, low_rank.next / refactor]),
        });
    }
    Ok(out)
}

fn bench_curve(
    model_desc: &fibercell::model::ModelDescription,
    case: &CurveCase,
    opts: &BenchOptions,
) -> Result<CurveBench, Error> {
    let mut desc = model_desc.clone();
    let mut physics = match desc.contact.as_ref().map(|c| &c.friction) {
        Some(FrictionSpec::Coulomb { mu, cohesion }) => {
            format!("Coulomb μ = {mu}, cohesion {cohesion:.3e} N")
        }
        Some(f) => format!("{f:?}"),
        None => "no contact".into(),
    };
    if let (Some(bound), Some(c)) = (case.tresca_bound, desc.contact.as_mut()) {
        c.friction = FrictionSpec::Tresca { bound };
        physics = format!("Tresca {bound:e} N");
    }
    if case.bonded {
        physics += ", --bonded";
    }
    if case.stabilization > 0.0 {
        physics += &format!(", --stabilization {:e}", case.stabilization);
    }
    let model = Model::from_description(&desc)?;
    let curve_opts = CurveOptions {
        strain: [case.strain, 0.0, 0.0, 0.0, 0.0, 0.0],
        steps: opts.curve_steps,
        unload: false,
        incremental: IncrementalOptions {
            bonded: case.bonded,
            stabilization: case.stabilization,
            deadline: opts
                .curve_time_limit
                .map(|s| Instant::now() + std::time::Duration::from_secs_f64(s)),
            ..IncrementalOptions::default()
        },
    };
    let t = Instant::now();
    let result = elasto_plastic_curve(&model, &curve_opts);
    let total = t.elapsed().as_secs_f64();
    let mut bench = CurveBench {
        name: case.name.into(),
        physics,
        steps: opts.curve_steps,
        strain: case.strain,
        tresca_bound: case.tresca_bound.unwrap_or(0.0),
        completed: 0,
        total,
        projected_total: total,
        increment_median: 0.0,
        increment_max: 0.0,
        state_iterations: 0,
        factorizations: 0,
        factor_reuses: 0,
        correction_steps: 0,
        low_rank_largest_order: 0,
        low_rank_most_columns: 0,
        crossover_order: None,
        sliding_at_end: 0,
        held: 0,
        max_equilibrium_residual: 0.0,
        stabilization_share: 0.0,
        stages: None,
        error: None,
        low_rank_bytes: None,
        output_bytes: None,
    };
    match result {
        Ok(c) => record_curve(&mut bench, &c, opts.curve_steps),
        Err(e) => bench.error = Some(e.to_string()),
    }
    Ok(bench)
}

/// Fills `bench` from the curve `c` of `steps` increments.
fn record_curve(bench: &mut CurveBench, c: &fibercell::homogenize::Curve, steps: usize) {
    let inc = &c.solution.increments;
    let secs: Vec<f64> = inc.iter().map(|r| r.seconds).collect();
    let spent: f64 = secs.iter().sum();
    bench.completed = inc.len();
    if !inc.is_empty() {
        bench.projected_total = bench.total - spent + spent / inc.len() as f64 * steps as f64;
    }
    bench.increment_max = secs.iter().copied().fold(0.0, f64::max);
    bench.increment_median = median(secs);
    bench.state_iterations = inc.iter().map(|r| r.iterations).sum();
    bench.factorizations = inc.iter().map(|r| r.factorizations).sum();
    bench.factor_reuses = inc.iter().map(|r| r.factor_reuses).sum();
    bench.correction_steps = inc.iter().map(|r| r.reuse_iterations).sum();
    bench.low_rank_largest_order = inc
        .iter()
        .map(|r| r.low_rank.largest_order)
        .max()
        .unwrap_or(0);
    bench.low_rank_most_columns = inc.iter().map(|r| r.low_rank.columns).max().unwrap_or(0);
    bench.crossover_order = inc.last().and_then(|r| r.low_rank.crossover_order);
    bench.held = inc.iter().map(|r| r.held).sum();
    bench.max_equilibrium_residual = inc
        .iter()
        .map(|r| r.equilibrium_residual)
        .fold(0.0, f64::max);
    bench.stabilization_share = inc.last().map_or(0.0, |r| {
        if r.dissipated > 0.0 {
            r.energy.stabilization.abs() / r.dissipated
        } else {
            0.0
        }
    });
    let mut stages = fibercell::solve::IncrementTimings::default();
    inc.iter().for_each(|r| stages.add(&r.timings));
    bench.stages = Some(stages.stages());
    bench.sliding_at_end = inc.last().map_or(0, |r| r.slip);
    bench.low_rank_bytes = inc.iter().map(|r| r.low_rank.largest_bytes).max();
    bench.output_bytes = Some(c.solution.memory_bytes());
}

/// Bytes held by the cell problems' large structures.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MemoryBench {
    /// The pattern of K (CSC structure and the element blocks' slot maps).
    pub pattern: usize,
    /// The values of K.
    pub values: usize,
    /// The values of faer's Cholesky factor with the default ordering, 8 · nnz(L).
    pub factor: usize,
    /// The same factor's values as stored ([`BackendBench::factor_bytes`]); absent in results
    /// written before it was reported.
    #[serde(default)]
    pub factor_stored: Option<usize>,
}

/// Runs every stage on the preset `cell`.
pub fn bench_cell(
    cell: &str,
    opts: &BenchOptions,
    machine: &super::Machine,
    log: &mut dyn FnMut(&str),
) -> Result<CellBench, Error> {
    let params = nonwoven_preset(cell, opts.seed)?;
    log(&format!("{cell}: generating"));
    let (generation, generated) = median_of(1, || nonwoven(&params))?;
    let model = Model::from_description(&generated.description)?;
    let periodicity = pair_boundary_nodes(&model)?;
    let tolerance = model.contact.as_ref().map_or(0.0, |c| c.tolerance);
    log(&format!("{cell}: contact search"));
    let short_repeats = opts.repeats.max(SHORT_STAGE_REPEATS);
    let (contact_search, _) = median_of(short_repeats, || {
        Ok(find_candidates(&model, tolerance, Some(&periodicity)))
    })?;
    let (contact_set, _) = median_of(short_repeats, || {
        Ok(ContactSet::build_with(&model, Some(&periodicity))?)
    })?;
    log(&format!("{cell}: pattern and fill"));
    let sys = PeriodicSystem::new(&model)?;
    let elements = model.elements().len();
    // Refills of one buffer, as in the incremental hot path; zeroing is not timed.
    let mut buffer = sys.zero_values();
    let mut refill = |add: &dyn Fn(&mut fibercell::homogenize::PeriodicValues)| {
        median(
            (0..short_repeats)
                .map(|_| {
                    buffer.values.fill(0.0);
                    let t = Instant::now();
                    add(&mut buffer);
                    t.elapsed().as_secs_f64()
                })
                .collect(),
        )
    };
    let fill_elements = refill(&|v| sys.add_elements(&model, v));
    let fill_contacts = refill(&|v| sys.add_contacts(v, |_| ContactStiffness::Stick));
    let values = sys.assemble(&model);
    let a = sys.pattern.matrix(&values.values)?;
    let n = sys.n_free();
    // The first cell problem's right-hand side, −K_fE e₁.
    let rhs: Vec<f64> = values.couplings.coupling.iter().map(|c| -c[0]).collect();
    let scattered = 144.0 * elements as f64 + 576.0 * sys.n_contacts() as f64;
    let fill_bytes = 8.0 * scattered;
    let mut backend_results = Vec::new();
    for (name, kind, ordering) in backends() {
        log(&format!("{cell}: {name}"));
        backend_results.push(bench_backend(
            &name,
            kind,
            &ordering,
            a,
            &rhs,
            opts.repeats,
            machine,
        )?);
    }
    log(&format!("{cell}: solves after contact switches"));
    let reuse = bench_reuse(
        &sys,
        &model,
        &rhs,
        &[0.001, 0.003, 0.01, 0.03],
        opts.repeats,
    )?;
    log(&format!("{cell}: six cell problems"));
    let (six, homogenized) = median_of(opts.repeats, || {
        homogenize_elastic(&model, &SolveOptions::default())
    })?;
    let default_case = CurveCase {
        name: "default",
        tresca_bound: None,
        bonded: false,
        stabilization: 0.0,
        strain: opts.curve_strain,
    };
    let mild_case = CurveCase {
        name: "mild",
        tresca_bound: Some(opts.tresca_bound),
        bonded: true,
        stabilization: 1e-8,
        strain: opts.mild_curve_strain,
    };
    let mut curves = [default_case, mild_case].map(|case| {
        (opts.curve_steps > 0 && case.strain != 0.0).then(|| {
            log(&format!(
                "{cell}: {}-increment {} curve",
                opts.curve_steps, case.name
            ));
            bench_curve(&generated.description, &case, opts)
        })
    });
    let mild_curve = curves[1].take().transpose()?;
    let curve = curves[0].take().transpose()?;
    let default_backend = backend_results.first();
    let factor_bytes = 8 * default_backend.and_then(|b| b.nnz_l).unwrap_or(0);
    let factor_stored = default_backend.and_then(|b| b.factor_bytes);
    Ok(CellBench {
        cell: cell.to_string(),
        fibers: generated.report.deposited,
        elements,
        contacts: sys.n_contacts(),
        dofs: n,
        nnz_k: a.nnz(),
        generation,
        contact_search,
        segments_per_second: elements as f64 / contact_search,
        contact_set,
        setup: sys.timings.contacts,
        pattern: sys.timings.pattern,
        fill_elements,
        elements_per_second: elements as f64 / fill_elements,
        fill_contacts,
        pairs_per_second: sys.n_contacts() as f64 / fill_contacts,
        fill_fraction_of_bandwidth: fill_bytes
            / (fill_elements + fill_contacts)
            / 1e9
            / machine.bandwidth_gbs,
        backends: backend_results,
        reuse,
        six_cell_problems: six,
        six_cell_problem_stages: homogenized.timings,
        curve,
        mild_curve,
        peak_memory: peak_memory_bytes(),
        memory: Some(MemoryBench {
            pattern: sys.pattern.memory_bytes(),
            values: values.values.capacity() * size_of::<f64>(),
            factor: factor_bytes,
            factor_stored,
        }),
    })
}
