//! Contact search between fiber elements: a uniform-grid broad phase over bounding boxes
//! inflated by the radii and a tolerance (O(n) for evenly sized elements, never all pairs),
//! then the exact segment–segment narrow phase.
//!
//! Excluded pairs: elements sharing a node (joined fibers touch by construction) and elements
//! of the same fiber separated along it by less than π (r_I + r_II) of fiber — closer than that a
//! fiber cannot fold back onto itself without bending tighter than its own radius. The search works
//! on the undeformed geometry (small displacements); periodic images will be searched by
//! shifting the positions of one side (issue 4).

use super::geometry::closest_points;
use crate::model::Model;
use nalgebra::Vector3;
use rayon::prelude::*;

/// A pair of elements whose surfaces are within the search tolerance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    /// Elements I and II (I < II).
    pub elements: [usize; 2],
    /// Contact parameters ξ_I, ξ_II ∈ [0, 1] along the elements (first → second node).
    pub xi: [f64; 2],
    /// Distance between the centerlines.
    pub distance: f64,
    /// Initial gap g = d − (r_I + r_II) (negative: penetration).
    pub gap: f64,
    /// Unit normal from the contact point of I to that of II (4.44, normalized).
    pub normal: [f64; 3],
}

/// Radius of every element (its fiber's).
fn element_radii(model: &Model) -> Vec<f64> {
    model
        .elements()
        .iter()
        .map(|e| model.fibers[e.fiber].section.radius)
        .collect()
}

