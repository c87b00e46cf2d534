//! The friction-driven elasto-plastic curve of a cell (thesis §5.1.2): a macroscopic strain path
//! ramped over increments with the stick/slip solver, the averaged stress resultants against
//! strain, the strain at which each contact switches, the piecewise-linear segments (one per
//! switch), the elastic/plastic split (5.5–5.6) and the dissipated energy.

use super::elastic::abd_on_factor;
use super::elastic_abd;
use super::segments::{linear_pieces, segment_starting_at, Segment};
use crate::cell::MacroStrain;
use crate::constraints::Discretization;
use crate::model::Model;
use crate::solve::{
    run_incremental, DriverCouplings, History, IncrementalOptions, IncrementalSolution, OnAllStick,
};
use crate::Error;
use serde::Serialize;

/// Options of [`elasto_plastic_curve`].
#[derive(Clone, Debug)]
pub struct CurveOptions {
    /// The macroscopic strain reached at the end of loading, E = (ε11, ε22, γ12, κ11, κ22, κ12).
    pub strain: MacroStrain,
    /// Increments of the loading branch.
    pub steps: usize,
    /// Unload to zero and reload to `strain` (hysteresis).
    pub unload: bool,
    /// Solver and state-iteration settings (`steps` and `path` are set from the above).
    pub incremental: IncrementalOptions,
}

/// One point of the curve.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CurvePoint {
    /// Increment.
    pub step: usize,
    /// Load factor along the path.
    pub alpha: f64,
    /// Macroscopic strain α E.
    pub strain: [f64; 6],
    /// Averaged stress resultants (N11, N22, N12 in N/m; M11, M22, M12 in N).
    pub resultant: [f64; 6],
    /// The all-stick elastic part A^elas α E (5.5).
    pub elastic: [f64; 6],
    /// resultant − elastic: the part lost to sliding (5.5–5.6).
    pub plastic: [f64; 6],
    /// Contacts open, stuck, sliding.
    pub open: usize,
    /// Stuck contacts.
    pub stick: usize,
    /// Sliding contacts.
    pub slip: usize,
    /// Dissipated energy per unit cell area so far (J/m²).
    pub dissipated: f64,
    /// Normwise backward error ‖Ax − b‖∞/(‖A‖∞‖x‖∞ + ‖b‖∞) of the increment's last linear
    /// solve (as `solve` reports it).
    pub backward_error: f64,
    /// The increment's equilibrium residual ‖R‖/(s + ‖α F‖) with the contact law's own
    /// forces, s the forces the elements carry (see
    /// [`crate::solve::IncrementRecord::equilibrium_residual`]).
    pub equilibrium_residual: f64,
    /// Contacts held in their state after chattering in this increment (their forces are the
    /// held state's, which the residual then measures).
    pub held: usize,
    /// State iterations of the increment.
    pub iterations: usize,
    /// Times the increment was halved (see [`crate::solve::IncrementRecord::cutbacks`]).
    pub cutbacks: usize,
    /// Work of the macroscopic resultants so far per unit cell area (J/m²), by the
    /// trapezoidal rule over the increments.
    pub external_work: f64,
    /// Elastic energy stored in the fibers and contact springs per unit area (J/m²).
    pub stored_energy: f64,
    /// Energy of the stabilizing springs per unit area (J/m²; 0 without stabilization).
    pub stabilization_energy: f64,
    /// |W_ext − E_el − E_stab − D| / W_ext: the energy balance (see
    /// [`crate::solve::EnergyBalance`]).
    pub energy_error: f64,
}

/// A contact changing state.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SwitchEvent {
    /// Contact (1-based).
    pub contact: usize,
    /// Increment at which the new state is first seen.
    pub step: usize,
    /// Macroscopic strain at the end of that increment.
    pub strain: [f64; 6],
    /// The strain where the switch happened: where the lines of the linear pieces before and
    /// after it meet (exact for a piecewise-linear response; within the increment).
    pub estimated_strain: [f64; 6],
    /// Previous state.
    pub from: &'static str,
    /// New state.
    pub to: &'static str,
}

