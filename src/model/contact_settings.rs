//! Validated contact settings and explicit contact pairs of a model.

use super::description::{ContactPairSpec, ContactSpec, FrictionSpec, PenetrationSpec, SideSpec};
use super::ModelError;
use super::{ContactSide, Friction};

/// Contact settings (from `[contact]`).
#[derive(Clone, Debug, PartialEq)]
pub struct ContactSettings {
    /// Search for contacts between fibers.
    pub search: bool,
    /// Surface distance below which a pair is a candidate (m).
    pub tolerance: f64,
    /// Normal penalty, or automatic.
    pub penalty_normal: Option<f64>,
    /// Tangential penalty, or equal to the normal one.
    pub penalty_tangent: Option<f64>,
    /// Rolling resistance (N·m/rad), or automatic.
    pub penalty_rotation: Option<f64>,
    /// Factor on every contact's penalties, default or given.
    pub penalty_scale: f64,
    /// Friction law.
    pub friction: Friction,
    /// Initially penetrating pairs.
    pub initial_penetration: PenetrationSpec,
    /// Bonded contacts: closed ones never open, open ones never close.
    pub bonded: bool,
}

/// An explicit contact pair (from `[[contacts]]`).
#[derive(Clone, Debug, PartialEq)]
pub struct ExplicitContact {
    /// Side I.
    pub a: ContactSide,
    /// Side II.
    pub b: ContactSide,
    /// Unit normal from I to II, when given.
    pub normal: Option<[f64; 3]>,
    /// Initial gap (m).
    pub gap: f64,
    /// Normal penalty override (N/m).
    pub penalty_normal: Option<f64>,
    /// Tangential penalty override (N/m).
    pub penalty_tangent: Option<f64>,
    /// Rolling resistance override (N·m/rad).
    pub penalty_rotation: Option<f64>,
}

fn invalid(item: &str, message: String) -> ModelError {
    ModelError::InvalidContact {
        item: item.to_string(),
        message,
    }
}

fn check_penalty(item: &str, what: &str, p: Option<f64>) -> Result<(), ModelError> {
    match p {
        Some(v) if !(v.is_finite() && v > 0.0) => Err(invalid(
            item,
            format!("{what} = {v} must be finite and > 0"),
        )),
        _ => Ok(()),
    }
}

fn check_rotation_penalty(item: &str, p: Option<f64>) -> Result<(), ModelError> {
    match p {
        Some(v) if !(v.is_finite() && v >= 0.0) => Err(invalid(
            item,
            format!("penalty_rotation = {v} must be finite and ≥ 0"),
        )),
        _ => Ok(()),
    }
}

/// Validates `[contact]`; `max_radius` gives the default search tolerance.
pub(super) fn check_settings(
    spec: &ContactSpec,
    max_radius: f64,
) -> Result<ContactSettings, ModelError> {
    let item = "[contact]";
    check_penalty(item, "penalty_normal", spec.penalty_normal)?;
    check_penalty(item, "penalty_tangent", spec.penalty_tangent)?;
    check_rotation_penalty(item, spec.penalty_rotation)?;
    check_penalty(item, "penalty_scale", spec.penalty_scale)?;
    let tolerance = spec.tolerance.unwrap_or(max_radius);
    if !(tolerance.is_finite() && tolerance >= 0.0) {
        return Err(invalid(
            item,
            format!("tolerance = {tolerance} must be finite and ≥ 0"),
        ));
    }
    let friction = match spec.friction {
        FrictionSpec::None => Friction::None,
        FrictionSpec::Coulomb { mu, cohesion } => {
            if !(mu.is_finite() && mu >= 0.0) {
                return Err(invalid(
                    item,
                    format!("friction coefficient mu = {mu} must be finite and ≥ 0"),
                ));
            }
            if !(cohesion.is_finite() && cohesion >= 0.0) {
                return Err(invalid(
                    item,
                    format!("cohesion = {cohesion} N must be finite and ≥ 0"),
                ));
            }
            Friction::Coulomb { mu, cohesion }
        }
        FrictionSpec::Tresca { bound } => {
            if !(bound.is_finite() && bound >= 0.0) {
                return Err(invalid(
                    item,
                    format!("Tresca bound = {bound} must be finite and ≥ 0"),
                ));
            }
            Friction::Tresca { bound }
        }
    };
    Ok(ContactSettings {
        search: spec.search,
        tolerance,
        penalty_normal: spec.penalty_normal,
        penalty_tangent: spec.penalty_tangent,
        penalty_rotation: spec.penalty_rotation,
        penalty_scale: spec.penalty_scale.unwrap_or(1.0),
        friction,
        initial_penetration: spec.initial_penetration.unwrap_or(PenetrationSpec::Adjust),
        bonded: spec.bonded,
    })
}

/// Validates an explicit pair; `side` resolves a side spec to node/element indices.
pub(super) fn check_pair(
    k: usize,
    spec: &ContactPairSpec,
    side: &dyn Fn(&SideSpec) -> Result<ContactSide, String>,
) -> Result<ExplicitContact, ModelError> {
    let item = format!("contact pair {}", k + 1);
    let a = side(&spec.a).map_err(|m| invalid(&item, m))?;
    let b = side(&spec.b).map_err(|m| invalid(&item, m))?;
    check_penalty(&item, "penalty_normal", spec.penalty_normal)?;
    check_penalty(&item, "penalty_tangent", spec.penalty_tangent)?;
    check_rotation_penalty(&item, spec.penalty_rotation)?;
    if !spec.gap.is_finite() {
        return Err(invalid(&item, format!("gap = {} is not finite", spec.gap)));
    }
    let normal = match spec.normal {
        Some(n) => {
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if !(len.is_finite() && len > 0.0) {
                return Err(invalid(
                    &item,
                    format!("normal {n:?} is zero or not finite"),
                ));
            }
            Some([n[0] / len, n[1] / len, n[2] / len])
        }
        None => None,
    };
    Ok(ExplicitContact {
        a,
        b,
        normal,
        gap: spec.gap,
        penalty_normal: spec.penalty_normal,
        penalty_tangent: spec.penalty_tangent,
        penalty_rotation: spec.penalty_rotation,
    })
}
