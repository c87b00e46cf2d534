//! Cell parameters of any fabric family, tagged by `family`: what the fixture catalog's
//! parameter files `fixtures/cells/<family>_<size>.params.toml` hold (read and checked against
//! their reference results by [`crate::io::read_cell_params`] and
//! [`crate::io::reference_results`]).

use super::{geotextile, knitted, nonwoven, weave, Geotextile, Knit, NonWoven, Weave};
use crate::model::ModelDescription;
use crate::Error;
use serde::{Deserialize, Serialize};

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

    /// The same parameters with the generator's seed set to `seed` (the non-woven's; the woven,
    /// knitted and geotextile generators are deterministic, and their cells do not depend on it).
    pub fn with_seed(&self, seed: u64) -> Self {
        let mut p = self.clone();
        if let CellParams::Nonwoven(n) = &mut p {
            n.seed = seed;
        }
        p
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
