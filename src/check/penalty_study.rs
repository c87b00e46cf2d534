//! The penalty study of a cell's elastic moduli: ABD at the model's penalties scaled by 1, 10
//! and 100, the rigid-contact limit by Richardson extrapolation in 1/p, its error, and the
//! penalty a requested accuracy needs.
//!
//! A penalty method's answer converges to the rigid-contact limit like A(s) = A∞ − C/s once
//! the contact springs are stiff against the fibers (`tests/curve_penalty_limit.rs` measures
//! the 1/s range from s ≈ 8 on the small non-woven); below it a 1/s² term still shows (the
//! ratio (A(10) − A(1)) / (A(100) − A(10)), 10 for pure 1/s, is 4.3–4.9 there): the contact
//! springs act in series with the fibers' compliance, A(s) = A∞ − C/(s + a). So the limit is
//! the exact fit of that form through the three values (Richardson with the shift a), its
//! error estimate the distance to the first-order limit from ×10 and ×100 alone, and the
//! penalty for an accuracy τ the scale where C/(s + a) = τ |A∞|.

use crate::homogenize::homogenize_elastic;
use crate::solve::SolveOptions;
use crate::{Error, Model};
use serde::Serialize;

/// The penalty scales of the study, relative to the model's.
pub const STUDY_SCALES: [f64; 3] = [1.0, 10.0, 100.0];

/// One modulus across the study.
#[derive(Clone, Debug, Serialize)]
pub struct PenaltyEntry {
    /// A11, A22, A66, D11, D22 or D66.
    pub name: &'static str,
    /// Its value at the model's penalties × 1, 10, 100.
    pub values: [f64; 3],
    /// The Richardson limit p → ∞ (the fit of A∞ − C/(s + a) through the three values).
    pub limit: f64,
    /// |limit − the first-order limit from ×10 and ×100|: an estimate of its error.
    pub limit_error: f64,
    /// (A(×10) − A(×1)) / (A(×100) − A(×10)): 10 when the error falls like 1/p.
    pub convergence_ratio: f64,
    /// |A(×1) − limit| / |limit|: the penalty error of the model as given.
    pub error_at_model: f64,
    /// Penalty scale (relative to the model's) at which the error is `accuracy`.
    pub scale_for_accuracy: f64,
}

/// What [`penalty_study`] found.
#[derive(Clone, Debug, Serialize)]
pub struct PenaltyStudy {
    /// The model's own `penalty_scale` (1 when not given).
    pub model_scale: f64,
    /// The requested relative accuracy of the moduli.
    pub accuracy: f64,
    /// ABD at each scale.
    pub abd: [[[f64; 6]; 6]; 3],
    /// Backward error of the cell problems at each scale.
    pub backward_errors: [f64; 3],
    /// max |ABD − ABDᵀ| / max |ABD| at each scale: ABD is symmetric in exact arithmetic, so
    /// this measures the round-off in the moduli, which grows with the penalty.
    pub roundoff: [f64; 3],
    /// The six diagonal moduli.
    pub entries: Vec<PenaltyEntry>,
    /// Largest [`PenaltyEntry::scale_for_accuracy`], times the model's scale: the
    /// `penalty_scale` to put in `[contact]` for `accuracy` (none when a scale failed).
    pub recommended_penalty_scale: Option<f64>,
    /// Estimated relative round-off of the moduli at that scale: the measured
    /// [`PenaltyStudy::roundoff`] interpolated in log–log, beyond ×100 grown like the scale.
    pub roundoff_at_recommended: Option<f64>,
    /// The scale whose cell problems could not be solved (a pivot lost to round-off), with
    /// the error: the study stops there and gives no limit.
    pub failed: Option<String>,
    /// When round-off would dominate the penalty error.
    pub warnings: Vec<String>,
}

const NAMES: [&str; 6] = ["A11", "A22", "A66", "D11", "D22", "D66"];

/// ABD at one penalty scale with its backward error and round-off (ABD's asymmetry).
#[derive(Clone, Copy, Debug)]
pub(crate) struct ScaledAbd {
    pub abd: [[f64; 6]; 6],
    pub backward_error: f64,
    pub asymmetry: f64,
}

