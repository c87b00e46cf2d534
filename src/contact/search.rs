//! Contact search between fiber elements: a uniform-grid broad phase over bounding boxes
//! inflated by the radii and a tolerance (O(n) for evenly sized elements, never all pairs),
//! then the exact segment–segment narrow phase.
//!
//! In a periodic cell the search also sees the periodic images of the elements: every element
//! whose box, shifted by (i L_x, j L_y) with i, j ∈ {−1, 0, 1}, reaches the cell's elements
//! enters the broad phase shifted, and a pair of an element with an image of another is a
//! contact across the cell boundary.
//!
//! Excluded pairs: elements joined by a chain of elements shorter than π (r_I + r_II) between
//! them (sharing a node: length 0) — closer than that along the fibers a fiber cannot fold back
//! onto itself, or onto a fiber fixed to it, without bending tighter than its own radius. In a
//! cell the chain is followed through the periodic boundary (a slave node is its master in the
//! next period). The search works on the undeformed geometry (small displacements).

use super::geometry::closest_points;
use crate::cell::Periodicity;
use crate::model::Model;
use nalgebra::Vector3;
use rayon::prelude::*;

/// A pair of elements whose surfaces are within the search tolerance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    /// Elements I and II (I ≤ II).
    pub elements: [usize; 2],
    /// Periods (i, j) by which the image of element II is shifted (\[0, 0\] outside cells).
    pub shift: [i32; 2],
    /// Contact parameters ξ_I, ξ_II ∈ [0, 1] along the elements (first → second node).
    pub xi: [f64; 2],
    /// Distance between the centerlines.
    pub distance: f64,
    /// Initial gap g = d − (r_I + r_II) (negative: penetration).
    pub gap: f64,
    /// Unit normal from the contact point of I to that of II (4.44, normalized).
    pub normal: [f64; 3],
}

/// What the search needs of a model, precomputed once: radii, element lengths, the periods and
/// every node's canonical (independent node, period shift), and the elements at each canonical
/// node.
struct SearchContext<'a> {
    model: &'a Model,
    radii: Vec<f64>,
    lengths: Vec<f64>,
    period: [f64; 2],
    canonical: Vec<(usize, [i32; 2])>,
    /// CSR: canonical node → (element, end 0/1).
    incident_start: Vec<usize>,
    incident: Vec<(usize, usize)>,
}

fn add(a: [i32; 2], b: [i32; 2]) -> [i32; 2] {
    [a[0] + b[0], a[1] + b[1]]
}

