//! The linear system a model's job solves, for other tools (`fibercell export-matrix`): a
//! cell's six elastic cell problems, or a supported model's reduced K u = F.

use crate::homogenize::{cell_problem, LinearSystem};
use crate::solve::ReducedSystem;
use crate::{Error, Model};

/// The system of a model's job and what it is.
#[derive(Clone, Debug)]
pub struct JobSystem {
    pub system: LinearSystem,
    /// One line saying which problem it is (for the header of an exported file).
    pub description: &'static str,
}

/// The system `model`'s job solves: with a `[cell]`, the six elastic cell problems
/// K_ff x_k = −K_fE e_k ([`cell_problem`]); otherwise the reduced static problem K u = F.
pub fn job_system(model: &Model) -> Result<JobSystem, Error> {
    if model.cell.is_some() {
        return Ok(JobSystem {
            system: cell_problem(model)?,
            description: "the six elastic cell problems K_ff x_k = -K_fE e_k (e_k = e11 e22 g12 \
                          k11 k22 k12; periodic nodes eliminated, one node anchored, closed \
                          contacts in stick)",
        });
    }
    let sys = ReducedSystem::assemble(model, Default::default())?;
    let dofs = (0..sys.dofs.n_free())
        .map(|k| {
            let (node, dof) = sys.dofs.node_dof(k);
            (model.nodes[node].id, dof)
        })
        .collect();
    Ok(JobSystem {
        system: LinearSystem {
            matrix: sys.matrix()?.to_owned(),
            rhs: sys.rhs.clone(),
            columns: 1,
            dofs,
        },
        description: "the reduced static problem K u = F (supported DOFs removed)",
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solve::{solve_static, SolveOptions, SolverConfig, SolverKind};
    use std::path::Path;

    /// A supported model's job system, solved, gives `solve_static`'s displacements row by row
    /// to 1e-9 of the largest: two solves of the same system agree to κ₁ε ≈ 7e-10 at most
    /// (κ₁ = 3.3e6 by `fibercell check`; measured 2.8e-12); a cell's has six right-hand sides,
    /// one per macroscopic strain.
    #[test]
    fn the_job_system_is_what_the_jobs_solve() {
        let model = crate::io::load_model(Path::new("fixtures/ok_frame3d.toml")).unwrap();
        let job = job_system(&model).unwrap();
        let sys = &job.system;
        assert_eq!(sys.columns, 1);
        let mut solver = SolverConfig::new(SolverKind::FaerCholesky).build().unwrap();
        solver.analyze(sys.matrix.as_ref()).unwrap();
        solver.factorize(sys.matrix.as_ref()).unwrap();
        let mut x = sys.rhs.clone();
        solver.solve_in_place(&mut x, 1).unwrap();
        let reference = solve_static(&model, &SolveOptions::default()).unwrap();
        let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (k, &(node, dof)) in sys.dofs.iter().enumerate() {
            let want = reference.displacements[model.node_index(node).unwrap()][dof.index()];
            assert!(
                (x[k] - want).abs() <= 1e-9 * scale,
                "row {k}: {} against {want}",
                x[k]
            );
        }
        let cell = crate::io::load_model(Path::new("fixtures/ok_cell_grid.toml")).unwrap();
        let job = job_system(&cell).unwrap();
        assert_eq!(job.system.columns, 6);
        assert_eq!(job.system.rhs.len(), 6 * job.system.dofs.len());
        assert!(job.description.contains("cell problems"));
    }
}
