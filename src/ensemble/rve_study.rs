//! The RVE-size study: ensembles of a non-woven at several cell sizes with the fiber density
//! kept, the mean and scatter of the main moduli against size, and the size from which the
//! relative 95 % interval of their mean stays below a tolerance — the representative volume
//! for that number of realizations (the interval shrinks like the scatter over √N).

use super::realization::Realization;
use super::run::{run_ensemble, Ensemble, EnsembleOptions, MAIN_MODULI};
use super::statistics::SampleSummary;
use crate::generate::{CellParams, FiberAmount, NonWoven};
use crate::solve::SolveOptions;
use crate::Error;
use serde::Serialize;
use std::path::Path;

/// Hears of each realization of an RVE study as it is done: the cell side, the realization
/// and whether it was read back from the store.
pub type RveProgress<'a> = &'a mut dyn FnMut(f64, &Realization, bool);

/// Options of [`run_rve_study`].
#[derive(Clone, Debug)]
pub struct RveStudyOptions {
    /// The non-woven at its own size; each size keeps its fibers per unit area (a count is
    /// scaled with the area, a volume fraction kept).
    pub params: NonWoven,
    /// Cell sides L (square cells L × L, m), in increasing order.
    pub sizes: Vec<f64>,
    /// Realizations per size.
    pub realizations: usize,
    /// Seed of the first realization of every size.
    pub first_seed: u64,
    /// Largest relative 95 % interval of a main modulus's mean at a representative size.
    pub tolerance: f64,
    /// Linear solver of the cell problems.
    pub solve: SolveOptions,
}

/// The ensemble at one size.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RveSize {
    /// Cell side L (m).
    pub size: f64,
    /// The generator's parameters at this size.
    pub params: NonWoven,
    /// Statistics of the main moduli A11, A22, A66, D11, D22, D66.
    pub moduli: [SampleSummary; 6],
    /// The whole ensemble (every realization).
    pub ensemble: Ensemble,
}

/// The study's results.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RveStudy {
    /// One ensemble per size, in increasing size.
    pub sizes: Vec<RveSize>,
    /// The tolerance on the relative interval.
    pub tolerance: f64,
    /// Per main modulus, the smallest size from which its relative interval stays within the
    /// tolerance (`None`: not within the sizes studied).
    pub representative: [Option<f64>; 6],
    /// The smallest size from which every main modulus's interval stays within it.
    pub representative_all: Option<f64>,
}

/// The non-woven `base` at side `size`: the same fibers per unit area.
pub fn scaled_nonwoven(base: &NonWoven, size: f64) -> NonWoven {
    let mut p = base.clone();
    let area = base.size[0] * base.size[1];
    p.size = [size, size];
    if let FiberAmount::Count { fibers } = base.amount {
        let scaled = (fibers as f64 * size * size / area).round();
        p.amount = FiberAmount::Count {
            fibers: (scaled as usize).max(1),
        };
    }
    p
}

/// The smallest of `sizes` (increasing) from which every later value of `relative` is within
/// `tolerance` (not NaN, not infinite).
pub fn representative_size(sizes: &[f64], relative: &[f64], tolerance: f64) -> Option<f64> {
    let within = |r: f64| r <= tolerance;
    let first_after_last_miss = relative
        .iter()
        .rposition(|&r| !within(r))
        .map_or(0, |k| k + 1);
    sizes.get(first_after_last_miss).copied()
}