/// The curve and everything derived from it.
#[derive(Clone, Debug, Serialize)]
pub struct Curve {
    /// The all-stick elastic ABD used for the split: six cell problems solved on the run's
    /// first factorization when that is the all-stick matrix (with factor reuse, the default),
    /// which then includes the open contacts' stabilizing springs ε (none by default);
    /// otherwise on a factorization of its own, exactly [`super::elastic_abd`].
    pub elastic_abd: [[f64; 6]; 6],
    /// Points, one per increment.
    pub points: Vec<CurvePoint>,
    /// State switches in order.
    pub switches: Vec<SwitchEvent>,
    /// Linear pieces between switches.
    pub segments: Vec<Segment>,
    /// The underlying incremental solution.
    #[serde(skip)]
    pub solution: IncrementalSolution,
}

/// The largest macroscopic strain (and curvature times the cell's larger period) a curve takes:
/// the beams and contacts are geometrically linear, so far beyond this the answer is that of
/// a different model.
pub const MAX_MACRO_STRAIN: f64 = 0.5;

/// Refuses strains beyond [`MAX_MACRO_STRAIN`] (curvatures times the larger period).
pub(super) fn check_small_strain(model: &Model, strain: &[f64; 6]) -> Result<(), Error> {
    let period = model
        .cell
        .as_ref()
        .map_or(1.0, |c| c.size[0].max(c.size[1]));
    for (k, (&e, name)) in strain.iter().zip(crate::cell::MACRO_NAMES).enumerate() {
        let measure = if k < 3 { e.abs() } else { e.abs() * period };
        if measure > MAX_MACRO_STRAIN {
            return Err(Error::InvalidOption(format!(
                "{name} = {e}: the model is geometrically linear (small strains); strains and \
                 curvatures times the period ({period} m) must stay within {MAX_MACRO_STRAIN}"
            )));
        }
    }
    Ok(())
}

/// The checks of a curve's path that need no model: a finite strain, at least one and at
/// most [`crate::solve::MAX_INCREMENTS`] increments in all (an ensemble refuses such a path
/// before its realizations run).
pub fn check_curve_path(strain: &MacroStrain, steps: usize, unload: bool) -> Result<(), Error> {
    if let Some(v) = strain.iter().find(|v| !v.is_finite()) {
        return Err(Error::InvalidOption(format!(
            "macroscopic strain component {v} is not finite"
        )));
    }
    if steps == 0 {
        return Err(Error::InvalidOption(
            "the number of increments must be at least 1".into(),
        ));
    }
    let path_length = if unload { 3 } else { 1 };
    if steps > crate::solve::MAX_INCREMENTS / path_length {
        return Err(Error::InvalidOption(format!(
            "{} increments{}: at most {} in all (every increment's results are kept)",
            steps,
            if unload {
                " per branch of load, unload and reload"
            } else {
                ""
            },
            crate::solve::MAX_INCREMENTS
        )));
    }
    Ok(())
}

