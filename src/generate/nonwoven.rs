//! Stochastic non-woven cells: fibers of random length, in-plane orientation, tilt and curl,
//! deposited one after the other onto a periodic cell so that each rests on the fibers
//! already there.
//!
//! Deposition of one fiber (a perfectly flexible fiber draped over the mat):
//! 1. its plan-view centerline (a straight line, or a circular arc of the given curl) starts at
//!    a uniform random point; it is split where it crosses the cell faces into pieces that
//!    wrap into the cell, the piece ends exactly on the faces (paired nodes);
//! 2. every deposited segment whose plan view comes within r + r' of it is a support: at the
//!    plan-view closest points (distance d) the new fiber must be at least
//!    z' + √((r + r')² − d²) high — a node is put there (supports closer than `min_spacing`
//!    share one node, which takes the higher of the two);
//! 3. nodes between supports interpolate the support heights linearly (the fiber drapes);
//!    the ends keep the height of the nearest support; a fiber with no support lies on the
//!    floor z = r; with tilt φ the fiber also rises at least at slope tan φ from its start;
//! 4. a final pass computes the exact 3D distance of each new element to each deposited
//!    segment near it and lifts the element where it penetrates by more than the tolerance
//!    (supports then touch with −tol ≤ gap ≤ 0; the model's `adjust` makes them stress free);
//! 5. gaps between the element nodes are filled to the requested element length.
//!
//! Fibers that end up touching nothing would float; they are dropped and counted.

use super::check::{invalid, material, positive};
use super::orientation::{sample_angle, Orientation};
use super::segment_grid::{Deposited, SegmentGrid};
use super::wrap::push_fiber;
use crate::contact::closest_points;
use crate::model::{CellSpec, ContactSpec, FrictionSpec, MaterialSpec, ModelDescription};
use crate::Error;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, LogNormal};
use serde::{Deserialize, Serialize};

/// How many fibers to deposit.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum FiberAmount {
    /// This many fibers.
    Count {
        /// Number of fibers.
        fibers: usize,
    },
    /// Fibers until their volume is `fraction` × L_x L_y × `thickness` (the last one cut to
    /// length); the cell's thickness is set to `thickness`.
    VolumeFraction {
        /// Solid volume fraction (0, 1).
        fraction: f64,
        /// Nominal thickness h (m).
        thickness: f64,
    },
}

/// Fiber lengths.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum LengthDistribution {
    /// Every fiber this long (m).
    Fixed {
        /// Length (m).
        length: f64,
    },
    /// Log-normal with this mean (m) and coefficient of variation, cut at half the smaller
    /// period (a longer fiber could touch its own periodic image).
    LogNormal {
        /// Mean length (m).
        mean: f64,
        /// Standard deviation / mean.
        cv: f64,
    },
}

/// The largest solid volume fraction a non-woven may be asked for.
pub const MAX_VOLUME_FRACTION: f64 = 0.5;

/// The most elements a generated non-woven may have (13 times the L preset's).
pub const MAX_ELEMENTS: usize = 2_000_000;

/// The largest tilt a non-woven's fibers may have (degrees): steeper ones stand up out of the
/// mat (1.5 rad before the parameter was in degrees).
pub const MAX_TILT_DEGREES: f64 = 85.0;

