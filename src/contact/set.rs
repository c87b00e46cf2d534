//! The contact pairs of a model: searched candidates and explicit pairs, with their normals,
//! tangent bases, gaps and penalties; initially penetrating pairs are counted and handled.

use super::{find_candidates, jump_operator, tangent_basis, Candidate, ContactPair, ContactSide};
use crate::element::local_frame;
use crate::model::{Model, ModelError, PenetrationSpec};
use nalgebra::Vector3;

/// Where a pair came from, for reports.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactOrigin {
    /// "search" or "explicit".
    pub kind: &'static str,
    /// The two sides.
    pub sides: [ContactSide; 2],
    /// Fiber ids of the two sides (for a node, the first fiber through it).
    pub fibers: [u64; 2],
    /// Position of the contact point of side I (m).
    pub point: [f64; 3],
}

/// (origin, sides, normal, gap, normal penalty, tangential penalty) before validation.
type RawPair = (
    &'static str,
    [ContactSide; 2],
    Vector3<f64>,
    f64,
    Option<f64>,
    Option<f64>,
);

/// Initially penetrating pairs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PenetrationReport {
    /// How many pairs start with a negative gap.
    pub count: usize,
    /// The largest overlap −g (m), 0 when none.
    pub worst_overlap: f64,
    /// What was done about them.
    pub adjusted: bool,
}

/// All contact pairs of a model.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ContactSet {
    /// Geometry and penalties.
    pub pairs: Vec<ContactPair>,
    /// Origin of each pair.
    pub origins: Vec<ContactOrigin>,
    /// Initially penetrating pairs.
    pub penetration: PenetrationReport,
}

/// 12 E I / L³ of an element: its transverse stiffness scale.
fn transverse_stiffness(model: &Model, e: usize) -> f64 {
    let el = model.elements()[e];
    let f = &model.fibers[el.fiber];
    let (_, l) = local_frame(&model.nodes[el.nodes[0]].x, &model.nodes[el.nodes[1]].x);
    12.0 * model.materials[f.material].young * f.section.second_moment() / l.powi(3)
}

fn side_elements(model: &Model, side: ContactSide) -> Vec<usize> {
    match side {
        ContactSide::Point { element, .. } => vec![element],
        ContactSide::Node(n) => (0..model.elements().len())
            .filter(|&e| model.elements()[e].nodes.contains(&n))
            .collect(),
    }
}

fn side_point(model: &Model, side: ContactSide) -> Vector3<f64> {
    match side {
        ContactSide::Node(n) => Vector3::from(model.nodes[n].x),
        ContactSide::Point { element, xi } => {
            let e = model.elements()[element];
            let (p, q) = (
                Vector3::from(model.nodes[e.nodes[0]].x),
                Vector3::from(model.nodes[e.nodes[1]].x),
            );
            p + (q - p) * xi
        }
    }
}

/// Default penalty: 1000 × the largest transverse stiffness 12EI/L³ of the elements on either
/// side, so the penalty compliance is a thousandth of the fibers' own bending compliance.
pub fn default_penalty(model: &Model, sides: [ContactSide; 2]) -> f64 {
    1000.0
        * sides
            .iter()
            .flat_map(|&s| side_elements(model, s))
            .map(|e| transverse_stiffness(model, e))
            .fold(0.0, f64::max)
}

/// A contact point at an element end is the node itself (the interpolation there is exactly the
/// nodal translation), so that the same crossing seen from two adjacent elements is one side.
fn side_of(model: &Model, element: usize, xi: f64) -> ContactSide {
    let e = model.elements()[element];
    if xi <= 1e-9 {
        ContactSide::Node(e.nodes[0])
    } else if xi >= 1.0 - 1e-9 {
        ContactSide::Node(e.nodes[1])
    } else {
        ContactSide::Point { element, xi }
    }
}

