//! The statistics of an ensemble's curves: per point of the common strain path, the mean,
//! standard deviation and 95 % interval of each stress resultant and of the dissipated energy
//! over the realizations whose curve ran to the end, and the convergence of the interval at
//! the peak of the path as the realizations accumulate.

use super::realization::{CurvePath, CurveSample, Realization};
use super::statistics::{summarize, SampleSummary};
use serde::Serialize;

/// One point of the path over the realizations.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CurvePointSummary {
    /// Increment (1-based) along the path.
    pub step: usize,
    /// Macroscopic strain α E of the point (the same in every realization).
    pub strain: [f64; 6],
    /// Each stress resultant (N11, N22, N12 in N/m; M11, M22, M12 in N).
    pub resultant: [SampleSummary; 6],
    /// Dissipated energy per unit area so far (J/m²).
    pub dissipated: SampleSummary,
}

/// The relative interval of the path's main resultant at its peak after n curves.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CurveConvergencePoint {
    /// Curves counted.
    pub n: usize,
    /// ci95 / |mean| of the resultant conjugate to the path's largest strain component at the
    /// end of loading.
    pub relative_ci95: f64,
}

/// Statistics of the curves of an ensemble.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CurveStatistics {
    /// The path every curve follows.
    pub path: CurvePath,
    /// Index (0–5) of the path's largest strain component and so of its main resultant.
    pub component: usize,
    /// Curves that ran to the end of the path (the statistics' sample).
    pub curves: usize,
    /// One summary per point of the path.
    pub points: Vec<CurvePointSummary>,
    /// The interval at the peak (the last loading point) as curves accumulate (from n = 2).
    pub convergence: Vec<CurveConvergencePoint>,
}

impl CurveStatistics {
    /// The statistics of the complete curves among `realizations` (in seed order).
    pub fn from_realizations(path: &CurvePath, realizations: &[Realization]) -> Self {
        let complete: Vec<&[CurveSample]> = realizations
            .iter()
            .filter_map(|r| r.curve.as_deref())
            .filter(|c| c.len() == path.points())
            .collect();
        let component = crate::io::dominant_component(&path.strain);
        let summary_at = |k: usize, n: usize, value: &dyn Fn(&CurveSample) -> f64| {
            summarize(
                &complete[..n]
                    .iter()
                    .map(|c| value(&c[k]))
                    .collect::<Vec<_>>(),
            )
        };
        let all = complete.len();
        let points = (0..path.points())
            .map(|k| CurvePointSummary {
                step: k + 1,
                strain: complete.first().map_or([0.0; 6], |c| c[k].strain),
                resultant: std::array::from_fn(|m| summary_at(k, all, &|s| s.resultant[m])),
                dissipated: summary_at(k, all, &|s| s.dissipated),
            })
            .collect();
        let peak = path.steps.saturating_sub(1);
        let convergence = (2..=all)
            .map(|n| CurveConvergencePoint {
                n,
                relative_ci95: summary_at(peak, n, &|s| s.resultant[component]).relative_ci95(),
            })
            .collect();
        CurveStatistics {
            path: path.clone(),
            component,
            curves: all,
            points,
            convergence,
        }
    }
}
