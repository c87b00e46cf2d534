//! Sample statistics of an ensemble: mean, standard deviation and the two-sided 95 % confidence
//! interval of the mean, x̄ ± t₀.₉₇₅,ₙ₋₁ s / √n (Student's t: the realizations are independent
//! and their scatter is estimated from the same sample).

use serde::{Deserialize, Serialize};

/// Statistics of one quantity over the realizations.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SampleSummary {
    /// Number of values.
    pub n: usize,
    /// Mean x̄.
    pub mean: f64,
    /// Sample standard deviation s (divisor n − 1; 0 for one value).
    pub std: f64,
    /// Half-width of the 95 % confidence interval of the mean, t₀.₉₇₅,ₙ₋₁ s / √n (infinite for
    /// one value: one realization says nothing about the scatter).
    pub ci95: f64,
}

impl SampleSummary {
    /// The interval's half-width relative to |mean| (infinite for a zero mean).
    pub fn relative_ci95(&self) -> f64 {
        if self.mean == 0.0 {
            f64::INFINITY
        } else {
            self.ci95 / self.mean.abs()
        }
    }
}

/// The statistics of `values` (at least one).
pub fn summarize(values: &[f64]) -> SampleSummary {
    let n = values.len();
    if n == 0 {
        return SampleSummary::default();
    }
    let mean = values.iter().sum::<f64>() / n as f64;
    if n == 1 {
        return SampleSummary {
            n,
            mean,
            std: 0.0,
            ci95: f64::INFINITY,
        };
    }
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
    let std = var.sqrt();
    let t = distrs::StudentsT::ppf(0.975, (n - 1) as f64);
    SampleSummary {
        n,
        mean,
        std,
        ci95: t * std / (n as f64).sqrt(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against hand computation and the t table (t₀.₉₇₅ for 4 and 9 degrees of freedom: 2.776
    /// and 2.262, Abramowitz & Stegun table 26.10).
    #[test]
    fn mean_deviation_and_interval_of_small_samples() {
        let s = summarize(&[1.0, 2.0, 3.0, 4.0, 5.0]);
        assert_eq!((s.n, s.mean), (5, 3.0));
        assert!((s.std - 2.5f64.sqrt()).abs() < 1e-15);
        assert!((s.ci95 / (s.std / 5f64.sqrt()) - 2.776).abs() < 5e-4);
        let ten: Vec<f64> = (0..10).map(f64::from).collect();
        let s = summarize(&ten);
        assert!((s.ci95 / (s.std / 10f64.sqrt()) - 2.262).abs() < 5e-4);
        let one = summarize(&[7.0]);
        assert_eq!((one.mean, one.std), (7.0, 0.0));
        assert!(one.ci95.is_infinite());
        assert_eq!(summarize(&[]).n, 0);
    }
}