/// ABD of `model` with its penalties scaled by [`STUDY_SCALES`] and the limit per diagonal
/// modulus, with the penalty for `accuracy` and warnings where round-off would dominate.
pub fn penalty_study(
    model: &Model,
    options: &SolveOptions,
    accuracy: f64,
) -> Result<PenaltyStudy, Error> {
    penalty_study_from(model, options, accuracy, None)
}

/// [`penalty_study`] with the model's own ABD (×1) already computed, when `at_model` gives it.
pub(crate) fn penalty_study_from(
    model: &Model,
    options: &SolveOptions,
    accuracy: f64,
    at_model: Option<ScaledAbd>,
) -> Result<PenaltyStudy, Error> {
    let model_scale = model.contact.as_ref().map_or(1.0, |c| c.penalty_scale);
    let mut abd = [[[0.0; 6]; 6]; 3];
    let mut backward_errors = [0.0; 3];
    let mut roundoff = [0.0; 3];
    for (k, s) in STUDY_SCALES.iter().enumerate() {
        if let (0, Some(first)) = (k, at_model) {
            (abd[0], backward_errors[0], roundoff[0]) =
                (first.abd, first.backward_error, first.asymmetry);
            continue;
        }
        let mut scaled = model.clone();
        if let Some(c) = scaled.contact.as_mut() {
            c.penalty_scale = model_scale * s;
        }
        let h = match homogenize_elastic(&scaled, options) {
            Ok(h) => h,
            Err(e @ (Error::Singular { .. } | Error::Solver(_))) => {
                let failed = format!(
                    "at {s}× the penalties (penalty_scale {:.3e}) the cell problems fail: {e}; \
                     round-off has taken over before the penalty limit",
                    model_scale * s
                );
                return Ok(PenaltyStudy {
                    model_scale,
                    accuracy,
                    abd,
                    backward_errors,
                    roundoff,
                    entries: Vec::new(),
                    recommended_penalty_scale: None,
                    roundoff_at_recommended: None,
                    warnings: vec![failed.clone()],
                    failed: Some(failed),
                });
            }
            Err(e) => return Err(e),
        };
        abd[k] = h.abd;
        backward_errors[k] = h.backward_error;
        roundoff[k] = h.asymmetry;
    }
    let entries: Vec<PenaltyEntry> = (0..6)
        .map(|i| {
            entry(
                NAMES[i],
                [abd[0][i][i], abd[1][i][i], abd[2][i][i]],
                accuracy,
            )
        })
        .collect();
    let needed = entries
        .iter()
        .map(|e| e.scale_for_accuracy)
        .fold(0.0f64, f64::max);
    let recommended_penalty_scale = model_scale * needed;
    let mut warnings = Vec::new();
    for e in &entries {
        let penalty_error = ((e.values[2] - e.limit) / e.limit).abs();
        if roundoff[2] > penalty_error {
            warnings.push(format!(
                "{}: at {}× the penalties the round-off {:.1e} (ABD's asymmetry) exceeds the \
                 penalty error {penalty_error:.1e}: the limit's digits below it are noise",
                e.name, STUDY_SCALES[2], roundoff[2]
            ));
        }
    }
    let roundoff_at_recommended = roundoff_at(&roundoff, needed);
    if roundoff_at_recommended > accuracy {
        warnings.push(format!(
            "at penalty_scale {recommended_penalty_scale:.3e} the estimated round-off \
             {roundoff_at_recommended:.1e} exceeds the requested accuracy {accuracy:.1e}: use \
             the extrapolated limits instead"
        ));
    }
    Ok(PenaltyStudy {
        model_scale,
        accuracy,
        abd,
        backward_errors,
        roundoff,
        entries,
        recommended_penalty_scale: Some(recommended_penalty_scale),
        roundoff_at_recommended: Some(roundoff_at_recommended),
        warnings,
        failed: None,
    })
}

