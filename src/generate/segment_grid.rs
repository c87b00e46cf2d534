//! A uniform grid of bins over a periodic cell for the segments already deposited: each
//! segment is filed in every bin its padded plan-view box touches (bin indices wrap), so a
//! query near a face also finds the segments beyond it. O(1) per query for evenly sized
//! segments — never all pairs.

/// A deposited segment (cell coordinates, inside the box).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Deposited {
    /// End points.
    pub ends: [[f64; 3]; 2],
    /// Radius.
    pub radius: f64,
    /// Physical fiber index.
    pub fiber: usize,
}

impl Deposited {
    /// The end points of the periodic image shifted by `shift` in the plane.
    pub fn shifted(&self, shift: [f64; 2]) -> [[f64; 3]; 2] {
        self.ends.map(|p| [p[0] + shift[0], p[1] + shift[1], p[2]])
    }
}

pub(crate) struct SegmentGrid {
    origin: [f64; 2],
    period: [f64; 2],
    bins: [usize; 2],
    bin_size: [f64; 2],
    /// Per bin the segments filed there.
    cells: Vec<Vec<u32>>,
    pub segments: Vec<Deposited>,
    /// Query stamp per segment, to report each once.
    seen: Vec<u32>,
    stamp: u32,
    /// Bins of the current insert or query (reused, no allocation per call).
    scratch: Vec<usize>,
}

impl SegmentGrid {
    /// Bins of about `bin` (m) over the cell.
    pub fn new(origin: [f64; 2], period: [f64; 2], bin: f64) -> Self {
        let bins = [0, 1].map(|k| ((period[k] / bin).floor() as usize).clamp(1, 4096));
        SegmentGrid {
            origin,
            period,
            bins,
            bin_size: [0, 1].map(|k| period[k] / bins[k] as f64),
            cells: vec![Vec::new(); bins[0] * bins[1]],
            segments: Vec::new(),
            seen: Vec::new(),
            stamp: 0,
            scratch: Vec::new(),
        }
    }

    /// Bin index range (unwrapped) covering [lo, hi] along axis k.
    fn span(&self, k: usize, lo: f64, hi: f64) -> (i64, i64) {
        let f = |v: f64| ((v - self.origin[k]) / self.bin_size[k]).floor() as i64;
        let (a, b) = (f(lo), f(hi));
        // Never more than one full period of bins.
        (a, b.min(a + self.bins[k] as i64 - 1))
    }

    /// The bins the plan-view box [lo, hi] touches, each once, into `self.scratch`.
    fn collect_bins(&mut self, lo: [f64; 2], hi: [f64; 2]) {
        let (x0, x1) = self.span(0, lo[0], hi[0]);
        let (y0, y1) = self.span(1, lo[1], hi[1]);
        self.scratch.clear();
        for i in x0..=x1 {
            for j in y0..=y1 {
                let bi = i.rem_euclid(self.bins[0] as i64) as usize;
                let bj = j.rem_euclid(self.bins[1] as i64) as usize;
                self.scratch.push(bi * self.bins[1] + bj);
            }
        }
        // A box wider than the cell wraps onto bins it already has.
        self.scratch.sort_unstable();
        self.scratch.dedup();
    }

    /// Files a segment.
    pub fn insert(&mut self, s: Deposited) {
        let id = self.segments.len() as u32;
        let [p, q] = s.ends;
        let pad = s.radius;
        let lo = [p[0].min(q[0]) - pad, p[1].min(q[1]) - pad];
        let hi = [p[0].max(q[0]) + pad, p[1].max(q[1]) + pad];
        self.collect_bins(lo, hi);
        for &b in &self.scratch {
            self.cells[b].push(id);
        }
        self.segments.push(s);
        self.seen.push(0);
    }

    /// The segments whose padded boxes may reach the plan-view box of `ends` padded by
    /// `pad`, each once, with the period shift (multiples of L_x, L_y) that brings it
    /// nearest to the query (minimum image).
    pub fn near(&mut self, ends: [[f64; 3]; 2], pad: f64, out: &mut Vec<(usize, [f64; 2])>) {
        out.clear();
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.seen.iter_mut().for_each(|s| *s = 0);
            self.stamp = 1;
        }
        let [p, q] = ends;
        let lo = [p[0].min(q[0]) - pad, p[1].min(q[1]) - pad];
        let hi = [p[0].max(q[0]) + pad, p[1].max(q[1]) + pad];
        let mid = [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])];
        self.collect_bins(lo, hi);
        for &b in &self.scratch {
            for &id in &self.cells[b] {
                let id = id as usize;
                if self.seen[id] == self.stamp {
                    continue;
                }
                self.seen[id] = self.stamp;
                let [a, c] = self.segments[id].ends;
                let shift = [0, 1].map(|k| {
                    let m = 0.5 * (a[k] + c[k]);
                    ((mid[k] - m) / self.period[k]).round() * self.period[k]
                });
                out.push((id, shift));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn queries_see_segments_across_the_faces() {
        let mut g = SegmentGrid::new([0.0, 0.0], [1.0, 1.0], 0.1);
        g.insert(Deposited {
            ends: [[0.95, 0.5, 0.0], [0.999, 0.5, 0.0]],
            radius: 0.01,
            fiber: 0,
        });
        g.insert(Deposited {
            ends: [[0.5, 0.5, 0.0], [0.55, 0.5, 0.0]],
            radius: 0.01,
            fiber: 1,
        });
        let mut out = Vec::new();
        g.near([[0.0, 0.45, 0.0], [0.02, 0.55, 0.0]], 0.03, &mut out);
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].0, 0);
        assert_eq!(out[0].1, [-1.0, 0.0], "the image one period to the left");
    }
}
