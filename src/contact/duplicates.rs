//! One crossing, one contact. The search reports every element pair near a crossing: two or
//! four at or near element ends, in a cell possibly once on each side of the boundary, on both
//! pieces of a fiber cut at the boundary, and once per yarn where a fiber lies across a junction
//! of several. These passes keep one candidate per crossing.

use super::set::side_of;
use super::{Candidate, ContactSide};
use crate::cell::{independent_node, strand_of_fibers, Periodicity};
use crate::model::Model;
use nalgebra::Vector3;

/// Positions of contact points in a model, modulo the periods of its cell.
struct Places<'a> {
    model: &'a Model,
    period: [f64; 2],
    canonical: Vec<usize>,
}

impl Places<'_> {
    /// The point at ξ on element `e`, in the image shifted by `shift`.
    fn point(&self, e: usize, xi: f64, shift: [i32; 2]) -> Vector3<f64> {
        let el = self.model.elements()[e];
        let (p, q) = (
            Vector3::from(self.model.nodes[el.nodes[0]].x),
            Vector3::from(self.model.nodes[el.nodes[1]].x),
        );
        let offset = Vector3::new(
            f64::from(shift[0]) * self.period[0],
            f64::from(shift[1]) * self.period[1],
            0.0,
        );
        p + (q - p) * xi + offset
    }

    /// The two contact points of a candidate (side II in its image).
    fn points(&self, c: &Candidate) -> [Vector3<f64>; 2] {
        [
            self.point(c.elements[0], c.xi[0], [0, 0]),
            self.point(c.elements[1], c.xi[1], c.shift),
        ]
    }

    /// A difference of positions reduced to the nearest period.
    fn wrap(&self, mut d: Vector3<f64>) -> Vector3<f64> {
        for k in 0..2 {
            if self.period[k] > 0.0 {
                d[k] -= self.period[k] * (d[k] / self.period[k]).round();
            }
        }
        d
    }

    /// The independent node a side is at, if its point is an element end (the node itself,
    /// [`side_of`]).
    fn node_of_side(&self, c: &Candidate, side: usize) -> Option<usize> {
        match side_of(self.model, c.elements[side], c.xi[side]) {
            ContactSide::Node(n) => Some(self.canonical[n]),
            ContactSide::Point { .. } => None,
        }
    }
}

/// The candidates of `found` with one per crossing: [`merge_per_strand`], then
/// [`merge_at_shared_nodes`].
pub(super) fn merge_duplicates(
    model: &Model,
    cell: Option<&Periodicity>,
    found: Vec<Candidate>,
) -> Vec<Candidate> {
    let places = Places {
        model,
        period: cell.map_or([0.0; 2], |p| p.geometry.size),
        canonical: (0..model.nodes.len())
            .map(|n| independent_node(cell, n))
            .collect(),
    };
    let strands = strand_of_fibers(model, cell);
    let kept = merge_per_strand(&places, &strands, found);
    merge_at_shared_nodes(&places, &strands, kept)
}

/// One crossing of two fibers is seen by every pair of their elements near it (two or four
/// when it lies at or near element ends, and in a cell possibly once on each side of the
/// boundary, or on both pieces of a fiber cut at the boundary). Per pair of strands (fibers
/// continued end to end, [`strand_of_fibers`]), candidates whose contact points lie within the
/// sum of the two diameters of a closer one — positions compared modulo the periods — are the
/// same contact and dropped.
fn merge_per_strand(
    places: &Places,
    strands: &[usize],
    mut found: Vec<Candidate>,
) -> Vec<Candidate> {
    let model = places.model;
    let strand = |e: usize| strands[model.elements()[e].fiber];
    let key = |x: &Candidate| {
        let (a, b) = (strand(x.elements[0]), strand(x.elements[1]));
        (a.min(b), a.max(b))
    };
    found.sort_by(|a, b| {
        key(a)
            .cmp(&key(b))
            .then(a.distance.total_cmp(&b.distance))
            .then(a.elements.cmp(&b.elements))
            .then(a.shift.cmp(&b.shift))
    });
    let mut kept: Vec<Candidate> = Vec::with_capacity(found.len());
    // The candidates merged into each kept one.
    let mut twins: Vec<Vec<Candidate>> = Vec::with_capacity(found.len());
    let mut group_start = 0;
    for c in found {
        if kept.get(group_start).is_some_and(|g| key(g) != key(&c)) {
            group_start = kept.len();
        }
        let reach = 2.0 * (c.distance - c.gap);
        let [pa, pb] = places.points(&c);
        let duplicate = kept[group_start..].iter().position(|k| {
            let [qa, qb] = places.points(k);
            // Compare whichever way round the pair was found: the same first point (modulo
            // the periods) and the same offset to the second.
            let same = places
                .wrap(pa - qa)
                .norm()
                .max(((pb - pa) - (qb - qa)).norm());
            let swapped = places
                .wrap(pa - qb)
                .norm()
                .max(((pb - pa) - (qa - qb)).norm());
            same.min(swapped) < reach
        });
        match duplicate {
            None => {
                kept.push(c);
                twins.push(Vec::new());
            }
            Some(i) => twins[group_start + i].push(c),
        }
    }
    for (k, twins) in kept.iter_mut().zip(&twins) {
        if let Some(at_nodes) = straddled_nodes(model, (places.period, strands), k, twins) {
            *k = at_nodes;
        }
    }
    kept.sort_by_key(|c| (c.elements, c.shift));
    kept
}

