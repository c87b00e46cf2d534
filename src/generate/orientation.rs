//! In-plane fiber orientation: isotropic, or a von Mises distribution of the doubled angle
//! (fibers are axial: θ and θ + π are the same direction), f(θ) ∝ exp(κ cos 2(θ − θ₀)), given
//! by its concentration κ or by the orientation tensor a = ⟨t ⊗ t⟩ it produces:
//! a₁₁ − a₂₂ = A(κ) cos 2θ₀, 2a₁₂ = A(κ) sin 2θ₀ with A(κ) = I₁(κ)/I₀(κ).

use rand::Rng;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The distribution of the in-plane fiber angle θ (from the x axis).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Orientation {
    /// Uniform θ: a = I/2.
    Isotropic,
    /// von Mises of the doubled angle about `mean_angle_degrees` with concentration κ ≥ 0.
    VonMises {
        /// θ₀ in degrees, counter-clockwise from x (as every angle of the CLI and the parameter
        /// files).
        mean_angle_degrees: f64,
        /// κ (0: isotropic).
        concentration: f64,
    },
    /// The von Mises distribution whose orientation tensor has these in-plane components
    /// (a₂₂ = 1 − a₁₁); the eigenvalues must lie in [0.5, 0.995].
    Tensor {
        /// a₁₁ = ⟨cos² θ⟩.
        a11: f64,
        /// a₁₂ = ⟨sin θ cos θ⟩.
        a12: f64,
    },
}

/// I₁(κ)/I₀(κ) from the power series (κ ≤ 200 here; terms stay finite).
pub fn bessel_ratio(kappa: f64) -> f64 {
    if kappa <= 0.0 {
        return 0.0;
    }
    let q = 0.25 * kappa * kappa;
    let (mut t0, mut t1) = (1.0, 0.5 * kappa);
    let (mut i0, mut i1) = (t0, t1);
    for k in 1..2000 {
        let k = k as f64;
        t0 *= q / (k * k);
        t1 *= q / (k * (k + 1.0));
        i0 += t0;
        i1 += t1;
        if t0 < 1e-17 * i0 && t1 < 1e-17 * i1 {
            break;
        }
    }
    i1 / i0
}

