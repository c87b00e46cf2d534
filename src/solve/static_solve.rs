//! The linear static analysis: setup → assemble → solve → check, readable in one function.

use super::{check_supported, ReducedSystem, SolverConfig, SolverKind};
use crate::assembly::FillMode;
use crate::constraints::{locate, support_reactions, Reaction};
use crate::model::Model;
use crate::Error;
use fibercell_solver::{solve_checked, FillOrdering, SolverError};
use serde::Serialize;
use std::time::Instant;

/// Options of [`solve_static`].
#[derive(Clone, Debug, Default)]
pub struct SolveOptions {
    /// Backend.
    pub solver: SolverKind,
    /// Fill-reducing ordering for the direct backends.
    pub ordering: FillOrdering,
    /// Serial or parallel value fill.
    pub fill: FillMode,
    /// Largest accepted normwise backward error ‖Ku − F‖∞/(‖K‖∞‖u‖∞ + ‖F‖∞) (default 1e-10
    /// when zero). The relative residual ‖Ku − F‖/‖F‖ is reported but not used to reject: on
    /// slender-fiber networks its roundoff floor ε‖K‖‖u‖/‖F‖ can exceed any fixed bar.
    pub max_backward_error: f64,
}

impl SolveOptions {
    /// The default options with the backend and ordering named as on the CLI (`faer-cholesky`,
    /// `faer-lu`, `cg`, `cholmod`; `auto`, `amd`, `nd`, `natural`); a backend this build lacks is
    /// an error.
    pub fn by_name(solver: &str, ordering: &str) -> Result<Self, Error> {
        let kind: SolverKind = solver.parse().map_err(Error::InvalidOption)?;
        if !kind.is_available() {
            return Err(Error::InvalidOption(format!(
                "solver \"{solver}\" is not in this build (CHOLMOD needs the cholmod feature)"
            )));
        }
        Ok(SolveOptions {
            solver: kind,
            ordering: FillOrdering::parse(ordering).map_err(Error::InvalidOption)?,
            ..SolveOptions::default()
        })
    }

    /// The backend configuration of these options for a system whose node blocks start at
    /// `node_blocks` (the one place every job builds its [`SolverConfig`]).
    pub fn solver_config(&self, node_blocks: Vec<usize>) -> SolverConfig {
        SolverConfig {
            kind: self.solver,
            ordering: self.ordering.clone(),
            node_blocks,
            cg_tolerance: None,
        }
    }
}

/// Wall-clock seconds of each stage.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Timings {
    /// DOF numbering, pattern and slot map, coloring.
    pub pattern: f64,
    /// Value fill and right-hand side.
    pub fill: f64,
    /// FillOrdering and symbolic factorization.
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
    /// FillOrdering used.
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
    /// ‖K u − F‖₂ / ‖F‖₂ of the reduced system.
    pub relative_residual: f64,
    /// ‖K u − F‖∞ / (‖K‖∞‖u‖∞ + ‖F‖∞) of the reduced system.
    pub backward_error: f64,
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

/// The accepted backward error of `options` (1e-10 when unset).
pub(crate) fn backward_tolerance(options: &SolveOptions) -> f64 {
    if options.max_backward_error > 0.0 {
        options.max_backward_error
    } else {
        1e-10
    }
}

/// Rejects a solve whose backward error exceeds `options.max_backward_error` (1e-10 when 0).
pub(crate) fn check_backward_error(
    options: &SolveOptions,
    backward_error: f64,
    context: &str,
) -> Result<(), Error> {
    let tol = backward_tolerance(options);
    if backward_error <= tol {
        return Ok(());
    }
    Err(Error::Solver(SolverError::Singular {
        column: None,
        detail: format!("{context}: backward error {backward_error:.3e} exceeds {tol:.1e}: the solution cannot be trusted"),
    }))
}

/// The error of a solution that overflowed, with the model's largest load or prescribed value.
pub(crate) fn non_finite_solution(model: &Model, context: &str) -> Error {
    let loads = model.loads.iter().map(|l| l.value.abs());
    let prescribed = model.supports.iter().map(|s| s.value.abs());
    Error::NonFiniteSolution {
        context: context.to_string(),
        largest: loads.chain(prescribed).fold(0.0, f64::max),
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
    let node_dof = |c: usize| (c < n).then(|| sys.dofs.node_dof(c));
    let reduced = if n == 0 {
        Vec::new()
    } else {
        let a = sys.matrix()?;
        let mut solver = options
            .solver_config(sys.dofs.node_block_starts())
            .build()?;
        let t = Instant::now();
        let info = solver.analyze(a).map_err(|e| locate(e, model, &node_dof))?;
        timings.analyze = t.elapsed().as_secs_f64();
        let t = Instant::now();
        solver
            .factorize(a)
            .map_err(|e| locate(e, model, &node_dof))?;
        timings.factorize = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let (mut x, mut report) = solve_checked(solver.as_mut(), a, &sys.rhs, 1)
            .map_err(|e| locate(e, model, &node_dof))?;
        // Iterative refinement with the same factor: x += A⁻¹(b − A x), while it helps.
        for _ in 0..2 {
            if report.relative_residual <= 1e-13 || report.info.iterations.is_some() {
                break;
            }
            let mut r = vec![0.0; n];
            a.mul_vec(&x, &mut r);
            r.iter_mut()
                .zip(&sys.rhs)
                .for_each(|(ri, bi)| *ri = bi - *ri);
            let (dx, _) = solve_checked(solver.as_mut(), a, &r, 1)
                .map_err(|e| locate(e, model, &node_dof))?;
            let refined: Vec<f64> = x.iter().zip(&dx).map(|(p, q)| p + q).collect();
            let res = fibercell_solver::relative_residual(a, &refined, &sys.rhs);
            if !(res < report.relative_residual) {
                break;
            }
            x = refined;
            report.relative_residual = res;
            report.backward_error = fibercell_solver::backward_error(a, &x, &sys.rhs);
        }
        timings.solve = t.elapsed().as_secs_f64();
        check_backward_error(
            options,
            report.backward_error,
            &format!("relative residual {:.3e}", report.relative_residual),
        )?;
        summary.ordering = info.ordering;
        summary.nnz_factor = info.nnz_factor;
        summary.flops = info.flops;
        summary.iterations = report.info.iterations;
        summary.relative_residual = report.relative_residual;
        summary.backward_error = report.backward_error;
        x
    };
    let u = sys.dofs.generalized(&reduced, 1.0);
    if u.iter().any(|v| !v.is_finite()) {
        return Err(non_finite_solution(model, "static solve"));
    }
    summary.timings = timings;
    Ok(StaticSolution {
        displacements: u
            .chunks(6)
            .map(|c| [c[0], c[1], c[2], c[3], c[4], c[5]])
            .collect(),
        reactions: support_reactions(model, &sys.elements.internal(model, &u), 1.0).1,
        summary,
    })
}