/// Parameters of a non-woven cell.

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NonWoven {
    /// Cell periods (L_x, L_y) (m).
    #[serde(deserialize_with = "crate::model::fixed_array::exactly")]
    pub size: [f64; 2],
    /// How many fibers.
    pub amount: FiberAmount,
    /// Fiber lengths.
    pub length: LengthDistribution,
    /// Fiber radius (m).
    pub radius: f64,
    /// In-plane orientation.
    pub orientation: Orientation,
    /// Largest tilt angle out of the plane in degrees (as every angle of the CLI and the
    /// parameter files): each fiber's φ is uniform in [0, tilt].
    pub tilt_degrees: f64,
    /// In-plane curvature of the fibers (1/m), with a random sign; 0 for straight fibers. At
    /// most π / length, so a fiber turns by at most half a circle.
    pub curl: f64,
    /// Largest element length (m).
    pub element_length: f64,
    /// Penetration tolerance relative to the radius (supports touch with gap ∈ [−tol·r, 0]).
    pub tolerance: f64,
    /// Young's modulus (Pa).
    pub young: f64,
    /// Poisson's ratio.
    pub poisson: f64,
    /// Coulomb friction coefficient.
    pub mu: f64,
    /// Shear strength of the bond at a fiber crossing (Pa; default 1 MPa, a thermally bonded
    /// polypropylene mat). Positive: the contacts are bonded (they never open, see
    /// [`crate::model::ContactSpec::bonded`]) and resist sliding up to the cohesion
    /// c = bond_strength · π r² plus μ N (Mohr–Coulomb). 0: loose fibers that merely touch —
    /// a pile of sticks without tensile stiffness, whose contacts open under the first strain.
    #[serde(default = "default_bond_strength")]
    pub bond_strength: f64,
    /// Seed of the random generator (ChaCha8): same seed, same cell.
    pub seed: u64,
}

impl Default for NonWoven {
    /// A small polypropylene-like mat: 5 mm × 5 mm, 200 fibers of 2 mm, radius 10 µm,
    /// isotropic, E = 1.5 GPa, ν = 0.4, μ = 0.3, elements ≤ 0.1 mm.
    fn default() -> Self {
        NonWoven {
            size: [5e-3, 5e-3],
            amount: FiberAmount::Count { fibers: 200 },
            length: LengthDistribution::Fixed { length: 2e-3 },
            radius: 1e-5,
            orientation: Orientation::Isotropic,
            tilt_degrees: 0.0,
            curl: 0.0,
            element_length: 1e-4,
            tolerance: 1e-3,
            young: 1.5e9,
            poisson: 0.4,
            mu: 0.3,
            bond_strength: default_bond_strength(),
            seed: 1,
        }
    }
}

fn default_bond_strength() -> f64 {
    1e6
}

/// The benchmark cells of the README and `fibercell bench`, all at one areal density (5.6
/// fibers of 2.5 mm per mm², radius 10 µm, isotropic): S (200 fibers, 6 mm cell), M (1,000
/// fibers, 13.4 mm, more than 5,000 contacts), L (5,000 fibers, 30 mm, more than 30,000
/// contacts, about 10⁶ DOFs), XL (20,000 fibers, 60 mm, L's elements: about 4·10⁶ DOFs).
pub fn nonwoven_preset(name: &str, seed: u64) -> Result<NonWoven, Error> {
    let (fibers, side, h) = match name.to_ascii_uppercase().as_str() {
        "S" => (200, 6e-3, 2.5e-4),
        "M" => (1000, 13.4e-3, 2.5e-4),
        "L" => (5000, 30e-3, 1.2e-4),
        "XL" => (20000, 60e-3, 1.2e-4),
        _ => {
            return Err(invalid(format!(
                "unknown cell size \"{name}\" (use S, M, L or XL)"
            )))
        }
    };
    Ok(NonWoven {
        size: [side, side],
        amount: FiberAmount::Count { fibers },
        length: LengthDistribution::Fixed { length: 2.5e-3 },
        element_length: h,
        seed,
        ..NonWoven::default()
    })
}

/// What the deposition did.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct DepositionReport {
    /// Fibers deposited.
    pub deposited: usize,
    /// Fibers dropped because they touched nothing.
    pub dropped: usize,
    /// Fiber pieces written (a fiber is cut where it crosses a face).
    pub pieces: usize,
    /// Supports (crossings) the fibers were draped over.
    pub supports: usize,
    /// Lift passes needed at most by one fiber.
    pub max_lift_passes: usize,
}

/// A generated cell and its report.
#[derive(Clone, Debug)]
pub struct GeneratedCell {
    /// The model.
    pub description: ModelDescription,
    /// What the deposition did.
    pub report: DepositionReport,
}

