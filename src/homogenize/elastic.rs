//! The six elastic cell problems (thesis 3.13–3.16 for a frame network): one factorization,
//! six right-hand sides −K_fE e_k, and ABD = (K_EE − K_Ef K_ff⁻¹ K_fE) / |Y|, the Schur
//! complement of the driver DOFs per unit cell area — symmetric by construction. A seventh
//! right-hand side is the out-of-plane pressure problem Θ (3.28, 5.2): its driver reactions per
//! unit area are B^hom (5.4).

use super::pressure::{default_pixel, pressure_load};
use super::{Orthotropic, PeriodicSystem, PeriodicValues, ThesisModuli};
use crate::cell::{macro_matrix, CellGeometry};
use crate::model::Model;
use crate::solve::DriverCouplings;
use crate::solve::{check_backward_error, SolveOptions};
use crate::Error;
use fibercell_solver::{solve_checked, solve_checked_into, CscRef, LinearSolver, SolverError};
use nalgebra::DMatrix;
use rayon::prelude::*;
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
    /// Largest normwise backward error ‖Ax − b‖∞/(‖A‖∞‖x‖∞ + ‖b‖∞) of the seven solves (the
    /// six cell problems and Θ); accepted up to 1e-10.
    pub backward_error: f64,
    /// Largest relative residual ‖Ax − b‖₂/‖b‖₂ of the seven solves (reported, as `solve`
    /// does, not used to reject: its roundoff floor ε‖A‖‖x‖/‖b‖ is large on stiff cells).
    pub relative_residual: f64,
    /// Backend.
    pub backend: String,
    /// The out-of-plane pressure problem.
    pub pressure: PressureResponse,
    /// For each unit load case k, the nodal displacements (the cell-problem solutions N_q).
    #[serde(skip)]
    pub cases: Vec<Vec<[f64; 6]>>,
    /// Cell geometry.
    #[serde(skip)]
    pub geometry: Option<CellGeometry>,
    /// Wall-clock time of each stage.
    pub timings: HomogenizeTimings,
}

/// Wall-clock seconds of the stages of [`homogenize_elastic`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct HomogenizeTimings {
    /// Boundary pairing, contact search (with periodic images), percolation check and the
    /// sparsity pattern.
    pub setup: f64,
    /// Value fill of K (elements and contacts) and of the driver couplings.
    pub assembly: f64,
    /// Symbolic analysis (ordering and elimination tree).
    pub analysis: f64,
    /// Numeric factorization.
    pub factorization: f64,
    /// The pressure load Θ, computed on a thread of its own during the analysis and
    /// factorization (its seconds overlap theirs and are not part of `total`).
    pub pressure_load: f64,
    /// The seven solves (six cell problems and Θ) with their residual check.
    pub solve: f64,
    /// ABD, moduli and the expanded cell-problem solutions.
    pub post: f64,
    /// Everything.
    pub total: f64,
}

impl HomogenizeTimings {
    /// The stages in order: setup, assembly, analysis, factorization, pressure load, solve,
    /// post-processing (laps of one clock, adding up to at most `total`, except the pressure
    /// load, which runs beside the analysis and factorization).
    pub fn stages(&self) -> [f64; 7] {
        [
            self.setup,
            self.assembly,
            self.analysis,
            self.factorization,
            self.pressure_load,
            self.solve,
            self.post,
        ]
    }
}

/// The response of the cell to a unit out-of-plane pressure (1 Pa pushing the top face down,
/// balanced by a uniform body force, zero macroscopic strain).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PressureResponse {
    /// B^hom (5.4): the volume-averaged resultants per unit pressure, N11, N22, N12 (N/m per
    /// Pa = m) and M11, M22, M12 (N per Pa = m²): the driver reactions plus the virial Σ M(x)ᵀ f
    /// of the load, which by reciprocity equals −(1/|Y|) × the work of the load on the periodic
    /// fluctuation of each unit cell problem. The thesis's p is the outward traction: its
    /// B^hom is the negative of this one.
    pub b_hom: [f64; 6],
    /// Fraction of the cell area that sees a fiber from above (where the pressure acts).
    pub coverage: f64,
    /// Pixel size of the top-surface sampling (m).
    pub pixel: f64,
    /// Nodal displacements and rotations per unit pressure (the solution Θ).
    #[serde(skip)]
    pub displacements: Vec<[f64; 6]>,
}

