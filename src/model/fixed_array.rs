//! Coordinates and sizes read strictly: TOML's deserializer fills a `[f64; N]` from the first
//! N items of a longer array and drops the rest (`x = [2.0, 0.0, 0.0, "junk"]` was a node at
//! (2, 0, 0)); these read the whole array and refuse any other length.

use serde::de::{Deserialize, Deserializer, Error};

/// Exactly N numbers.
pub(crate) fn exactly<'de, D: Deserializer<'de>, const N: usize>(
    d: D,
) -> Result<[f64; N], D::Error> {
    let v = Vec::<f64>::deserialize(d)?;
    let n = v.len();
    v.try_into()
        .map_err(|_| D::Error::invalid_length(n, &format!("an array of {N} numbers").as_str()))
}

/// Nothing, or exactly N numbers.
pub(crate) fn optional<'de, D: Deserializer<'de>, const N: usize>(
    d: D,
) -> Result<Option<[f64; N]>, D::Error> {
    let Some(v) = Option::<Vec<f64>>::deserialize(d)? else {
        return Ok(None);
    };
    let n = v.len();
    v.try_into()
        .map(Some)
        .map_err(|_| D::Error::invalid_length(n, &format!("an array of {N} numbers").as_str()))
}
