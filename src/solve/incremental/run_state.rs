//! A stick/slip run between increments, without its setup: what a [`crate::Cell`] keeps per
//! material point. An increment resumes it on the cell's setup, advances it like a run's
//! increment (with cutbacks) and parks it again; a failed or trial increment leaves its
//! committed values as they were.

use super::cell_tangent::Tangent;
use super::commit::EnergyHistory;
use super::contact_states::ContactStates;
use super::factors::Factors;
use super::load_path::LoadPath;
use super::matrix_values::MatrixValues;
use super::records::{IncrementRecord, IncrementalSolution};
use super::setup::Setup;
use super::StickSlip;
use crate::solve::kept_contact_loads::KeptContactLoads;
use crate::Error;

/// An increment's record and, when asked for, the consistent tangent after it.
pub(crate) struct Advanced {
    pub record: IncrementRecord,
    pub tangent: Option<Tangent>,
}

/// The committed state of a run (contact states, slips, displacements, energies, load path)
/// and its caches (factorizations, matrix values), which any committed state may use.
pub(crate) struct RunState {
    pub(super) contacts: ContactStates,
    pub(super) factors: Factors,
    pub(super) matrix: MatrixValues,
    pub(super) kept_loads: Option<KeptContactLoads>,
    pub(super) q: Vec<f64>,
    pub(super) energy: EnergyHistory,
    /// The last increment's records only.
    pub(super) out: IncrementalSolution,
    pub(super) path: LoadPath,
    /// Load factor on `path`.
    pub alpha: f64,
    /// Increments committed.
    pub step: usize,
}

impl Clone for RunState {
    /// The committed state with caches of its own, empty: its next increment factorizes
    /// anew (its results equal the original's to the solver's tolerances, not bit for bit).
    fn clone(&self) -> Self {
        self.without_caches()
    }
}

impl RunState {
    /// The bytes of the symmetric factor its memory rules count with (tests).
    #[cfg(test)]
    pub(crate) fn factor_bytes(&self) -> Option<usize> {
        self.factors.factor_bytes
    }

    /// At rest: every closed contact in stick, no slip, on the setup's own load path.
    pub fn start(setup: &Setup<'_>) -> Self {
        StickSlip::new(setup, None).park(0.0, 0)
    }

    /// Turns the load path at the current load factor: from here the prescribed values change
    /// by `direction` (per generalized DOF) per unit α, and α restarts at 0.
    fn turn(&mut self, setup: &Setup<'_>, direction: Vec<f64>) {
        self.path.turn(setup, self.alpha, direction);
        self.alpha = 0.0;
        self.contacts.restart_path();
        self.factors.affine.clear();
    }

    /// One increment to load factor `alpha` on the path (turned first to `turn`, see
    /// [`RunState::turn`]), committed: its record, and with `tangent` the consistent tangent
    /// there. On an error the committed state is as before (its caches released).
    pub fn advance(
        &mut self,
        setup: &Setup<'_>,
        turn: Option<Vec<f64>>,
        alpha: f64,
        tangent: bool,
    ) -> Result<Advanced, Error> {
        let committed = self.without_caches();
        let run = std::mem::replace(self, committed);
        let (done, result) = run.taken(setup, turn, alpha, tangent);
        if result.is_ok() {
            *self = done;
        }
        result
    }

    /// The increment [`RunState::advance`] takes, not committed: the committed state stays,
    /// with the caches the trial built (none after a failed one).
    pub fn trial(
        &mut self,
        setup: &Setup<'_>,
        turn: Option<Vec<f64>>,
        alpha: f64,
        tangent: bool,
    ) -> Result<Advanced, Error> {
        let mut run = self.without_caches();
        std::mem::swap(&mut run.factors, &mut self.factors);
        std::mem::swap(&mut run.matrix, &mut self.matrix);
        let (done, result) = run.taken(setup, turn, alpha, tangent);
        // The caches of a failed trial are dropped, as a failed update drops them.
        if result.is_ok() {
            self.factors = done.factors;
            self.matrix = done.matrix;
        }
        result
    }

    /// This state after the increment to `alpha` (turned first to `turn`), and the increment's
    /// outcome: the state is consumed, the caller keeps what it needs.
    fn taken(
        mut self,
        setup: &Setup<'_>,
        turn: Option<Vec<f64>>,
        alpha: f64,
        tangent: bool,
    ) -> (Self, Result<Advanced, Error>) {
        if let Some(direction) = turn {
            self.turn(setup, direction);
        }
        let (from, step) = (self.alpha, self.step + 1);
        let mut solver = StickSlip::resume(setup, self);
        let advanced = solver.advance(step, (from, alpha), 0);
        let mut done = solver.park(alpha, step);
        let result = advanced.and_then(|()| done.advanced(setup, tangent));
        (done, result)
    }

    /// The last increment's record (the others dropped) and, with `tangent`, the tangent.
    fn advanced(&mut self, setup: &Setup<'_>, tangent: bool) -> Result<Advanced, Error> {
        self.keep_last_record();
        let record = self
            .out
            .increments
            .last()
            .cloned()
            .ok_or(Error::InvalidOption(
                "the increment committed no record".into(),
            ))?;
        let tangent = if tangent {
            Some(self.tangent(setup)?)
        } else {
            None
        };
        Ok(Advanced { record, tangent })
    }

    /// The committed values with empty caches (no matrix values: [`StickSlip::resume`] makes
    /// them anew from the elastic ones, as without a reference factorization).
    fn without_caches(&self) -> Self {
        RunState {
            contacts: self.contacts.clone(),
            factors: self.factors.emptied(),
            matrix: MatrixValues::empty(),
            kept_loads: self.kept_loads.clone(),
            q: self.q.clone(),
            energy: self.energy.clone(),
            out: self.out.clone(),
            path: self.path.clone(),
            alpha: self.alpha,
            step: self.step,
        }
    }

    /// Drops the caches (factorizations, low-rank columns, matrix values): the committed state
    /// alone stays, and the next increment factorizes anew.
    pub fn release_caches(&mut self) {
        self.factors = self.factors.emptied();
        self.matrix = MatrixValues::empty();
    }

    /// Drops every record but the last increment's (a cell state lives for many increments).
    fn keep_last_record(&mut self) {
        self.out.keep_last();
    }
}

impl<'s, 'a> StickSlip<'s, 'a, '_> {
    /// Resumes `run` on `setup` (with matrix values again if its caches were released).
    pub(super) fn resume(setup: &'s Setup<'a>, run: RunState) -> Self {
        let RunState {
            contacts,
            factors,
            mut matrix,
            kept_loads,
            q,
            energy,
            out,
            path,
            step,
            ..
        } = run;
        let mut factors = factors;
        // A state past rest without caches solves on the cell's rest factorization (a state
        // at rest meets it in its first factorization, bit for bit as a run).
        if let (None, true, Some(shared)) = (&factors.reference, step > 0, &setup.shared) {
            shared.adopt(&mut factors, &mut matrix);
        }
        StickSlip {
            setup,
            contacts,
            factors,
            matrix,
            kept_loads,
            q,
            energy,
            out,
            path,
            on_all_stick: None,
        }
    }

    /// The run's state after `step` increments, at load factor `alpha`.
    pub(super) fn park(self, alpha: f64, step: usize) -> RunState {
        let StickSlip {
            contacts,
            factors,
            matrix,
            kept_loads,
            q,
            energy,
            out,
            path,
            ..
        } = self;
        RunState {
            contacts,
            factors,
            matrix,
            kept_loads,
            q,
            energy,
            out,
            path,
            alpha,
            step,
        }
    }
}