/// Seconds since `clock`, which restarts.
fn lap_seconds(clock: &mut std::time::Instant) -> f64 {
    let now = std::time::Instant::now();
    let t = (now - *clock).as_secs_f64();
    *clock = now;
    t
}

/// The cell matrix of `model` with all closed contacts stuck, assembled, analysed and
/// factorized: the system, its values, the factorization (stages timed into `timings`) and
/// what `beside` returns — it runs on a thread of its own during the analysis and
/// factorization, whose ordering and symbolic steps leave a core idle.
fn factor_cell<T: Send>(
    model: &Model,
    options: &SolveOptions,
    timings: &mut HomogenizeTimings,
    beside: impl FnOnce(&PeriodicSystem, &PeriodicValues) -> T + Send,
) -> Result<(PeriodicSystem, PeriodicValues, Box<dyn LinearSolver>, T), Error> {
    let mut clock = std::time::Instant::now();
    let sys = PeriodicSystem::new(model)?;
    timings.setup = lap_seconds(&mut clock);
    let vals = sys.assemble(model);
    let a = sys.pattern.matrix(&vals.values)?;
    timings.assembly = lap_seconds(&mut clock);
    let mut solver = options
        .solver_config(sys.discretization.node_block_starts())
        .build()?;
    let (factored, extra) = std::thread::scope(|scope| {
        let side = scope.spawn(|| beside(&sys, &vals));
        let mut factor = || -> Result<(), Error> {
            solver.analyze(a).map_err(|e| sys.locate(model, e))?;
            timings.analysis = lap_seconds(&mut clock);
            solver.factorize(a).map_err(|e| sys.locate(model, e))?;
            timings.factorization = lap_seconds(&mut clock);
            Ok(())
        };
        let factored = factor();
        let extra = side
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        (factored, extra)
    });
    factored?;
    Ok((sys, vals, solver, extra))
}

/// ABD = (K_EE + K_Ef x) / |Y| from the driver couplings and the six cell-problem solutions
/// x = −K_ff⁻¹ K_fE (columns of length `n`, stacked).
pub(crate) fn abd_of(couplings: &DriverCouplings, x: &[f64], n: usize, area: f64) -> [[f64; 6]; 6] {
    // K_Ef x in one pass over the couplings (each sum still in row order).
    let mut schur = [[0.0; 6]; 6];
    for (i, c) in couplings.coupling.iter().enumerate().take(n) {
        for k in 0..6 {
            let xi = x[k * n + i];
            for (row, cj) in schur.iter_mut().zip(c) {
                row[k] += cj * xi;
            }
        }
    }
    std::array::from_fn(|j| std::array::from_fn(|k| (couplings.k_ee[(j, k)] + schur[j][k]) / area))
}

/// max |ABD − ABDᵀ| / max |ABD|: zero in exact arithmetic, so the round-off of the moduli.
pub(crate) fn abd_asymmetry(abd: &[[f64; 6]; 6]) -> f64 {
    let scale = abd.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    (0..6)
        .flat_map(|j| (0..6).map(move |k| (j, k)))
        .map(|(j, k)| (abd[j][k] - abd[k][j]).abs())
        .fold(0.0f64, f64::max)
        / scale.max(f64::MIN_POSITIVE)
}

/// The right-hand sides −K_fE e_k of the six cell problems, stacked, with room for `extra`
/// more columns (zero).
pub(crate) fn cell_rhs(couplings: &DriverCouplings, n: usize, extra: usize) -> Vec<f64> {
    let mut rhs = vec![0.0; (6 + extra) * n];
    for (i, c) in couplings.coupling.iter().enumerate() {
        for k in 0..6 {
            rhs[k * n + i] = -c[k];
        }
    }
    rhs
}

/// The linear systems a job solves, as matrices for other tools: the matrix, its right-hand
/// sides (column after column) and, per row, the node id and DOF of the unknown.
#[derive(Clone, Debug)]
pub struct LinearSystem {
    /// The matrix, both triangles stored.
    pub matrix: fibercell_solver::CscMatrix,
    /// The right-hand sides, `columns` of length n, column after column.
    pub rhs: Vec<f64>,
    /// Number of right-hand sides.
    pub columns: usize,
    /// Per row: node id and DOF of its unknown.
    pub dofs: Vec<(u64, crate::model::Dof)>,
}

