//! The curve files of an ensemble: per point of the path the statistics of every resultant and
//! of the dissipation (`ensemble-curve.csv`), every realization's own curve (`curves.csv`), and
//! a plot of the realizations with the mean and its 95 % interval.

use super::curve_files::{RESULTANT_NAMES, RESULTANT_UNITS};
use super::plot::{LinePlot, Series};
use crate::cell::MACRO_NAMES;
use crate::ensemble::{CurveStatistics, Ensemble, SampleSummary};
use crate::Error;
use std::fmt::Write;

/// `step`, the six strains, then mean, std and ci95 of each resultant and of the dissipation.
pub fn ensemble_curve_csv(c: &CurveStatistics) -> String {
    let mut s = String::from("step");
    for name in MACRO_NAMES {
        let _ = write!(s, ",{name}");
    }
    for name in RESULTANT_NAMES.iter().chain(&["dissipated"]) {
        let _ = write!(s, ",{name}_mean,{name}_std,{name}_ci95");
    }
    s.push('\n');
    let summary = |s: &mut String, x: &SampleSummary| {
        let _ = write!(s, ",{:e},{:e},{:e}", x.mean, x.std, x.ci95);
    };
    for p in &c.points {
        let _ = write!(s, "{}", p.step);
        for v in p.strain {
            let _ = write!(s, ",{v:e}");
        }
        for x in p.resultant.iter().chain([&p.dissipated]) {
            summary(&mut s, x);
        }
        s.push('\n');
    }
    s
}

/// Every realization's curve: `seed`, `step`, the six strains, the six resultants, the
/// dissipation and the increment's equilibrium residual.
pub fn realization_curves_csv(e: &Ensemble) -> String {
    let mut s = String::from("seed,step");
    for name in MACRO_NAMES.iter().chain(&RESULTANT_NAMES) {
        let _ = write!(s, ",{name}");
    }
    s.push_str(",dissipated,equilibrium_residual\n");
    for r in &e.realizations {
        for (k, p) in r.curve.iter().flatten().enumerate() {
            let _ = write!(s, "{},{}", r.seed, k + 1);
            for v in p.strain.iter().chain(&p.resultant) {
                let _ = write!(s, ",{v:e}");
            }
            let _ = writeln!(s, ",{:e},{:e}", p.dissipated, p.equilibrium_residual);
        }
    }
    s
}

/// The main resultant against its strain: every complete curve in grey, the mean, and the mean
/// ± its 95 % interval. Returns (SVG, PNG).
pub fn ensemble_curve_plot(e: &Ensemble, title: &str) -> Result<Option<(String, Vec<u8>)>, Error> {
    let Some(c) = &e.curve else {
        return Ok(None);
    };
    let k = c.component;
    let origin = std::iter::once((0.0, 0.0));
    let realizations: Vec<Vec<(f64, f64)>> = e
        .realizations
        .iter()
        .filter_map(|r| r.curve.as_deref())
        .filter(|curve| curve.len() == c.path.points())
        .map(|curve| {
            origin
                .clone()
                .chain(curve.iter().map(|p| (p.strain[k], p.resultant[k])))
                .collect()
        })
        .collect();
    let band = |sign: f64| -> Vec<(f64, f64)> {
        let r = |x: &SampleSummary| x.mean + sign * x.ci95;
        origin
            .clone()
            .chain(c.points.iter().map(|p| (p.strain[k], r(&p.resultant[k]))))
            .collect()
    };
    let (mean, upper, lower) = (band(0.0), band(1.0), band(-1.0));
    let mut series: Vec<Series> = realizations
        .iter()
        .enumerate()
        .map(|(i, points)| Series {
            points,
            colour: (190, 190, 190),
            label: if i == 0 { "realizations" } else { "" },
        })
        .collect();
    series.push(Series {
        points: &mean,
        colour: (70, 130, 180),
        label: "mean",
    });
    // The interval is drawn only where it is finite (from two curves on).
    if c.curves >= 2 {
        series.push(Series {
            points: &upper,
            colour: (220, 20, 60),
            label: "95 % interval of the mean",
        });
        series.push(Series {
            points: &lower,
            colour: (220, 20, 60),
            label: "",
        });
    }
    let y_label = format!("{} ({})", RESULTANT_NAMES[k], RESULTANT_UNITS[k]);
    let plot = LinePlot {
        title,
        x_label: MACRO_NAMES[k],
        y_label: &y_label,
        series: &series,
        markers: &[],
        marker_label: "",
    };
    Ok(Some((plot.svg()?, plot.png()?)))
}
