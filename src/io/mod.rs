//! Files: the native model format (TOML and JSON, one schema), Abaqus `.inp` import, results
//! (CSV, JSON), VTK (`.vtp`, `.vtu`, `.pvd`), Matrix Market output and plots (SVG, PNG). Outputs are written atomically.

mod abaqus;
mod abaqus_cell;
mod abaqus_export;
mod atomic;
mod catalog;
mod curve_files;
mod ensemble_curve_files;
mod ensemble_files;
mod inp_number;
mod job_system;
mod matrix_market;
mod native;
mod plot;
mod results;
mod rve_files;
mod toml_parts;
mod vtk;

pub use crate::input_error::InputError;
pub use abaqus::{parse_abaqus, MAX_GENERATED_MEMBERS};
pub use abaqus_export::{to_abaqus, to_inp, InpFlavour, InpOptions};
pub use atomic::{begin_results, remove_unfinished_outputs, write_atomic, write_results};
pub use catalog::{cell_digest, read_cell_params, reference_results, ReferenceResults};
pub use curve_files::{
    curve_csv, curve_plot, dominant_component, switches_csv, write_curve_files, RESULTANT_NAMES,
    RESULTANT_UNITS, STRAIN_UNITS,
};
pub use ensemble_curve_files::{ensemble_curve_csv, ensemble_curve_plot, realization_curves_csv};
pub use ensemble_files::{abd_entry_name, convergence_csv, ensemble_csv, write_ensemble_files};
pub use inp_number::{inp_number, MAX_FIELD};
pub use job_system::{job_system, JobSystem};
pub use matrix_market::{write_job_system, write_matrix_market, write_matrix_market_dense};
pub use native::{parse_json, parse_toml, parse_toml_as, to_json, to_toml};
pub use plot::{LinePlot, RosePlot, Series, PLOT_SIZE, ROSE_SIZE};
pub use results::{
    contacts_csv, displacements_csv, incremental_json, increments_csv, solution_json,
};
pub use rve_files::{rve_csv, write_rve_files};
pub use vtk::{
    contacts_vtp, model_vtk, network_vtk, series_pvd, step_file, NetworkFormat, VtkEncoding,
};

use crate::model::{Model, ModelDescription};
use crate::Error;
use std::path::Path;

/// Reads a model file, choosing the format by extension (`.toml`, `.json`, `.inp`), and
/// validates it; the parse's freed memory goes back to the system (see
/// [`crate::free_memory`]).
pub fn load_model(path: &Path) -> Result<Model, Error> {
    let desc = read_description(path)?;
    let model = Model::from_description(&desc)?;
    drop(desc);
    crate::free_memory::release_free_memory();
    Ok(model)
}

/// Reads a model file into its unvalidated description.
pub fn read_description(path: &Path) -> Result<ModelDescription, Error> {
    let shown = path.display().to_string();
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    let parse: fn(&str, &str) -> Result<ModelDescription, InputError> = match ext.as_deref() {
        Some("toml") => parse_toml,
        Some("json") => parse_json,
        Some("inp") => parse_abaqus,
        _ => return Err(InputError::UnknownFormat { path: shown }.into()),
    };
    Ok(parse(&read_text(path)?, &shown)?)
}

/// Reads a whole text file; the error names it.
pub fn read_text(path: &Path) -> Result<String, InputError> {
    std::fs::read_to_string(path).map_err(|e| InputError::Read {
        path: path.display().to_string(),
        message: e.to_string(),
    })
}

/// Reads a TOML file into `T` (e.g. generator parameters such as
/// [`NonWoven`](crate::generate::NonWoven)); errors name the file, line and column.
pub fn read_toml_file<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T, Error> {
    Ok(parse_toml_as(
        &read_text(path)?,
        &path.display().to_string(),
    )?)
}

/// Writes a model description as `.toml` or `.json` (by extension), atomically.
pub fn write_description(path: &Path, d: &ModelDescription) -> Result<(), Error> {
    let text = match path.extension().and_then(|e| e.to_str()) {
        Some("json") => to_json(d),
        Some("toml") => to_toml(d),
        _ => {
            return Err(Error::InvalidOption(format!(
                "{}: the output must be a .toml or .json file",
                path.display()
            )))
        }
    }
    .map_err(|message| Error::Output {
        path: path.display().to_string(),
        message,
    })?;
    write_atomic(path, text.as_bytes())
}

/// How [`write_model`] writes: the VTK encoding and the input-file flavour.
#[derive(Clone, Copy, Debug, Default)]
pub struct WriteOptions {
    pub vtk: VtkEncoding,
    pub inp: InpOptions,
}

/// Writes a model in the format of the path's extension — `.toml`, `.json`, `.inp` (Abaqus,
/// or CalculiX by `opts.inp`),
/// `.vtp` or `.vtu` (the network with its radius, see [`network_vtk`]) or `.pvd` (a
/// collection of `{stem}_fibers.vtp` and `{stem}_contacts.vtp` written next to it) —
/// validating it first; each file is written atomically, VTK files in `opts.vtk`. Returns the
/// paths written.
pub fn write_model(
    path: &Path,
    d: &ModelDescription,
    opts: &WriteOptions,
) -> Result<Vec<std::path::PathBuf>, Error> {
    let encoding = opts.vtk;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    let model = Model::from_description(d)?;
    match ext.as_deref() {
        Some("toml") | Some("json") => write_description(path, d)?,
        Some("inp") => write_atomic(path, to_inp(d, &opts.inp)?.as_bytes())?,
        Some(ext @ ("vtp" | "vtu")) => {
            let format = if ext == "vtp" {
                NetworkFormat::PolyData
            } else {
                NetworkFormat::UnstructuredGrid
            };
            let zero = vec![[0.0; 6]; model.nodes.len()];
            write_atomic(
                path,
                network_vtk(&model, &zero, format, encoding).as_bytes(),
            )?
        }
        Some("pvd") => {
            let stem = path
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("model")
                .to_string();
            let (network, contacts, pvd) = model_vtk(&model, &stem, encoding)?;
            let fibers = path.with_file_name(format!("{stem}_fibers.vtp"));
            let points = path.with_file_name(format!("{stem}_contacts.vtp"));
            write_atomic(&fibers, network.as_bytes())?;
            write_atomic(&points, contacts.as_bytes())?;
            write_atomic(path, pvd.as_bytes())?;
            return Ok(vec![path.to_path_buf(), fibers, points]);
        }
        _ => {
            return Err(Error::InvalidOption(format!(
                "{}: unknown output format (use .toml, .json, .inp, .vtp, .vtu or .pvd)",
                path.display()
            )))
        }
    }
    Ok(vec![path.to_path_buf()])
}
