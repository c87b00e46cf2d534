//! Reactions at prescribed DOFs: R_c = (K u)_c − F_c (the right-hand side F_f − K_fc u_c is
//! [`crate::assembly::ElementBlocks::rhs`]).

use super::Discretization;
use crate::model::{Dof, Model};

/// A reaction at a prescribed DOF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reaction {
    /// Node index.
    pub node: usize,
    /// DOF.
    pub dof: Dof,
    /// Force (N) or moment (N·m) the support exerts.
    pub value: f64,
}

/// The support reactions R_c = f_c − α F_c at every prescribed DOF from the generalized forces
/// `forces` (K u for a frame, K q + the contact forces in a stick/slip run) at load factor
/// `alpha`: summed per DOF, and each. The one reaction loop of every job.
pub fn support_reactions(model: &Model, forces: &[f64], alpha: f64) -> ([f64; 6], Vec<Reaction>) {
    let mut sum = [0.0; 6];
    let mut reactions = Vec::with_capacity(model.supports.len());
    for s in &model.supports {
        let g = Discretization::global(s.node, s.dof);
        let load: f64 = model
            .loads
            .iter()
            .filter(|l| l.node == s.node && l.dof == s.dof)
            .map(|l| alpha * l.value)
            .sum();
        let value = forces[g] - load;
        sum[s.dof.index()] += value;
        reactions.push(Reaction {
            node: s.node,
            dof: s.dof,
            value,
        });
    }
    (sum, reactions)
}
