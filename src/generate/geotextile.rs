//! Geotextile cells (thesis §5.3.3, §5.3.4): families of straight parallel fibers, rigidly joined
//! where two families of one layer cross, stacked in layers that are either joined at their
//! crossings by short connector beams or touch there with frictional contact.
//!
//! Family k is the set of lines n·p = offset + i s (n = (−sin θ, cos θ), spacing s). It is
//! periodic in the cell only if a period shifts it onto itself: L_x |sin θ| / s and
//! L_y |cos θ| / s must be whole numbers. Each line is clipped to the cell into pieces whose
//! ends lie on the faces; the piece leaving through x = L_x continues as the piece entering at
//! x = 0, and the two end nodes pair. Every crossing of two pieces of one layer becomes one
//! shared node (a fixed junction); crossings of adjacent layers get a node on each fiber.

use super::check::{invalid, material, positive};
use crate::model::{
    CellSpec, ContactSpec, FiberSpec, FrictionSpec, MaterialSpec, ModelDescription, NodeSpec,
    PenetrationSpec,
};
use crate::Error;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

/// One family of parallel straight fibers.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FiberFamily {
    /// Direction of the fibers, counter-clockwise from x (degrees).
    pub angle_degrees: f64,
    /// Perpendicular distance between neighbouring fibers (m).
    pub spacing: f64,
    /// Fiber radius (m).
    pub radius: f64,
    /// Perpendicular offset of the first fiber from the cell origin (m; default spacing / 2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub offset: Option<f64>,
    /// Layer, counted from 0 at the bottom.
    #[serde(default)]
    pub layer: usize,
}

/// How fibers of adjacent layers are held where they cross.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum LayerJunction {
    /// A connector beam from fiber axis to fiber axis (length r + r′, radius the smaller r):
    /// a bonded or welded junction.
    Fixed,
    /// The fibers touch with zero gap and Coulomb friction μ (found by the contact search).
    Contact {
        /// Friction coefficient.
        mu: f64,
    },
}

/// Parameters of a geotextile cell.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Geotextile {
    /// Cell periods (L_x, L_y) (m).
    #[serde(deserialize_with = "crate::model::fixed_array::exactly")]
    pub size: [f64; 2],
    /// Fiber families (at least one; a layer with one family only must be joined to another).
    pub families: Vec<FiberFamily>,
    /// Largest element length (m).
    pub element_length: f64,
    /// Junctions between layers.
    pub layer_junction: LayerJunction,
    /// Young's modulus (Pa).
    pub young: f64,
    /// Poisson's ratio.
    pub poisson: f64,
}

impl Default for Geotextile {
    /// A square biaxial geogrid: 10 mm cell, fibers along x and y 5 mm apart, radius 0.5 mm,
    /// E = 10⁸ Pa (thesis §5.3.3), ν = 0.3, elements ≤ 1.25 mm.
    fn default() -> Self {
        let family = |angle_degrees| FiberFamily {
            angle_degrees,
            spacing: 5e-3,
            radius: 5e-4,
            offset: None,
            layer: 0,
        };
        Geotextile {
            size: [1e-2, 1e-2],
            families: vec![family(0.0), family(90.0)],
            element_length: 1.25e-3,
            layer_junction: LayerJunction::Fixed,
            young: 1e8,
            poisson: 0.3,
        }
    }
}

