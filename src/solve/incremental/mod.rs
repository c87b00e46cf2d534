//! The incremental stick/slip solver (thesis §4.3 "Contact solution algorithm"): the load is
//! applied in N increments α_n = n/N; all closed contacts start in stick; inside each increment
//! the contact contributions are rebuilt for the current states, the system is solved, and every
//! contact is re-classified by a return mapping — open if it does not penetrate, stick if the
//! trial tangential force p_T (Eᵀ B q − s) lies within the friction bound (μN or G), otherwise
//! slip at the bound along the trial direction — until no state changes.
//!
//! A contact that changes its state or slip direction four times within one increment (the
//! discrete penalty problem can have no consistent state for it: e.g. closed it is pulled apart,
//! open it penetrates) is held in its state for the rest of the increment; so are the contacts
//! still changing in the last allowed iteration. The count is reported per increment, with the
//! equilibrium residual that measures what holding them left (an error above
//! [`MAX_HELD_RESIDUAL`]).
//!
//! The pattern (elements ∪ all candidate contact blocks) and each backend's symbolic analysis are
//! built once. The first symmetric factorization is the reference: later systems are its matrix
//! plus the changed contacts' blocks, assembled as such and solved as a low-rank correction of
//! it while that is cheaper than refactorizing (see [`IncrementalOptions::reuse_factor`]).
//! Otherwise systems with a Coulomb-sliding contact are nonsymmetric and go to LU, all others
//! to the chosen symmetric backend.
//!
//! The solver is a [`StickSlip`] object built once per run ([`setup`]); each increment reads
//! like the algorithm — assemble ([`assemble`]), solve with factor reuse ([`factor_reuse`],
//! [`factorize`]), classify by the return mapping ([`classify`], [`return_mapping`]), and at
//! convergence commit ([`commit`]).

mod assemble;
mod bound_acceleration;
mod cell_tangent;
mod classify;
mod commit;
mod contact_states;
mod cutback;
mod driver_couplings;
mod factor_reuse;
mod factorize;
mod factors;
mod increment;
mod load_path;
mod matrix_values;
mod options;
mod records;
mod return_mapping;
mod run_state;
mod setup;
mod shared_reference;
mod stabilizer;

pub use driver_couplings::DriverCouplings;
pub use options::{
    History, IncrementalOptions, Progress, ProgressFn, BOUND_TOLERANCE, EQUILIBRIUM_TOLERANCE,
    MAX_CONTACT_RECORDS, MAX_CUTBACKS, MAX_HELD_RESIDUAL, MAX_INCREMENTS, MAX_LOW_RANK_COLUMNS,
    MAX_SETTLED_RESIDUAL, STALLED_EQUILIBRIUM_TOLERANCE,
};
pub use records::{
    ContactRecord, EnergyBalance, IncrementRecord, IncrementalSolution, LowRankSizes,
};

use assemble::System;
use classify::{Classified, ResidualFloor};
use commit::EnergyHistory;
use contact_states::ContactStates;
use factors::Factors;
use increment::Increment;
use load_path::LoadPath;
use matrix_values::MatrixValues;
use options::CHATTER_SWITCHES;
pub(crate) use return_mapping::gather;
pub(crate) use run_state::{Advanced, RunState};
pub(crate) use setup::Setup;

use super::kept_contact_loads::KeptContactLoads;
use super::low_rank::Capacitance;
use super::static_solve::{check_backward_error, non_finite_solution};
use crate::constraints::Discretization;
use crate::contact::{ContactSet, ContactSide};
use crate::model::Model;
use crate::Error;
use fibercell_solver::{CscRef, LinearSolver, SolveReport};
use std::borrow::Cow;
use std::sync::Arc;

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

/// Called once with the run's first symmetric factorization when that is the all-stick matrix
/// (every closed contact in stick, every other open; open contacts carry their stabilizing
/// springs when [`IncrementalOptions::stabilization`] > 0): the factorized solver, the matrix
/// and, for a periodic cell, its couplings to the drivers in the same states. The
/// elasto-plastic curve solves its six elastic cell problems on it.
pub(crate) type OnAllStick<'h> = &'h mut dyn FnMut(
    &mut dyn LinearSolver,
    CscRef<'_>,
    Option<&DriverCouplings>,
) -> Result<(), Error>;