impl NonWoven {
    /// Checks every parameter, naming the bad one.
    pub fn validate(&self) -> Result<(), Error> {
        let positive = |name: &str, v: f64| positive("non-woven", name, v);
        positive("size[0]", self.size[0])?;
        positive("size[1]", self.size[1])?;
        positive("radius", self.radius)?;
        positive("element_length", self.element_length)?;
        positive("young", self.young)?;
        positive("tolerance", self.tolerance)?;
        material("non-woven", self.poisson, self.mu)?;
        if !(self.bond_strength.is_finite() && self.bond_strength >= 0.0) {
            return Err(invalid(format!(
                "non-woven bond_strength = {} Pa must be finite and ≥ 0 (0: unbonded fibers)",
                self.bond_strength
            )));
        }
        if !(self.tilt_degrees >= 0.0 && self.tilt_degrees <= MAX_TILT_DEGREES) {
            return Err(invalid(format!(
                "non-woven tilt_degrees = {} must be in [0, {MAX_TILT_DEGREES}]",
                self.tilt_degrees
            )));
        }
        let lmax = 0.5 * self.size[0].min(self.size[1]);
        let mean = match self.length {
            LengthDistribution::Fixed { length } => {
                positive("length", length)?;
                length
            }
            LengthDistribution::LogNormal { mean, cv } => {
                positive("length mean", mean)?;
                if !(0.0..=2.0).contains(&cv) {
                    return Err(invalid(format!(
                        "non-woven length cv = {cv} must be in [0, 2]"
                    )));
                }
                mean
            }
        };
        if mean > lmax {
            return Err(invalid(format!(
                "non-woven fiber length {mean} m exceeds half the smaller period ({lmax} m): a fiber could touch its own image"
            )));
        }
        if mean < 4.0 * self.radius {
            return Err(invalid(format!(
                "non-woven fiber length {mean} m is shorter than two diameters"
            )));
        }
        if !(self.curl >= 0.0 && self.curl * mean <= std::f64::consts::PI) {
            return Err(invalid(format!(
                "non-woven curl = {} 1/m must be in [0, π/length]",
                self.curl
            )));
        }
        if self.element_length < 2.0 * self.radius {
            return Err(invalid(format!(
                "non-woven element_length {} m is below a fiber diameter",
                self.element_length
            )));
        }
        let fibers = match self.amount {
            FiberAmount::Count { fibers: 0 } => {
                return Err(invalid("non-woven fiber count 0 must be at least 1".into()))
            }
            FiberAmount::Count { fibers } => fibers as f64,
            FiberAmount::VolumeFraction {
                fraction,
                thickness,
            } => {
                if !(fraction > 0.0 && fraction <= MAX_VOLUME_FRACTION) {
                    return Err(invalid(format!(
                        "non-woven volume fraction {fraction} must be in (0, \
                         {MAX_VOLUME_FRACTION}]: fibers deposited one on another cannot fill \
                         more (at 0.5 in 0.1 mm they already pile up 20 mm high)"
                    )));
                }
                positive("thickness", thickness)?;
                let volume = fraction * self.size[0] * self.size[1] * thickness;
                volume / (std::f64::consts::PI * self.radius.powi(2) * mean)
            }
        };
        // The model's size, before anything is deposited: 10⁷ fibers grew past 5 GB.
        let elements = fibers * (mean / self.element_length).ceil().max(1.0);
        if !(elements <= MAX_ELEMENTS as f64) {
            return Err(invalid(format!(
                "non-woven of {fibers:.0} fibers of about {:.0} elements each: {elements:.2e} \
                 elements, at most {MAX_ELEMENTS} (the L preset has 1.5·10⁵); use fewer or \
                 shorter fibers, a larger element_length or a smaller cell",
                (mean / self.element_length).ceil()
            )));
        }
        self.orientation.parameters().map_err(invalid)?;
        Ok(())
    }
}

/// A point of a fiber's plan-view centerline by arc length.
struct Centerline {
    start: [f64; 2],
    angle: f64,
    curvature: f64,
}

impl Centerline {
    fn at(&self, s: f64) -> [f64; 2] {
        let (c, t) = (self.curvature, self.angle);
        if c.abs() * s < 1e-9 {
            [self.start[0] + s * t.cos(), self.start[1] + s * t.sin()]
        } else {
            [
                self.start[0] + ((t + c * s).sin() - t.sin()) / c,
                self.start[1] + (t.cos() - (t + c * s).cos()) / c,
            ]
        }
    }
}

