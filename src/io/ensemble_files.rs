//! The result files of an ensemble: the statistics of every ABD entry (`ensemble.csv`), the
//! convergence of the confidence interval (`convergence.csv` and a plot), the curves' files
//! when it has curves (see [`super::ensemble_curve_files`]), and the whole run with every
//! realization (`ensemble.json`, written last).

use super::ensemble_curve_files::{
    ensemble_curve_csv, ensemble_curve_plot, realization_curves_csv,
};
use super::plot::{LinePlot, Series};
use crate::cell::MACRO_NAMES;
use crate::ensemble::{Ensemble, MAIN_MODULI};
use crate::Error;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// The name of ABD entry (i, j): A, B or D by block, indices in Voigt notation (6 for the
/// shear), e.g. A11, B16, D66.
pub fn abd_entry_name(i: usize, j: usize) -> String {
    let block = match (i / 3, j / 3) {
        (0, 0) => "A",
        (1, 1) => "D",
        _ => "B",
    };
    let voigt = |k: usize| [1, 2, 6][k % 3];
    format!("{block}{}{}", voigt(i), voigt(j))
}

/// `entry,i,j,n,mean,std,ci95,relative_ci95` for the 36 entries.
pub fn ensemble_csv(e: &Ensemble) -> String {
    let mut s = String::from("entry,row,column,n,mean,std,ci95,relative_ci95\n");
    for (i, row) in MACRO_NAMES.iter().enumerate() {
        for (j, column) in MACRO_NAMES.iter().enumerate() {
            let x = &e.abd[i][j];
            let _ = writeln!(
                s,
                "{},{},{},{},{:e},{:e},{:e},{:e}",
                abd_entry_name(i, j),
                row,
                column,
                x.n,
                x.mean,
                x.std,
                x.ci95,
                x.relative_ci95()
            );
        }
    }
    s
}

/// `n` and the relative 95 % interval of each main modulus after n realizations.
pub fn convergence_csv(e: &Ensemble) -> String {
    let names: Vec<String> = MAIN_MODULI.iter().map(|&k| abd_entry_name(k, k)).collect();
    let mut s = format!("n,{}\n", names.join(","));
    for p in &e.convergence {
        let row: Vec<String> = p.relative_ci95.iter().map(|v| format!("{v:e}")).collect();
        let _ = writeln!(s, "{},{}", p.n, row.join(","));
    }
    s
}

/// One line per main modulus (A11, A22, A66, D11, D22, D66: `points[m]`), and `extra` lines
/// after them (SVG, PNG).
pub(super) fn main_moduli_plot(
    title: &str,
    (x_label, y_label): (&str, &str),
    points: &[Vec<(f64, f64)>],
    extra: Option<Series>,
) -> Result<(String, Vec<u8>), Error> {
    const COLOURS: [(u8, u8, u8); 6] = [
        (70, 130, 180),
        (220, 20, 60),
        (34, 139, 34),
        (255, 140, 0),
        (128, 0, 128),
        (105, 105, 105),
    ];
    let names: Vec<String> = MAIN_MODULI.iter().map(|&k| abd_entry_name(k, k)).collect();
    let mut series: Vec<Series> = points
        .iter()
        .zip(COLOURS)
        .zip(&names)
        .map(|((points, colour), label)| Series {
            points,
            colour,
            label,
        })
        .collect();
    series.extend(extra);
    let plot = LinePlot {
        title,
        x_label,
        y_label,
        series: &series,
        markers: &[],
        marker_label: "",
    };
    Ok((plot.svg()?, plot.png()?))
}

/// The relative interval of the main moduli against n (SVG, PNG).
fn convergence_plot(e: &Ensemble, title: &str) -> Result<(String, Vec<u8>), Error> {
    let points: Vec<Vec<(f64, f64)>> = (0..MAIN_MODULI.len())
        .map(|m| {
            e.convergence
                .iter()
                .filter(|p| p.relative_ci95[m].is_finite())
                .map(|p| (p.n as f64, 100.0 * p.relative_ci95[m]))
                .collect()
        })
        .collect();
    let labels = ("realizations n", "95 % interval of the mean / mean (%)");
    main_moduli_plot(title, labels, &points, None)
}

/// Writes `ensemble.csv`, `convergence.csv`, `convergence.svg`, `convergence.png`, with curves
/// `ensemble-curve.csv`, `curves.csv`, `ensemble-curve.svg` and `ensemble-curve.png`, and last
/// `ensemble.json` into `dir`, each atomically, so that a folder with `ensemble.json` is
/// complete; returns their paths.
pub fn write_ensemble_files(dir: &Path, e: &Ensemble, title: &str) -> Result<Vec<PathBuf>, Error> {
    let json = serde_json::to_string_pretty(e).map_err(|err| Error::Output {
        path: "ensemble.json".into(),
        message: err.to_string(),
    })?;
    let (svg, png) = convergence_plot(e, title)?;
    let (table, convergence) = (ensemble_csv(e), convergence_csv(e));
    let mut files: Vec<(&str, &[u8])> = vec![
        ("ensemble.csv", table.as_bytes()),
        ("convergence.csv", convergence.as_bytes()),
        ("convergence.svg", svg.as_bytes()),
        ("convergence.png", &png),
    ];
    let curve_tables = e
        .curve
        .as_ref()
        .map(|c| (ensemble_curve_csv(c), realization_curves_csv(e)));
    let curve_plot = ensemble_curve_plot(e, title)?;
    if let (Some((points, curves)), Some((svg, png))) = (&curve_tables, &curve_plot) {
        files.push(("ensemble-curve.csv", points.as_bytes()));
        files.push(("curves.csv", curves.as_bytes()));
        files.push(("ensemble-curve.svg", svg.as_bytes()));
        files.push(("ensemble-curve.png", png));
    }
    files.push(("ensemble.json", json.as_bytes()));
    super::write_results(dir, &files)
}

#[cfg(test)]
mod tests {
    use super::abd_entry_name;

    #[test]
    fn entry_names_follow_the_voigt_blocks() {
        assert_eq!(abd_entry_name(0, 0), "A11");
        assert_eq!(abd_entry_name(2, 2), "A66");
        assert_eq!(abd_entry_name(0, 5), "B16");
        assert_eq!(abd_entry_name(4, 3), "D21");
        assert_eq!(abd_entry_name(5, 5), "D66");
    }
}