/// The six elastic cell problems of `model` (which needs a `[cell]`): K_ff after periodic
/// elimination and anchoring, with every closed contact in stick (thesis 5.5), and the right-
/// hand sides −K_fE e_k for e_k = ε11, ε22, γ12, κ11, κ22, κ12 — what
/// [`homogenize_elastic`] factorizes and solves.
pub fn cell_problem(model: &Model) -> Result<LinearSystem, Error> {
    let sys = PeriodicSystem::new(model)?;
    let vals = sys.assemble(model);
    let n = sys.n_free();
    let matrix = sys.pattern.matrix(&vals.values)?.to_owned();
    let dofs = (0..n)
        .map(|k| {
            let (node, dof) = sys.node_dof(k);
            (model.nodes[node].id, dof)
        })
        .collect();
    Ok(LinearSystem {
        matrix,
        rhs: cell_rhs(&vals.couplings, n, 0),
        columns: 6,
        dofs,
    })
}

/// The all-stick ABD of `model` alone: the six cell problems of [`homogenize_elastic`]
/// without the pressure problem Θ, the moduli and the expanded solutions (what
/// [`super::elasto_plastic_curve`] splits its resultants with).
pub fn elastic_abd(model: &Model, options: &SolveOptions) -> Result<[[f64; 6]; 6], Error> {
    let (sys, vals, mut solver, ()) =
        factor_cell(model, options, &mut HomogenizeTimings::default(), |_, _| ())?;
    let a = sys.pattern.matrix(&vals.values)?;
    let area = sys.periodicity.geometry.area();
    abd_on_factor(&vals.couplings, area, solver.as_mut(), a, options, &|e| {
        sys.locate(model, e)
    })
}

/// The all-stick ABD from the six cell problems −K_fE e_k of `couplings` (K_fE and K_EE)
/// solved on `solver`, a factorization of `a`: K_ff itself, or a matrix on the same free DOFs
/// that stands for it (the incremental run's all-stick matrix, whose pattern also holds the
/// open contacts). The backward error is checked against `a`.
pub(super) fn abd_on_factor(
    couplings: &DriverCouplings,
    area: f64,
    solver: &mut dyn LinearSolver,
    a: CscRef<'_>,
    options: &SolveOptions,
    locate: &dyn Fn(SolverError) -> Error,
) -> Result<[[f64; 6]; 6], Error> {
    let n = couplings.coupling.len();
    let rhs = cell_rhs(couplings, n, 0);
    let (x, report) = solve_checked(solver, a, &rhs, 6).map_err(locate)?;
    check_backward_error(options, report.backward_error, "cell problems")?;
    Ok(abd_of(couplings, &x, n, area))
}

/// The Θ load of a cell beside its right-hand side on the unknowns: the part on the driver,
/// and the virial Σ M(x)ᵀ f over the loaded points (images at their shifted positions).
struct ThetaLoad {
    /// The load on the driver's six DOFs.
    driver_load: [f64; 6],
    /// Σ M(x)ᵀ f.
    virial: [f64; 6],
    /// Covered fraction of the cell.
    coverage: f64,
    /// Pixel size (m).
    pixel: f64,
    /// Wall-clock seconds it took.
    seconds: f64,
}

