//! The six elastic cell problems (thesis 3.13–3.16 for a frame network): one factorization,
//! six right-hand sides −K_fE e_k, and ABD = (K_EE − K_Ef K_ff⁻¹ K_fE) / |Y|, the Schur
//! complement of the driver DOFs per unit cell area — symmetric by construction.

use super::{Orthotropic, PeriodicSystem, ThesisModuli};
use crate::cell::CellGeometry;
use crate::model::Model;
use crate::solve::{check_backward_error, locate, make_solver, SolveOptions};
use crate::Error;
use fibercell_solver::{solve_checked, SolverError};
use serde::Serialize;

/// Effective properties of a cell.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Homogenized {
    /// ABD per unit cell area; rows and columns ε11, ε22, γ12, κ11, κ22, κ12: A in N/m, B in N,
    /// D in N·m.
    pub abd: [[f64; 6]; 6],
    /// max |ABD − ABDᵀ| / max |ABD|.
    pub asymmetry: f64,
    /// Cell area L_x L_y (m²).
    pub area: f64,
    /// Thickness used for moduli in Pa (m).
    pub thickness: f64,
    /// The thesis's moduli.
    pub moduli: ThesisModuli,
    /// Orthotropic constants.
    pub orthotropic: Orthotropic,
    /// Unknowns of the cell problem.
    pub free_dofs: usize,
    /// Slave nodes eliminated by periodicity.
    pub paired_nodes: usize,
    /// Closed contacts included in stick (the elastic moduli A^elas of thesis 5.5).
    pub contacts: usize,
    /// Largest backward error of the six solves.
    pub backward_error: f64,
    /// Backend.
    pub backend: String,
    /// For each unit load case k, the nodal displacements (the cell-problem solutions N_q).
    #[serde(skip)]
    pub cases: Vec<Vec<[f64; 6]>>,
    /// Cell geometry.
    #[serde(skip)]
    pub geometry: Option<CellGeometry>,
}

/// Solves the six unit cell problems of `model` (which needs a `[cell]`) and returns ABD and
/// the derived constants.
pub fn homogenize_elastic(model: &Model, options: &SolveOptions) -> Result<Homogenized, Error> {
    let sys = PeriodicSystem::new(model)?;
    let vals = sys.assemble(model);
    let n = sys.n_free();
    let a = sys.pattern.matrix(&vals.values)?;
    let mut solver = make_solver(options.solver, &options.ordering, Vec::new())?;
    let node_dof = |c: usize| (c < n).then(|| sys.node_dof(c));
    let locate = |e: SolverError| locate(e, model, &node_dof);
    solver.analyze(a).map_err(locate)?;
    solver.factorize(a).map_err(locate)?;
    let mut rhs = vec![0.0; 6 * n];
    for (i, c) in vals.coupling.iter().enumerate() {
        for k in 0..6 {
            rhs[k * n + i] = -c[k];
        }
    }
    let (x, report) = solve_checked(solver.as_mut(), a, &rhs, 6).map_err(locate)?;
    check_backward_error(options, report.backward_error, "cell problems")?;
    let g = sys.periodicity.geometry;
    let area = g.area();
    let mut abd = [[0.0; 6]; 6];
    for (j, row) in abd.iter_mut().enumerate() {
        for (k, v) in row.iter_mut().enumerate() {
            let schur: f64 = (0..n).map(|i| vals.coupling[i][j] * x[k * n + i]).sum();
            *v = (vals.k_ee[(j, k)] + schur) / area;
        }
    }
    let scale = abd.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let asym = (0..6)
        .flat_map(|j| (0..6).map(move |k| (j, k)))
        .map(|(j, k)| (abd[j][k] - abd[k][j]).abs())
        .fold(0.0f64, f64::max)
        / scale.max(f64::MIN_POSITIVE);
    let cases = (0..6)
        .map(|k| {
            let mut e = [0.0; 6];
            e[k] = 1.0;
            sys.expand(&x[k * n..(k + 1) * n], &e)
        })
        .collect();
    Ok(Homogenized {
        moduli: ThesisModuli::from_abd(&abd),
        orthotropic: Orthotropic::from_abd(&abd, g.thickness),
        abd,
        asymmetry: asym,
        area,
        thickness: g.thickness,
        free_dofs: n,
        paired_nodes: sys.periodicity.n_slaves(),
        contacts: sys.n_contacts(),
        backward_error: report.backward_error,
        backend: report.backend.to_string(),
        cases,
        geometry: Some(g),
    })
}