/// κ with A(κ) = `ratio` ∈ [0, 0.99] by bisection.
pub fn concentration_for(ratio: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 200.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if bessel_ratio(mid) < ratio {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

impl Orientation {
    /// (θ₀ in rad, κ) of the distribution; an error names the bad value.
    pub fn parameters(&self) -> Result<(f64, f64), String> {
        match *self {
            Orientation::Isotropic => Ok((0.0, 0.0)),
            Orientation::VonMises {
                mean_angle_degrees,
                concentration,
            } => {
                if !mean_angle_degrees.is_finite() {
                    return Err(format!(
                        "orientation mean_angle_degrees {mean_angle_degrees} is not finite"
                    ));
                }
                if !(0.0..=200.0).contains(&concentration) {
                    return Err(format!(
                        "orientation concentration {concentration} must be in [0, 200]"
                    ));
                }
                Ok((mean_angle_degrees.to_radians(), concentration))
            }
            Orientation::Tensor { a11, a12 } => {
                if !(a11.is_finite() && a12.is_finite()) {
                    return Err(format!("orientation tensor ({a11}, {a12}) is not finite"));
                }
                let (c, s) = (2.0 * a11 - 1.0, 2.0 * a12);
                let ratio = (c * c + s * s).sqrt();
                if !(ratio <= 0.99) || !(0.0..=1.0).contains(&a11) {
                    return Err(format!(
                        "orientation tensor a11 = {a11}, a12 = {a12}: its largest eigenvalue {} must lie in [0.5, 0.995]",
                        0.5 * (1.0 + ratio)
                    ));
                }
                Ok((0.5 * s.atan2(c), concentration_for(ratio)))
            }
        }
    }

    /// The expected orientation tensor [a₁₁, a₂₂, a₁₂].
    pub fn expected_tensor(&self) -> Result<[f64; 3], String> {
        let (t0, k) = self.parameters()?;
        let a = bessel_ratio(k);
        let (c, s) = (a * (2.0 * t0).cos(), a * (2.0 * t0).sin());
        Ok([0.5 * (1.0 + c), 0.5 * (1.0 - c), 0.5 * s])
    }
}

/// Samples θ from the distribution with parameters (θ₀, κ): the doubled angle from von Mises
/// by the Best–Fisher rejection method (uniform for κ = 0), halved.
pub fn sample_angle<R: Rng>(rng: &mut R, (mean, kappa): (f64, f64)) -> f64 {
    if kappa < 1e-8 {
        return rng.random::<f64>() * PI;
    }
    let tau = 1.0 + (1.0 + 4.0 * kappa * kappa).sqrt();
    let rho = (tau - (2.0 * tau).sqrt()) / (2.0 * kappa);
    let r = (1.0 + rho * rho) / (2.0 * rho);
    let psi = loop {
        let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
        let z = (PI * u1).cos();
        let f = (1.0 + r * z) / (r + z);
        let c = kappa * (r - f);
        if c * (2.0 - c) - u2 > 0.0 || (c / u2).ln() + 1.0 - c >= 0.0 {
            let angle = f.clamp(-1.0, 1.0).acos();
            break if u3 > 0.5 { angle } else { -angle };
        }
    };
    mean + 0.5 * psi
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn bessel_ratio_matches_tabulated_values() {
        // I1/I0 from Abramowitz & Stegun Table 9.8: I0(1) = 1.266065878, I1(1) = 0.565159104;
        // I0(5) = 27.23987182, I1(5) = 24.33564214.
        assert!((bessel_ratio(1.0) - 0.565159104 / 1.266065878).abs() < 1e-9);
        assert!((bessel_ratio(5.0) - 24.33564214 / 27.23987182).abs() < 1e-9);
        assert!((concentration_for(bessel_ratio(3.7)) - 3.7).abs() < 1e-9);
    }

    #[test]
    fn sampled_tensors_reach_the_expected_one() {
        // 40,000 samples: the standard error of ⟨cos 2θ⟩ is below 0.004; tolerance 0.015.
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for o in [
            Orientation::Isotropic,
            Orientation::Tensor { a11: 0.8, a12: 0.1 },
            Orientation::VonMises {
                mean_angle_degrees: 1f64.to_degrees(),
                concentration: 2.0,
            },
        ] {
            let p = o.parameters().unwrap();
            let n = 40_000;
            let mut a = [0.0; 3];
            for _ in 0..n {
                let t = sample_angle(&mut rng, p);
                a[0] += t.cos().powi(2) / n as f64;
                a[1] += t.sin().powi(2) / n as f64;
                a[2] += t.sin() * t.cos() / n as f64;
            }
            let want = o.expected_tensor().unwrap();
            for k in 0..3 {
                assert!((a[k] - want[k]).abs() < 0.015, "{o:?}: {a:?} vs {want:?}");
            }
        }
        let t = Orientation::Tensor { a11: 0.8, a12: 0.1 }
            .expected_tensor()
            .unwrap();
        assert!((t[0] - 0.8).abs() < 1e-9 && (t[2] - 0.1).abs() < 1e-9);
    }

    #[test]
    fn bad_parameters_are_named() {
        let e = Orientation::Tensor { a11: 1.0, a12: 0.0 }
            .parameters()
            .unwrap_err();
        assert!(e.contains("largest eigenvalue"), "{e}");
        let e = Orientation::VonMises {
            mean_angle_degrees: 0.0,
            concentration: f64::NAN,
        }
        .parameters()
        .unwrap_err();
        assert!(e.contains("concentration"), "{e}");
    }
}