/// The incremental analysis on any discretization (supported structure or periodic cell).
pub(crate) fn run_incremental(
    model: &Model,
    disc: &Discretization,
    set: ContactSet,
    opts: &IncrementalOptions,
    on_all_stick: Option<OnAllStick<'_>>,
) -> Result<IncrementalSolution, Error> {
    let path = load_path(opts)?;
    let records = path.len().saturating_mul(set.pairs.len());
    if records > MAX_CONTACT_RECORDS {
        return Err(Error::InvalidOption(format!(
            "{} increments × {} contacts = {records} contact records, more than the {} \
             (about 4.5 GB) a run keeps: use fewer increments",
            path.len(),
            set.pairs.len(),
            MAX_CONTACT_RECORDS
        )));
    }
    let setup = Setup::new(
        Cow::Borrowed(model),
        Cow::Borrowed(disc),
        set,
        Cow::Borrowed(opts),
    )?;
    let mut solver = StickSlip::new(&setup, on_all_stick);
    let mut from = 0.0;
    for (step, &alpha) in (1..).zip(&path) {
        solver.advance(step, (from, alpha), 0)?;
        from = alpha;
        if let (Some(p), Some(record)) = (&opts.progress, solver.out.increments.last()) {
            (p.0)(step, path.len(), record);
        }
        if opts
            .deadline
            .is_some_and(|d| std::time::Instant::now() >= d)
        {
            break;
        }
    }
    Ok(solver.out)
}

/// The load factors of the increments: the options' path, else α_n = n/N.
fn load_path(opts: &IncrementalOptions) -> Result<Vec<f64>, Error> {
    let n = opts.path.as_ref().map_or(opts.steps, Vec::len);
    if n > MAX_INCREMENTS {
        return Err(Error::InvalidOption(format!(
            "{n} increments: at most {MAX_INCREMENTS} (every increment's results are kept)"
        )));
    }
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
    Ok(path)
}

/// The stick/slip solver of one run (thesis §4.3): its fixed data, the contacts' states, the
/// factorizations and matrix values, and the results so far.
pub(crate) struct StickSlip<'s, 'a, 'h> {
    setup: &'s Setup<'a>,
    contacts: ContactStates,
    factors: Factors,
    matrix: MatrixValues,
    /// The loads of the contacts without prescribed DOFs in their base states (open as open,
    /// the others stuck) with the slips they were summed at: kept across increments and
    /// updated at the contacts whose base state or slip changed (few per increment), instead
    /// of summed anew.
    kept_loads: Option<KeptContactLoads>,
    /// Generalized displacements of the last solve.
    q: Vec<f64>,
    energy: EnergyHistory,
    out: IncrementalSolution,
    /// The prescribed values and elastic load along α.
    path: LoadPath,
    /// Told about the first reference factorization when it is the all-stick matrix.
    on_all_stick: Option<OnAllStick<'h>>,
}

/// A state iteration's solution: the unknowns, the solve's report (none while a low-rank
/// solution waits for its check, or without unknowns), and the capacitance of that check.
struct Solved {
    x: Vec<f64>,
    report: Option<SolveReport>,
    unchecked: Option<Capacitance>,
}

impl<'s, 'a, 'h> StickSlip<'s, 'a, 'h> {
    fn new(setup: &'s Setup<'a>, on_all_stick: Option<OnAllStick<'h>>) -> Self {
        let n = 6 * setup.disc.n_gnodes();
        StickSlip {
            contacts: ContactStates::new(setup),
            path: LoadPath::new(setup),
            factors: Factors::new(setup.n_free(), setup.pairs.len()),
            on_all_stick,
            matrix: MatrixValues::empty(),
            kept_loads: None,
            q: vec![0.0; n],
            energy: EnergyHistory {
                previous: (vec![0.0; n], vec![0.0; n]),
                ..EnergyHistory::default()
            },
            out: IncrementalSolution {
                contacts: Arc::clone(&setup.set),
                increments: Vec::new(),
                contact_results: Vec::new(),
                contact_states: Vec::new(),
                displacements: Vec::new(),
                reactions: Vec::new(),
            },
            setup,
        }
    }

