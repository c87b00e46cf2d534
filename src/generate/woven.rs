//! Woven cells like thesis §5.3.4: plain and twill weaves of undulating warps (along x) and wefts
//! (along y) whose crossovers touch with zero initial gap.
//!
//! One repeat of R warps and R wefts (R = 2 for plain, over + under for a twill) spans the cell;
//! warp j passes over weft i where (i − j) mod R < `over` (plain: over 1, under 1). At a
//! crossover the upper yarn's axis is at +a and the lower's at −a (a = r, so the surfaces touch,
//! and both tangents are horizontal: the contact normal is z). Between neighbouring crossovers
//! at heights h₀, h₁ a yarn follows z = h₀ + (h₁ − h₀)(1 − cos πt)/2 — for a plain weave exactly
//! the sinusoid ± a sin(2πx/L_x); along a float (h₀ = h₁) it stays level.

use super::check::{invalid, material, positive};
use crate::model::{
    CellSpec, ContactSpec, FiberSpec, FrictionSpec, MaterialSpec, ModelDescription, NodeSpec,
};
use crate::Error;
use serde::{Deserialize, Serialize};

/// The interlacing pattern.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum WeavePattern {
    /// Over one, under one.
    Plain,
    /// Each warp floats over `over` wefts and under `under`, the pattern stepping by one weft
    /// from warp to warp (2/1 twill: over 2, under 1; 2/2 twill: over 2, under 2).
    Twill {
        /// Wefts floated over.
        over: usize,
        /// Wefts passed under.
        under: usize,
    },
}

impl WeavePattern {
    /// (over, under).
    fn floats(self) -> (usize, usize) {
        match self {
            WeavePattern::Plain => (1, 1),
            WeavePattern::Twill { over, under } => (over, under),
        }
    }

    /// Yarns of each family in one repeat.
    pub fn repeat(self) -> usize {
        let (o, u) = self.floats();
        o + u
    }

    /// Whether warp j passes over weft i.
    pub fn warp_over(self, warp: usize, weft: usize) -> bool {
        let r = self.repeat();
        (weft + r - warp % r) % r < self.floats().0
    }
}

/// Parameters of a woven cell.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Weave {
    /// Interlacing pattern.
    pub pattern: WeavePattern,
    /// Cell size (L_x, L_y) (m): one repeat of the pattern.
    #[serde(deserialize_with = "crate::model::fixed_array::exactly")]
    pub size: [f64; 2],
    /// Yarn radius r (m); the undulation amplitude is r, so crossing yarns touch.
    pub radius: f64,
    /// Elements per half distance between crossovers.
    pub half_pitch_elements: usize,
    /// Young's modulus (Pa).
    pub young: f64,
    /// Poisson's ratio.
    pub poisson: f64,
    /// Coulomb friction coefficient at the crossovers.
    pub mu: f64,
    /// Normal penalty (N/m), or the automatic default.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub penalty_normal: Option<f64>,
}

impl Default for Weave {
    /// The thesis's woven material (E = 10⁶ Pa, ν = 0.3, μ = 0.3): a plain weave on a
    /// 4 mm × 4 mm cell of 0.2 mm yarns, 48 elements.
    fn default() -> Self {
        Weave {
            pattern: WeavePattern::Plain,
            size: [4e-3, 4e-3],
            radius: 2e-4,
            half_pitch_elements: 3,
            young: 1e6,
            poisson: 0.3,
            mu: 0.3,
            penalty_normal: None,
        }
    }
}

