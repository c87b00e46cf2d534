//! The contact pairs of a model: searched candidates and explicit pairs, with their normals,
//! tangent bases, gaps and penalties; initially penetrating pairs are counted and handled.

use super::duplicates::merge_duplicates;
use super::{find_candidates, jump_operator, tangent_basis, ContactPair, ContactSide, Jump};
use crate::cell::Periodicity;
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
    /// Periods (i, j) by which the image of side II is shifted (\[0, 0\] unless the contact
    /// crosses the boundary of a periodic cell).
    pub shift: [i32; 2],
    /// Fiber ids of the two sides (for a node, the first fiber through it).
    pub fibers: [u64; 2],
    /// Position of the contact point of side I (m).
    pub point: [f64; 3],
}

/// A pair before validation.
struct RawPair {
    kind: &'static str,
    sides: [ContactSide; 2],
    shift: [i32; 2],
    normal: Vector3<f64>,
    gap: f64,
    penalties: [Option<f64>; 3],
}

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

/// The elements at each node, built once per contact set (a side that is a node looks its
/// elements up here instead of scanning every element).
struct NodeElements(Vec<Vec<usize>>);

impl NodeElements {
    fn new(model: &Model) -> Self {
        let mut at = vec![Vec::new(); model.nodes.len()];
        for (e, el) in model.elements().iter().enumerate() {
            for &n in &el.nodes {
                at[n].push(e);
            }
        }
        NodeElements(at)
    }

    /// The elements of each side: its element, or every element at its node.
    fn of(&self, sides: [ContactSide; 2]) -> [Vec<usize>; 2] {
        sides.map(|side| match side {
            ContactSide::Point { element, .. } => vec![element],
            ContactSide::Node(n) => self.0[n].clone(),
        })
    }
}

/// Radius of the fiber of a side's first element (0 for a side without elements).
fn side_radius(model: &Model, elements: &[usize]) -> f64 {
    elements.first().map_or(0.0, |&e| {
        model.fibers[model.elements()[e].fiber].section.radius
    })
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
    penalty_of_elements(model, &NodeElements::new(model).of(sides))
}

fn penalty_of_elements(model: &Model, elements: &[Vec<usize>; 2]) -> f64 {
    1000.0
        * elements
            .iter()
            .flatten()
            .map(|&e| transverse_stiffness(model, e))
            .fold(0.0, f64::max)
}

/// Default rolling resistance p_N a²/4, with a half the smaller fiber radius of the two sides:
/// the rotational stiffness of the normal penalty spread over a disc of radius a.
fn rotation_penalty_of_elements(
    model: &Model,
    elements: &[Vec<usize>; 2],
    penalty_normal: f64,
) -> f64 {
    let radius = elements
        .iter()
        .flatten()
        .map(|&e| model.fibers[model.elements()[e].fiber].section.radius)
        .fold(f64::INFINITY, f64::min);
    if radius.is_finite() {
        penalty_normal * (0.5 * radius).powi(2) / 4.0
    } else {
        0.0
    }
}

/// The jump of the contact point seen from either fiber, x_I + s r_I n and x_II − s r_II n with
/// s = d / (r_I + r_II) for centerlines d = r_I + r_II + g apart (the touching surface points
/// when g = 0; with an overlap or a gap, the one point that divides it in proportion to the
/// radii), instead of the centerline points: [u]_s = [u] + θ_I × s r_I n + θ_II × s r_II n
/// = B q − [n]× s (r_I R_I + r_II R_II) q. A rigid rotation ω moves the centerline points (d
/// apart along n) relative to each other by ω × d n, tangentially: with the centerline jump of
/// thesis Lemma 4.26 a sticking contact resists rigid rotations, which makes the cell problems
/// depend on where the cell lies (the macro curvature fields rotate every point differently).
/// The two points of the surface jump are one point of space, so a rigid motion moves them
/// together (with levers r_I and r_II alone, an overlap g of the generated non-wovens left
/// ω × g n: rotations of a free model 4·10⁻⁹ off its null space); its normal component, and so
/// K_N, is unchanged (nᵀ [n]× = 0).
fn surface_jump(
    model: &Model,
    mut jump: Jump,
    sides: [ContactSide; 2],
    elements: &[Vec<usize>; 2],
    (n, gap): (&Vector3<f64>, f64),
) -> Jump {
    let radii = [
        side_radius(model, &elements[0]),
        side_radius(model, &elements[1]),
    ];
    let sum = radii[0] + radii[1];
    let s = if sum > 0.0 { 1.0 + gap / sum } else { 1.0 };
    let first_side_blocks = match sides[0] {
        ContactSide::Node(_) => 1,
        ContactSide::Point { .. } => 2,
    };
    let cross = nalgebra::Matrix3::new(0.0, -n[2], n[1], n[2], 0.0, -n[0], -n[1], n[0], 0.0);
    // jump.r holds +R_I for side I's nodes and −R_II for side II's.
    for k in 0..jump.nodes.len() {
        let lever = if k < first_side_blocks {
            -s * radii[0]
        } else {
            s * radii[1]
        };
        let r_block = jump.r.fixed_view::<3, 6>(0, 6 * k).into_owned();
        let add = cross * r_block * lever;
        let mut b_block = jump.b.fixed_view_mut::<3, 6>(0, 6 * k);
        b_block += add;
    }
    jump
}