/// Runs an ensemble of `opts.realizations` at each size; with `store`, size k keeps its
/// realizations in `store/size-<L>` (a rerun reuses them). `progress` hears of each
/// realization with its size.
pub fn run_rve_study(
    opts: &RveStudyOptions,
    store: Option<&Path>,
    mut progress: Option<RveProgress<'_>>,
) -> Result<RveStudy, Error> {
    check_sizes(&opts.sizes)?;
    // The base parameters set the density: a zero area or fiber count would scale to nonsense.
    opts.params.validate()?;
    if !(opts.tolerance > 0.0 && opts.tolerance.is_finite()) {
        return Err(Error::InvalidOption(format!(
            "tolerance {}: give a positive relative interval, e.g. 0.05",
            opts.tolerance
        )));
    }
    // Every size's parameters are checked before any realization runs (a size below twice
    // the fiber length fails for every seed alike).
    for &size in &opts.sizes {
        scaled_nonwoven(&opts.params, size)
            .validate()
            .map_err(|e| match e {
                Error::InvalidOption(m) => Error::InvalidOption(format!("cell size {size} m: {m}")),
                other => other,
            })?;
    }
    let mut sizes = Vec::with_capacity(opts.sizes.len());
    for &size in &opts.sizes {
        let params = scaled_nonwoven(&opts.params, size);
        let ensemble_opts = EnsembleOptions {
            params: CellParams::Nonwoven(params.clone()),
            realizations: opts.realizations,
            first_seed: opts.first_seed,
            solve: opts.solve.clone(),
            curve: None,
        };
        let dir = store.map(|d| d.join(format!("size-{size:e}")));
        let mut hear = |r: &Realization, reused: bool| {
            if let Some(p) = progress.as_mut() {
                p(size, r, reused);
            }
        };
        let ensemble = run_ensemble(&ensemble_opts, dir.as_deref(), Some(&mut hear))?;
        sizes.push(RveSize {
            size,
            params,
            moduli: MAIN_MODULI.map(|k| ensemble.abd[k][k]),
            ensemble,
        });
    }
    let side: Vec<f64> = sizes.iter().map(|s| s.size).collect();
    let representative: [Option<f64>; 6] = std::array::from_fn(|m| {
        let relative: Vec<f64> = sizes.iter().map(|s| s.moduli[m].relative_ci95()).collect();
        representative_size(&side, &relative, opts.tolerance)
    });
    let representative_all = representative
        .iter()
        .try_fold(0.0f64, |worst, r| r.map(|r| worst.max(r)));
    Ok(RveStudy {
        sizes,
        tolerance: opts.tolerance,
        representative,
        representative_all,
    })
}

fn check_sizes(sizes: &[f64]) -> Result<(), Error> {
    if sizes.is_empty() {
        return Err(Error::InvalidOption(
            "an RVE study needs at least one cell size".into(),
        ));
    }
    if let Some(s) = sizes.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
        return Err(Error::InvalidOption(format!(
            "cell size {s}: sizes are positive lengths in m"
        )));
    }
    if let Some(w) = sizes.windows(2).find(|w| w[1] <= w[0]) {
        return Err(Error::InvalidOption(format!(
            "cell sizes {} and {}: give them in increasing order",
            w[0], w[1]
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::representative_size;

    /// The size from which the interval stays within the tolerance: a dip that rises again
    /// does not count, an infinite or NaN interval (one realization) is outside.
    #[test]
    fn the_representative_size_is_where_the_interval_stays_within() {
        let sizes = [1.0, 2.0, 3.0, 4.0];
        assert_eq!(
            representative_size(&sizes, &[0.3, 0.04, 0.06, 0.03], 0.05),
            Some(4.0)
        );
        assert_eq!(
            representative_size(&sizes, &[0.3, 0.04, 0.05, 0.03], 0.05),
            Some(2.0)
        );
        assert_eq!(representative_size(&sizes, &[0.01; 4], 0.05), Some(1.0));
        assert_eq!(
            representative_size(&sizes, &[0.01, 0.01, 0.01, 0.2], 0.05),
            None
        );
        let odd = [0.01, f64::NAN, 0.01, 0.01];
        assert_eq!(representative_size(&sizes, &odd, 0.05), Some(3.0));
        let one = [0.01, 0.01, 0.01, f64::INFINITY];
        assert_eq!(representative_size(&sizes, &one, 0.05), None);
    }
}