impl Geotextile {
    /// Checks every parameter, naming the bad one (`families[k].spacing`, …).
    pub fn validate(&self) -> Result<(), Error> {
        let [lx, ly] = self.size;
        let positive = |name: &str, v: f64| positive("geotextile", name, v);
        for (name, v) in [
            ("size[0]", lx),
            ("size[1]", ly),
            ("element_length", self.element_length),
            ("young", self.young),
        ] {
            positive(name, v)?;
        }
        if lx.hypot(ly) / self.element_length > 1e6 {
            return Err(invalid(format!(
                "geotextile: element_length = {} gives more than 10⁶ elements per fiber",
                self.element_length
            )));
        }
        let mu = match self.layer_junction {
            LayerJunction::Contact { mu } => mu,
            LayerJunction::Fixed => 0.0,
        };
        material("geotextile", self.poisson, mu)?;
        if self.families.is_empty() {
            return Err(invalid("geotextile: no fiber families".into()));
        }
        for (k, f) in self.families.iter().enumerate() {
            // Layers are numbered from 0 without gaps (checked below), so a layer is below the
            // number of families; `layer + 1` of a huge one would wrap around.
            if f.layer >= self.families.len() {
                return Err(invalid(format!(
                    "geotextile: families[{k}].layer = {} but there are {} families: layers are \
                     numbered 0, 1, … without gaps",
                    f.layer,
                    self.families.len()
                )));
            }
            positive(&format!("families[{k}].spacing"), f.spacing)?;
            positive(&format!("families[{k}].radius"), f.radius)?;
            if !f.angle_degrees.is_finite() || !f.offset.unwrap_or(0.0).is_finite() {
                return Err(invalid(format!(
                    "geotextile: families[{k}]: angle and offset must be finite"
                )));
            }
            if 2.0 * f.radius >= f.spacing {
                return Err(invalid(format!(
                    "geotextile: families[{k}]: diameter {} is not below the spacing {}",
                    2.0 * f.radius,
                    f.spacing
                )));
            }
            let (s, c) = f.angle_degrees.to_radians().sin_cos();
            let lines = (lx * s.abs() + ly * c.abs()) / f.spacing;
            if lines > 10_000.0 {
                return Err(invalid(format!(
                    "geotextile: families[{k}] has {lines:.0} fibers per cell (at most 10,000)"
                )));
            }
            for (axis, count) in [
                ("x", lx * s.abs() / f.spacing),
                ("y", ly * c.abs() / f.spacing),
            ] {
                if (count - count.round()).abs() > 1e-6 * count.max(1.0) {
                    return Err(invalid(format!(
                        "geotextile: families[{k}] (angle {}°, spacing {}) is not periodic: the \
                         period along {axis} shifts it by {count:.6} spacings, not a whole number",
                        f.angle_degrees, f.spacing
                    )));
                }
            }
        }
        let layers = self.layer_count();
        for l in 0..layers {
            if !self.families.iter().any(|f| f.layer == l) {
                return Err(invalid(format!("geotextile: layer {l} has no family")));
            }
        }
        Ok(())
    }

    fn layer_count(&self) -> usize {
        self.families.iter().map(|f| f.layer + 1).max().unwrap_or(0)
    }

    /// Height of each layer's axis: the bottom layer's fibers rest on z = 0, each next layer
    /// on the one below (the largest radii of the two).
    fn layer_heights(&self) -> Vec<f64> {
        let rmax: Vec<f64> = (0..self.layer_count())
            .map(|l| {
                self.families
                    .iter()
                    .filter(|f| f.layer == l)
                    .map(|f| f.radius)
                    .fold(0.0, f64::max)
            })
            .collect();
        let mut z = vec![rmax[0]];
        for l in 1..rmax.len() {
            // A hair of overlap (10⁻⁹) so touching layers are closed contacts.
            z.push(z[l - 1] + (rmax[l - 1] + rmax[l]) * (1.0 - 1e-9));
        }
        z
    }
}

/// A piece of a family line clipped to the cell: plan-view ends, family, and the stations
/// (parameters t ∈ [0, 1]) where it must have a node.
struct Piece {
    a: [f64; 2],
    b: [f64; 2],
    family: usize,
    stations: Vec<f64>,
}

