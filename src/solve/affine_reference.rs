//! The reference solution A₀⁻¹ b₀ of an increment from two earlier ones instead of a solve.
//!
//! On one reference factorization A₀, b₀ is the load with every contact as A₀ has it (its
//! state, slip direction and the slip it was factorized at): the element load α F plus contact
//! loads constant or linear in α. Then b₀(α) = (1 − t) b₀(αₐ) + t b₀(α_b), t = (α − αₐ) /
//! (α_b − αₐ), and as A₀⁻¹ and its forward half are linear, so is the reference. Each b₀ is
//! checked against the line through the two kept ones before their combination stands for its
//! solve; a b₀ off the line, or further from the two than [`MAX_EXTRAPOLATION`], is solved for
//! and replaces the older one.

use super::low_rank::{LowRankCorrection, Reference};

/// The largest |t| (and |1 − t|) a combination is taken at: its rounding grows with it.
const MAX_EXTRAPOLATION: f64 = 4.0;

/// How far b₀ may lie off the line, relative to the largest entry of the three loads: a few
/// roundings of the sums that build each load (at most 6.2e-16 over the benchmark's M curve).
/// What is off by less is neglected, below the backward error a low-rank solve is checked to.
const LINE_TOLERANCE: f64 = 4e-15;

/// Up to two solved loads on one A₀ with their references.
#[derive(Default)]
pub(crate) struct AffineReferences {
    /// Oldest first.
    points: Vec<Point>,
}

struct Point {
    alpha: f64,
    b0: Vec<f64>,
    reference: Reference,
}

impl AffineReferences {
    /// Forgets the points (A₀ was refactorized).
    pub(crate) fn clear(&mut self) {
        self.points.clear();
    }

    /// The reference of `b0` at load factor `alpha` as a combination of the two points, when
    /// `b0` lies on their line to rounding and not too far from them (`low_rank`: the columns
    /// its Wᵀ f is for).
    pub(crate) fn predict(
        &self,
        alpha: f64,
        b0: &[f64],
        low_rank: &LowRankCorrection,
    ) -> Option<Reference> {
        let [a, b] = self.points.as_slice() else {
            return None;
        };
        let t = (alpha - a.alpha) / (b.alpha - a.alpha);
        if !t.is_finite() || t.abs().max((1.0 - t).abs()) > MAX_EXTRAPOLATION {
            return None;
        }
        let largest = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let scale = largest(b0).max(largest(&a.b0)).max(largest(&b.b0));
        let on_line = b0
            .iter()
            .zip(a.b0.iter().zip(&b.b0))
            .all(|(x, (p, q))| (x - (p + t * (q - p))).abs() <= LINE_TOLERANCE * scale);
        if !on_line {
            return None;
        }
        // Both Wᵀ f to every column, so that the combination has them all.
        low_rank.project(&a.reference);
        low_rank.project(&b.reference);
        Reference::combine(&a.reference, &b.reference, t)
    }

    /// Keeps `b0` at `alpha`, solved for as `reference`, in place of the older point (none
    /// when its α is one of theirs).
    pub(crate) fn record(&mut self, alpha: f64, b0: Vec<f64>, reference: &Reference) {
        if self.points.iter().any(|p| p.alpha == alpha) {
            return;
        }
        if self.points.len() == 2 {
            self.points.remove(0);
        }
        self.points.push(Point {
            alpha,
            b0,
            reference: reference.clone(),
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::BlockCoefficients;
    use crate::solve::low_rank::tests::path_graph_factor;
    use crate::solve::{ContactChange, SolverKind};
    use nalgebra::Vector6;

    /// Two contacts' changes of two tangential columns each (springs removed, as stick → slip).
    fn changes() -> Vec<ContactChange> {
        (0..2)
            .map(|c| {
                let mut stiffness = BlockCoefficients::zeros();
                stiffness[(1, 1)] = -0.4 - 0.1 * c as f64;
                stiffness[(2, 2)] = -0.3;
                let mut load = Vector6::zeros();
                load[1] = 0.2 + c as f64;
                ContactChange {
                    contact: c,
                    stiffness,
                    load,
                }
            })
            .collect()
    }

    /// b₀(α) = c + α d on a low-rank correction of a path-graph Laplacian plus a diagonal,
    /// with columns added between the points and the prediction: the solve from the predicted
    /// reference equals the solve from one computed for b₀(α) (1e-12), at t = 4 from the
    /// points; beyond MAX_EXTRAPOLATION, with one point, or with b₀ off the line by 1e-9 there
    /// is none. With forward references (faer Cholesky) and full ones (faer LU).
    #[test]
    fn a_load_affine_in_alpha_is_solved_from_two_points() {
        for kind in [SolverKind::FaerCholesky, SolverKind::FaerLu] {
            let n = 40;
            let (_, mut a0) = path_graph_factor(n, kind);
            let column = |c: usize, k: usize| {
                vec![
                    ((5 * c + 3 * k) % n, 1.0),
                    ((11 * c + 7 * k + 20) % n, -0.5),
                ]
            };
            let all = changes();
            let mut low_rank = LowRankCorrection::new(n, all.len());
            low_rank
                .extend(a0.as_mut(), &all[..1], column)
                .expect("extend");
            let b0 = |alpha: f64| -> Vec<f64> {
                (0..n)
                    .map(|i| ((i * 7) % 5) as f64 - 2.0 + alpha * (1.0 + (i % 3) as f64))
                    .collect()
            };
            let mut affine = AffineReferences::default();
            assert!(affine.predict(0.1, &b0(0.1), &low_rank).is_none());
            for alpha in [0.1, 0.2] {
                let reference = low_rank.reference(a0.as_mut(), b0(alpha)).expect("solve");
                // Used once, so that a forward reference carries Wᵀ f for the first columns.
                let cap = low_rank.capacitance(&all[..1]);
                let load = low_rank.active_load(&all[..1]);
                low_rank
                    .solve_from(a0.as_mut(), &cap, &reference, &load)
                    .expect("solve");
                affine.record(alpha, b0(alpha), &reference);
                if alpha == 0.1 {
                    assert!(
                        affine.predict(0.3, &b0(0.3), &low_rank).is_none(),
                        "one point"
                    );
                }
            }
            low_rank.extend(a0.as_mut(), &all, column).expect("extend");
            let alpha = 0.5;
            let predicted = affine
                .predict(alpha, &b0(alpha), &low_rank)
                .expect("on the line");
            let solved = low_rank.reference(a0.as_mut(), b0(alpha)).expect("solve");
            let cap = low_rank.capacitance(&all);
            let load = low_rank.active_load(&all);
            let mut from = |r: &Reference| low_rank.solve_from(a0.as_mut(), &cap, r, &load);
            let want = from(&solved).expect("solve");
            let got = from(&predicted).expect("solve");
            let big = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let err = want
                .iter()
                .zip(&got)
                .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
            assert!(err <= 1e-12 * big, "{kind:?}: {err} of {big}");
            assert!(affine.predict(0.7, &b0(0.7), &low_rank).is_none(), "t = 6");
            let mut off = b0(alpha);
            off[n / 2] += 1e-9 * off.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(
                affine.predict(alpha, &off, &low_rank).is_none(),
                "off the line"
            );
        }
    }
}
