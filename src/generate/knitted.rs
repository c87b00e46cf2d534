//! Plain (single) jersey weft-knitted cells: `courses` rows of `wales` interlocked loops.
//!
//! One course is a yarn running along x; loop i of it follows, for t ∈ [0, 2π],
//! x = w (i + t/2π) + A sin 2t, y = −(H/2) cos t, z = Z cos 2t + Y cos t:
//! the sinker loop at t = 0 (bottom, z = Z + Y), the legs, the needle-loop head at t = π (top,
//! z = Z − Y). A > w/4π makes the legs lean outwards, so the head is wider than the neck. The
//! course above is the same yarn shifted by the course spacing c < H: the legs of its loops
//! pass behind the head of the loop below and its sinker loops in front of that loop's legs —
//! four crossings per loop, the interlock of a jersey. Z and Y are solved (Newton) so that at
//! both kinds of crossing the discretized yarns touch: every crossing is a closed contact with
//! zero gap (a relative overlap of 10⁻⁶ that the contact's `adjust` treatment makes stress free).
//! The yarns are cut at the cell faces into paired pieces (the heads of the top course wrap to
//! the bottom).

use super::check::{invalid, material, positive};
use super::wrap::{push_fiber, wrap_polyline};
use crate::contact::closest_points;
use crate::model::{
    CellSpec, ContactSpec, FrictionSpec, MaterialSpec, ModelDescription, PenetrationSpec,
};
use crate::Error;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Parameters of a plain-jersey cell.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Knit {
    /// Loops per course in the cell.
    pub wales: usize,
    /// Courses in the cell.
    pub courses: usize,
    /// Wale spacing w (m): loop-to-loop distance along a course.
    pub wale_spacing: f64,
    /// Course spacing c (m): row-to-row distance, below the loop height.
    pub course_spacing: f64,
    /// Loop height H (m): sinker to head.
    pub loop_height: f64,
    /// Lean A of the legs (m), > w/4π so the head is wider than the neck.
    pub lean: f64,
    /// Yarn radius (m).
    pub radius: f64,
    /// Elements per loop (a multiple of 4 keeps the loop symmetric).
    pub loop_elements: usize,
    /// Young's modulus (Pa).
    pub young: f64,
    /// Poisson's ratio.
    pub poisson: f64,
    /// Coulomb friction coefficient at the crossings.
    pub mu: f64,
}

impl Default for Knit {
    /// Two wales by two courses of a 0.2 mm yarn: w = 1 mm, c = 0.7 mm, H = 1 mm, A = 0.2 mm,
    /// 32 elements per loop, E = 1 GPa, ν = 0.35, μ = 0.3.
    fn default() -> Self {
        Knit {
            wales: 2,
            courses: 2,
            wale_spacing: 1e-3,
            course_spacing: 7e-4,
            loop_height: 1e-3,
            lean: 2e-4,
            radius: 5e-5,
            loop_elements: 32,
            young: 1e9,
            poisson: 0.35,
            mu: 0.3,
        }
    }
}

impl Knit {
    /// Checks every parameter, naming the bad one.
    pub fn validate(&self) -> Result<(), Error> {
        for (name, v) in [
            ("wale_spacing", self.wale_spacing),
            ("course_spacing", self.course_spacing),
            ("loop_height", self.loop_height),
            ("lean", self.lean),
            ("radius", self.radius),
            ("young", self.young),
        ] {
            positive("knitted", name, v)?;
        }
        material("knitted", self.poisson, self.mu)?;
        let loops = self.wales.checked_mul(self.courses);
        if self.wales == 0 || self.courses == 0 || loops.is_none_or(|n| n > 10_000) {
            return Err(invalid(format!(
                "knitted: wales = {}, courses = {}: both ≥ 1, at most 10,000 loops",
                self.wales, self.courses
            )));
        }
        if self.loop_elements < 8 || self.loop_elements > 1_000 {
            return Err(invalid(format!(
                "knitted: loop_elements = {} must be in [8, 1000]",
                self.loop_elements
            )));
        }
        let w = self.wale_spacing;
        if !(self.lean > w / (4.0 * PI) && self.lean < 0.375 * w - self.radius) {
            return Err(invalid(format!(
                "knitted: lean = {} must be in (w/4π, 3w/8 − r) = ({}, {}): the head must be wider \
                 than the neck and clear of the next loop",
                self.lean,
                w / (4.0 * PI),
                0.375 * w - self.radius
            )));
        }
        if !(self.course_spacing < self.loop_height) {
            return Err(invalid(format!(
                "knitted: course_spacing = {} must be below loop_height = {}: loops of adjacent \
                 courses must overlap to interlock",
                self.course_spacing, self.loop_height
            )));
        }
        if !(2.0 * self.course_spacing > self.loop_height + 2.0 * self.radius) {
            return Err(invalid(format!(
                "knitted: course_spacing = {} must exceed (loop_height + 2r)/2 = {}: a head would \
                 touch the sinker two courses up",
                self.course_spacing,
                0.5 * (self.loop_height + 2.0 * self.radius)
            )));
        }
        Ok(())
    }

    /// The centerline of the yarn of course `k` from loop `first` to loop `last` (exclusive),
    /// y measured from the middle of the course.
    fn yarn(&self, k: i64, first: i64, last: i64, z: [f64; 2]) -> Vec<[f64; 3]> {
        let n = self.loop_elements as i64;
        let (w, h) = (self.wale_spacing, 0.5 * self.loop_height);
        (first * n..=last * n)
            .map(|j| {
                let loop_index = j.div_euclid(n);
                let t = 2.0 * PI * (j.rem_euclid(n)) as f64 / n as f64;
                [
                    w * (loop_index as f64 + t / (2.0 * PI)) + self.lean * (2.0 * t).sin(),
                    self.course_spacing * k as f64 - h * t.cos(),
                    z[0] * (2.0 * t).cos() + z[1] * t.cos(),
                ]
            })
            .collect()
    }