    /// Increment `step` to load factor `alpha`: state iterations — assemble, solve, classify
    /// — until no contact changes, then commit.
    fn increment(&mut self, step: usize, alpha: f64) -> Result<(), Error> {
        let mut inc = Increment::new(self.setup, &self.path, step, alpha);
        // New α and committed slips: a new reference load.
        self.factors.reference_solution = None;
        self.contacts.switches.fill(0);
        self.contacts.symmetric_step = false;
        self.contacts.acceleration.restart();
        self.contacts.predict_bounds(alpha);
        let max_iterations = self.setup.opts.max_state_iterations;
        let mut floor = ResidualFloor::default();
        for iteration in 1..=max_iterations {
            let mut system = self.assemble(&mut inc)?;
            let solved = self.solve(&mut inc, &mut system, iteration)?;
            let mut classified = self.classify_settled(alpha, iteration, &mut floor);
            let mut report = solved.report;
            if let (true, Some(cap)) = (classified.changed.is_empty(), &solved.unchecked) {
                inc.lap(|t| &mut t.classify);
                let Some((checked, refined)) =
                    self.confirm(&mut inc, &mut system, cap, solved.x)?
                else {
                    continue; // the same states again, on a new reference
                };
                report = Some(checked);
                if refined {
                    classified = self.classify_settled(alpha, iteration, &mut floor);
                }
            }
            let Classified {
                trials, changed, ..
            } = classified;
            if changed.is_empty() {
                inc.lap(|t| &mut t.classify);
                self.commit(inc, iteration, &trials, report);
                return self.check_equilibrium(step);
            }
            if iteration == max_iterations {
                // The contacts still changing are held in the states they were solved with,
                // as chattering ones are: the equilibrium residual then says whether that is
                // a solution (see `check_equilibrium`).
                for &i in &changed {
                    self.contacts.switches[i] = self.contacts.switches[i].max(CHATTER_SWITCHES);
                }
                let Classified { trials, .. } = self.classify();
                inc.lap(|t| &mut t.classify);
                self.commit(inc, iteration, &trials, report);
                return self.check_equilibrium(step);
            }
            let direction_tol = self.setup.direction_tol;
            self.contacts.advance(
                &self.setup.pairs,
                &trials,
                &changed,
                iteration,
                direction_tol,
                self.factors.reference.as_deref(),
            );
            inc.lap(|t| &mut t.classify);
        }
        Err(Error::InvalidOption("no state iteration ran".into()))
    }

    /// An increment must end in equilibrium: one that held contacts to
    /// [`MAX_HELD_RESIDUAL`], one whose contacts all settled to [`MAX_SETTLED_RESIDUAL`].
    fn check_equilibrium(&self, step: usize) -> Result<(), Error> {
        let Some(last) = self.out.increments.last() else {
            return Ok(());
        };
        if last.held == 0 && last.equilibrium_residual > MAX_SETTLED_RESIDUAL {
            return Err(Error::RoundOff {
                step,
                residual: last.equilibrium_residual,
                limit: MAX_SETTLED_RESIDUAL,
            });
        }
        if last.held == 0 || !(last.equilibrium_residual > MAX_HELD_RESIDUAL) {
            return Ok(());
        }
        Err(Error::NoEquilibrium {
            step,
            residual: last.equilibrium_residual,
            held: (0..self.setup.pairs.len())
                .filter(|&i| self.contacts.held(i))
                .map(|i| self.describe(i))
                .collect(),
        })
    }

    /// Solves `system`: on the reference factorization with a low-rank correction when that
    /// is possible and cheaper, else directly.
    fn solve(
        &mut self,
        inc: &mut Increment,
        system: &mut System,
        iteration: usize,
    ) -> Result<Solved, Error> {
        let solved = match self.solve_low_rank(inc, system, iteration)? {
            Some((r, unchecked)) => {
                inc.factor_reuses += 1;
                inc.reuse_iterations += r.refinements;
                let report = unchecked
                    .is_none()
                    .then(|| factor_reuse::low_rank_report(&r));
                Solved {
                    x: r.x,
                    report,
                    unchecked,
                }
            }
            None => {
                if system.nonsymmetric && self.setup.low_rank_possible {
                    // Not on the reference: a symmetric fixed-point step instead of a sparse
                    // LU (see `ContactStates::symmetric_step`), whose factorization becomes
                    // the reference (the sliding contacts' blocks are then in A₀, and only
                    // their Coulomb terms and later changes in the correction).
                    self.contacts.symmetric_step = true;
                    self.factors.refresh_reference = true;
                    *system = self.assemble(inc)?;
                }
                let (x, report) = self.solve_direct(inc, system)?;
                Solved {
                    x,
                    report,
                    unchecked: None,
                }
            }
        };
        let bwd = solved.report.as_ref().map_or(0.0, |r| r.backward_error);
        check_backward_error(&self.setup.opts.solve, bwd, &inc.name())?;
        inc.lap(|t| &mut t.solve);
        if solved.x.iter().any(|v| !v.is_finite()) {
            return Err(non_finite_solution(&self.setup.model, &inc.name()));
        }
        self.q = self
            .path
            .generalized(&self.setup.disc, &solved.x, inc.alpha);
        Ok(solved)
    }

    /// Contact i with its two sides, for error messages.
    fn describe(&self, i: usize) -> String {
        let (model, set) = (&self.setup.model, &self.setup.set);
        let o = &set.origins[i];
        let side = |s: ContactSide| match s {
            ContactSide::Node(n) => format!("node {}", model.nodes[n].id),
            ContactSide::Point { element, xi } => {
                let e = model.elements()[element];
                format!(
                    "fiber {} at nodes {}–{} ξ={xi:.3}",
                    model.fibers[e.fiber].id,
                    model.nodes[e.nodes[0]].id,
                    model.nodes[e.nodes[1]].id
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
}
