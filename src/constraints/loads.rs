//! Right-hand side and reactions.
//!
//! With K split into free (f) and prescribed (c) DOFs, K_ff u_f = F_f − K_fc u_c; the reduced
//! matrix K_ff is a principal submatrix of the symmetric K and stays symmetric. Reactions are
//! R_c = (K u)_c − F_c.

use super::Discretization;
use crate::assembly::element_stiffness;
use crate::model::{Dof, Model};
use rayon::prelude::*;

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

/// Global nodal load vector F (6 per node).
fn global_loads(model: &Model) -> Vec<f64> {
    let mut f = vec![0.0; 6 * model.nodes.len()];
    for l in &model.loads {
        f[Discretization::global(l.node, l.dof)] += l.value;
    }
    f
}

/// K u over all global DOFs, element by element (u: 6 per node).
pub fn internal_forces(model: &Model, u: &[f64]) -> Vec<f64> {
    let contributions: Vec<(usize, [f64; 12])> = (0..model.elements().len())
        .into_par_iter()
        .map(|e| {
            let k = element_stiffness(model, e);
            let nodes = model.elements()[e].nodes;
            let mut ue = [0.0; 12];
            for (a, &nd) in nodes.iter().enumerate() {
                ue[6 * a..6 * a + 6].copy_from_slice(&u[6 * nd..6 * nd + 6]);
            }
            let mut fe = [0.0; 12];
            for (r, f) in fe.iter_mut().enumerate() {
                *f = (0..12).map(|c| k[(r, c)] * ue[c]).sum();
            }
            (e, fe)
        })
        .collect();
    let mut out = vec![0.0; u.len()];
    for (e, fe) in contributions {
        for (a, &nd) in model.elements()[e].nodes.iter().enumerate() {
            for d in 0..6 {
                out[6 * nd + d] += fe[6 * a + d];
            }
        }
    }
    out
}

/// The reduced right-hand side F_f − K_fc u_c.
pub fn reduced_rhs(model: &Model, dofs: &Discretization) -> Vec<f64> {
    let f = global_loads(model);
    let mut rhs = vec![0.0; dofs.n_free()];
    for (g, v) in f.iter().enumerate() {
        if let Some(r) = dofs.reduced(g) {
            rhs[r] += v;
        }
    }
    if dofs.has_nonzero_prescribed() {
        // K u_c with u_c the prescribed values (zero on free DOFs).
        let uc: Vec<f64> = (0..dofs.n_global())
            .map(|g| {
                if dofs.reduced(g).is_some() {
                    0.0
                } else {
                    dofs.prescribed_value(g)
                }
            })
            .collect();
        let kuc = internal_forces(model, &uc);
        for (g, v) in kuc.iter().enumerate() {
            if let Some(r) = dofs.reduced(g) {
                rhs[r] -= v;
            }
        }
    }
    rhs
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
