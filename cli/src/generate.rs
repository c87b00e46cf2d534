//! `fibercell generate`: the cell generators.

use crate::command::GenerateKind;
use fibercell::{io, Error};
use std::path::Path;

pub(crate) fn generate(kind: GenerateKind) -> Result<(), Error> {
    use fibercell::generate::{CellParams, FiberAmount, LengthDistribution, NonWoven};
    match kind {
        GenerateKind::Nonwoven {
            params,
            preset,
            size,
            fibers,
            volume_fraction,
            thickness,
            length,
            length_cv,
            radius,
            orientation,
            tilt,
            curl,
            element_length,
            seed,
            output,
        } => {
            let mut p = match params {
                Some(path) => io::read_toml_file::<NonWoven>(&path)?,
                None => match preset {
                    Some(name) => fibercell::generate::nonwoven_preset(&name, 1)?,
                    None => NonWoven::default(),
                },
            };
            if let Some(v) = size {
                p.size = v;
            }
            if let Some(fibers) = fibers {
                p.amount = FiberAmount::Count { fibers };
            }
            if let (Some(fraction), Some(thickness)) = (volume_fraction, thickness) {
                p.amount = FiberAmount::VolumeFraction {
                    fraction,
                    thickness,
                };
            }
            if length.is_some() || length_cv.is_some() {
                let mean = length.unwrap_or(match p.length {
                    LengthDistribution::Fixed { length } => length,
                    LengthDistribution::LogNormal { mean, .. } => mean,
                });
                // A cv of 0 is a fixed length; any other (NaN and negative ones too) goes to
                // the generator's validation, like the parameter file's.
                p.length = match length_cv {
                    Some(cv) if cv != 0.0 => LengthDistribution::LogNormal { mean, cv },
                    _ => LengthDistribution::Fixed { length: mean },
                };
            }
            if let Some(v) = radius {
                p.radius = v;
            }
            if let Some(v) = orientation {
                p.orientation = v;
            }
            if let Some(v) = tilt {
                p.tilt_degrees = v;
            }
            if let Some(v) = curl {
                p.curl = v;
            }
            if let Some(v) = element_length {
                p.element_length = v;
            }
            if let Some(v) = seed {
                p.seed = v;
            }
            let t = std::time::Instant::now();
            let cell = fibercell::generate::nonwoven(&p)?;
            let r = &cell.report;
            let label = format!(
                "non-woven (seed {}): {} fibers deposited, {} dropped (touching nothing), {} supports",
                p.seed, r.deposited, r.dropped, r.supports
            );
            finish_generated(&label, t, &cell.description, &output)
        }
        GenerateKind::Woven {
            params,
            pattern,
            size,
            radius,
            output,
        } => {
            let mut p: fibercell::generate::Weave = params_or_default(params.as_deref())?;
            if let Some(v) = pattern {
                p.pattern = v;
            }
            if let Some(v) = size {
                p.size = v;
            }
            if let Some(v) = radius {
                p.radius = v;
            }
            generate_cell(CellParams::Woven(p), &output)
        }
        GenerateKind::Geotextile {
            params,
            size,
            families,
            contact_mu,
            element_length,
            output,
        } => {
            let mut p: fibercell::generate::Geotextile = params_or_default(params.as_deref())?;
            if let Some(v) = size {
                p.size = v;
            }
            if !families.is_empty() {
                p.families = families;
            }
            if let Some(mu) = contact_mu {
                p.layer_junction = fibercell::generate::LayerJunction::Contact { mu };
            }
            if let Some(v) = element_length {
                p.element_length = v;
            }
            generate_cell(CellParams::Geotextile(p), &output)
        }
        GenerateKind::From { params, output } => {
            generate_cell(fibercell::io::read_cell_params(&params)?, &output)
        }
        GenerateKind::Knitted {
            params,
            wales,
            courses,
            radius,
            output,
        } => {
            let mut p: fibercell::generate::Knit = params_or_default(params.as_deref())?;
            if let Some(v) = wales {
                p.wales = v;
            }
            if let Some(v) = courses {
                p.courses = v;
            }
            if let Some(v) = radius {
                p.radius = v;
            }
            generate_cell(CellParams::Knitted(p), &output)
        }
    }
}

/// Generator parameters from a TOML file, or the generator's defaults.
fn params_or_default<T: serde::de::DeserializeOwned + Default>(
    path: Option<&Path>,
) -> Result<T, Error> {
    match path {
        Some(path) => io::read_toml_file(path),
        None => Ok(T::default()),
    }
}

/// Generates a cell of any family, writes it and prints its statistics.
fn generate_cell(params: fibercell::generate::CellParams, output: &Path) -> Result<(), Error> {
    let t = std::time::Instant::now();
    let d = params.generate()?;
    let label = match &params {
        fibercell::generate::CellParams::Geotextile(g) => {
            format!("geotextile ({} families)", g.families.len())
        }
        _ => d.name.clone().unwrap_or_default(),
    };
    finish_generated(&label, t, &d, output)
}

/// Writes a generated cell and prints its statistics.
fn finish_generated(
    label: &str,
    started: std::time::Instant,
    d: &fibercell::model::ModelDescription,
    output: &Path,
) -> Result<(), Error> {
    let elapsed = started.elapsed().as_secs_f64();
    let model = fibercell::Model::from_description(d)?;
    let stats = fibercell::stats::network_stats(&model)?;
    io::write_description(output, d)?;
    println!(
        "{label}: generated in {elapsed:.2} s, written to {}",
        output.display()
    );
    println!("{}", stats.summary());
    Ok(())
}
