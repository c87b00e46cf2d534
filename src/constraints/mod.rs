//! Supports and periodicity: the numbering of the unknowns, and the reactions at prescribed
//! DOFs.

mod discretization;
mod loads;
mod locate;

pub use discretization::Discretization;
pub use loads::{support_reactions, Reaction};
pub(crate) use locate::locate;
