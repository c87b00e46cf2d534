//! Anderson acceleration of the fixed point on the Coulomb bounds.
//!
//! Each state iteration solves with the sliding contacts' friction forces at bounds b and
//! returns the bounds G(b) = c + μ max(N(b), 0) of the normal forces it found. The plain update
//! b ← G(b) converges linearly, with the rate μ times the coupling of the normal forces to the
//! friction forces: 0.1–0.15 per iteration on the M non-woven (bounds from 10⁻³ to 10⁻⁸ of
//! themselves in five iterations), close to 1 on L, where thousands of bounds were still
//! moving after 50. Anderson's method (type II, Walker & Ni 2011) takes the combination of the
//! last m iterates whose residuals f = G(b) − b cancel best:
//!
//! γ = argmin ‖f_k − ΔF γ‖,  b_{k+1} = G(b_k) − (ΔB + ΔF) γ,
//!
//! ΔB and ΔF the differences of successive iterates and residuals. For a linear G it is a
//! Krylov method on the bounds (GMRES in exact arithmetic); the residuals are weighted by
//! 1/G(b), as the bounds' convergence is judged relative to themselves. The history restarts
//! whenever the set of sliding contacts changes (the map is another one then), and when the
//! weighted residual grows, which falls back to the plain update.

use nalgebra::{DMatrix, DVector};
use std::collections::VecDeque;

/// Iterates of the bound fixed point combined (the depth m).
const DEPTH: usize = 5;

/// The history of the fixed point on the bounds of one increment.
#[derive(Clone, Debug, Default)]
pub(super) struct BoundAcceleration {
    /// The contacts whose bounds are iterated (sliding in the last trial), ascending.
    sliding: Vec<usize>,
    /// Their residuals' weights: 1 / bound at the start of the history.
    weight: Vec<f64>,
    /// Their iterates b and weighted residuals f, oldest first (at most `DEPTH + 1`).
    history: VecDeque<(DVector<f64>, DVector<f64>)>,
}

impl BoundAcceleration {
    /// Forgets the history (a new increment).
    pub fn restart(&mut self) {
        self.sliding.clear();
        self.weight.clear();
        self.history.clear();
    }

    /// The next bounds of the contacts `sliding` (ascending), from the bounds `bounds` the
    /// last system was solved with and those its solution gives, `trial`; `floor` is the
    /// smallest bound the law has (the cohesion).
    pub fn next(
        &mut self,
        sliding: &[usize],
        bounds: &[f64],
        trial: &[f64],
        floor: f64,
        relaxation: f64,
    ) -> Vec<f64> {
        if sliding != self.sliding {
            self.restart();
            self.sliding = sliding.to_vec();
            self.weight = sliding
                .iter()
                .map(|&i| 1.0 / trial[i].abs().max(bounds[i].abs()).max(f64::MIN_POSITIVE))
                .collect();
        }
        let weight = &self.weight;
        let b = DVector::from_iterator(sliding.len(), sliding.iter().map(|&i| bounds[i]));
        let f = DVector::from_iterator(
            sliding.len(),
            sliding
                .iter()
                .zip(weight)
                .map(|(&i, w)| (trial[i] - bounds[i]) * w),
        );
        self.history.push_back((b.clone(), f.clone()));
        if self.history.len() > DEPTH + 1 {
            self.history.pop_front();
        }
        let plain: Vec<f64> = sliding
            .iter()
            .map(|&i| bounds[i] + relaxation * (trial[i] - bounds[i]))
            .collect();
        let Some(gamma) = self.coefficients(&f) else {
            return plain;
        };
        // b + β f − (ΔB + β ΔF) γ, with f and ΔF unweighted.
        let m = gamma.len();
        let mut next = plain;
        for (j, g) in gamma.iter().enumerate() {
            let (b0, f0) = &self.history[self.history.len() - 1 - m + j];
            let (b1, f1) = &self.history[self.history.len() - m + j];
            for (k, x) in next.iter_mut().enumerate() {
                let d_b = b1[k] - b0[k];
                let d_f = relaxation * (f1[k] - f0[k]) / weight[k];
                *x -= g * (d_b + d_f);
            }
        }
        next.iter().map(|&x| x.max(floor)).collect()
    }

    /// γ minimizing ‖f − ΔF γ‖ over the history's differences, by a least-squares solve
    /// (SVD, small singular values dropped); `None` without differences or a usable γ.
    fn coefficients(&self, f: &DVector<f64>) -> Option<DVector<f64>> {
        let h = self.history.len();
        if h < 2 {
            return None;
        }
        let m = h - 1;
        let n = f.len();
        let df = DMatrix::from_fn(n, m, |k, j| self.history[j + 1].1[k] - self.history[j].1[k]);
        let svd = df.svd(true, true);
        let tol = 1e-12 * svd.singular_values.max();
        let gamma = svd.solve(f, tol).ok()?;
        gamma.iter().all(|g| g.is_finite()).then_some(gamma)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fixed point of an affine map G(b) = c + J b of six bounds, J symmetric with the
    /// eigenvalues 0.95 (slow), −1.3 (the plain update diverges, oscillating) and four small
    /// ones: b* = (I − J)⁻¹ c. The accelerated iteration reaches it to 1e-10 in ten steps;
    /// the plain one, in twenty, has moved away from it.
    #[test]
    fn anderson_steps_reach_the_fixed_point_the_plain_update_misses() {
        let n = 6;
        // An orthogonal Q from the QR of a fixed matrix, J = Q Λ Qᵀ.
        let a = DMatrix::from_fn(n, n, |i, j| {
            ((3 * i + 7 * j) % 5) as f64 + (i == j) as u8 as f64
        });
        let q = a.qr().q();
        let lambda = DVector::from_vec(vec![0.95, -1.3, 0.5, 0.1, -0.2, 0.3]);
        let j = &q * DMatrix::from_diagonal(&lambda) * q.transpose();
        let c = DVector::from_fn(n, |i, _| 2.0 + 0.3 * i as f64);
        let exact = (DMatrix::identity(n, n) - &j)
            .lu()
            .solve(&c)
            .expect("I − J is invertible");
        assert!(exact.iter().all(|&b| b > 0.0), "a positive fixed point");
        let g = |b: &[f64]| {
            (&c + &j * DVector::from_column_slice(b))
                .as_slice()
                .to_vec()
        };
        let error = |b: &[f64]| (DVector::from_column_slice(b) - &exact).norm() / exact.norm();
        let sliding: Vec<usize> = (0..n).collect();
        let mut acc = BoundAcceleration::default();
        let (mut accelerated, mut plain) = (exact.as_slice().to_vec(), exact.as_slice().to_vec());
        accelerated.iter_mut().for_each(|b| *b *= 0.5);
        plain.iter_mut().for_each(|b| *b *= 0.5);
        for _ in 0..10 {
            let trial = g(&accelerated);
            accelerated = acc.next(&sliding, &accelerated, &trial, 0.0, 1.0);
        }
        for _ in 0..20 {
            plain = g(&plain);
        }
        assert!(
            error(&accelerated) <= 1e-10,
            "accelerated: {}",
            error(&accelerated)
        );
        assert!(error(&plain) > 1.0, "plain: {}", error(&plain));
        // A new set of sliding contacts restarts the history: one plain step.
        let fewer = [0, 2, 4];
        let before = accelerated.clone();
        let trial: Vec<f64> = before.iter().map(|b| b + 1.0).collect();
        let next = acc.next(&fewer, &before, &trial, 0.0, 1.0);
        assert_eq!(next, fewer.iter().map(|&i| trial[i]).collect::<Vec<_>>());
    }
}