/// A fiber lying across a junction where several yarns meet (a node they share) touches it once,
/// but the search finds it once per yarn, all with the junction node as one side. Candidates
/// with one side at the same node (modulo the periods) whose other sides lie on one strand
/// within the sum of the two diameters of each other are one contact: the closest is kept.
fn merge_at_shared_nodes(
    places: &Places,
    strands: &[usize],
    kept: Vec<Candidate>,
) -> Vec<Candidate> {
    let strand = |e: usize| strands[places.model.elements()[e].fiber];
    // (junction node, candidate, side at the node), grouped by node.
    let mut at_node: Vec<(usize, usize, usize)> = kept
        .iter()
        .enumerate()
        .flat_map(|(i, c)| (0..2).filter_map(move |s| Some((places.node_of_side(c, s)?, i, s))))
        .collect();
    at_node.sort_unstable();
    // From the node's side to the other side's point, and the other side's strand.
    let from_node = |c: &Candidate, s: usize| {
        let [a, b] = places.points(c);
        let offset = if s == 0 { b - a } else { a - b };
        (offset, strand(c.elements[1 - s]))
    };
    let mut dropped = vec![false; kept.len()];
    for group in at_node.chunk_by(|x, y| x.0 == y.0) {
        for (k, &(_, i, si)) in group.iter().enumerate() {
            for &(_, j, sj) in &group[k + 1..] {
                if i == j || dropped[i] || dropped[j] {
                    continue;
                }
                let ((oi, fi), (oj, fj)) = (from_node(&kept[i], si), from_node(&kept[j], sj));
                let reach = 2.0 * (kept[i].distance - kept[i].gap);
                if fi == fj && (oi - oj).norm() < reach {
                    let worse = if kept[j].distance < kept[i].distance {
                        i
                    } else {
                        j
                    };
                    dropped[worse] = true;
                }
            }
        }
    }
    kept.into_iter()
        .zip(dropped)
        .filter_map(|(c, d)| (!d).then_some(c))
        .collect()
}

/// A crossing at a node of each fiber where both polylines kink (a woven crossover) is closest
/// not at the nodes but a little way along the adjacent elements (a chord cuts inside the
/// curve), at equally close element pairs on both sides of each node: keeping one of them
/// would break the symmetry of the crossing. When the equally close candidates (within 10⁻⁹)
/// lie on both elements at a node of each fiber, the contact is placed at the two nodes.
fn straddled_nodes(
    model: &Model,
    (period, strands): ([f64; 2], &[usize]),
    kept: &Candidate,
    twins: &[Candidate],
) -> Option<Candidate> {
    let els = model.elements();
    let fiber = |e: usize| els[e].fiber;
    let tol = 1e-9 * kept.distance.abs().max(f64::MIN_POSITIVE);
    // The near-equal candidates, oriented like `kept` (side I on kept's first strand).
    let mut same: Vec<([usize; 2], [i32; 2])> = vec![(kept.elements, kept.shift)];
    for t in twins.iter().filter(|t| t.distance <= kept.distance + tol) {
        if strands[fiber(t.elements[0])] == strands[fiber(kept.elements[0])] {
            same.push((t.elements, t.shift));
        } else {
            same.push(([t.elements[1], t.elements[0]], [-t.shift[0], -t.shift[1]]));
        }
    }
    if same.len() < 2 || same.iter().any(|(_, s)| *s != kept.shift) {
        return None;
    }
    // The node shared by two different elements of one side, if any.
    let shared = |side: usize| -> Option<(usize, usize)> {
        for (a, _) in &same {
            for (b, _) in &same {
                let (ea, eb) = (els[a[side]], els[b[side]]);
                if a[side] != b[side] && ea.nodes[1] == eb.nodes[0] {
                    return Some((a[side], ea.nodes[1]));
                }
            }
        }
        None
    };
    let ((ea, na), (eb, nb)) = (shared(0)?, shared(1)?);
    let x = |n: usize| Vector3::from(model.nodes[n].x);
    let offset = Vector3::new(
        f64::from(kept.shift[0]) * period[0],
        f64::from(kept.shift[1]) * period[1],
        0.0,
    );
    let d = x(nb) + offset - x(na);
    let distance = d.norm();
    if distance <= 0.0 {
        return None;
    }
    let radius = |e: usize| model.fibers[fiber(e)].section.radius;
    let n = d / distance;
    Some(Candidate {
        elements: [ea, eb],
        shift: kept.shift,
        xi: [1.0, 1.0],
        distance,
        gap: distance - radius(ea) - radius(eb),
        normal: [n[0], n[1], n[2]],
    })
}