/// One crossing of two fibers is seen by every pair of their elements near it (two or four
/// when it lies at or near element ends). Per pair of fibers, candidates whose contact points
/// lie within the sum of the two diameters of a closer one are the same contact and dropped.
fn merge_duplicates(model: &Model, mut found: Vec<Candidate>) -> Vec<Candidate> {
    let fiber = |e: usize| model.elements()[e].fiber;
    let point = |e: usize, xi: f64| {
        let el = model.elements()[e];
        let (p, q) = (
            Vector3::from(model.nodes[el.nodes[0]].x),
            Vector3::from(model.nodes[el.nodes[1]].x),
        );
        p + (q - p) * xi
    };
    found.sort_by(|a, b| {
        let ka = (
            fiber(a.elements[0]).min(fiber(a.elements[1])),
            fiber(a.elements[0]).max(fiber(a.elements[1])),
        );
        let kb = (
            fiber(b.elements[0]).min(fiber(b.elements[1])),
            fiber(b.elements[0]).max(fiber(b.elements[1])),
        );
        ka.cmp(&kb)
            .then(a.distance.total_cmp(&b.distance))
            .then(a.elements.cmp(&b.elements))
    });
    let mut kept: Vec<Candidate> = Vec::with_capacity(found.len());
    let mut group_start = 0;
    for c in found {
        let key = |x: &Candidate| {
            (
                fiber(x.elements[0]).min(fiber(x.elements[1])),
                fiber(x.elements[0]).max(fiber(x.elements[1])),
            )
        };
        if kept.get(group_start).is_some_and(|g| key(g) != key(&c)) {
            group_start = kept.len();
        }
        let reach = 2.0 * (c.distance - c.gap);
        let (pa, pb) = (point(c.elements[0], c.xi[0]), point(c.elements[1], c.xi[1]));
        let duplicate = kept[group_start..].iter().any(|k| {
            let (qa, qb) = (point(k.elements[0], k.xi[0]), point(k.elements[1], k.xi[1]));
            // Compare whichever way round the pair was found.
            let same = (pa - qa).norm().max((pb - qb).norm());
            let swapped = (pa - qb).norm().max((pb - qa).norm());
            same.min(swapped) < reach
        });
        if !duplicate {
            kept.push(c);
        }
    }
    kept.sort_by_key(|c| c.elements);
    kept
}

impl ContactSet {
    /// Builds the pairs of `model` (empty without `[contact]`).
    pub fn build(model: &Model) -> Result<Self, ModelError> {
        let Some(settings) = &model.contact else {
            return Ok(ContactSet::default());
        };
        let mut raw: Vec<RawPair> = Vec::new();
        if settings.search {
            for c in merge_duplicates(model, find_candidates(model, settings.tolerance)) {
                let sides = [
                    side_of(model, c.elements[0], c.xi[0]),
                    side_of(model, c.elements[1], c.xi[1]),
                ];
                raw.push(("search", sides, Vector3::from(c.normal), c.gap, None, None));
            }
        }
        for (k, x) in model.explicit_contacts.iter().enumerate() {
            let sides = [x.a, x.b];
            let normal = match x.normal {
                Some(n) => Vector3::from(n),
                None => {
                    let d = side_point(model, x.b) - side_point(model, x.a);
                    if d.norm() <= 0.0 {
                        return Err(ModelError::InvalidContact {
                            item: format!("contact pair {}", k + 1),
                            message: "its two points coincide: give a normal".into(),
                        });
                    }
                    d.normalize()
                }
            };
            raw.push((
                "explicit",
                sides,
                normal,
                x.gap,
                x.penalty_normal,
                x.penalty_tangent,
            ));
        }
        let mut set = ContactSet::default();
        for (k, (kind, sides, normal, gap, pn, pt)) in raw.into_iter().enumerate() {
            let jump = jump_operator(model, sides[0], sides[1]).ok_or_else(|| {
                ModelError::InvalidContact {
                    item: format!("contact pair {}", k + 1),
                    message: "its two sides share a node".into(),
                }
            })?;
            let preferred = match sides[0] {
                ContactSide::Point { element, .. } => {
                    let e = model.elements()[element];
                    Vector3::from(model.nodes[e.nodes[1]].x)
                        - Vector3::from(model.nodes[e.nodes[0]].x)
                }
                ContactSide::Node(_) => Vector3::new(1.0, 0.0, 0.0),
            };
            let penalty_normal = pn
                .or(settings.penalty_normal)
                .unwrap_or_else(|| default_penalty(model, sides));
            let penalty_tangent = pt.or(settings.penalty_tangent).unwrap_or(penalty_normal);
            let mut gap = gap;
            if gap < 0.0 {
                set.penetration.count += 1;
                set.penetration.worst_overlap = set.penetration.worst_overlap.max(-gap);
                if settings.initial_penetration == PenetrationSpec::Adjust {
                    gap = 0.0;
                    set.penetration.adjusted = true;
                }
            }
            let fiber_of = |s: ContactSide| {
                side_elements(model, s)
                    .first()
                    .map_or(0, |&e| model.fibers[model.elements()[e].fiber].id)
            };
            let p = side_point(model, sides[0]);
            set.origins.push(ContactOrigin {
                kind,
                sides,
                fibers: [fiber_of(sides[0]), fiber_of(sides[1])],
                point: [p[0], p[1], p[2]],
            });
            set.pairs.push(ContactPair {
                jump,
                tangents: tangent_basis(&normal, &preferred),
                normal,
                gap,
                penalty_normal,
                penalty_tangent,
            });
        }
        Ok(set)
    }

    /// Node lists of the contact blocks (for the pattern).
    pub fn blocks(&self) -> Vec<Vec<usize>> {
        self.pairs.iter().map(|p| p.jump.nodes.clone()).collect()
    }
}