/// What a station is.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    /// A fiber end.
    End,
    /// A face crossing: axis and period index of the face line.
    Face(usize, i64),
    /// Element-length subdivision.
    Uniform,
    /// A support (crossing with a deposited fiber).
    Support,
}

/// A station along the fiber: arc length, unwrapped plan position, kind.
#[derive(Clone, Copy, Debug)]
struct Station {
    s: f64,
    p: [f64; 2],
    kind: Kind,
    /// Required height (max over its supports), if supported.
    support: Option<f64>,
    z: f64,
}

/// Generates a non-woven cell.
pub fn nonwoven(params: &NonWoven) -> Result<GeneratedCell, Error> {
    params.validate()?;
    let [lx, ly] = params.size;
    let r = params.radius;
    let h = params.element_length;
    let min_spacing = 2.0 * r;
    let tol = params.tolerance * r;
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    let orient = params.orientation.parameters().map_err(invalid)?;
    let lmax = 0.5 * lx.min(ly);
    let lognormal = match params.length {
        LengthDistribution::LogNormal { mean, cv } if cv > 0.0 => {
            let s2 = (1.0 + cv * cv).ln();
            Some(
                LogNormal::new(mean.ln() - 0.5 * s2, s2.sqrt())
                    .map_err(|e| invalid(format!("non-woven length distribution: {e}")))?,
            )
        }
        _ => None,
    };
    let mean_length = match params.length {
        LengthDistribution::Fixed { length } => length,
        LengthDistribution::LogNormal { mean, .. } => mean,
    };
    let (count, volume_target) = match params.amount {
        FiberAmount::Count { fibers } => (fibers, f64::INFINITY),
        FiberAmount::VolumeFraction {
            fraction,
            thickness,
        } => (usize::MAX, fraction * lx * ly * thickness),
    };
    let area = std::f64::consts::PI * r * r;
    let mut grid = SegmentGrid::new([0.0, 0.0], params.size, h.max(4.0 * r));
    let mut pieces: Vec<(usize, Vec<[f64; 3]>)> = Vec::new();
    let mut touched: Vec<bool> = Vec::new();
    let mut report = DepositionReport::default();
    let mut volume = 0.0;
    let mut near = Vec::new();
    let mut fiber = 0usize;
    let mut redraws = 0usize;
    while fiber < count && volume < volume_target * (1.0 - 1e-12) {
        let mut length = match &lognormal {
            Some(d) => d.sample(&mut rng).clamp(4.0 * r, lmax),
            None => mean_length,
        };
        if volume + area * length > volume_target {
            length = (volume_target - volume) / area;
        }
        let start = [rng.random::<f64>() * lx, rng.random::<f64>() * ly];
        let angle = sample_angle(&mut rng, orient);
        let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
        let tilt = params.tilt_degrees.to_radians() * rng.random::<f64>();
        if length < 4.0 * r {
            break; // the remainder of the target volume is less than a short fiber
        }
        let line = Centerline {
            start,
            angle,
            curvature: sign * params.curl.min(std::f64::consts::PI / length),
        };
        let Some(mut stations) = plan_stations(&line, length, params.size, h, min_spacing) else {
            // A corner or an end on a face: redraw.
            redraws += 1;
            if redraws > 1000 {
                return Err(invalid(
                    "non-woven: 1000 fibers in a row passed a cell corner or ended on a face; the cell is too small for the fibers".into(),
                ));
            }
            continue;
        };
        volume += area * length;
        redraws = 0;
        touched.push(false);
        // Supports from the deposited segments.
        let mut supports: Vec<(f64, f64)> = Vec::new();
        for w in stations.windows(2) {
            let (a, b) = (w[0], w[1]);
            let (pa, pb) = wrap_pair(a.p, b.p, params.size);
            near_supports(
                &mut grid,
                [pa, pb],
                (a.s, b.s),
                (r, tol),
                &mut near,
                &mut supports,
            );
        }
        report.supports += supports.len();
        apply_supports(&mut stations, &mut supports, min_spacing);
        drape(&mut stations, r, tilt);
        // Fill long gaps to the element length (heights interpolated).
        let mut stations = refine(&stations, h);
        // Lift where the straight elements still penetrate; the last pass, which lifts
        // nothing, sees the final gaps and names the fibers touched.
        let lifted = lift(&mut stations, &mut grid, params.size, r, tol, &mut near)?;
        report.max_lift_passes = report.max_lift_passes.max(lifted.passes);
        if !lifted.touching.is_empty() {
            touched[fiber] = true;
        }
        for &other in &lifted.touching {
            touched[other] = true;
        }
        // File the new elements.
        for w in stations.windows(2) {
            let (pa, pb) = wrap_pair(w[0].p, w[1].p, params.size);
            grid.insert(Deposited {
                ends: [[pa[0], pa[1], w[0].z], [pb[0], pb[1], w[1].z]],
                radius: r,
                fiber,
            });
        }
        for piece in split_pieces(&stations, params.size) {
            pieces.push((fiber, piece));
        }
        fiber += 1;
    }
    report.deposited = fiber;
    report.dropped = touched.iter().filter(|t| !**t).count();
    let description = describe(params, &pieces, &touched, &mut report)?;
    Ok(GeneratedCell {
        description,
        report,
    })
}