impl Weave {
    /// Checks every parameter, naming the bad one.
    pub fn validate(&self) -> Result<(), Error> {
        let positive = |name: &str, v: f64| positive("woven", name, v);
        for (name, v) in [
            ("size[0]", self.size[0]),
            ("size[1]", self.size[1]),
            ("radius", self.radius),
            ("young", self.young),
        ] {
            positive(name, v)?;
        }
        if let Some(p) = self.penalty_normal {
            positive("penalty_normal", p)?;
        }
        material("woven", self.poisson, self.mu)?;
        if !(1..=10_000).contains(&self.half_pitch_elements) {
            return Err(invalid(format!(
                "woven: half_pitch_elements = {} must be in [1, 10000]",
                self.half_pitch_elements
            )));
        }
        let (o, u) = self.pattern.floats();
        // Each bound first: o + u of huge floats would wrap around.
        if o == 0 || u == 0 || o > 64 || u > 64 || o + u > 64 {
            return Err(invalid(format!(
                "woven: pattern over {o}, under {u}: both must be ≥ 1 (and the repeat ≤ 64)"
            )));
        }
        let r = self.pattern.repeat() as f64;
        for (k, l) in self.size.into_iter().enumerate() {
            if 2.0 * self.radius >= l / r {
                return Err(invalid(format!(
                    "woven: yarn diameter {} is not below the yarn spacing size[{k}]/{r} = {}",
                    2.0 * self.radius,
                    l / r
                )));
            }
        }
        Ok(())
    }
}

/// The woven cell: warp j at y = (j + ½) L_y/R, weft i at x = (i + ½) L_x/R; yarn heights
/// a = r (1 − 10⁻⁹) at the crossovers, so every crossover is closed (the hair of overlap is
/// adjusted to a zero gap).
pub fn weave(p: &Weave) -> Result<ModelDescription, Error> {
    p.validate()?;
    let [lx, ly] = p.size;
    let r = p.pattern.repeat();
    let a = p.radius * (1.0 - 1e-9);
    let per_pitch = 2 * p.half_pitch_elements;
    let mut d = ModelDescription {
        name: Some(match p.pattern {
            WeavePattern::Plain => "plain weave".into(),
            WeavePattern::Twill { over, under } => format!("{over}/{under} twill"),
        }),
        materials: vec![MaterialSpec {
            name: "yarn".into(),
            young: p.young,
            poisson: Some(p.poisson),
            shear: None,
        }],
        cell: Some(CellSpec {
            size: p.size,
            origin: Some([0.0, 0.0]),
            thickness: Some(4.0 * p.radius),
            tolerance: None,
        }),
        contact: Some(ContactSpec {
            search: true,
            penalty_normal: p.penalty_normal,
            friction: FrictionSpec::Coulomb {
                mu: p.mu,
                cohesion: 0.0,
            },
            ..Default::default()
        }),
        ..Default::default()
    };
    // heights[k]: the yarn's height at its k-th crossover (at (k + ½) pitch).
    let yarn = |d: &mut ModelDescription, heights: &[f64], place: &dyn Fn(f64, f64) -> [f64; 3]| {
        let stations = r * per_pitch;
        let ids: Vec<u64> = (0..=stations)
            .map(|k| {
                // Position in pitches from the face; crossovers at ½, 3/2, …
                let s = k as f64 / per_pitch as f64;
                let before = (s - 0.5).floor();
                let t = s - 0.5 - before;
                let h0 = heights[(before as i64).rem_euclid(r as i64) as usize];
                let h1 = heights[((before as i64) + 1).rem_euclid(r as i64) as usize];
                // cos πt written as sin π(½ − t): exactly 0 midway between crossovers.
                let cos = (std::f64::consts::PI * (0.5 - t)).sin();
                let z = 0.5 * (h0 + h1) - 0.5 * (h1 - h0) * cos;
                push(d, place(s / r as f64, z))
            })
            .collect();
        let id = d.fibers.len() as u64 + 1;
        d.fibers.push(FiberSpec {
            id,
            nodes: ids,
            radius: p.radius,
            material: "yarn".into(),
        });
    };
    for j in 0..r {
        let y = (j as f64 + 0.5) * ly / r as f64;
        let heights: Vec<f64> = (0..r)
            .map(|i| if p.pattern.warp_over(j, i) { a } else { -a })
            .collect();
        yarn(&mut d, &heights, &|f, z| [f * lx, y, z]);
    }
    for i in 0..r {
        let x = (i as f64 + 0.5) * lx / r as f64;
        let heights: Vec<f64> = (0..r)
            .map(|j| if p.pattern.warp_over(j, i) { -a } else { a })
            .collect();
        yarn(&mut d, &heights, &|f, z| [x, f * ly, z]);
    }
    Ok(d)
}

fn push(d: &mut ModelDescription, x: [f64; 3]) -> u64 {
    let id = d.nodes.len() as u64 + 1;
    d.nodes.push(NodeSpec { id, x });
    id
}
