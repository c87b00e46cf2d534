//! The native model format: [`ModelDescription`] through serde, as TOML or JSON.

use super::toml_parts::{parse_in_parts, PARTS_FROM_BYTES};
use super::InputError;
use crate::model::ModelDescription;

fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

/// Parses a TOML model; errors carry line and column. A large one is parsed in parts on all
/// threads where the parts must give the whole document's description
/// (cut at `[[nodes]]` and `[[fibers]]` header lines, each part parsed alone; any doubt, and
/// every error, goes to the whole document), else whole.
pub fn parse_toml(text: &str, path: &str) -> Result<ModelDescription, InputError> {
    let threads = rayon::current_num_threads();
    if text.len() >= PARTS_FROM_BYTES && threads > 1 {
        if let Some(d) = parse_in_parts(text, PARTS_PER_THREAD * threads) {
            return Ok(d);
        }
    }
    parse_toml_as(text, path)
}

/// Parts per thread of a large TOML model (they differ in how long their entries take).
const PARTS_PER_THREAD: usize = 2;

/// Parses any TOML document into `T` (a model, generator parameters); errors carry line and
/// column.
pub fn parse_toml_as<T: serde::de::DeserializeOwned>(
    text: &str,
    path: &str,
) -> Result<T, InputError> {
    toml::from_str(text).map_err(|e| {
        let (line, column) = e.span().map_or((0, 0), |s| line_col(text, s.start));
        InputError::Syntax {
            path: path.into(),
            line,
            column,
            message: e.message().trim().to_string(),
        }
    })
}

/// Parses a JSON model; errors carry line and column.
pub fn parse_json(text: &str, path: &str) -> Result<ModelDescription, InputError> {
    serde_json::from_str(text).map_err(|e| InputError::Syntax {
        path: path.into(),
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })
}

/// Writes a model as TOML.
pub fn to_toml(d: &ModelDescription) -> Result<String, String> {
    toml::to_string(d).map_err(|e| e.to_string())
}

/// Writes a model as pretty JSON.
pub fn to_json(d: &ModelDescription) -> Result<String, String> {
    serde_json::to_string_pretty(d).map_err(|e| e.to_string())
}