/// Arc length along its fiber at the start of every element.
fn arc_positions(model: &Model) -> Vec<f64> {
    let els = model.elements();
    let mut pos = vec![0.0; els.len()];
    for e in 1..els.len() {
        if els[e].fiber == els[e - 1].fiber {
            let [p, q] = els[e - 1].nodes;
            let l: f64 = (0..3)
                .map(|k| (model.nodes[q].x[k] - model.nodes[p].x[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            pos[e] = pos[e - 1] + l;
        }
    }
    pos
}

fn excluded(model: &Model, radii: &[f64], arc: &[f64], a: usize, b: usize) -> bool {
    let (ea, eb) = (model.elements()[a], model.elements()[b]);
    if ea.nodes.iter().any(|n| eb.nodes.contains(n)) {
        return true;
    }
    if ea.fiber != eb.fiber {
        return false;
    }
    // Fiber between the end of the earlier element and the start of the later one.
    let (first, second) = if arc[a] <= arc[b] { (a, b) } else { (b, a) };
    let [p, q] = model.elements()[first].nodes;
    let len_first: f64 = (0..3)
        .map(|k| (model.nodes[q].x[k] - model.nodes[p].x[k]).powi(2))
        .sum::<f64>()
        .sqrt();
    arc[second] - (arc[first] + len_first) < std::f64::consts::PI * (radii[a] + radii[b])
}

/// Narrow phase for one pair: a candidate if the surfaces are within `tolerance`.
fn narrow(model: &Model, radii: &[f64], a: usize, b: usize, tolerance: f64) -> Option<Candidate> {
    let (ea, eb) = (model.elements()[a], model.elements()[b]);
    let x = |n: usize| &model.nodes[n].x;
    let c = closest_points(
        x(ea.nodes[0]),
        x(ea.nodes[1]),
        x(eb.nodes[0]),
        x(eb.nodes[1]),
    );
    let gap = c.distance - radii[a] - radii[b];
    if gap > tolerance {
        return None;
    }
    let point = |e: [usize; 2], s: f64| {
        let (p, q) = (Vector3::from(*x(e[0])), Vector3::from(*x(e[1])));
        (p + (q - p) * s, (q - p).normalize())
    };
    let (pa, ta) = point(ea.nodes, c.s);
    let (pb, tb) = point(eb.nodes, c.t);
    let d = pb - pa;
    // Centerlines that touch have no normal of their own: take the crossing direction.
    let normal = if c.distance > 1e-12 * (radii[a] + radii[b]) {
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
        xi: [c.s, c.t],
        distance: c.distance,
        gap,
        normal: [normal[0], normal[1], normal[2]],
    })
}

/// All element pairs whose surfaces are within `tolerance` (≥ 0) of each other, sorted by
/// element pair.
pub fn find_candidates(model: &Model, tolerance: f64) -> Vec<Candidate> {
    let els = model.elements();
    if els.len() < 2 {
        return Vec::new();
    }
    let radii = element_radii(model);
    let arc = arc_positions(model);
    // Inflated boxes: half the tolerance on each side, so boxes of a candidate pair overlap.
    let boxes: Vec<([f64; 3], [f64; 3])> = els
        .iter()
        .zip(&radii)
        .map(|(e, r)| {
            let (p, q) = (model.nodes[e.nodes[0]].x, model.nodes[e.nodes[1]].x);
            let pad = r + 0.5 * tolerance;
            let lo = [
                p[0].min(q[0]) - pad,
                p[1].min(q[1]) - pad,
                p[2].min(q[2]) - pad,
            ];
            let hi = [
                p[0].max(q[0]) + pad,
                p[1].max(q[1]) + pad,
                p[2].max(q[2]) + pad,
            ];
            (lo, hi)
        })
        .collect();
    let cell = boxes
        .iter()
        .map(|(lo, hi)| (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max))
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let origin = boxes.iter().fold([f64::MAX; 3], |m, (lo, _)| {
        [m[0].min(lo[0]), m[1].min(lo[1]), m[2].min(lo[2])]
    });
    let index = |x: f64, k: usize| ((x - origin[k]) / cell).floor() as u64;
    // 21 bits per axis; larger grids wrap around, which only merges cells (pairs are still
    // checked, and duplicates removed below).
    let key = |i: u64, j: u64, k: u64| {
        ((i & 0x1F_FFFF) << 42) | ((j & 0x1F_FFFF) << 21) | (k & 0x1F_FFFF)
    };
    // Every box goes into the (at most 2×2×2) cells it overlaps.
    let mut entries: Vec<(u64, u32)> = Vec::with_capacity(8 * els.len());
    for (e, (lo, hi)) in boxes.iter().enumerate() {
        for i in index(lo[0], 0)..=index(hi[0], 0) {
            for j in index(lo[1], 1)..=index(hi[1], 1) {
                for k in index(lo[2], 2)..=index(hi[2], 2) {
                    entries.push((key(i, j, k), e as u32));
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
    let overlap = |a: usize, b: usize| {
        (0..3).all(|k| boxes[a].0[k] <= boxes[b].1[k] && boxes[b].0[k] <= boxes[a].1[k])
    };
    let mut found: Vec<Candidate> = groups
        .par_iter()
        .flat_map_iter(|&(s, e)| {
            let cell_key = entries[s].0;
            let members = &entries[s..e];
            let mut out = Vec::new();
            for (x, &(_, a)) in members.iter().enumerate() {
                for &(_, b) in &members[x + 1..] {
                    let (a, b) = (a.min(b) as usize, a.max(b) as usize);
                    if !overlap(a, b) {
                        continue;
                    }
                    // Report a pair only in the cell holding the low corner of the boxes'
                    // intersection, so each pair is tested once.
                    let corner = [0, 1, 2].map(|k| index(boxes[a].0[k].max(boxes[b].0[k]), k));
                    if key(corner[0], corner[1], corner[2]) != cell_key
                        || excluded(model, &radii, &arc, a, b)
                    {
                        continue;
                    }
                    if let Some(c) = narrow(model, &radii, a, b, tolerance) {
                        out.push(c);
                    }
                }
            }
            out
        })
        .collect();
    found.par_sort_unstable_by_key(|c| c.elements);
    found.dedup_by_key(|c| c.elements);
    found
}

/// The same result by testing all pairs: O(n²), for tests only.
pub fn find_candidates_brute_force(model: &Model, tolerance: f64) -> Vec<Candidate> {
    let radii = element_radii(model);
    let arc = arc_positions(model);
    let n = model.elements().len();
    let mut out = Vec::new();
    for a in 0..n {
        for b in a + 1..n {
            if !excluded(model, &radii, &arc, a, b) {
                if let Some(c) = narrow(model, &radii, a, b, tolerance) {
                    out.push(c);
                }
            }
        }
    }
    out
}
