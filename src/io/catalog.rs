//! The fixture catalog's files: cell parameter files (`fixtures/cells/<family>_<size>
//! .params.toml`), the fingerprint of a cell's file, and the reference results a cell's
//! statistics and elastic homogenization give.

use crate::generate::CellParams;
use crate::model::ModelDescription;
use crate::Error;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Reads a cell parameter file (TOML); errors name the file, line and column.
pub fn read_cell_params(path: &Path) -> Result<CellParams, Error> {
    super::read_toml_file(path)
}

/// What the fixtures' reference files record of a cell: its statistics and elastic ABD.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReferenceResults {
    /// Physical fibers.
    pub fibers: usize,
    /// Elements.
    pub elements: usize,
    /// Total centerline length (m).
    pub total_length: f64,
    /// Solid volume fraction (with the cell's thickness).
    pub volume_fraction: f64,
    /// Closed contacts.
    pub contacts: usize,
    /// Elastic ABD per unit area (ε11, ε22, γ12, κ11, κ22, κ12).
    pub abd: [[f64; 6]; 6],
    /// [`cell_digest`] of the cell: lets a test check that the parameters regenerate exactly
    /// the cell where the cell itself is too large to commit.
    pub cell_digest: String,
}

/// A fingerprint of a cell: FNV-1a (64 bits, hexadecimal) of its canonical TOML text
/// ([`super::to_toml`]), so two cells have the same digest when their files would be the
/// same.
pub fn cell_digest(d: &ModelDescription) -> Result<String, Error> {
    let text = super::to_toml(d).map_err(|message| Error::Output {
        path: "the cell's TOML text".into(),
        message,
    })?;
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in text.as_bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    Ok(format!("{h:016x}"))
}

/// The reference results of a cell: statistics and the elastic homogenization with the
/// default solver.
pub fn reference_results(d: &ModelDescription) -> Result<ReferenceResults, Error> {
    let model = crate::Model::from_description(d)?;
    let s = crate::stats::network_stats(&model)?;
    let h = crate::homogenize::homogenize_elastic(&model, &Default::default())?;
    Ok(ReferenceResults {
        fibers: s.fibers,
        elements: s.elements,
        total_length: s.total_length,
        volume_fraction: s.volume_fraction.unwrap_or(0.0),
        contacts: h.contacts,
        abd: h.abd,
        cell_digest: cell_digest(d)?,
    })
}
