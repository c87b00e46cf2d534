//! The fixture catalog: a small and a medium cell of each fabric family, from parameter files
//! `fixtures/cells/<family>_<size>.params.toml`, and their reference results.

use super::{geotextile, knitted, nonwoven, weave, Geotextile, Knit, NonWoven, Weave};
use crate::model::ModelDescription;
use crate::Error;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Parameters of a cell of any family, tagged by `family` in the parameter file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "family", rename_all = "snake_case")]
pub enum CellParams {
    /// [`Weave`].
    Woven(Weave),
    /// [`Geotextile`].
    Geotextile(Geotextile),
    /// [`Knit`].
    Knitted(Knit),
    /// [`NonWoven`].
    Nonwoven(NonWoven),
}

impl CellParams {
    /// Reads a parameter file (TOML); errors name the file, line and column.
    pub fn read(path: &Path) -> Result<Self, Error> {
        crate::io::read_toml_file(path)
    }

    /// The parameters of a JSON object tagged by `family` whose other fields override the
    /// family's defaults (what the Python and C bindings take: only the fields one changes).
    pub fn from_json_with_defaults(text: &str) -> Result<Self, Error> {
        let bad = |e: serde_json::Error| Error::InvalidOption(format!("generator parameters: {e}"));
        let given: serde_json::Value = serde_json::from_str(text).map_err(bad)?;
        let defaults = match given.get("family").and_then(|f| f.as_str()) {
            Some("woven") => CellParams::Woven(Weave::default()),
            Some("geotextile") => CellParams::Geotextile(Geotextile::default()),
            Some("knitted") => CellParams::Knitted(Knit::default()),
            Some("nonwoven") => CellParams::Nonwoven(NonWoven::default()),
            other => {
                return Err(Error::InvalidOption(format!(
                    "generator parameters: family {other:?} is not woven, geotextile, knitted \
                     or nonwoven"
                )))
            }
        };
        let mut merged = serde_json::to_value(&defaults).map_err(bad)?;
        if let (Some(m), Some(g)) = (merged.as_object_mut(), given.as_object()) {
            for (k, v) in g {
                m.insert(k.clone(), v.clone());
            }
        }
        serde_json::from_value(merged).map_err(bad)
    }

    /// The cell.
    pub fn generate(&self) -> Result<ModelDescription, Error> {
        match self {
            CellParams::Woven(p) => weave(p),
            CellParams::Geotextile(p) => geotextile(p),
            CellParams::Knitted(p) => knitted(p),
            CellParams::Nonwoven(p) => Ok(nonwoven(p)?.description),
        }
    }
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
/// ([`crate::io::to_toml`]), so two cells have the same digest when their files would be the
/// same.
pub fn cell_digest(d: &ModelDescription) -> Result<String, Error> {
    let text = crate::io::to_toml(d).map_err(|message| Error::Output {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Given fields override the defaults, the others keep them; an unknown family or field
    /// type is an error naming the parameters.
    #[test]
    fn json_parameters_override_the_defaults() {
        let p =
            CellParams::from_json_with_defaults(r#"{"family": "knitted", "wales": 3}"#).unwrap();
        let CellParams::Knitted(k) = p else {
            panic!("not a knit: {p:?}")
        };
        assert_eq!(k.wales, 3);
        assert_eq!(k.courses, Knit::default().courses);
        for bad in [
            r#"{"family": "crochet"}"#,
            r#"{"family": "knitted", "wales": "x"}"#,
            "[",
        ] {
            let e = CellParams::from_json_with_defaults(bad)
                .unwrap_err()
                .to_string();
            assert!(e.contains("generator parameters"), "{e}");
        }
    }
}