/// The unit-pressure load of `model` moved onto the generalized DOFs of `sys` (Tᵀ f, periodic
/// images included) and added into `column` (one value per free unknown).
fn theta_load(model: &Model, sys: &PeriodicSystem, column: &mut [f64]) -> ThetaLoad {
    let start = std::time::Instant::now();
    let g = sys.periodicity.geometry;
    let disc = &sys.discretization;
    let driver = disc.driver().unwrap_or(usize::MAX);
    let load = pressure_load(model, &g, 1.0, default_pixel(model));
    let (mut driver_load, mut virial) = ([0.0; 6], [0.0; 6]);
    for (e, shift, f) in &load.elements {
        let nodes = model.elements()[*e].nodes;
        let shifts = [*shift, *shift];
        // Tᵀ f on the generalized nodes; most elements are their own (T = I).
        let moved;
        let (gnodes, fg): (&[usize], &[f64]) = if disc.is_identity_block(&nodes, &shifts) {
            (&nodes, f.as_slice())
        } else {
            let (gnodes, t) = disc.block_of_images(&nodes, &shifts);
            moved = (
                gnodes,
                t.transpose() * DMatrix::from_column_slice(12, 1, f.as_slice()),
            );
            (&moved.0, moved.1.as_slice())
        };
        for (c, &gn) in gnodes.iter().enumerate() {
            for d in 0..6 {
                if gn == driver {
                    driver_load[d] += fg[6 * c + d];
                } else if let Some(r) = disc.reduced(6 * gn + d) {
                    column[r] += fg[6 * c + d];
                }
            }
        }
        for (a, &node) in nodes.iter().enumerate() {
            let x = g.relative(&model.nodes[node].x);
            let m = macro_matrix(
                x[0] + f64::from(shift[0]) * g.size[0],
                x[1] + f64::from(shift[1]) * g.size[1],
                x[2],
            );
            for (k, v) in virial.iter_mut().enumerate() {
                *v += (0..6).map(|d| m[(d, k)] * f[6 * a + d]).sum::<f64>();
            }
        }
    }
    ThetaLoad {
        driver_load,
        virial,
        coverage: load.coverage,
        pixel: load.pixel,
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// What the thread beside the analysis prepares for the seven solves of
/// [`homogenize_elastic`].
struct CellLoads {
    /// The right-hand sides: the six cell problems −K_fE e_k, then Θ, column after column.
    rhs: Vec<f64>,
    /// A buffer of the same length for the solutions, its pages mapped (by writing zeros) so
    /// that the solve does not wait on their first touch.
    solutions: Vec<f64>,
    /// The pressure load's driver part, virial and sampling.
    theta: ThetaLoad,
}

/// The [`CellLoads`] of `model` on the system `sys` with the values `vals`.
fn cell_loads(model: &Model, sys: &PeriodicSystem, vals: &PeriodicValues) -> CellLoads {
    let n = sys.n_free();
    let mut rhs = cell_rhs(&vals.couplings, n, 1);
    let theta = theta_load(model, sys, &mut rhs[6 * n..]);
    let mut solutions = Vec::with_capacity(rhs.len());
    solutions.resize(rhs.len(), 0.0);
    CellLoads {
        rhs,
        solutions,
        theta,
    }
}

/// Solves the six unit cell problems of `model` (which needs a `[cell]`) and returns ABD and
/// the derived constants.
pub fn homogenize_elastic(model: &Model, options: &SolveOptions) -> Result<Homogenized, Error> {
    let start = std::time::Instant::now();
    let mut timings = HomogenizeTimings::default();
    let (sys, vals, mut solver, loads) = factor_cell(model, options, &mut timings, |sys, vals| {
        cell_loads(model, sys, vals)
    })?;
    let load = loads.theta;
    timings.pressure_load = load.seconds;
    let mut clock = std::time::Instant::now();
    let mut lap = || lap_seconds(&mut clock);
    let n = sys.n_free();
    let a = sys.pattern.matrix(&vals.values)?;
    let locate = |e: SolverError| sys.locate(model, e);
    let g = sys.periodicity.geometry;
    let area = g.area();
    let (x, report) =
        solve_checked_into(solver.as_mut(), a, &loads.rhs, loads.solutions, 7).map_err(locate)?;
    check_backward_error(options, report.backward_error, "cell problems")?;
    timings.solve = lap();
    let theta = &x[6 * n..7 * n];
    // Driver reaction (internal force minus the load on the drivers) plus the load virial: the
    // volume average of the stress, as (5.4) defines it.
    let b_hom: [f64; 6] = std::array::from_fn(|k| {
        let reaction: f64 = (0..n)
            .map(|i| vals.couplings.coupling[i][k] * theta[i])
            .sum();
        (reaction - load.driver_load[k] + load.virial[k]) / area
    });
    // ABD and the pressure solution's expansion to every node beside the expansions of the six
    // cell problems (each its own pass; on L 0.06 s one after another, 0.03 s side by side).
    let ((abd, displacements), cases) = rayon::join(
        || {
            rayon::join(
                || abd_of(&vals.couplings, &x, n, area),
                || sys.expand(theta, &[0.0; 6]),
            )
        },
        || {
            (0..6)
                .into_par_iter()
                .map(|k| {
                    let mut e = [0.0; 6];
                    e[k] = 1.0;
                    sys.expand(&x[k * n..(k + 1) * n], &e)
                })
                .collect::<Vec<_>>()
        },
    );
    let pressure = PressureResponse {
        b_hom,
        coverage: load.coverage,
        pixel: load.pixel,
        displacements,
    };
    let asym = abd_asymmetry(&abd);
    timings.post = lap();
    timings.total = start.elapsed().as_secs_f64();
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
        relative_residual: report.relative_residual,
        backend: report.backend.to_string(),
        pressure,
        cases,
        geometry: Some(g),
        timings,
    })
}
