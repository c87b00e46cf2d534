//! Parameter checks shared by the generators: errors name the generator and the field.

use crate::Error;

/// An invalid-parameter error.
pub(super) fn invalid(msg: String) -> Error {
    Error::InvalidOption(msg)
}

/// `value` must be finite and > 0.
pub(super) fn positive(generator: &str, field: &str, value: f64) -> Result<(), Error> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(invalid(format!(
            "{generator}: {field} = {value} must be positive and finite"
        )))
    }
}

/// Poisson's ratio in (−1, 0.5) and a friction coefficient ≥ 0.
pub(super) fn material(generator: &str, poisson: f64, mu: f64) -> Result<(), Error> {
    if !(poisson > -1.0 && poisson < 0.5) {
        return Err(invalid(format!(
            "{generator}: poisson = {poisson} must be in (−1, 0.5)"
        )));
    }
    if !(mu >= 0.0 && mu.is_finite()) {
        return Err(invalid(format!("{generator}: mu = {mu} must be ≥ 0")));
    }
    Ok(())
}