fn sub(a: [i32; 2], b: [i32; 2]) -> [i32; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

impl<'a> SearchContext<'a> {
    fn new(model: &'a Model, cell: Option<&Periodicity>) -> Self {
        let els = model.elements();
        let radii = els
            .iter()
            .map(|e| model.fibers[e.fiber].section.radius)
            .collect();
        let lengths = els
            .iter()
            .map(|e| {
                let [p, q] = e.nodes;
                (Vector3::from(model.nodes[q].x) - Vector3::from(model.nodes[p].x)).norm()
            })
            .collect();
        let n = model.nodes.len();
        let canonical: Vec<(usize, [i32; 2])> = (0..n)
            .map(|i| cell.and_then(|p| p.master[i]).unwrap_or((i, [0, 0])))
            .collect();
        let mut incident_start = vec![0usize; n + 1];
        for e in els {
            for &nd in &e.nodes {
                incident_start[canonical[nd].0 + 1] += 1;
            }
        }
        for i in 0..n {
            incident_start[i + 1] += incident_start[i];
        }
        let mut fill = incident_start.clone();
        let mut incident = vec![(0, 0); incident_start[n]];
        for (k, e) in els.iter().enumerate() {
            for (end, &nd) in e.nodes.iter().enumerate() {
                let c = canonical[nd].0;
                incident[fill[c]] = (k, end);
                fill[c] += 1;
            }
        }
        SearchContext {
            model,
            radii,
            lengths,
            period: cell.map_or([0.0; 2], |p| p.geometry.size),
            canonical,
            incident_start,
            incident,
        }
    }

    /// Position of node `n` in the image shifted by `shift`.
    fn position(&self, n: usize, shift: [i32; 2]) -> [f64; 3] {
        let x = self.model.nodes[n].x;
        [
            x[0] + f64::from(shift[0]) * self.period[0],
            x[1] + f64::from(shift[1]) * self.period[1],
            x[2],
        ]
    }

    /// The canonical states (node, shift) of the ends of element `e`'s image `shift`.
    fn ends(&self, e: usize, shift: [i32; 2]) -> [(usize, [i32; 2]); 2] {
        self.model.elements()[e].nodes.map(|n| {
            let (c, s) = self.canonical[n];
            (c, add(s, shift))
        })
    }

    /// Whether element `a` and the image `shift` of element `b` are joined by a chain of
    /// elements shorter than π (r_a + r_b): a bounded shortest-path search from a's ends.
    fn excluded(&self, a: usize, b: usize, shift: [i32; 2]) -> bool {
        let targets = self.ends(b, shift);
        let start = self.ends(a, [0, 0]);
        if start.iter().any(|s| targets.contains(s)) {
            return true;
        }
        let limit = std::f64::consts::PI * (self.radii[a] + self.radii[b]);
        // Few states are ever reached: a linear-scan priority list is enough.
        let mut open: Vec<(f64, (usize, [i32; 2]))> = start.iter().map(|&s| (0.0, s)).collect();
        let mut done: Vec<(usize, [i32; 2])> = Vec::new();
        while let Some(k) = (0..open.len()).min_by(|&i, &j| open[i].0.total_cmp(&open[j].0)) {
            let (dist, (node, at)) = open.swap_remove(k);
            if done.contains(&(node, at)) {
                continue;
            }
            done.push((node, at));
            for &(e, end) in
                &self.incident[self.incident_start[node]..self.incident_start[node + 1]]
            {
                if e == a {
                    continue;
                }
                // The image of e with this end at `at`.
                let image = sub(at, self.canonical[self.model.elements()[e].nodes[end]].1);
                let d = dist + self.lengths[e];
                if d >= limit {
                    continue;
                }
                let other = self.ends(e, image)[1 - end];
                if targets.contains(&other) {
                    return true;
                }
                if !done.contains(&other) {
                    open.push((d, other));
                }
            }
        }
        false
    }

    /// Narrow phase for one pair: a candidate if the surfaces are within `tolerance`.
    fn narrow(&self, a: usize, b: usize, shift: [i32; 2], tolerance: f64) -> Option<Candidate> {
        let (ea, eb) = (self.model.elements()[a], self.model.elements()[b]);
        let pa = ea.nodes.map(|n| self.position(n, [0, 0]));
        let pb = eb.nodes.map(|n| self.position(n, shift));
        let c = closest_points(&pa[0], &pa[1], &pb[0], &pb[1]);
        let (ra, rb) = (self.radii[a], self.radii[b]);
        let gap = c.distance - ra - rb;
        if gap > tolerance {
            return None;
        }
        let point = |e: [[f64; 3]; 2], s: f64| {
            let (p, q) = (Vector3::from(e[0]), Vector3::from(e[1]));
            (p + (q - p) * s, (q - p).normalize())
        };
        let (xa, ta) = point(pa, c.s);
        let (xb, tb) = point(pb, c.t);
        let d = xb - xa;
        // Centerlines that touch have no normal of their own: take the crossing direction.
        let normal = if c.distance > 1e-12 * (ra + rb) {
            d / c.distance
        } else {
            let m = ta.cross(&tb);
            if m.norm() > 1e-12 {
                m.normalize()
            } else {
                let k = (0..3)
                    .min_by(|&i, &j| ta[i].abs().total_cmp(&ta[j].abs()))
                    .unwrap_or(2);
                let mut aux = Vector3::zeros();
                aux[k] = 1.0;
                ta.cross(&aux).normalize()
            }
        };
        Some(Candidate {
            elements: [a, b],
            shift,
            xi: [c.s, c.t],
            distance: c.distance,
            gap,
            normal: [normal[0], normal[1], normal[2]],
        })
    }

    /// The pair (a, image s of b) written with the lower element first.
    fn canonical_pair(
        a: usize,
        sa: [i32; 2],
        b: usize,
        sb: [i32; 2],
    ) -> Option<(usize, usize, [i32; 2])> {
        let rel = sub(sb, sa);
        if a < b || (a == b && rel > [0, 0]) {
            Some((a, b, rel))
        } else if a > b {
            Some((b, a, sub([0, 0], rel)))
        } else {
            None
        }
    }
}

/// The shifts of the periodic images searched: none outside a cell, the eight neighbours in one.
fn image_shifts(cell: Option<&Periodicity>) -> Vec<[i32; 2]> {
    match cell {
        None => Vec::new(),
        Some(_) => (-1..=1)
            .flat_map(|i| (-1..=1).map(move |j| [i, j]))
            .filter(|s| *s != [0, 0])
            .collect(),
    }
}

type Aabb = ([f64; 3], [f64; 3]);

/// All element pairs whose surfaces are within `tolerance` (≥ 0) of each other, sorted by
/// element pair and shift; with `cell`, also pairs of an element with a periodic image of
/// another (or of itself).
pub fn find_candidates(
    model: &Model,
    tolerance: f64,
    cell: Option<&Periodicity>,
) -> Vec<Candidate> {
    let els = model.elements();
    if els.is_empty() {
        return Vec::new();
    }
    let ctx = SearchContext::new(model, cell);
    let pad_box = |e: usize, shift: [i32; 2]| -> Aabb {
        let [p, q] = els[e].nodes.map(|n| ctx.position(n, shift));
        let pad = ctx.radii[e] + 0.5 * tolerance;
        (
            [0, 1, 2].map(|k| p[k].min(q[k]) - pad),
            [0, 1, 2].map(|k| p[k].max(q[k]) + pad),
        )
    };
    // Inflated boxes: half the tolerance on each side, so boxes of a candidate pair overlap.
    let mut items: Vec<(usize, [i32; 2])> = (0..els.len()).map(|e| (e, [0, 0])).collect();
    let mut boxes: Vec<Aabb> = (0..els.len()).map(|e| pad_box(e, [0, 0])).collect();
    let overlap = |a: &Aabb, b: &Aabb| (0..3).all(|k| a.0[k] <= b.1[k] && b.0[k] <= a.1[k]);
    // Images that reach the box around all elements can touch one of them.
    let all = boxes
        .iter()
        .fold(([f64::MAX; 3], [f64::MIN; 3]), |m, (lo, hi)| {
            (
                [0, 1, 2].map(|k| m.0[k].min(lo[k])),
                [0, 1, 2].map(|k| m.1[k].max(hi[k])),
            )
        });
    for shift in image_shifts(cell) {
        for e in 0..els.len() {
            let b = pad_box(e, shift);
            if overlap(&b, &all) {
                items.push((e, shift));
                boxes.push(b);
            }
        }
    }
    if items.len() < 2 {
        return Vec::new();
    }
    let cell_size = boxes
        .iter()
        .map(|(lo, hi)| (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max))
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let origin = boxes.iter().fold([f64::MAX; 3], |m, (lo, _)| {
        [m[0].min(lo[0]), m[1].min(lo[1]), m[2].min(lo[2])]
    });
    let index = |x: f64, k: usize| ((x - origin[k]) / cell_size).floor() as u64;
    // 21 bits per axis; larger grids wrap around, which only merges cells (pairs are still
    // checked, and duplicates removed below).
    let key = |i: u64, j: u64, k: u64| {
        ((i & 0x1F_FFFF) << 42) | ((j & 0x1F_FFFF) << 21) | (k & 0x1F_FFFF)
    };
    // Every box goes into the (at most 2×2×2) cells it overlaps.
    let mut entries: Vec<(u64, u32)> = Vec::with_capacity(8 * items.len());
    for (it, (lo, hi)) in boxes.iter().enumerate() {
        for i in index(lo[0], 0)..=index(hi[0], 0) {
            for j in index(lo[1], 1)..=index(hi[1], 1) {
                for k in index(lo[2], 2)..=index(hi[2], 2) {
                    entries.push((key(i, j, k), it as u32));
                }
            }
        }
    }
    entries.par_sort_unstable();
    let mut groups: Vec<(usize, usize)> = Vec::new();
    let mut start = 0;
    for w in 1..=entries.len() {
        if w == entries.len() || entries[w].0 != entries[start].0 {
            if w - start > 1 {
                groups.push((start, w));
            }
            start = w;
        }
    }
    let mut found: Vec<Candidate> = groups
        .par_iter()
        .flat_map_iter(|&(s, e)| {
            let cell_key = entries[s].0;
            let members = &entries[s..e];
            let mut out = Vec::new();
            for (x, &(_, i)) in members.iter().enumerate() {
                for &(_, j) in &members[x + 1..] {
                    let (i, j) = (i as usize, j as usize);
                    let ((a, sa), (b, sb)) = (items[i], items[j]);
                    // One side must be an element itself; a pair of two images is a shifted
                    // copy of a pair found with one of them unshifted.
                    if (sa != [0, 0] && sb != [0, 0]) || !overlap(&boxes[i], &boxes[j]) {
                        continue;
                    }
                    // Report a pair only in the cell holding the low corner of the boxes'
                    // intersection, so each pair is tested once per cell.
                    let corner = [0, 1, 2].map(|k| index(boxes[i].0[k].max(boxes[j].0[k]), k));
                    if key(corner[0], corner[1], corner[2]) != cell_key {
                        continue;
                    }
                    let Some((a, b, rel)) = SearchContext::canonical_pair(a, sa, b, sb) else {
                        continue;
                    };
                    if ctx.excluded(a, b, rel) {
                        continue;
                    }
                    if let Some(c) = ctx.narrow(a, b, rel, tolerance) {
                        out.push(c);
                    }
                }
            }
            out
        })
        .collect();
    found.par_sort_unstable_by_key(|c| (c.elements, c.shift));
    found.dedup_by_key(|c| (c.elements, c.shift));
    found
}

/// The same result by testing all pairs (and all image shifts): O(n²), for tests only.
pub fn find_candidates_brute_force(
    model: &Model,
    tolerance: f64,
    cell: Option<&Periodicity>,
) -> Vec<Candidate> {
    let ctx = SearchContext::new(model, cell);
    let n = model.elements().len();
    let mut shifts = vec![[0, 0]];
    shifts.extend(image_shifts(cell));
    let mut out = Vec::new();
    for a in 0..n {
        for b in a..n {
            for &s in &shifts {
                if (a == b && s <= [0, 0]) || ctx.excluded(a, b, s) {
                    continue;
                }
                if let Some(c) = ctx.narrow(a, b, s, tolerance) {
                    out.push(c);
                }
            }
        }
    }
    out.sort_by_key(|c| (c.elements, c.shift));
    out
}
