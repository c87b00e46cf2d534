//! One realization of an ensemble: the cell a seed generates, its six cell problems and
//! optionally its elasto-plastic curve, kept as a file of its own so that a rerun finds it and a
//! killed run loses no finished work.

use crate::cell::MacroStrain;
use crate::generate::CellParams;
use crate::homogenize::{elasto_plastic_curve, homogenize_elastic, CurveOptions};
use crate::io::write_atomic;
use crate::solve::{IncrementalOptions, SolveOptions};
use crate::{Error, Model};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What one realization gave: its ABD, or the error that stopped it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Realization {
    /// Generator seed.
    pub seed: u64,
    /// ABD per unit cell area (A in N/m, B in N, D in N·m); `None` when the realization failed.
    pub abd: Option<[[f64; 6]; 6]>,
    /// Fibers of the generated cell (pieces cut by the faces counted apiece).
    pub fibers: usize,
    /// Closed contacts of the cell problems.
    pub contacts: usize,
    /// Wall-clock seconds of generation and the cell problems.
    pub seconds: f64,
    /// Why it failed, when it did (a failed curve: its error, with the ABD kept).
    pub error: Option<String>,
    /// The curve along the ensemble's [`CurvePath`], when it asks for one and the curve ran.
    #[serde(default)]
    pub curve: Option<Vec<CurveSample>>,
}

/// The strain path of an ensemble's curves: the macroscopic strain reached at the end of
/// loading in `steps` increments, then unloaded to zero and reloaded with `unload` — the
/// `curve` command's path, with its defaults for everything else.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CurvePath {
    /// E = (ε11, ε22, γ12, κ11, κ22, κ12) at the end of loading.
    pub strain: MacroStrain,
    /// Increments of the loading branch.
    pub steps: usize,
    /// Unload to zero and reload.
    pub unload: bool,
}

impl CurvePath {
    /// Points of a complete curve along the path (three branches with `unload`).
    pub fn points(&self) -> usize {
        self.steps * if self.unload { 3 } else { 1 }
    }
}

/// One point of a realization's curve: what the ensemble's statistics need of
/// [`crate::homogenize::CurvePoint`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CurveSample {
    /// Macroscopic strain α E.
    pub strain: [f64; 6],
    /// Averaged stress resultants (N11, N22, N12 in N/m; M11, M22, M12 in N).
    pub resultant: [f64; 6],
    /// Dissipated energy per unit cell area so far (J/m²).
    pub dissipated: f64,
    /// The increment's equilibrium residual ‖R‖/‖F‖.
    pub equilibrium_residual: f64,
}

/// Generates the cell of `seed`, solves its six cell problems and, with `curve`, ramps it
/// along that path; an error is kept in the result (an ensemble goes on without that
/// realization, or without its curve).
pub fn run_realization(
    params: &CellParams,
    seed: u64,
    solve: &SolveOptions,
    curve: Option<&CurvePath>,
) -> Realization {
    let start = Instant::now();
    let mut r = Realization {
        seed,
        abd: None,
        fibers: 0,
        contacts: 0,
        seconds: 0.0,
        error: None,
        curve: None,
    };
    let outcome = (|| -> Result<_, Error> {
        let description = params.with_seed(seed).generate()?;
        let model = Model::from_description(&description)?;
        let h = homogenize_elastic(&model, solve)?;
        Ok((model, h))
    })();
    match outcome {
        Ok((model, h)) => {
            r.abd = Some(h.abd);
            r.fibers = model.fibers.len();
            r.contacts = h.contacts;
            if let Some(path) = curve {
                match realization_curve(&model, path, solve) {
                    Ok(points) => r.curve = Some(points),
                    Err(e) => r.error = Some(format!("curve: {e}")),
                }
            }
        }
        Err(e) => r.error = Some(e.to_string()),
    }
    r.seconds = start.elapsed().as_secs_f64();
    r
}

