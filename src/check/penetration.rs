//! Contact penetration at the solution, relative to the smaller radius of the two fibers.
//!
//! A penalty contact carries its force N = p_N g by overlapping by g, so the penalty's
//! softness shows as penetration. The contact kinematics (a point contact, its normal and
//! tangents fixed) hold while g is a small fraction of the radii. For a supported model the
//! solution is the job's (the stick/slip run's last increment); for a cell it is each elastic
//! cell problem at a macroscopic strain of the requested size (curvatures κ = 2ε/h, the strain
//! ε at the fabric's faces), the overlap a contact starts with, max(−ḡ, 0), plus |δg| under it.

use crate::contact::{ContactOrigin, ContactPair, ContactState};
use crate::homogenize::PeriodicSystem;
use crate::model::Model;
use crate::solve::{gather, solve_incremental, IncrementalOptions, SolveOptions};
use crate::Error;
use serde::Serialize;
use std::collections::HashMap;

/// The worst contact under one load.
#[derive(Clone, Debug, Serialize)]
pub struct PenetrationCase {
    /// The load: a macroscopic strain, or the job's solution.
    pub load: String,
    /// Largest penetration of a closed contact (m).
    pub penetration: f64,
    /// It over the smaller radius of the contact's two fibers.
    pub ratio: f64,
    /// Index of that contact in the model's contact set (as `fibercell contacts` numbers them).
    pub contact: usize,
    /// Its fibers' ids.
    pub fibers: [u64; 2],
}

/// Penetrations of the closed contacts, per load.
#[derive(Clone, Debug, Serialize)]
pub struct PenetrationCheck {
    /// One per load (the worst contact of each).
    pub cases: Vec<PenetrationCase>,
    /// Contacts measured.
    pub contacts: usize,
}

impl PenetrationCheck {
    /// The case with the largest ratio.
    pub fn worst(&self) -> Option<&PenetrationCase> {
        self.cases.iter().max_by(|a, b| a.ratio.total_cmp(&b.ratio))
    }
}

/// The smaller radius of the fibers of each contact of `origins`.
fn smaller_radii(model: &Model, origins: &[ContactOrigin]) -> Vec<f64> {
    let radius: HashMap<u64, f64> = model
        .fibers
        .iter()
        .map(|f| (f.id, f.section.radius))
        .collect();
    origins
        .iter()
        .map(|o| {
            let r = |id| radius.get(&id).copied().unwrap_or(f64::NAN);
            r(o.fibers[0]).min(r(o.fibers[1]))
        })
        .collect()
}

/// The worst of `penetration(i)` over contacts `0..radii.len()` relative to `radii`; contact i
/// is number `index(i)` of the model's contact set.
fn worst_case(
    load: String,
    radii: &[f64],
    origins: &[ContactOrigin],
    index: impl Fn(usize) -> usize,
    penetration: impl Fn(usize) -> f64,
) -> PenetrationCase {
    let mut case = PenetrationCase {
        load,
        penetration: 0.0,
        ratio: 0.0,
        contact: 0,
        fibers: [0, 0],
    };
    for (i, &r) in radii.iter().enumerate() {
        let g = penetration(i);
        if g / r > case.ratio {
            (case.penetration, case.ratio, case.contact) = (g, g / r, index(i));
            case.fibers = origins[i].fibers;
        }
    }
    case
}

/// n·B q of `pair` for the generalized displacements `q`: the change of its penetration.
fn normal_jump(pair: &ContactPair, q: &[f64]) -> f64 {
    pair.kinematics(&gather(q, &pair.jump.nodes)).penetration + pair.gap
}

/// The names of the six macroscopic quantities.
const CASES: [&str; 6] = ["ε11", "ε22", "γ12", "κ11", "κ22", "κ12"];

/// Penetrations of a cell's closed contacts under each of the six macroscopic strains of size
/// `strain` (curvatures 2 `strain` / h), from the unit cell-problem solutions `x` (six columns
/// of length n, stacked).
pub fn cell_penetration(
    model: &Model,
    sys: &PeriodicSystem,
    x: &[f64],
    strain: f64,
) -> PenetrationCheck {
    let n = sys.n_free();
    let radii = smaller_radii(model, &sys.contact_origins);
    let h = sys.periodicity.geometry.thickness;
    let driver = sys.discretization.driver();
    let cases = (0..6)
        .map(|k| {
            let size = if k < 3 { strain } else { 2.0 * strain / h };
            let mut q = sys.discretization.generalized(&x[k * n..(k + 1) * n], 0.0);
            if let Some(d) = driver {
                q[6 * d + k] = 1.0;
            }
            let load = format!("{} = {size:.3e}", CASES[k]);
            let index = |i: usize| sys.contact_indices[i];
            worst_case(load, &radii, &sys.contact_origins, index, |i| {
                let pair = &sys.contacts[i];
                (-pair.gap).max(0.0) + size * normal_jump(pair, &q).abs()
            })
        })
        .collect();
    PenetrationCheck {
        cases,
        contacts: radii.len(),
    }
}

/// Penetrations of a supported model's closed contacts at the job's solution: the stick/slip
/// run with default options on `solve`, its last increment.
pub fn solution_penetration(
    model: &Model,
    solve: &SolveOptions,
) -> Result<PenetrationCheck, Error> {
    let options = IncrementalOptions {
        solve: solve.clone(),
        ..IncrementalOptions::default()
    };
    let sol = solve_incremental(model, &options)?;
    let origins = &sol.contacts.origins;
    let radii = smaller_radii(model, origins);
    let last = sol.contact_results.last().map(|r| &r[..]).unwrap_or(&[]);
    let load = format!("the solution (increment {})", sol.increments.len());
    let case = worst_case(
        load,
        &radii,
        origins,
        |i| i,
        |i| match last.get(i) {
            Some(r) if r.state != ContactState::Open => (-r.gap).max(0.0),
            _ => 0.0,
        },
    );
    Ok(PenetrationCheck {
        cases: vec![case],
        contacts: radii.len(),
    })
}
