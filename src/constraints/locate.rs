//! Solver errors located in the model: a pivot failure at an unknown named as its node, DOF
//! and fibers.

use crate::model::{Dof, Model};
use crate::Error;
use fibercell_solver::SolverError;

/// Maps a pivot failure at a reduced column to the node, DOF and fibers; `node_dof` gives the
/// (node, DOF) of a column, `None` when it is not a physical node's DOF.
pub(crate) fn locate(
    e: SolverError,
    model: &Model,
    node_dof: &dyn Fn(usize) -> Option<(usize, Dof)>,
) -> Error {
    match e {
        SolverError::NotPositiveDefinite { column, pivot } => {
            match node_dof(column).filter(|(n, _)| *n < model.nodes.len()) {
                Some((node, dof)) => Error::Singular {
                    node: model.nodes[node].id,
                    dof,
                    fibers: model.fibers_at_node(node),
                    pivot,
                },
                None => Error::Solver(SolverError::NotPositiveDefinite { column, pivot }),
            }
        }
        other => Error::Solver(other),
    }
}
