//! The result files of an RVE-size study: per size the statistics of the main moduli
//! (`rve.csv`), two plots — the moduli's means against size, relative to the largest size's,
//! and their relative 95 % intervals against size with the tolerance — and the whole study
//! (`rve.json`, written last).

use super::ensemble_files::{abd_entry_name, main_moduli_plot};
use super::plot::Series;
use crate::ensemble::{RveStudy, MAIN_MODULI};
use crate::Error;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// `size`, realizations that succeeded, then per main modulus mean, std, ci95 and
/// relative ci95.
pub fn rve_csv(study: &RveStudy) -> String {
    let mut s = String::from("size,n");
    for k in MAIN_MODULI {
        let name = abd_entry_name(k, k);
        let _ = write!(
            s,
            ",{name}_mean,{name}_std,{name}_ci95,{name}_relative_ci95"
        );
    }
    s.push('\n');
    for z in &study.sizes {
        let _ = write!(s, "{:e},{}", z.size, z.moduli[0].n);
        for x in &z.moduli {
            let _ = write!(
                s,
                ",{:e},{:e},{:e},{:e}",
                x.mean,
                x.std,
                x.ci95,
                x.relative_ci95()
            );
        }
        s.push('\n');
    }
    s
}

/// One line per main modulus against the cell size (mm), `value(size, modulus)`.
fn plot(
    study: &RveStudy,
    title: &str,
    y_label: &str,
    value: &dyn Fn(usize, usize) -> f64,
    extra: Option<Series>,
) -> Result<(String, Vec<u8>), Error> {
    let points: Vec<Vec<(f64, f64)>> = (0..MAIN_MODULI.len())
        .map(|m| {
            (0..study.sizes.len())
                .map(|z| (1e3 * study.sizes[z].size, value(z, m)))
                .filter(|p| p.1.is_finite())
                .collect()
        })
        .collect();
    main_moduli_plot(title, ("cell side L (mm)", y_label), &points, extra)
}

/// Writes `rve.csv`, `rve-moduli.svg`/`.png`, `rve-interval.svg`/`.png` and last `rve.json`
/// into `dir`, each atomically; returns their paths.
pub fn write_rve_files(dir: &Path, study: &RveStudy, title: &str) -> Result<Vec<PathBuf>, Error> {
    let json = serde_json::to_string_pretty(study).map_err(|err| Error::Output {
        path: "rve.json".into(),
        message: err.to_string(),
    })?;
    let last = study.sizes.last();
    let relative_mean = |z: usize, m: usize| {
        let reference = last.map_or(f64::NAN, |l| l.moduli[m].mean);
        study.sizes[z].moduli[m].mean / reference
    };
    let (moduli_svg, moduli_png) = plot(
        study,
        title,
        "mean / mean at the largest size",
        &relative_mean,
        None,
    )?;
    let span: Vec<(f64, f64)> = [study.sizes.first(), last]
        .iter()
        .flatten()
        .map(|z| (1e3 * z.size, 100.0 * study.tolerance))
        .collect();
    let tolerance = Series {
        points: &span,
        colour: (0, 0, 0),
        label: "tolerance",
    };
    let (interval_svg, interval_png) = plot(
        study,
        title,
        "95 % interval of the mean / mean (%)",
        &|z, m| 100.0 * study.sizes[z].moduli[m].relative_ci95(),
        Some(tolerance),
    )?;
    let table = rve_csv(study);
    super::write_results(
        dir,
        &[
            ("rve.csv", table.as_bytes()),
            ("rve-moduli.svg", moduli_svg.as_bytes()),
            ("rve-moduli.png", &moduli_png),
            ("rve-interval.svg", interval_svg.as_bytes()),
            ("rve-interval.png", &interval_png),
            ("rve.json", json.as_bytes()),
        ],
    )
}
