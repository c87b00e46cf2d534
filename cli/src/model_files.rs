//! `fibercell stats` and `fibercell convert`: a model file summarized or written in another format.

use crate::output::to_pretty;
use fibercell::{io, Error};
use std::path::Path;

pub(crate) fn stats(model_path: &Path, json: bool, rose: Option<&Path>) -> Result<(), Error> {
    let model = io::load_model(model_path)?;
    let s = fibercell::stats::network_stats(&model)?;
    if let Some(prefix) = rose {
        let fractions = fibercell::stats::orientation_histogram(&model, 18);
        let title = format!(
            "{}: fiber orientation (length-weighted)",
            model_path.display()
        );
        let plot = io::RosePlot {
            title: &title,
            fractions: &fractions,
        };
        let (svg, png) = (plot.svg()?, plot.png()?);
        io::write_atomic(&prefix.with_extension("svg"), svg.as_bytes())?;
        io::write_atomic(&prefix.with_extension("png"), &png)?;
    }
    if json {
        println!("{}", to_pretty(&s)?);
    } else {
        println!("{}: {}", model_path.display(), s.summary());
    }
    Ok(())
}

pub(crate) fn convert(input: &Path, output: &Path, opts: &io::WriteOptions) -> Result<(), Error> {
    let d = io::read_description(input)?;
    let written = io::write_model(output, &d, opts)?;
    let names: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
    println!("{} → {}", input.display(), names.join(", "));
    Ok(())
}
