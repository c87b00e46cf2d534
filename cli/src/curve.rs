//! `fibercell curve`: the elasto-plastic curve along a macro strain path.

use crate::output::{progress_bar, to_pretty};
use fibercell::solve::{IncrementalOptions, SolveOptions};
use fibercell::{io, Error};
use std::path::Path;

pub(crate) fn curve(
    model_path: &Path,
    (strain, steps, unload): (fibercell::cell::MacroStrain, usize, bool),
    (solve, bonded, stabilization): (SolveOptions, bool, f64),
    (json, log): (bool, bool),
    out: &Path,
) -> Result<(), Error> {
    use fibercell::homogenize::{elasto_plastic_curve, CurveOptions};
    let model = io::load_model(model_path)?;
    // curve.json is written last: a folder that holds it is complete.
    io::begin_results(out, "curve.json")?;
    let (bar, progress) = progress_bar("curve", log);
    let incremental = IncrementalOptions {
        progress: Some(progress),
        bonded,
        stabilization,
        solve,
        ..IncrementalOptions::default()
    };
    let c = elasto_plastic_curve(
        &model,
        &CurveOptions {
            strain,
            steps,
            unload,
            incremental,
        },
    );
    bar.finish_and_clear();
    let c = c?;
    let title = format!(
        "{}: elasto-plastic curve ({} switches to slip)",
        model_path.display(),
        c.switches.iter().filter(|s| s.to == "slip").count()
    );
    io::write_curve_files(out, &c, &title)?;
    if json {
        println!("{}", to_pretty(&c)?);
        return Ok(());
    }
    let k = io::dominant_component(&strain);
    let last = c.points.last();
    println!(
        "{}: {} increments, {} switches, {} linear segments; final {} = {:.4e} {}, dissipated {:.4e} J/m²; results in {}",
        model_path.display(),
        c.points.len(),
        c.switches.len(),
        c.segments.len(),
        io::RESULTANT_NAMES[k],
        last.map_or(0.0, |p| p.resultant[k]),
        io::RESULTANT_UNITS[k],
        last.map_or(0.0, |p| p.dissipated),
        out.display()
    );
    for s in c.switches.iter().take(20) {
        println!(
            "  contact {} {} → {} at {} = {:.6e} (increment {})",
            s.contact,
            s.from,
            s.to,
            fibercell::cell::MACRO_NAMES[k],
            s.estimated_strain[k],
            s.step
        );
    }
    if c.switches.len() > 20 {
        println!("  … {} switches in all (switches.csv)", c.switches.len());
    }
    Ok(())
}