/// The pieces of family `k` in the cell [0, L_x] × [0, L_y].
fn clip_family(k: usize, f: &FiberFamily, size: [f64; 2]) -> Result<Vec<Piece>, Error> {
    let [lx, ly] = size;
    let (s, c) = f.angle_degrees.to_radians().sin_cos();
    let (n, d) = ([-s, c], [c, s]);
    let offset = f.offset.unwrap_or(0.5 * f.spacing);
    let corners = [[0.0, 0.0], [lx, 0.0], [0.0, ly], [lx, ly]];
    let proj = |p: [f64; 2]| n[0] * p[0] + n[1] * p[1];
    let (lo, hi) = corners.iter().fold((f64::MAX, f64::MIN), |(lo, hi), &p| {
        (lo.min(proj(p)), hi.max(proj(p)))
    });
    let eps = 1e-9 * lx.max(ly);
    let mut pieces = Vec::new();
    let first = ((lo - offset) / f.spacing).ceil() as i64;
    let last = ((hi - offset) / f.spacing).floor() as i64;
    for i in first..=last {
        let level = offset + i as f64 * f.spacing;
        if corners.iter().any(|&p| (proj(p) - level).abs() < eps) {
            return Err(invalid(format!(
                "geotextile: families[{k}]: a fiber passes through a cell corner; change its offset"
            )));
        }
        // Clip the line p = level n + t d to the box (Liang–Barsky).
        let p0 = [level * n[0], level * n[1]];
        let (mut t0, mut t1) = (f64::MIN, f64::MAX);
        for axis in 0..2 {
            let len = size[axis];
            if d[axis].abs() < 1e-14 {
                if p0[axis] < eps || p0[axis] > len - eps {
                    // On or outside a face parallel to the line.
                    if p0[axis] > -eps && p0[axis] < len + eps {
                        return Err(invalid(format!(
                            "geotextile: families[{k}]: a fiber lies on a cell face; change its offset"
                        )));
                    }
                    t1 = f64::MIN;
                }
                continue;
            }
            let (ta, tb) = ((0.0 - p0[axis]) / d[axis], (len - p0[axis]) / d[axis]);
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
        }
        if t1 - t0 > eps {
            let at = |t: f64| [p0[0] + t * d[0], p0[1] + t * d[1]];
            pieces.push(Piece {
                a: at(t0),
                b: at(t1),
                family: k,
                stations: vec![0.0, 1.0],
            });
        }
    }
    Ok(pieces)
}

/// Parameters (t, u) where pieces p and q cross, if they do (ends included).
fn crossing(p: &Piece, q: &Piece) -> Option<(f64, f64)> {
    let r = [p.b[0] - p.a[0], p.b[1] - p.a[1]];
    let s = [q.b[0] - q.a[0], q.b[1] - q.a[1]];
    let den = r[0] * s[1] - r[1] * s[0];
    if den.abs() < 1e-12 * (r[0].hypot(r[1]) * s[0].hypot(s[1])) {
        return None; // parallel
    }
    let w = [q.a[0] - p.a[0], q.a[1] - p.a[1]];
    let t = (w[0] * s[1] - w[1] * s[0]) / den;
    let u = (w[0] * r[1] - w[1] * r[0]) / den;
    let tol = 1e-12;
    (t > -tol && t < 1.0 + tol && u > -tol && u < 1.0 + tol)
        .then(|| (t.clamp(0.0, 1.0), u.clamp(0.0, 1.0)))
}

/// Node ids keyed by position (rounded to 10⁻⁹ of the cell): a point shared by pieces gets one
/// node.
struct NodeTable {
    ids: HashMap<(i64, i64, usize), u64>,
    quantum: f64,
}

impl NodeTable {
    fn node(&mut self, d: &mut ModelDescription, p: [f64; 2], layer: usize, z: f64) -> u64 {
        let key = (
            (p[0] / self.quantum).round() as i64,
            (p[1] / self.quantum).round() as i64,
            layer,
        );
        *self.ids.entry(key).or_insert_with(|| {
            let id = d.nodes.len() as u64 + 1;
            d.nodes.push(NodeSpec {
                id,
                x: [p[0], p[1], z],
            });
            id
        })
    }
}

