//! Supports and loads: the right-hand side of the reduced system (nodal loads minus the
//! coupling to prescribed DOFs) and the reactions at prescribed DOFs.

mod discretization;
mod loads;

pub use discretization::Discretization;
pub use loads::{internal_forces, reduced_rhs, support_reactions, Reaction};
