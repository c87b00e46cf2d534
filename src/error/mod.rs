//! The crate-wide error type, and the leaf error types of the modules below it (which
//! re-export theirs), so that `error` uses none of the modules whose errors it wraps.

mod cell_error;
mod pattern_error;

pub use cell_error::CellError;
pub use pattern_error::PatternTooLargeError;

use crate::input_error::InputError;
use crate::model::{Dof, ModelError};
use fibercell_solver::SolverError;

/// Everything fibercell can report; each variant names the offending item.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A model file could not be read or parsed.
    #[error(transparent)]
    Input(#[from] InputError),
    /// The periodic cell is invalid.
    #[error("invalid cell: {0}")]
    Cell(#[from] CellError),
    /// The model is invalid.
    #[error("invalid model: {0}")]
    Model(#[from] ModelError),
    /// A group of connected fibers has no support at all.
    #[error("fiber{} {} {} held by nothing: no support acts on the connected group they form, so the system is singular", if fibers.len() == 1 { "" } else { "s" }, list(fibers), if fibers.len() == 1 { "is" } else { "are" })]
    Unsupported {
        /// Ids of the fibers of that group.
        fibers: Vec<u64>,
    },
    /// The stiffness is singular (a mechanism) at a DOF.
    #[error("the stiffness is singular at node {node}, DOF {dof} (fiber{} {}): the structure can move there without resistance — a mechanism or a missing support (relative pivot {pivot:.2e})", if fibers.len() == 1 { "" } else { "s" }, list(fibers))]
    Singular {
        /// Node id.
        node: u64,
        /// DOF.
        dof: Dof,
        /// Fibers through that node.
        fibers: Vec<u64>,
        /// The pivot relative to its diagonal entry.
        pivot: f64,
    },
    /// A static solve was asked of a periodic cell, whose problems are the cell problems.
    #[error("the model is a periodic cell without supports: a static solve has nothing to hold it; run `fibercell homogenize` for its effective stiffness (ABD) or `fibercell curve` for its friction curve")]
    CellWithoutSupports,
    /// The sparse solver failed.
    #[error("solver: {0}")]
    Solver(#[from] SolverError),
    /// The stiffness pattern does not fit the 32-bit slot map.
    #[error(transparent)]
    PatternTooLarge(#[from] PatternTooLargeError),
    /// The state iteration of an increment settled only by holding contacts (that chattered, or
    /// still changed in its last iteration), and the held state is not in equilibrium: the
    /// cell has a mechanism there, or the increment is too large for the states to settle.
    #[error("increment {step}: no equilibrium (residual ‖R‖/‖F‖ = {residual:.1e}) with {} contact{} held in a state the contact law does not give them, as they chattered or still changed at the last state iteration ({}): where a fiber has lost its hold, its contacts open or sliding, the quasi-static problem has a mechanism, which bonded contacts (`--bonded`, `bonded = true` in [contact]) or a cohesion (`cohesion` in the friction law) remove; otherwise smaller increments (more --steps) let the states settle", held.len(), if held.len() == 1 { "" } else { "s" }, held.iter().take(10).cloned().collect::<Vec<_>>().join("; "))]
    NoEquilibrium {
        /// Increment (1-based).
        step: usize,
        /// Its equilibrium residual.
        residual: f64,
        /// The held contacts, described.
        held: Vec<String>,
    },
    /// The state iteration of an increment settled with no contact held, but its equilibrium
    /// residual is above [`crate::solve::MAX_SETTLED_RESIDUAL`]: the contact forces N = p g are
    /// round-off, the penetrations g = N/p having approached the round-off of the
    /// displacements.
    #[error("increment {step}: every contact settled, but the equilibrium residual ‖R‖/‖F‖ = {residual:.1e} is above {limit:.0e}: the contact forces are round-off — the penalties are so large that the penetrations N/p approach the round-off of the displacements; lower them (`penalty_scale` in [contact]; `fibercell check` names the scale an accuracy needs)")]
    RoundOff {
        /// Increment (1-based).
        step: usize,
        /// Its equilibrium residual.
        residual: f64,
        /// The limit it exceeds.
        limit: f64,
    },
    /// An option is out of range.
    #[error("invalid option: {0}")]
    InvalidOption(String),
    /// The solution is not finite although every input is: loads or prescribed values so
    /// large that the displacements overflow.
    #[error("{context}: the solution overflows (the largest load or prescribed value is {largest:e}): the displacements are beyond floating point; use smaller loads or other units")]
    NonFiniteSolution {
        /// Where (the static solve, an increment).
        context: String,
        /// The largest applied load or prescribed value.
        largest: f64,
    },
    /// `fibercell check` measured a property outside its limit.
    #[error("{} check{} failed: {}", failed.len(), if failed.len() == 1 { "" } else { "s" }, failed.join("; "))]
    ChecksFailed {
        /// Each failed check with what was measured.
        failed: Vec<String>,
    },
    /// Writing an output failed.
    #[error("cannot write {path}: {message}")]
    Output {
        /// The file.
        path: String,
        /// Why.
        message: String,
    },
}

/// Up to 20 ids, comma separated, then the total.
pub(crate) fn list(ids: &[u64]) -> String {
    let mut s: Vec<String> = ids.iter().take(20).map(|i| i.to_string()).collect();
    if ids.len() > 20 {
        s.push(format!("… ({} in all)", ids.len()));
    }
    s.join(", ")
}