/// The geotextile cell described by `g`.
pub fn geotextile(g: &Geotextile) -> Result<ModelDescription, Error> {
    g.validate()?;
    let [lx, ly] = g.size;
    let z = g.layer_heights();
    let mut pieces = Vec::new();
    for (k, f) in g.families.iter().enumerate() {
        pieces.extend(clip_family(k, f, g.size)?);
    }
    let layer = |p: &Piece| g.families[p.family].layer;
    // Crossings: same layer → shared node; adjacent layers → a node on each (and a connector).
    let mut links = Vec::new();
    for i in 0..pieces.len() {
        for j in i + 1..pieces.len() {
            let (li, lj) = (layer(&pieces[i]), layer(&pieces[j]));
            if li.abs_diff(lj) > 1 || pieces[i].family == pieces[j].family {
                continue;
            }
            if let Some((t, u)) = crossing(&pieces[i], &pieces[j]) {
                pieces[i].stations.push(t);
                pieces[j].stations.push(u);
                if li != lj {
                    links.push((i, t, j, u));
                }
            }
        }
    }
    let mut d = ModelDescription {
        name: Some("geotextile".into()),
        materials: vec![MaterialSpec {
            name: "fiber".into(),
            young: g.young,
            poisson: Some(g.poisson),
            shear: None,
        }],
        cell: Some(CellSpec {
            size: g.size,
            origin: Some([0.0, 0.0]),
            thickness: None,
            tolerance: None,
        }),
        ..Default::default()
    };
    let mut table = NodeTable {
        ids: HashMap::new(),
        quantum: 1e-9 * lx.max(ly),
    };
    let at = |p: &Piece, t: f64| {
        [
            p.a[0] + t * (p.b[0] - p.a[0]),
            p.a[1] + t * (p.b[1] - p.a[1]),
        ]
    };
    for (k, p) in pieces.iter_mut().enumerate() {
        p.stations.sort_by(f64::total_cmp);
        let len = (p.b[0] - p.a[0]).hypot(p.b[1] - p.a[1]);
        let q = table.quantum / len;
        p.stations.dedup_by(|a, b| (*a - *b).abs() < q);
        let (l, r) = (g.families[p.family].layer, g.families[p.family].radius);
        let mut nodes = Vec::new();
        for w in p.stations.windows(2) {
            let n = ((w[1] - w[0]) * len / g.element_length).ceil().max(1.0) as usize;
            for e in 0..n {
                let t = w[0] + (w[1] - w[0]) * e as f64 / n as f64;
                nodes.push(table.node(&mut d, at(p, t), l, z[l]));
            }
        }
        nodes.push(table.node(&mut d, p.b, l, z[l]));
        d.fibers.push(FiberSpec {
            id: k as u64 + 1,
            nodes,
            radius: r,
            material: "fiber".into(),
        });
    }
    match g.layer_junction {
        LayerJunction::Fixed => {
            for (i, t, j, u) in links {
                let (pi, pj) = (&pieces[i], &pieces[j]);
                let a = table.node(&mut d, at(pi, t), layer(pi), z[layer(pi)]);
                let b = table.node(&mut d, at(pj, u), layer(pj), z[layer(pj)]);
                let radius = g.families[pi.family]
                    .radius
                    .min(g.families[pj.family].radius);
                d.fibers.push(FiberSpec {
                    id: d.fibers.len() as u64 + 1,
                    nodes: vec![a, b],
                    radius,
                    material: "fiber".into(),
                });
            }
        }
        LayerJunction::Contact { mu } => {
            let rmin = g.families.iter().map(|f| f.radius).fold(f64::MAX, f64::min);
            d.contact = Some(ContactSpec {
                search: true,
                tolerance: Some(0.1 * rmin),
                friction: FrictionSpec::Coulomb { mu, cohesion: 0.0 },
                initial_penetration: Some(PenetrationSpec::Adjust),
                ..Default::default()
            });
        }
    }
    Ok(d)
}