/// The round-off at `scale` (× the model's) from the measured values at [`STUDY_SCALES`]:
/// log–log interpolation, the end values held below ×1 and grown like the scale above ×100.
fn roundoff_at(measured: &[f64; 3], scale: f64) -> f64 {
    let floor = f64::EPSILON;
    let log = |v: f64| v.max(floor).ln();
    let (s, r) = (STUDY_SCALES.map(f64::ln), measured.map(log));
    let x = scale.max(STUDY_SCALES[0]).ln();
    let y = if x <= s[1] {
        r[0] + (r[1] - r[0]) * (x - s[0]) / (s[1] - s[0])
    } else if x <= s[2] {
        r[1] + (r[2] - r[1]) * (x - s[1]) / (s[2] - s[1])
    } else {
        r[2] + (x - s[2])
    };
    y.exp()
}

/// The limit and error measures of one modulus from its values at ×1, ×10, ×100: the exact
/// fit of A(s) = A∞ − C/(s + a) through the three (a contact spring in series with the
/// fibers' own compliance: a = 0 is the pure 1/s of stiff penalties) gives the limit and the
/// penalty error C/(s + a) at scale s; the first-order limit from ×10 and ×100 alone,
/// A(100) + (A(100) − A(10))/9, differs from it by the error estimate. Where the values do
/// not fit that form (ratio ≤ 1, a ≤ −1), the first-order limit and a = 0 are used.
fn entry(name: &'static str, v: [f64; 3], accuracy: f64) -> PenaltyEntry {
    let (d1, d2) = (v[1] - v[0], v[2] - v[1]);
    let ratio = d1 / d2;
    let first_order = v[2] + d2 / 9.0;
    // (A(10) − A(1)) / (A(100) − A(10)) = (100 + a) / (10 (1 + a)).
    let shift = (100.0 - 10.0 * ratio) / (10.0 * ratio - 1.0);
    let (a, c, limit) = if ratio.is_finite() && ratio > 1.0 && shift > -1.0 {
        let c = d2 * (10.0 + shift) * (100.0 + shift) / 90.0;
        (shift, c, v[2] + c / (100.0 + shift))
    } else {
        (0.0, d2 * 100.0 / 9.0, first_order)
    };
    let error_at_model = if limit != 0.0 {
        ((v[0] - limit) / limit).abs()
    } else {
        0.0
    };
    let scale_for_accuracy = if limit != 0.0 {
        (c.abs() / (accuracy * limit.abs()) - a).max(0.0)
    } else {
        0.0
    };
    PenaltyEntry {
        name,
        values: v,
        limit,
        limit_error: (limit - first_order).abs(),
        convergence_ratio: ratio,
        error_at_model,
        scale_for_accuracy,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On an exact A(s) = A∞ − C/s the limit, the ratio 10 and the scale for an accuracy are
    /// exact: A∞ = 200, C = 12 → A(1) = 188, A(10) = 198.8, A(100) = 199.88; error at the model
    /// 6 %, scale for 1e-3: C/(A∞ 1e-3) = 60.
    #[test]
    fn richardson_is_exact_on_one_over_p() {
        let e = entry("A11", [188.0, 198.8, 199.88], 1e-3);
        assert!((e.limit - 200.0).abs() < 1e-10);
        assert!(e.limit_error < 1e-10);
        assert!((e.convergence_ratio - 10.0).abs() < 1e-9);
        assert!((e.error_at_model - 0.06).abs() < 1e-12);
        assert!((e.scale_for_accuracy - 60.0).abs() < 1e-8);
    }

    /// A spring in series, A(s) = 200 − 12/(s + 2): ratio 102/30 = 3.4, the fit recovers
    /// a = 2 and the limit 200 exactly; the first-order limit from ×10 and ×100 is
    /// 199.980392… (error estimate 0.019608); the scale for 1e-3 solves 12/(s + 2) = 0.2:
    /// s = 58.
    #[test]
    fn a_series_spring_is_fitted() {
        let f = |s: f64| 200.0 - 12.0 / (s + 2.0);
        let e = entry("A11", [f(1.0), f(10.0), f(100.0)], 1e-3);
        assert!((e.convergence_ratio - 3.4).abs() < 1e-9);
        assert!((e.limit - 200.0).abs() < 1e-9, "{}", e.limit);
        assert!(
            (e.limit_error - (200.0 - 199.980_392_156_862_75)).abs() < 1e-9,
            "{}",
            e.limit_error
        );
        assert!(
            (e.scale_for_accuracy - 58.0).abs() < 1e-6,
            "{}",
            e.scale_for_accuracy
        );
    }
}
