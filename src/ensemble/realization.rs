//! One realization of an ensemble: the cell a seed generates and its six cell problems, kept
//! as a file of its own so that a rerun finds it and a killed run loses no finished work.

use crate::generate::CellParams;
use crate::homogenize::homogenize_elastic;
use crate::io::write_atomic;
use crate::solve::SolveOptions;
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
    /// Why it failed, when it did.
    pub error: Option<String>,
}

/// Generates the cell of `seed` and solves its six cell problems; an error of either is kept
/// in the result (an ensemble goes on without that realization).
pub fn run_realization(params: &CellParams, seed: u64, solve: &SolveOptions) -> Realization {
    let start = Instant::now();
    let mut r = Realization {
        seed,
        abd: None,
        fibers: 0,
        contacts: 0,
        seconds: 0.0,
        error: None,
    };
    let outcome = (|| -> Result<_, Error> {
        let description = params.with_seed(seed).generate()?;
        let model = Model::from_description(&description)?;
        let h = homogenize_elastic(&model, solve)?;
        Ok((model.fibers.len(), h))
    })();
    match outcome {
        Ok((fibers, h)) => {
            r.abd = Some(h.abd);
            r.fibers = fibers;
            r.contacts = h.contacts;
        }
        Err(e) => r.error = Some(e.to_string()),
    }
    r.seconds = start.elapsed().as_secs_f64();
    r
}

/// The folder of an ensemble's realizations: one JSON file per seed, written whole or not at
/// all.
pub struct RealizationStore {
    dir: PathBuf,
}

impl RealizationStore {
    /// The store of the realizations of `params` in `dir/realizations` (created if missing).
    /// The parameters (but the seed) are kept beside them in `params.json`: a store of other
    /// parameters is an error, not reused.
    pub fn open(dir: &Path, params: &CellParams) -> Result<Self, Error> {
        let dir = dir.join("realizations");
        let output = |e: String| Error::Output {
            path: dir.display().to_string(),
            message: e,
        };
        std::fs::create_dir_all(&dir).map_err(|e| output(e.to_string()))?;
        let file = dir.join("params.json");
        let ours = serde_json::to_value(params.with_seed(0)).map_err(|e| output(e.to_string()))?;
        match std::fs::read_to_string(&file) {
            Ok(text) => {
                let theirs: serde_json::Value =
                    serde_json::from_str(&text).map_err(|e| invalid_file(&file, &e.to_string()))?;
                if theirs != ours {
                    return Err(Error::InvalidOption(format!(
                        "{} holds realizations of other generator parameters: give another \
                         results folder, or delete that one to start afresh",
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

fn invalid_file(path: &Path, why: &str) -> Error {
    Error::InvalidOption(format!(
        "{} is not a file this ensemble wrote ({why}): delete it (a realization's is then run \
         again)",
        path.display()
    ))
}
