//! The files of an elasto-plastic curve: `curve.csv`, `switches.csv`, `curve.json` and the plot
//! `curve.svg` / `curve.png` (the dominant strain component against its resultant, the
//! all-stick line, the switches to slip circled where the pieces' lines meet).

use super::plot::{LinePlot, Series};
use crate::cell::MACRO_NAMES;
use crate::homogenize::{segment_starting_at, Curve};
use crate::Error;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// Names of the averaged stress resultants, in the order of [`MACRO_NAMES`].
pub const RESULTANT_NAMES: [&str; 6] = ["N11", "N22", "N12", "M11", "M22", "M12"];
/// Units of the resultants.
pub const RESULTANT_UNITS: [&str; 6] = ["N/m", "N/m", "N/m", "N", "N", "N"];
/// Units of the macroscopic strains and curvatures of [`MACRO_NAMES`].
pub const STRAIN_UNITS: [&str; 6] = ["-", "-", "-", "1/m", "1/m", "1/m"];

/// `curve.csv`: per increment the step, α, the strain, the resultants, their elastic and
/// plastic parts, the open/stick/slip counts and the dissipated energy per area.
pub fn curve_csv(c: &Curve) -> String {
    let mut csv = String::from("step,alpha [-]");
    for (n, u) in MACRO_NAMES.iter().zip(STRAIN_UNITS) {
        let _ = write!(csv, ",{n} [{u}]");
    }
    for prefix in ["", "elastic_", "plastic_"] {
        for (r, u) in RESULTANT_NAMES.iter().zip(RESULTANT_UNITS) {
            let _ = write!(csv, ",{prefix}{r} [{u}]");
        }
    }
    csv.push_str(",open,stick,slip,dissipated [J/m^2]\n");
    for pt in &c.points {
        let _ = write!(csv, "{},{}", pt.step, pt.alpha);
        for v in pt
            .strain
            .iter()
            .chain(&pt.resultant)
            .chain(&pt.elastic)
            .chain(&pt.plastic)
        {
            let _ = write!(csv, ",{v:e}");
        }
        let _ = writeln!(
            csv,
            ",{},{},{},{:e}",
            pt.open, pt.stick, pt.slip, pt.dissipated
        );
    }
    csv
}

/// `switches.csv`: every state change, with the strain at the end of its increment and the
/// estimated switch strain.
pub fn switches_csv(c: &Curve) -> String {
    let mut sw = String::from("contact,step,from,to");
    for prefix in ["", "estimated_"] {
        for (n, u) in MACRO_NAMES.iter().zip(STRAIN_UNITS) {
            let _ = write!(sw, ",{prefix}{n} [{u}]");
        }
    }
    sw.push('\n');
    for s in &c.switches {
        let _ = write!(sw, "{},{},{},{}", s.contact, s.step, s.from, s.to);
        for v in s.strain.iter().chain(&s.estimated_strain) {
            let _ = write!(sw, ",{v:e}");
        }
        sw.push('\n');
    }
    sw
}

/// The strain component the path drives most (index into [`MACRO_NAMES`]).
pub fn dominant_component(strain: &[f64; 6]) -> usize {
    (0..6)
        .max_by(|&a, &b| strain[a].abs().total_cmp(&strain[b].abs()))
        .unwrap_or(0)
}

/// The curve plot: the dominant component of the path against its conjugate resultant, the
/// all-stick line and the switches to slip. Returns (SVG, PNG).
pub fn curve_plot(c: &Curve, title: &str) -> Result<(String, Vec<u8>), Error> {
    let peak = c
        .points
        .iter()
        .max_by(|a, b| a.alpha.abs().total_cmp(&b.alpha.abs()))
        .map_or([0.0; 6], |p| p.strain);
    let k = dominant_component(&peak);
    // From the unstrained origin along the path.
    let trace = |value: fn(&crate::homogenize::CurvePoint) -> [f64; 6]| -> Vec<(f64, f64)> {
        std::iter::once((0.0, 0.0))
            .chain(c.points.iter().map(|p| (p.strain[k], value(p)[k])))
            .collect()
    };
    let total = trace(|p| p.resultant);
    let elastic = trace(|p| p.elastic);
    // A switch is marked where the lines of the pieces meet: on the new piece's line.
    let markers: Vec<(f64, f64)> = c
        .switches
        .iter()
        .filter(|s| s.to == "slip")
        .filter_map(|s| {
            let seg = segment_starting_at(&c.segments, s.step)?;
            let first = c.points.get(s.step - 1)?;
            let y = first.resultant[k] + seg.slope[k] * (seg.alpha[0] - first.alpha);
            Some((s.estimated_strain[k], y))
        })
        .collect();
    let y_label = format!("{} ({})", RESULTANT_NAMES[k], RESULTANT_UNITS[k]);
    let series = [
        Series {
            points: &total,
            colour: (70, 130, 180),
            label: "cell (stick/slip)",
        },
        Series {
            points: &elastic,
            colour: (128, 128, 128),
            label: "all stick (A^elas)",
        },
    ];
    let plot = LinePlot {
        title,
        x_label: MACRO_NAMES[k],
        y_label: &y_label,
        series: &series,
        markers: &markers,
        marker_label: "switch to slip",
    };
    Ok((plot.svg()?, plot.png()?))
}

/// Writes `curve.csv`, `switches.csv`, `curve.svg`, `curve.png` and last `curve.json` into
/// `dir` (created if missing), each atomically, so that a folder with `curve.json` is complete
/// (see [`super::begin_results`]); returns their paths.
pub fn write_curve_files(dir: &Path, c: &Curve, title: &str) -> Result<Vec<PathBuf>, Error> {
    let json = serde_json::to_string_pretty(c).map_err(|e| Error::Output {
        path: "curve.json".into(),
        message: e.to_string(),
    })?;
    let (svg, png) = curve_plot(c, title)?;
    let (curve, switches) = (curve_csv(c), switches_csv(c));
    super::write_results(
        dir,
        &[
            ("curve.csv", curve.as_bytes()),
            ("switches.csv", switches.as_bytes()),
            ("curve.svg", svg.as_bytes()),
            ("curve.png", &png),
            ("curve.json", json.as_bytes()),
        ],
    )
}