/// The plan-view stations at most `h` apart along the centerline, with every face crossing
/// as a station (exact face coordinate); None when a face crossing comes within `min_spacing`
/// of another or of an end (a corner or a fiber ending on a face: the fiber is redrawn).
fn plan_stations(
    line: &Centerline,
    length: f64,
    period: [f64; 2],
    h: f64,
    min_spacing: f64,
) -> Option<Vec<Station>> {
    let n = ((length / h).ceil() as usize).max(1);
    let station = |s: f64, p: [f64; 2], kind| Station {
        s,
        p,
        kind,
        support: None,
        z: 0.0,
    };
    let mut out = vec![station(0.0, line.at(0.0), Kind::End)];
    let mut prev = line.at(0.0);
    for k in 1..=n {
        let s1 = length * k as f64 / n as f64;
        let s0 = length * (k - 1) as f64 / n as f64;
        let p = line.at(s1);
        let mut hits: Vec<(f64, usize, i64)> = Vec::new();
        for axis in 0..2 {
            let (a, b) = (prev[axis] / period[axis], p[axis] / period[axis]);
            for m in (a.min(b).ceil() as i64)..=(a.max(b).floor() as i64) {
                let t = (m as f64 - a) / (b - a);
                if t > 0.0 && t <= 1.0 {
                    hits.push((t, axis, m));
                }
            }
        }
        hits.sort_by(|x, y| x.0.total_cmp(&y.0));
        for (t, axis, m) in hits {
            let s = s0 + t * (s1 - s0);
            let mut q = [
                prev[0] + t * (p[0] - prev[0]),
                prev[1] + t * (p[1] - prev[1]),
            ];
            q[axis] = m as f64 * period[axis];
            let last_face = out.iter().rev().find(|st| st.kind != Kind::Uniform);
            if last_face.is_some_and(|st| s - st.s < min_spacing) || length - s < min_spacing {
                return None;
            }
            // Uniform stations too close to the face give way to it.
            while out
                .last()
                .is_some_and(|st| st.kind == Kind::Uniform && s - st.s < min_spacing)
            {
                out.pop();
            }
            out.push(station(s, q, Kind::Face(axis, m)));
        }
        let kind = if k == n { Kind::End } else { Kind::Uniform };
        let last = out[out.len() - 1];
        if kind == Kind::End || s1 - last.s >= min_spacing {
            out.push(station(s1, p, kind));
        }
        prev = p;
    }
    Some(out)
}

/// The periodic cell (i, j) that holds the midpoint of the plan segment a–b: a segment between
/// two face crossings lies in one cell, whatever roundoff does at its ends.
fn cell_of(a: [f64; 2], b: [f64; 2], period: [f64; 2]) -> [f64; 2] {
    [0, 1].map(|k| (0.5 * (a[k] + b[k]) / period[k]).floor())
}

