//! A plain-weave periodic cell like thesis §5.3.4: two warps along x and two wefts along y,
//! sinusoidal undulation, the four crossovers touching with zero initial gap (nodes sit at the
//! crossovers, where the yarns are at their extreme heights and the contact normal is z).

use crate::model::{
    CellSpec, ContactSpec, FiberSpec, FrictionSpec, MaterialSpec, ModelDescription, NodeSpec,
};

/// Parameters of a plain-weave cell.
#[derive(Clone, Debug, PartialEq)]
pub struct PlainWeave {
    /// Cell size (L_x, L_y) (m): two yarns of each family per cell.
    pub size: [f64; 2],
    /// Yarn radius r (m); the undulation amplitude is r, so crossing yarns touch.
    pub radius: f64,
    /// Elements per quarter wavelength.
    pub quarter_elements: usize,
    /// Young's modulus (Pa) and Poisson's ratio of the yarns.
    pub young: f64,
    /// Poisson's ratio.
    pub poisson: f64,
    /// Coulomb friction coefficient at the crossovers.
    pub mu: f64,
    /// Normal penalty (N/m), or the automatic default.
    pub penalty_normal: Option<f64>,
}

impl Default for PlainWeave {
    /// The thesis's woven material (E = 10⁶ Pa, ν = 0.3, μ = 0.3) on a 4 mm × 4 mm cell of
    /// 0.2 mm yarns, 48 elements.
    fn default() -> Self {
        PlainWeave {
            size: [4e-3, 4e-3],
            radius: 2e-4,
            quarter_elements: 3,
            young: 1e6,
            poisson: 0.3,
            mu: 0.3,
            penalty_normal: None,
        }
    }
}

/// The cell: warp j at y = (j + ½) L_y/2 with z = ± a sin(2πx/L_x), weft i at x = (i + ½) L_x/2
/// with z = ∓ a sin(2πy/L_y) (alternating over and under), a = r (1 − 10⁻⁹) so every crossover
/// is closed (the hair of overlap is adjusted to a zero gap).
pub fn plain_weave(p: &PlainWeave) -> ModelDescription {
    let [lx, ly] = p.size;
    let a = p.radius * (1.0 - 1e-9);
    let q = p.quarter_elements.max(1);
    let stations = 4 * q;
    let mut d = ModelDescription {
        name: Some("plain weave".into()),
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
            friction: FrictionSpec::Coulomb { mu: p.mu },
            ..Default::default()
        }),
        ..Default::default()
    };
    let mut yarns: Vec<Vec<u64>> = Vec::new();
    let two_pi = 2.0 * std::f64::consts::PI;
    for j in 0..2 {
        let y = (j as f64 + 0.5) * ly / 2.0;
        let sign = if j == 0 { 1.0 } else { -1.0 };
        let ids = (0..=stations)
            .map(|k| {
                let x = k as f64 * lx / stations as f64;
                push(&mut d, [x, y, sign * a * (two_pi * x / lx).sin()])
            })
            .collect();
        yarns.push(ids);
    }
    for i in 0..2 {
        let x = (i as f64 + 0.5) * lx / 2.0;
        let sign = if i == 0 { -1.0 } else { 1.0 };
        let ids = (0..=stations)
            .map(|k| {
                let y = k as f64 * ly / stations as f64;
                push(&mut d, [x, y, sign * a * (two_pi * y / ly).sin()])
            })
            .collect();
        yarns.push(ids);
    }
    d.fibers = yarns
        .into_iter()
        .enumerate()
        .map(|(k, nodes)| FiberSpec {
            id: k as u64 + 1,
            nodes,
            radius: p.radius,
            material: "yarn".into(),
        })
        .collect();
    d
}

fn push(d: &mut ModelDescription, x: [f64; 3]) -> u64 {
    let id = d.nodes.len() as u64 + 1;
    d.nodes.push(NodeSpec { id, x });
    id
}
