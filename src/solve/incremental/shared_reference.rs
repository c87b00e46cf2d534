//! A reference factorization shared by every state of a [`crate::Cell`]: the all-stick matrix
//! at rest, factorized once when the cell is built. A state whose first reference has the same
//! values (every state at rest does) solves on it instead of factorizing its own, bit for bit
//! the same; a state without caches (cloned, or released) takes it as its reference and solves
//! with its contacts changed since rest as a low-rank correction. Backends that cannot share a
//! factorization ([`LinearSolver::share`] is `None`) leave each state to factorize its own.

use super::assemble::assembled_values;
use super::factorize::reference_blocks;
use super::factors::{Factors, ReferenceBlock};
use super::matrix_values::MatrixValues;
use super::run_state::RunState;
use super::setup::Setup;
use crate::solve::SolverConfig;
use crate::Error;
use fibercell_solver::LinearSolver;
use std::sync::{Arc, Mutex};

/// The rest state's matrix, contact blocks and factorization.
pub(super) struct SharedReference {
    /// The matrix values at rest, in the pattern's slots.
    values: Arc<Vec<f64>>,
    blocks: Vec<ReferenceBlock>,
    /// Locked only to make a shared solver.
    solver: Mutex<Box<dyn LinearSolver>>,
    /// What the factorization took (s): the states' measure of a factorization's cost.
    factorize_seconds: f64,
    /// The bytes of the factor's values (from the analysis), for the states' memory rules.
    factor_bytes: Option<usize>,
}

impl SharedReference {
    /// Factorizes the rest state of `setup` for sharing; `None` when the run does no low-rank
    /// solves, the backend cannot share, or the factorization fails (a state's first update
    /// then meets the failure itself and reports it with its increment).
    pub(super) fn build(setup: &Setup<'_>) -> Result<Option<Self>, Error> {
        if !setup.low_rank_possible || setup.n_free() == 0 {
            return Ok(None);
        }
        let rest = RunState::start(setup);
        let mut values = Vec::new();
        setup.elastic_values(&mut values)?;
        assembled_values(setup, &rest.contacts, &mut values);
        let a = setup.pattern.matrix(&values)?;
        let mut solver = SolverConfig {
            kind: setup.opts.solve.solver,
            ..setup.solver_config.clone()
        }
        .build()?;
        if solver.share().is_none() {
            return Ok(None);
        }
        let Ok(info) = solver.analyze(a) else {
            return Ok(None);
        };
        let started = std::time::Instant::now();
        if solver.factorize(a).is_err() {
            return Ok(None);
        }
        Ok(Some(SharedReference {
            blocks: reference_blocks(setup, &rest.contacts),
            factorize_seconds: started.elapsed().as_secs_f64(),
            factor_bytes: info.factor_bytes,
            values: Arc::new(values),
            solver: Mutex::new(solver),
        }))
    }

    /// A solver on the shared analysis and factorization.
    pub(super) fn solver(&self) -> Option<Box<dyn LinearSolver>> {
        self.solver.lock().ok()?.share()
    }

    /// Whether `values` are the rest matrix's.
    pub(super) fn is_of(&self, values: &[f64]) -> bool {
        self.values[..] == *values
    }

    /// What a factorization took when the cell was built (s).
    pub(super) fn factorize_seconds(&self) -> f64 {
        self.factorize_seconds
    }

    /// The bytes of the shared factor's values, when its analysis counted them.
    pub(super) fn factor_bytes(&self) -> Option<usize> {
        self.factor_bytes
    }

    /// Makes the shared factorization the reference of `factors` and `matrix`, which have
    /// none: the contacts' changes since rest are then a low-rank correction of it.
    pub(super) fn adopt(&self, factors: &mut Factors, matrix: &mut MatrixValues) {
        let Some(solver) = self.solver() else {
            return;
        };
        factors.backends.reference = Some(solver);
        factors.reference = Some(self.blocks.clone());
        factors.refresh_reference = false;
        factors.reference_solution = None;
        factors.cost.factorize = Some(self.factorize_seconds);
        factors.factor_bytes = self.factor_bytes;
        factors.low_rank.reset();
        factors.affine.clear();
        matrix.adopt_reference(&self.values);
    }
}