/// Plan positions of a segment's ends wrapped into the cell together (by the cell of its
/// midpoint).
fn wrap_pair(a: [f64; 2], b: [f64; 2], period: [f64; 2]) -> ([f64; 2], [f64; 2]) {
    let cell = cell_of(a, b, period);
    let shift = [cell[0] * period[0], cell[1] * period[1]];
    (
        [a[0] - shift[0], a[1] - shift[1]],
        [b[0] - shift[0], b[1] - shift[1]],
    )
}

/// Supports of the plan segment `ends` (arc lengths `s`): (arc length, required height).
fn near_supports(
    grid: &mut SegmentGrid,
    ends: [[f64; 2]; 2],
    s: (f64, f64),
    (r, tol): (f64, f64),
    near: &mut Vec<(usize, [f64; 2])>,
    out: &mut Vec<(f64, f64)>,
) {
    let q = [[ends[0][0], ends[0][1], 0.0], [ends[1][0], ends[1][1], 0.0]];
    grid.near(q, 2.0 * r, near);
    for &(id, shift) in near.iter() {
        let t = grid.segments[id];
        let [a, b] = t.shifted(shift).map(|p| [p[0], p[1], 0.0]);
        let cp = closest_points(&q[0], &q[1], &a, &b);
        let reach = r + t.radius;
        if cp.distance < reach {
            let z = t.ends[0][2] + cp.t * (t.ends[1][2] - t.ends[0][2]);
            // Touching less half the tolerance: closed for certain, gap −tol/2 (roundoff
            // could leave an exact touch open).
            let need = z + (reach * reach - cp.distance * cp.distance).sqrt() - 0.5 * tol;
            out.push((s.0 + cp.s * (s.1 - s.0), need));
        }
    }
}

/// Puts each support on a station: the nearest end, face or support station within
/// `min_spacing`, or a new support station; a station's required height is the highest of
/// its supports. Subdivision stations within `min_spacing` of a support are then removed.
fn apply_supports(stations: &mut Vec<Station>, supports: &mut [(f64, f64)], min_spacing: f64) {
    supports.sort_by(|a, b| a.0.total_cmp(&b.0));
    for &(s, need) in supports.iter() {
        let k = stations.partition_point(|st| st.s < s);
        let nearest = (k.saturating_sub(3)..(k + 3).min(stations.len()))
            .filter(|&i| stations[i].kind != Kind::Uniform)
            .min_by(|&a, &b| {
                (stations[a].s - s)
                    .abs()
                    .total_cmp(&(stations[b].s - s).abs())
            });
        match nearest {
            Some(i) if (stations[i].s - s).abs() < min_spacing => {
                let st = &mut stations[i];
                st.support = Some(st.support.map_or(need, |v| v.max(need)));
            }
            _ => {
                // On the chord between the two stations around it.
                let k = k.clamp(1, stations.len() - 1);
                let (a, b) = (stations[k - 1], stations[k]);
                let t = ((s - a.s) / (b.s - a.s)).clamp(0.0, 1.0);
                stations.insert(
                    k,
                    Station {
                        s,
                        p: [
                            a.p[0] + t * (b.p[0] - a.p[0]),
                            a.p[1] + t * (b.p[1] - a.p[1]),
                        ],
                        kind: Kind::Support,
                        support: Some(need),
                        z: 0.0,
                    },
                );
            }
        }
    }
    let keep: Vec<bool> = (0..stations.len())
        .map(|i| {
            stations[i].kind != Kind::Uniform
                || ![i.checked_sub(1), Some(i + 1)]
                    .into_iter()
                    .flatten()
                    .filter_map(|j| stations.get(j))
                    .any(|o| o.kind == Kind::Support && (o.s - stations[i].s).abs() < min_spacing)
        })
        .collect();
    let mut k = 0;
    stations.retain(|_| {
        k += 1;
        keep[k - 1]
    });
}

