//! The linear static analysis: setup → assemble → solve → check, readable in one function.

use super::{check_supported, make_solver, ReducedSystem, SolverKind};
use crate::assembly::FillMode;
use crate::constraints::{reactions, Reaction};
use crate::model::Model;
use crate::Error;
use fibercell_solver::{solve_checked, Ordering, SolverError};
use serde::Serialize;
use std::time::Instant;

/// Options of [`solve_static`].
#[derive(Clone, Debug, Default)]
pub struct SolveOptions {
    /// Backend.
    pub solver: SolverKind,
    /// Fill-reducing ordering for the direct backends.
    pub ordering: Ordering,
    /// Serial or parallel value fill.
    pub fill: FillMode,
    /// Largest accepted relative residual ‖Ku − F‖/‖F‖ (default 1e-8 when zero).
    pub max_residual: f64,
}

/// Wall-clock seconds of each stage.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Timings {
    /// DOF numbering, pattern and slot map, coloring.
    pub pattern: f64,
    /// Value fill and right-hand side.
    pub fill: f64,
    /// Ordering and symbolic factorization.
    pub analyze: f64,
    /// Numeric factorization.
    pub factorize: f64,
    /// Solve and residual check.
    pub solve: f64,
}

/// What the solver did.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SolveSummary {
    /// Backend name.
    pub backend: String,
    /// Ordering used.
    pub ordering: String,
    /// Nodes × 6.
    pub dofs: usize,
    /// Free DOFs (order of the reduced system).
    pub free_dofs: usize,
    /// Stored entries of the reduced stiffness.
    pub nnz: usize,
    /// Entries of the factor, when a direct method.
    pub nnz_factor: Option<usize>,
    /// Flops of the factorization, when known.
    pub flops: Option<f64>,
    /// Iterations, for CG.
    pub iterations: Option<usize>,
    /// ‖K u − F‖ / ‖F‖ of the reduced system.
    pub relative_residual: f64,
    /// Stage timings.
    pub timings: Timings,
}

/// Displacements and rotations of every node, reactions, and the solver's report.
#[derive(Clone, Debug)]
pub struct StaticSolution {
    /// [ux, uy, uz, rx, ry, rz] per node index.
    pub displacements: Vec<[f64; 6]>,
    /// Reactions at the prescribed DOFs.
    pub reactions: Vec<Reaction>,
    /// Solver report.
    pub summary: SolveSummary,
}

/// Maps a pivot failure at a reduced column to the node, DOF and fibers.
fn locate(e: SolverError, model: &Model, sys: &ReducedSystem) -> Error {
    match e {
        SolverError::NotPositiveDefinite { column, pivot } if column < sys.dofs.n_free() => {
            let (node, dof) = sys.dofs.node_dof(column);
            Error::Singular {
                node: model.nodes[node].id,
                dof,
                fibers: model.fibers_at_node(node),
                pivot,
            }
        }
        other => Error::Solver(other),
    }
}

/// Solves K u = F for the supports and loads of `model`.
pub fn solve_static(model: &Model, options: &SolveOptions) -> Result<StaticSolution, Error> {
    check_supported(model)?;
    let sys = ReducedSystem::assemble(model, options.fill)?;
    let mut timings = Timings {
        pattern: sys.seconds.0,
        fill: sys.seconds.1,
        ..Timings::default()
    };
    let n = sys.dofs.n_free();
    let mut summary = SolveSummary {
        backend: options.solver.name().into(),
        dofs: sys.dofs.n_global(),
        free_dofs: n,
        nnz: sys.pattern.nnz(),
        ..SolveSummary::default()
    };
    let reduced = if n == 0 {
        Vec::new()
    } else {
        let a = sys.matrix()?;
        let mut solver = make_solver(options.solver, &options.ordering, sys.dofs.node_block_starts())?;
        let t = Instant::now();
        let info = solver.analyze(a).map_err(|e| locate(e, model, &sys))?;
        timings.analyze = t.elapsed().as_secs_f64();
        let t = Instant::now();
        solver.factorize(a).map_err(|e| locate(e, model, &sys))?;
        timings.factorize = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let (x, report) = solve_checked(solver.as_mut(), a, &sys.rhs, 1).map_err(|e| locate(e, model, &sys))?;
        timings.solve = t.elapsed().as_secs_f64();
        let tol = if options.max_residual > 0.0 { options.max_residual } else { 1e-8 };
        if !(report.relative_residual <= tol) {
            return Err(Error::Solver(SolverError::Singular {
                column: None,
                detail: format!(
                    "relative residual {:.3e} exceeds {tol:.1e}: the system is too ill-conditioned to trust",
                    report.relative_residual
                ),
            }));
        }
        summary.ordering = info.ordering;
        summary.nnz_factor = info.nnz_factor;
        summary.flops = info.flops;
        summary.iterations = report.info.iterations;
        summary.relative_residual = report.relative_residual;
        x
    };
    let u = sys.dofs.expand(&reduced);
    summary.timings = timings;
    Ok(StaticSolution {
        displacements: u.chunks(6).map(|c| [c[0], c[1], c[2], c[3], c[4], c[5]]).collect(),
        reactions: reactions(model, &sys.dofs, &u),
        summary,
    })
}