/// Ramps the macroscopic strain of a periodic cell with contacts along `opts`.
pub fn elasto_plastic_curve(model: &Model, opts: &CurveOptions) -> Result<Curve, Error> {
    check_curve_path(&opts.strain, opts.steps, opts.unload)?;
    check_small_strain(model, &opts.strain)?;
    // The cell is set up once: pairing, contacts, percolation through the closed contacts (the
    // all-stick system must hold together) and the anchor.
    let (p, set, anchor) = crate::homogenize::system::prepare_cell(model, true)?;
    let disc = Discretization::periodic(model, &p, &opts.strain, Some(anchor));
    let n = opts.steps;
    let mut path: Vec<f64> = (1..=n).map(|k| k as f64 / n as f64).collect();
    if opts.unload {
        path.extend((0..n).rev().map(|k| k as f64 / n as f64));
        path.extend((1..=n).map(|k| k as f64 / n as f64));
    }
    // The points and switches need every increment's summary and contact states only.
    let history = match opts.incremental.history {
        History::Auto => History::Last,
        h => h,
    };
    let inc = IncrementalOptions {
        steps: path.len(),
        path: Some(path),
        history,
        ..opts.incremental.clone()
    };
    let area = p.geometry.area();
    let mut from_reference = None;
    let locate = |e| disc.locate(model, e);
    // The elastic ABD: six solves on the run's first factorization, the all-stick matrix,
    // with the run's own couplings to the drivers.
    let mut on_all_stick = |solver: &mut dyn fibercell_solver::LinearSolver,
                            a: fibercell_solver::CscRef<'_>,
                            couplings: Option<&DriverCouplings>| {
        if let Some(couplings) = couplings {
            let solve = &opts.incremental.solve;
            from_reference = Some(abd_on_factor(couplings, area, solver, a, solve, &locate)?);
        }
        Ok(())
    };
    let hook: OnAllStick<'_> = &mut on_all_stick;
    let sol = run_incremental(model, &disc, set, &inc, Some(hook))?;
    let elastic_abd = match from_reference {
        Some(abd) => abd,
        None => elastic_abd(model, &opts.incremental.solve)?,
    };
    let mut points = Vec::with_capacity(sol.increments.len());
    for r in &sol.increments {
        let strain = opts.strain.map(|e| r.alpha * e);
        let resultant = r.macro_reaction.unwrap_or([0.0; 6]).map(|v| v / area);
        let el: [f64; 6] =
            std::array::from_fn(|i| (0..6).map(|j| elastic_abd[i][j] * strain[j]).sum());
        points.push(CurvePoint {
            step: r.step,
            alpha: r.alpha,
            strain,
            resultant,
            elastic: el,
            plastic: std::array::from_fn(|i| resultant[i] - el[i]),
            open: r.open,
            stick: r.stick,
            slip: r.slip,
            dissipated: r.dissipated / area,
            backward_error: r.backward_error,
            equilibrium_residual: r.equilibrium_residual,
            held: r.held,
            iterations: r.iterations,
            cutbacks: r.cutbacks,
            external_work: r.energy.external_work / area,
            stored_energy: r.energy.stored / area,
            stabilization_energy: r.energy.stabilization / area,
            energy_error: r.energy.relative_error,
        });
    }
    // Switches: a contact's state differs from the previous increment (initial: from the first).
    let mut switches = Vec::new();
    for (k, point) in points.iter().enumerate().skip(1) {
        for (c, (now, before)) in sol.contact_states[k]
            .iter()
            .zip(&sol.contact_states[k - 1])
            .enumerate()
        {
            if now != before {
                switches.push(SwitchEvent {
                    contact: c + 1,
                    step: k + 1,
                    strain: point.strain,
                    estimated_strain: point.strain,
                    from: before.name(),
                    to: now.name(),
                });
            }
        }
    }
    // Pieces: break where any switch happens or the path turns.
    let turns: Vec<usize> = (1..points.len().saturating_sub(1))
        .filter(|&k| {
            let (a, b, c) = (points[k - 1].alpha, points[k].alpha, points[k + 1].alpha);
            (b - a) * (c - b) < 0.0
        })
        .map(|k| k + 2)
        .collect();
    let mut breaks: Vec<usize> = switches
        .iter()
        .map(|s| s.step)
        .chain(turns.iter().copied())
        .collect();
    breaks.sort_unstable();
    breaks.dedup();
    let samples: Vec<(f64, [f64; 6])> = points.iter().map(|p| (p.alpha, p.resultant)).collect();
    let segments = linear_pieces(&samples, &breaks, &turns, &opts.strain);
    for s in &mut switches {
        if let Some(seg) = segment_starting_at(&segments, s.step) {
            s.estimated_strain = opts.strain.map(|e| seg.alpha[0] * e);
        }
    }
    Ok(Curve {
        elastic_abd,
        points,
        switches,
        segments,
        solution: sol,
    })
}