    /// Smallest centerline distance at the crossings where course 1 lies in front of course 0
    /// and where it lies behind, for the heights (Z, Y); and the smallest distance between
    /// course 0 and course 2 or the next loop of course 0 (must stay clear).
    fn crossing_distances(&self, z: [f64; 2]) -> ([f64; 2], f64) {
        let lower = self.yarn(0, 0, 1, z);
        let upper = self.yarn(1, -1, 2, z);
        let mut d = [f64::INFINITY; 2];
        for p in lower.windows(2) {
            for q in upper.windows(2) {
                let c = closest_points(&p[0], &p[1], &q[0], &q[1]);
                if c.distance < 4.0 * self.radius {
                    let zp = p[0][2] + c.s * (p[1][2] - p[0][2]);
                    let zq = q[0][2] + c.t * (q[1][2] - q[0][2]);
                    let k = usize::from(zq > zp);
                    d[k] = d[k].min(c.distance);
                }
            }
        }
        // Heads and upper legs (the middle half of a loop) of neighbouring loops of a course.
        let n = self.loop_elements;
        let middle = |y: &[[f64; 3]]| y[n / 4..=3 * n / 4].to_vec();
        let pairs = [
            (lower.clone(), self.yarn(2, -1, 2, z)),
            (middle(&lower), middle(&self.yarn(0, 1, 2, z))),
        ];
        let mut clear = f64::INFINITY;
        for (a, b) in &pairs {
            for p in a.windows(2) {
                for q in b.windows(2) {
                    clear = clear.min(closest_points(&p[0], &p[1], &q[0], &q[1]).distance);
                }
            }
        }
        (d, clear)
    }

    /// (Z, Y) such that both kinds of crossing touch at distance `target`.
    fn solve_heights(&self, target: f64) -> Result<[f64; 2], Error> {
        let mut z = [target / 1.4, 0.0];
        let residual = |z: [f64; 2]| {
            let (d, _) = self.crossing_distances(z);
            [d[0] - target, d[1] - target]
        };
        for _ in 0..50 {
            let f = residual(z);
            if f.iter().any(|v| !v.is_finite()) {
                break;
            }
            if f.iter().all(|v| v.abs() < 1e-12 * target) {
                return Ok(z);
            }
            let h = 1e-7 * target;
            let fz = residual([z[0] + h, z[1]]);
            let fy = residual([z[0], z[1] + h]);
            let j = [
                [(fz[0] - f[0]) / h, (fy[0] - f[0]) / h],
                [(fz[1] - f[1]) / h, (fy[1] - f[1]) / h],
            ];
            let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
            if !(det.abs() > 1e-12) {
                break;
            }
            z[0] -= (j[1][1] * f[0] - j[0][1] * f[1]) / det;
            z[1] -= (-j[1][0] * f[0] + j[0][0] * f[1]) / det;
        }
        Err(invalid(
            "knitted: no yarn heights make the interlocking loops touch; change the loop shape \
             (lean, loop_height, course_spacing)"
                .into(),
        ))
    }
}

/// The plain-jersey cell described by `k`.
pub fn knitted(k: &Knit) -> Result<ModelDescription, Error> {
    k.validate()?;
    let r = k.radius;
    let target = 2.0 * r * (1.0 - 1e-6);
    let z = k.solve_heights(target)?;
    let (_, clear) = k.crossing_distances(z);
    if clear < 2.0 * r {
        return Err(invalid(format!(
            "knitted: neighbouring loops of one course, or courses two apart, come {clear:e} m \
             apart, closer than the yarn diameter {}; widen wale_spacing or course_spacing",
            2.0 * r
        )));
    }
    let period = [
        k.wales as f64 * k.wale_spacing,
        k.courses as f64 * k.course_spacing,
    ];
    let mut d = ModelDescription {
        name: Some(format!("plain jersey {}×{}", k.wales, k.courses)),
        materials: vec![MaterialSpec {
            name: "yarn".into(),
            young: k.young,
            poisson: Some(k.poisson),
            shear: None,
        }],
        contact: Some(ContactSpec {
            search: true,
            tolerance: Some(0.1 * r),
            friction: FrictionSpec::Coulomb {
                mu: k.mu,
                cohesion: 0.0,
            },
            initial_penetration: Some(PenetrationSpec::Adjust),
            // Interlocked loops: a crossing of two loops cannot separate without the yarns
            // passing through each other, so closed contacts stay closed (a bilateral normal
            // spring) and only stick and slip evolve. Unilateral contacts leave a relaxed knit,
            // whose loops merely touch, no hold in shear: under g12 all of them opened or slid
            // in the first increment.
            bonded: true,
            ..Default::default()
        }),
        cell: Some(CellSpec {
            size: period,
            origin: Some([0.0, 0.0]),
            thickness: None,
            tolerance: None,
        }),
        ..Default::default()
    };
    let element = k.wale_spacing / k.loop_elements as f64;
    for course in 0..k.courses as i64 {
        let mut yarn = k.yarn(course, 0, k.wales as i64, z);
        for p in &mut yarn {
            p[1] += 0.5 * k.course_spacing; // courses at (k + ½) c
        }
        for piece in wrap_polyline(&yarn, period, 0.25 * element) {
            push_fiber(&mut d, &piece, r, "yarn");
        }
    }
    Ok(d)
}