/// A contact point at an element end is the node itself (the interpolation there is exactly the
/// nodal translation), so that the same crossing seen from two adjacent elements is one side.
pub(super) fn side_of(model: &Model, element: usize, xi: f64) -> ContactSide {
    let e = model.elements()[element];
    if xi <= 1e-9 {
        ContactSide::Node(e.nodes[0])
    } else if xi >= 1.0 - 1e-9 {
        ContactSide::Node(e.nodes[1])
    } else {
        ContactSide::Point { element, xi }
    }
}

impl ContactSet {
    /// Builds the pairs of `model` (empty without `[contact]`), without periodic images.
    pub fn build(model: &Model) -> Result<Self, ModelError> {
        Self::build_with(model, None)
    }

    /// Builds the pairs of `model`; with `cell`, the search also finds contacts with the
    /// periodic images of the elements (across the cell boundary).
    pub fn build_with(model: &Model, cell: Option<&Periodicity>) -> Result<Self, ModelError> {
        let Some(settings) = &model.contact else {
            return Ok(ContactSet::default());
        };
        let mut raw: Vec<RawPair> = Vec::new();
        if settings.search {
            let found = find_candidates(model, settings.tolerance, cell);
            for c in merge_duplicates(model, cell, found) {
                raw.push(RawPair {
                    kind: "search",
                    sides: [
                        side_of(model, c.elements[0], c.xi[0]),
                        side_of(model, c.elements[1], c.xi[1]),
                    ],
                    shift: c.shift,
                    normal: Vector3::from(c.normal),
                    gap: c.gap,
                    penalties: [None; 3],
                });
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
            raw.push(RawPair {
                kind: "explicit",
                sides,
                shift: [0, 0],
                normal,
                gap: x.gap,
                penalties: [x.penalty_normal, x.penalty_tangent, x.penalty_rotation],
            });
        }
        let mut set = ContactSet::default();
        // The pairs (1.6 kB each: 78 MB on L) in place before they are made, their pages
        // mapped in one request per 256 KiB instead of a fault per page as each is pushed.
        set.pairs.reserve_exact(raw.len());
        set.origins.reserve_exact(raw.len());
        fibercell_solver::populate_par(set.pairs.spare_capacity_mut());
        let at_nodes = NodeElements::new(model);
        for (k, pair) in raw.into_iter().enumerate() {
            let RawPair {
                kind,
                sides,
                shift,
                normal,
                gap,
                penalties: [pn, pt, pr],
            } = pair;
            let elements = at_nodes.of(sides);
            let centerline = jump_operator(model, sides[0], sides[1], shift).ok_or_else(|| {
                ModelError::InvalidContact {
                    item: format!("contact pair {}", k + 1),
                    message: "its two sides share a node".into(),
                }
            })?;
            // Found by the search: the jump of the touching surface points (objective).
            let jump = if kind == "search" {
                surface_jump(model, centerline, sides, &elements, (&normal, gap))
            } else {
                centerline
            };
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
                .unwrap_or_else(|| penalty_of_elements(model, &elements));
            let penalty_tangent = pt.or(settings.penalty_tangent).unwrap_or(penalty_normal);
            let penalty_rotation = pr
                .or(settings.penalty_rotation)
                .unwrap_or_else(|| rotation_penalty_of_elements(model, &elements, penalty_normal));
            let scale = settings.penalty_scale;
            let (penalty_normal, penalty_tangent, penalty_rotation) = (
                scale * penalty_normal,
                scale * penalty_tangent,
                scale * penalty_rotation,
            );
            let mut gap = gap;
            if gap < 0.0 {
                set.penetration.count += 1;
                set.penetration.worst_overlap = set.penetration.worst_overlap.max(-gap);
                if settings.initial_penetration == PenetrationSpec::Adjust {
                    gap = 0.0;
                    set.penetration.adjusted = true;
                }
            }
            let fiber_of = |side: usize| {
                elements[side]
                    .first()
                    .map_or(0, |&e| model.fibers[model.elements()[e].fiber].id)
            };
            let p = side_point(model, sides[0]);
            set.origins.push(ContactOrigin {
                kind,
                sides,
                shift,
                fibers: [fiber_of(0), fiber_of(1)],
                point: [p[0], p[1], p[2]],
            });
            set.pairs.push(ContactPair {
                jump,
                tangents: tangent_basis(&normal, &preferred),
                normal,
                gap,
                penalty_normal,
                penalty_tangent,
                penalty_rotation,
            });
        }
        Ok(set)
    }

    /// Node lists of the contact blocks (for the pattern).
    pub fn blocks(&self) -> Vec<Vec<usize>> {
        self.pairs.iter().map(|p| p.jump.nodes.clone()).collect()
    }
}