/// The curve of `model` along `path`, as samples.
fn realization_curve(
    model: &Model,
    path: &CurvePath,
    solve: &SolveOptions,
) -> Result<Vec<CurveSample>, Error> {
    let c = elasto_plastic_curve(
        model,
        &CurveOptions {
            strain: path.strain,
            steps: path.steps,
            unload: path.unload,
            incremental: IncrementalOptions {
                solve: solve.clone(),
                ..IncrementalOptions::default()
            },
        },
    )?;
    Ok(c.points
        .iter()
        .map(|p| CurveSample {
            strain: p.strain,
            resultant: p.resultant,
            dissipated: p.dissipated,
            equilibrium_residual: p.equilibrium_residual,
        })
        .collect())
}

/// The folder of an ensemble's realizations: one JSON file per seed, written whole or not at
/// all.
pub struct RealizationStore {
    dir: PathBuf,
}

impl RealizationStore {
    /// The store of the realizations of `params` (and curves along `curve`) in
    /// `dir/realizations` (created if missing). The parameters (but the seed) and the path are
    /// kept beside them in `params.json`: a store of other parameters or another path is an
    /// error, not reused.
    pub fn open(dir: &Path, params: &CellParams, curve: Option<&CurvePath>) -> Result<Self, Error> {
        let dir = dir.join("realizations");
        let output = |e: String| Error::Output {
            path: dir.display().to_string(),
            message: e,
        };
        std::fs::create_dir_all(&dir).map_err(|e| output(e.to_string()))?;
        let file = dir.join("params.json");
        let ours = store_identity(params, curve).map_err(|e| output(e.to_string()))?;
        match std::fs::read_to_string(&file) {
            Ok(text) => {
                let theirs: serde_json::Value =
                    serde_json::from_str(&text).map_err(|e| invalid_file(&file, &e.to_string()))?;
                if theirs != ours {
                    return Err(Error::InvalidOption(format!(
                        "{} holds realizations of other generator parameters or another curve \
                         path: give another results folder, or delete that one to start afresh",
                        dir.display()
                    )));
                }
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                let text =
                    serde_json::to_string_pretty(&ours).map_err(|e| output(e.to_string()))?;
                write_atomic(&file, text.as_bytes())?;
            }
            Err(e) => return Err(invalid_file(&file, &e.to_string())),
        }
        Ok(RealizationStore { dir })
    }

    fn path(&self, seed: u64) -> PathBuf {
        self.dir.join(format!("seed-{seed}.json"))
    }

    /// The stored realization of `seed`, if a run finished it; a file that does not hold one
    /// (edited by hand, another program's) is an error naming it.
    pub fn load(&self, seed: u64) -> Result<Option<Realization>, Error> {
        let path = self.path(seed);
        let text = match std::fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(invalid_file(&path, &e.to_string())),
        };
        let r: Realization =
            serde_json::from_str(&text).map_err(|e| invalid_file(&path, &e.to_string()))?;
        if r.seed != seed {
            return Err(invalid_file(&path, &format!("it holds seed {}", r.seed)));
        }
        Ok(Some(r))
    }

    /// Stores `r` (atomically).
    pub fn save(&self, r: &Realization) -> Result<(), Error> {
        let text = serde_json::to_string_pretty(r).map_err(|e| Error::Output {
            path: self.path(r.seed).display().to_string(),
            message: e.to_string(),
        })?;
        write_atomic(&self.path(r.seed), text.as_bytes())
    }
}

/// What a store's realizations were computed for: the generator's parameters without the seed
/// and, when the ensemble has curves, their path (a store without curves keeps the parameters
/// alone, as before curves were added).
fn store_identity(
    params: &CellParams,
    curve: Option<&CurvePath>,
) -> serde_json::Result<serde_json::Value> {
    let params = serde_json::to_value(params.with_seed(0))?;
    match curve {
        None => Ok(params),
        Some(c) => Ok(serde_json::json!({ "generator": params, "curve": c })),
    }
}

fn invalid_file(path: &Path, why: &str) -> Error {
    Error::InvalidOption(format!(
        "{} is not a file this ensemble wrote ({why}): delete it (a realization's is then run \
         again)",
        path.display()
    ))
}
