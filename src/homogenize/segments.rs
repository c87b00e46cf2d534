//! The piecewise-linear pieces of an elasto-plastic curve (thesis §5.1.2, Fig. 5.2): between two
//! contact-state switches (or turns of the strain path) the response is linear in the load
//! factor; each switch starts a new piece. A piece's line is fitted to its own points, and
//! where two lines meet is the switch point — the strain at which the contact switched, which
//! lies inside the increment where the switch was first seen.

use serde::Serialize;

/// A linear piece of the curve.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Segment {
    /// First and last increment of the piece.
    pub steps: [usize; 2],
    /// Load factor where the piece begins (where its line meets the previous one; 0 for the
    /// first piece, the turning point after a reversal of the path) and at its last point.
    pub alpha: [f64; 2],
    /// d(resultant)/dα over the piece (least squares over its points; for a piece of one
    /// point, the chord from the point before).
    pub slope: [f64; 6],
}

/// The piece that starts at increment `step` (pieces are ordered by their first increment).
pub fn segment_starting_at(segments: &[Segment], step: usize) -> Option<&Segment> {
    let k = segments.partition_point(|g| g.steps[0] < step);
    segments.get(k).filter(|g| g.steps[0] == step)
}

/// A line N(α) = mean + slope (α − alpha_mean), per component.
#[derive(Clone, Copy)]
struct Line {
    alpha_mean: f64,
    mean: [f64; 6],
    slope: [f64; 6],
}

impl Line {
    fn at(&self, alpha: f64) -> [f64; 6] {
        std::array::from_fn(|i| self.mean[i] + self.slope[i] * (alpha - self.alpha_mean))
    }

    /// Least-squares line through (α_k, N_k).
    fn fit(points: &[(f64, [f64; 6])]) -> Line {
        let n = points.len() as f64;
        let am = points.iter().map(|p| p.0).sum::<f64>() / n;
        let mean: [f64; 6] =
            std::array::from_fn(|i| points.iter().map(|p| p.1[i]).sum::<f64>() / n);
        let saa: f64 = points.iter().map(|p| (p.0 - am).powi(2)).sum();
        let slope = std::array::from_fn(|i| {
            if saa > 0.0 {
                points
                    .iter()
                    .map(|p| (p.0 - am) * (p.1[i] - mean[i]))
                    .sum::<f64>()
                    / saa
            } else {
                0.0
            }
        });
        Line {
            alpha_mean: am,
            mean,
            slope,
        }
    }
}

/// Splits the points (α_k, N_k), k = 1…n, at `breaks` (the 1-based increments that start a new
/// piece) into linear pieces. `turns` lists the breaks that are reversals of the path (the piece
/// starts exactly at the previous point); the others are state switches (the piece starts where
/// its line meets the previous piece's along the path's strain `strain`, clamped to the
/// increment). The path starts at (0, 0).
pub(crate) fn linear_pieces(
    points: &[(f64, [f64; 6])],
    breaks: &[usize],
    turns: &[usize],
    strain: &[f64; 6],
) -> Vec<Segment> {
    let origin = (0.0, [0.0; 6]);
    let mut segments: Vec<Segment> = Vec::new();
    let mut previous: Option<Line> = None;
    let mut start = 1;
    let ends = breaks
        .iter()
        .copied()
        .filter(|&b| b > 1 && b <= points.len())
        .chain(std::iter::once(points.len() + 1));
    for end_excl in ends {
        if end_excl <= start {
            continue;
        }
        let own = &points[start - 1..end_excl - 1];
        let before = if start == 1 {
            origin
        } else {
            points[start - 2]
        };
        // A piece that starts at a known point on its own line includes it in the fit.
        let exact_start = start == 1 || turns.contains(&start);
        let fit_points: Vec<(f64, [f64; 6])> = if exact_start || own.len() == 1 {
            std::iter::once(before).chain(own.iter().copied()).collect()
        } else {
            own.to_vec()
        };
        let line = Line::fit(&fit_points);
        let alpha0 = match previous {
            Some(prev) if !exact_start && own.len() > 1 => meeting_point(&prev, &line, strain)
                .map_or(before.0, |a| {
                    let (lo, hi) = (before.0.min(own[0].0), before.0.max(own[0].0));
                    a.clamp(lo, hi)
                }),
            _ => before.0,
        };
        let last = own[own.len() - 1].0;
        if last != alpha0 || own.len() > 1 {
            segments.push(Segment {
                steps: [start, end_excl - 1],
                alpha: [alpha0, last],
                slope: line.slope,
            });
        }
        previous = Some(line);
        start = end_excl;
    }
    segments
}