/// Heights: supports at their required height (not below the floor z = r), linear in between,
/// constant beyond the outermost supports; then at least the tilt line from the start.
fn drape(stations: &mut [Station], r: f64, tilt: f64) {
    let supported: Vec<usize> = (0..stations.len())
        .filter(|&i| stations[i].support.is_some())
        .collect();
    if supported.is_empty() {
        stations.iter_mut().for_each(|s| s.z = r);
    } else {
        for &i in &supported {
            stations[i].z = stations[i].support.unwrap_or(r).max(r);
        }
        let (first, last) = (supported[0], supported[supported.len() - 1]);
        for i in 0..first {
            stations[i].z = stations[first].z;
        }
        for i in last + 1..stations.len() {
            stations[i].z = stations[last].z;
        }
        for w in supported.windows(2) {
            let (a, b) = (stations[w[0]], stations[w[1]]);
            for st in &mut stations[w[0] + 1..w[1]] {
                let t = (st.s - a.s) / (b.s - a.s);
                st.z = a.z + t * (b.z - a.z);
            }
        }
    }
    if tilt > 0.0 {
        let (z0, slope) = (stations[0].z, tilt.tan());
        for st in stations.iter_mut() {
            st.z = st.z.max(z0 + st.s * slope);
        }
    }
}

/// Inserts stations so that no element is longer than `h` (plan positions on the centerline
/// chord between the two stations, heights interpolated).
fn refine(stations: &[Station], h: f64) -> Vec<Station> {
    let mut out = Vec::with_capacity(stations.len() * 2);
    for w in stations.windows(2) {
        let (a, b) = (w[0], w[1]);
        out.push(a);
        let n = ((b.s - a.s) / h).ceil() as usize;
        for k in 1..n {
            let t = k as f64 / n as f64;
            out.push(Station {
                s: a.s + t * (b.s - a.s),
                p: [
                    a.p[0] + t * (b.p[0] - a.p[0]),
                    a.p[1] + t * (b.p[1] - a.p[1]),
                ],
                kind: Kind::Uniform,
                support: None,
                z: a.z + t * (b.z - a.z),
            });
        }
    }
    if let Some(last) = stations.last() {
        out.push(*last);
    }
    out
}

/// Surface gap between the element `ends` (radius r) and a deposited segment shifted by
/// `shift`, the parameter u of the closest point along the element, and the vertical lift of
/// that point that makes the gap −`tol`/2 with the closest points held: with the horizontal
/// and vertical parts h, v of their distance, √((r + r′ − tol/2)² − h²) − v (exact for
/// side-by-side fibers, where the normal is nearly horizontal).
fn gap_at(
    ends: [[f64; 3]; 2],
    r: f64,
    t: &Deposited,
    shift: [f64; 2],
    tol: f64,
) -> (f64, f64, f64) {
    let [a, b] = t.shifted(shift);
    let cp = closest_points(&ends[0], &ends[1], &a, &b);
    let at = |p: [f64; 3], q: [f64; 3], s: f64| [0, 1, 2].map(|k| p[k] + s * (q[k] - p[k]));
    let (p, q) = (at(ends[0], ends[1], cp.s), at(a, b, cp.t));
    let h = (p[0] - q[0]).hypot(p[1] - q[1]);
    let target = r + t.radius - 0.5 * tol;
    let lift = (target * target - h * h).max(0.0).sqrt() - (p[2] - q[2]);
    (cp.distance - (r + t.radius), cp.s, lift.max(0.0))
}

/// The outcome of [`lift`].
struct Lifted {
    /// Passes over the fiber's elements, the last one lifting nothing.
    passes: usize,
    /// Deposited fibers the new one touches (gap ≤ 0) at its final heights (with repeats).
    touching: Vec<usize>,
}

