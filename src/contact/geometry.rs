//! Closest points between two segments (the fiber centerlines of two elements), robust for
//! parallel and near-parallel segments and for end points.

use nalgebra::Vector3;

/// The closest points P(s) = p0 + s (p1 − p0) and Q(t) = q0 + t (q1 − q0), s, t ∈ [0, 1].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosestPoints {
    /// Parameter on the first segment.
    pub s: f64,
    /// Parameter on the second segment.
    pub t: f64,
    /// Distance between the points.
    pub distance: f64,
}

fn v(p: &[f64; 3]) -> Vector3<f64> {
    Vector3::new(p[0], p[1], p[2])
}

/// Closest points of two segments. For (near-)parallel segments the minimum is not unique; the
/// middle of the overlap of their projections is taken, so the contact point is well defined.
pub fn closest_points(p0: &[f64; 3], p1: &[f64; 3], q0: &[f64; 3], q1: &[f64; 3]) -> ClosestPoints {
    let (p0, q0) = (v(p0), v(q0));
    let d1 = v(p1) - p0;
    let d2 = v(q1) - q0;
    let r = p0 - q0;
    let a = d1.dot(&d1);
    let e = d2.dot(&d2);
    let f = d2.dot(&r);
    let finish = |s: f64, t: f64| ClosestPoints {
        s,
        t,
        distance: ((p0 + d1 * s) - (q0 + d2 * t)).norm(),
    };
    if a <= f64::MIN_POSITIVE && e <= f64::MIN_POSITIVE {
        return finish(0.0, 0.0);
    }
    if a <= f64::MIN_POSITIVE {
        return finish(0.0, (f / e).clamp(0.0, 1.0));
    }
    let c = d1.dot(&r);
    if e <= f64::MIN_POSITIVE {
        return finish((-c / a).clamp(0.0, 1.0), 0.0);
    }
    let b = d1.dot(&d2);
    let denom = a * e - b * b;
    let s = if denom > 1e-12 * a * e {
        ((b * f - c * e) / denom).clamp(0.0, 1.0)
    } else {
        // Parallel: middle of the overlap of Q's projection onto P.
        let s0 = ((q0 - p0).dot(&d1) / a).clamp(0.0, 1.0);
        let s1 = ((q0 + d2 - p0).dot(&d1) / a).clamp(0.0, 1.0);
        0.5 * (s0 + s1)
    };
    // Best t for this s, then best s for that t (both clamped): the standard two-step
    // projection that handles the end-point cases.
    let t = ((b * s + f) / e).clamp(0.0, 1.0);
    let s = ((b * t - c) / a).clamp(0.0, 1.0);
    let t = ((b * s + f) / e).clamp(0.0, 1.0);
    finish(s, t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute(p0: &[f64; 3], p1: &[f64; 3], q0: &[f64; 3], q1: &[f64; 3]) -> f64 {
        let n = 400;
        let mut best = f64::MAX;
        for i in 0..=n {
            for j in 0..=n {
                let (s, t) = (i as f64 / n as f64, j as f64 / n as f64);
                let d: f64 = (0..3)
                    .map(|k| {
                        let a = p0[k] + s * (p1[k] - p0[k]);
                        let b = q0[k] + t * (q1[k] - q0[k]);
                        (a - b) * (a - b)
                    })
                    .sum::<f64>()
                    .sqrt();
                best = best.min(d);
            }
        }
        best
    }

    #[test]
    fn crossing_parallel_collinear_and_end_cases() {
        // Crossing at right angles, 0.3 apart in z.
        let c = closest_points(
            &[0.0, 0.0, 0.0],
            &[2.0, 0.0, 0.0],
            &[1.0, -1.0, 0.3],
            &[1.0, 1.0, 0.3],
        );
        assert!(
            (c.s - 0.5).abs() < 1e-15
                && (c.t - 0.5).abs() < 1e-15
                && (c.distance - 0.3).abs() < 1e-15
        );
        // Parallel with partial overlap: middle of the overlap [1, 2] of the first.
        let c = closest_points(
            &[0.0, 0.0, 0.0],
            &[2.0, 0.0, 0.0],
            &[1.0, 0.2, 0.0],
            &[3.0, 0.2, 0.0],
        );
        assert!(
            (c.s - 0.75).abs() < 1e-12
                && (c.t - 0.25).abs() < 1e-12
                && (c.distance - 0.2).abs() < 1e-12
        );
        // End point to end point.
        let c = closest_points(
            &[0.0, 0.0, 0.0],
            &[1.0, 0.0, 0.0],
            &[2.0, 1.0, 0.0],
            &[3.0, 1.0, 1.0],
        );
        assert!((c.s - 1.0).abs() < 1e-15 && c.t.abs() < 1e-15);
        assert!((c.distance - 2f64.sqrt()).abs() < 1e-14);
        // Random-ish cases against a brute-force scan.
        let cases = [
            (
                [0.1, 0.2, 0.3],
                [1.0, -0.5, 0.2],
                [0.4, 0.9, -0.3],
                [0.5, -1.0, 0.8],
            ),
            (
                [0.0, 0.0, 0.0],
                [1.0, 1.0, 1.0],
                [1.0, 1.0, 1.0001],
                [2.0, 2.0, 2.0002],
            ),
            (
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.5, 0.5, 0.0],
                [0.5, 2.0, 0.0],
            ),
        ];
        for (p0, p1, q0, q1) in cases {
            let c = closest_points(&p0, &p1, &q0, &q1);
            assert!(c.distance <= brute(&p0, &p1, &q0, &q1) + 1e-9, "{c:?}");
        }
    }
}