/// α where two lines meet, judged on the work-conjugate projection Σ_i N_i E_i of the path's
/// strain E (the component the path drives); None when its slope does not change.
fn meeting_point(a: &Line, b: &Line, strain: &[f64; 6]) -> Option<f64> {
    let project = |v: &[f64; 6]| v.iter().zip(strain).map(|(x, e)| x * e).sum::<f64>();
    let (sa, sb) = (project(&a.slope), project(&b.slope));
    let scale = sa.abs().max(sb.abs());
    if !((sb - sa).abs() > 1e-9 * scale) {
        return None;
    }
    // a(α) = b(α) on the projection.
    Some((project(&a.at(0.0)) - project(&b.at(0.0))) / (sb - sa))
}

#[cfg(test)]
mod tests {
    use super::*;

    const E: [f64; 6] = [0.01, 0.0, 0.0, 0.0, 0.0, 0.0];

    /// N = 3α up to α = 0.35, then N = 1.05 + (α − 0.35): sampled at α = k/10.
    fn kinked() -> Vec<(f64, [f64; 6])> {
        (1..=10)
            .map(|k| {
                let a = k as f64 / 10.0;
                let n = if a <= 0.35 {
                    3.0 * a
                } else {
                    1.05 + (a - 0.35)
                };
                (a, [n, 0.0, -2.0 * n, 0.0, 0.0, 0.0])
            })
            .collect()
    }

    #[test]
    fn the_kink_is_found_between_increments() {
        let s = linear_pieces(&kinked(), &[4], &[], &E);
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].steps, [1, 3]);
        assert!((s[0].slope[0] - 3.0).abs() < 1e-12);
        assert!((s[0].slope[2] + 6.0).abs() < 1e-12);
        assert!((s[1].slope[0] - 1.0).abs() < 1e-12);
        assert!((s[1].alpha[0] - 0.35).abs() < 1e-12, "{:?}", s[1].alpha);
        assert_eq!(s[1].alpha[1], 1.0);
    }

    #[test]
    fn a_turn_starts_at_the_turning_point() {
        // Up to α = 0.5 with slope 2, back down with slope 1 (a stick branch after sliding).
        let mut p: Vec<(f64, [f64; 6])> = (1..=5)
            .map(|k| (k as f64 / 10.0, [0.2 * k as f64, 0.0, 0.0, 0.0, 0.0, 0.0]))
            .collect();
        p.extend((0..5).rev().map(|k| {
            let a = k as f64 / 10.0;
            (a, [1.0 - (0.5 - a), 0.0, 0.0, 0.0, 0.0, 0.0])
        }));
        let s = linear_pieces(&p, &[6], &[6], &E);
        assert_eq!(s.len(), 2);
        assert_eq!(s[1].alpha, [0.5, 0.0]);
        assert!((s[1].slope[0] - 1.0).abs() < 1e-12);
    }

    #[test]
    fn one_point_pieces_take_the_chord() {
        let s = linear_pieces(&kinked(), &[4, 5], &[], &E);
        assert_eq!(s.len(), 3);
        assert_eq!(s[1].steps, [4, 4]);
        assert_eq!(s[1].alpha[0], 0.3);
        let chord = (1.05 + 0.05 - 0.9) / 0.1;
        assert!((s[1].slope[0] - chord).abs() < 1e-12);
    }
}