/// Lifts elements that penetrate deposited segments by more than `tol` until none does.
fn lift(
    stations: &mut [Station],
    grid: &mut SegmentGrid,
    period: [f64; 2],
    r: f64,
    tol: f64,
    near: &mut Vec<(usize, [f64; 2])>,
) -> Result<Lifted, Error> {
    let mut touching = Vec::new();
    for pass in 1..=1000 {
        let mut lifted = false;
        touching.clear();
        for k in 0..stations.len().saturating_sub(1) {
            let (pa, pb) = wrap_pair(stations[k].p, stations[k + 1].p, period);
            let ends = [
                [pa[0], pa[1], stations[k].z],
                [pb[0], pb[1], stations[k + 1].z],
            ];
            grid.near(ends, 2.0 * r, near);
            // The deepest penetration and where along the element it is.
            let mut worst = (0.0f64, 0.5, 0.0);
            for &(id, shift) in near.iter() {
                let t = grid.segments[id];
                let (g, u, lift) = gap_at(ends, r, &t, shift, tol);
                if g < -tol && -g > worst.0 {
                    worst = (-g, u, lift);
                }
                if g <= 0.0 {
                    touching.push(t.fiber);
                }
            }
            if worst.0 > 0.0 {
                // Lift the element's point at u by the lift that aims at gap −tol/2, the two
                // nodes in proportion to their shape functions, so a contact at a node lifts
                // only that node and the neighbouring supports stay in touch. (A lift of the
                // penetration depth alone is far too little for side-by-side fibers.)
                let (_, u, dz) = worst;
                let w = (1.0 - u) * (1.0 - u) + u * u;
                stations[k].z += dz * (1.0 - u) / w;
                stations[k + 1].z += dz * u / w;
                lifted = true;
            }
        }
        if !lifted {
            return Ok(Lifted {
                passes: pass,
                touching,
            });
        }
    }
    Err(invalid(
        "non-woven deposition: a fiber still penetrates the mat after 1000 lift passes".into(),
    ))
}

/// The pieces of a fiber: node positions in cell coordinates, cut at the face stations.
fn split_pieces(stations: &[Station], period: [f64; 2]) -> Vec<Vec<[f64; 3]>> {
    let mut pieces = Vec::new();
    let mut start = 0;
    for k in 1..stations.len() {
        if matches!(stations[k].kind, Kind::Face(..)) || k == stations.len() - 1 {
            let run = &stations[start..=k];
            // The cell image of this run: that of its first element.
            let cell = cell_of(run[0].p, run[1].p, period);
            let piece = run
                .iter()
                .map(|st| {
                    let mut x = [
                        st.p[0] - cell[0] * period[0],
                        st.p[1] - cell[1] * period[1],
                        st.z,
                    ];
                    if let Kind::Face(axis, m) = st.kind {
                        // Exactly on the face: 0 or L.
                        x[axis] = (m as f64 - cell[axis]) * period[axis];
                    }
                    // Roundoff can leave a coordinate a hair outside the box.
                    for i in 0..2 {
                        x[i] = x[i].clamp(0.0, period[i]);
                    }
                    x
                })
                .collect();
            pieces.push(piece);
            start = k;
        }
    }
    pieces
}

/// The model description of the kept fibers' pieces.
fn describe(
    params: &NonWoven,
    pieces: &[(usize, Vec<[f64; 3]>)],
    touched: &[bool],
    report: &mut DepositionReport,
) -> Result<ModelDescription, Error> {
    let r = params.radius;
    let thickness = match params.amount {
        FiberAmount::VolumeFraction { thickness, .. } => Some(thickness),
        FiberAmount::Count { .. } => None,
    };
    let mut d = ModelDescription {
        name: Some(format!("non-woven (seed {})", params.seed)),
        materials: vec![MaterialSpec {
            name: "fiber".into(),
            young: params.young,
            poisson: Some(params.poisson),
            shear: None,
        }],
        contact: Some(ContactSpec {
            search: true,
            tolerance: Some(0.1 * r),
            friction: FrictionSpec::Coulomb {
                mu: params.mu,
                cohesion: params.bond_strength * std::f64::consts::PI * r * r,
            },
            bonded: params.bond_strength > 0.0,
            ..Default::default()
        }),
        cell: Some(CellSpec {
            size: params.size,
            origin: Some([0.0, 0.0]),
            thickness,
            tolerance: None,
        }),
        ..Default::default()
    };
    for (fiber, nodes) in pieces {
        if !touched[*fiber] {
            continue;
        }
        push_fiber(&mut d, nodes, r, "fiber");
    }
    report.pieces = d.fibers.len();
    if d.fibers.is_empty() {
        return Err(invalid(
            "non-woven: no two fibers touch; raise the number or the length of the fibers".into(),
        ));
    }
    Ok(d)
}
