//! The ensemble run: realizations of consecutive seeds, each stored as it finishes, then the
//! statistics of every ABD entry (and curve point) and the convergence of the confidence
//! interval.

use super::curve_statistics::CurveStatistics;
use super::realization::{run_realization, CurvePath, Realization, RealizationStore};
use super::statistics::{summarize, SampleSummary};
use crate::generate::CellParams;
use crate::solve::SolveOptions;
use crate::Error;
use serde::Serialize;
use std::path::Path;

/// Hears of each realization as it is done, and whether it was read back from the store.
pub type EnsembleProgress<'a> = &'a mut dyn FnMut(&Realization, bool);

/// Options of [`run_ensemble`].
#[derive(Clone, Debug)]
pub struct EnsembleOptions {
    /// The generator and its parameters (the seed is replaced by each realization's).
    pub params: CellParams,
    /// Number of realizations N.
    pub realizations: usize,
    /// Seed of the first realization; the others follow it.
    pub first_seed: u64,
    /// Linear solver of the cell problems (and curves).
    pub solve: SolveOptions,
    /// Also ramp each realization along this path (the `curve` command's).
    pub curve: Option<CurvePath>,
}

/// The diagonal ABD entries whose interval convergence is reported: A11, A22, A66, D11, D22,
/// D66.
pub const MAIN_MODULI: [usize; 6] = [0, 1, 2, 3, 4, 5];

/// The relative confidence intervals of the main moduli after the first n realizations.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ConvergencePoint {
    /// Successful realizations counted.
    pub n: usize,
    /// ci95 / |mean| of ABD\[k\]\[k\] for k in [`MAIN_MODULI`].
    pub relative_ci95: [f64; 6],
}

/// An ensemble's results.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Ensemble {
    /// Every realization in seed order, failed ones with their error.
    pub realizations: Vec<Realization>,
    /// Statistics of each ABD entry over the successful realizations.
    pub abd: [[SampleSummary; 6]; 6],
    /// The interval of the main moduli as the successful realizations accumulate (from n = 2).
    pub convergence: Vec<ConvergencePoint>,
    /// Realizations read back from an earlier run instead of computed.
    pub reused: usize,
    /// Statistics of the curves, when the ensemble has them.
    pub curve: Option<CurveStatistics>,
}

impl Ensemble {
    /// The statistics of `realizations` (in seed order), with their curves' along `path`.
    pub fn from_realizations(
        realizations: Vec<Realization>,
        reused: usize,
        path: Option<&CurvePath>,
    ) -> Self {
        let ok: Vec<&[[f64; 6]; 6]> = realizations.iter().filter_map(|r| r.abd.as_ref()).collect();
        let abd = std::array::from_fn(|i| {
            std::array::from_fn(|j| summarize(&ok.iter().map(|a| a[i][j]).collect::<Vec<_>>()))
        });
        let convergence = (2..=ok.len())
            .map(|n| ConvergencePoint {
                n,
                relative_ci95: MAIN_MODULI.map(|k| {
                    summarize(&ok[..n].iter().map(|a| a[k][k]).collect::<Vec<_>>()).relative_ci95()
                }),
            })
            .collect();
        let curve = path.map(|p| CurveStatistics::from_realizations(p, &realizations));
        Ensemble {
            realizations,
            abd,
            convergence,
            reused,
            curve,
        }
    }

    /// The failed realizations: (seed, error).
    pub fn failed(&self) -> Vec<(u64, &str)> {
        self.realizations
            .iter()
            .filter_map(|r| Some((r.seed, r.error.as_deref()?)))
            .collect()
    }
}

/// The seeds of `opts`' realizations, after checking what every realization would refuse
/// alike (no realization, a curve path without increments, with too many or a non-finite
/// strain).
pub(super) fn seeds(opts: &EnsembleOptions) -> Result<std::ops::RangeInclusive<u64>, Error> {
    if opts.realizations == 0 {
        return Err(Error::InvalidOption(
            "an ensemble needs at least one realization".into(),
        ));
    }
    let last = opts
        .first_seed
        .checked_add(opts.realizations as u64 - 1)
        .ok_or_else(|| {
            Error::InvalidOption(format!(
                "seeds {} + {} realizations pass the largest seed",
                opts.first_seed, opts.realizations
            ))
        })?;
    if let Some(p) = &opts.curve {
        crate::homogenize::check_curve_path(&p.strain, p.steps, p.unload)?;
    }
    Ok(opts.first_seed..=last)
}

/// Runs the realizations of `opts` in seed order (each with its curve when `opts.curve` asks
/// for one). With `store`, each is written to
/// `store/realizations/seed-<seed>.json` as it finishes, and one already there is read back
/// instead of run again (a killed run restarts where it stopped). `progress` hears of each
/// realization as it is done (and whether it was reused).
pub fn run_ensemble(
    opts: &EnsembleOptions,
    store: Option<&Path>,
    mut progress: Option<EnsembleProgress<'_>>,
) -> Result<Ensemble, Error> {
    let seeds = seeds(opts)?;
    let store = store
        .map(|dir| RealizationStore::open(dir, &opts.params, opts.curve.as_ref()))
        .transpose()?;
    let mut done = Vec::with_capacity(opts.realizations);
    let mut reused = 0;
    for seed in seeds {
        let earlier = match &store {
            Some(s) => s.load(seed)?,
            None => None,
        };
        let was_stored = earlier.is_some();
        let r = match earlier {
            Some(r) => r,
            None => run_realization(&opts.params, seed, &opts.solve, opts.curve.as_ref()),
        };
        if let (Some(s), false) = (&store, was_stored) {
            s.save(&r)?;
        }
        reused += usize::from(was_stored);
        if let Some(p) = progress.as_mut() {
            p(&r, was_stored);
        }
        done.push(r);
    }
    Ok(Ensemble::from_realizations(
        done,
        reused,
        opts.curve.as_ref(),
    ))
}
