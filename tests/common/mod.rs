//! Helpers shared by the integration tests: small model builders.
#![allow(dead_code)]

pub mod grid_abd;
pub mod zigzag;

use fibercell::model::{
    DofSet, FiberSpec, LoadSpec, MaterialSpec, ModelDescription, NodeSpec, SupportSpec,
};
use fibercell::Model;

pub const E: f64 = 2.1e11;
pub const NU: f64 = 0.3;

pub fn steel() -> MaterialSpec {
    MaterialSpec {
        name: "steel".into(),
        young: E,
        poisson: Some(NU),
        shear: None,
    }
}

/// A straight fiber from `a` to `b` in `n` elements, clamped at `a`, with a tip force and
/// moment at `b`. Node ids 1..=n+1 from a to b.
pub fn cantilever(
    a: [f64; 3],
    b: [f64; 3],
    n: usize,
    radius: f64,
    force: [f64; 3],
    moment: [f64; 3],
) -> ModelDescription {
    let nodes: Vec<NodeSpec> = (0..=n)
        .map(|k| {
            let t = k as f64 / n as f64;
            NodeSpec {
                id: k as u64 + 1,
                x: [
                    a[0] + t * (b[0] - a[0]),
                    a[1] + t * (b[1] - a[1]),
                    a[2] + t * (b[2] - a[2]),
                ],
            }
        })
        .collect();
    ModelDescription {
        name: Some("cantilever".into()),
        materials: vec![steel()],
        fibers: vec![FiberSpec {
            id: 1,
            nodes: nodes.iter().map(|n| n.id).collect(),
            radius,
            material: "steel".into(),
        }],
        nodes,
        supports: vec![SupportSpec {
            node: 1,
            dofs: vec![DofSet::All],
            value: 0.0,
        }],
        loads: vec![LoadSpec {
            node: n as u64 + 1,
            force,
            moment,
        }],
        ..Default::default()
    }
}

#[allow(unused_imports)]
pub use fibercell::generate::clamped_grid as grid;

pub fn build(d: &ModelDescription) -> Model {
    Model::from_description(d).expect("valid test model")
}

/// Relative difference |a − b| / max(|b|, floor).
pub fn rel(a: f64, b: f64, floor: f64) -> f64 {
    (a - b).abs() / b.abs().max(floor)
}

/// Thesis (4.25), (4.26) with H₂ corrected, second derivatives, written out independently of
/// the library.
fn d2_hermite(s: f64, l: f64) -> [f64; 4] {
    [
        (-6.0 * l + 12.0 * s) / l.powi(3),
        (-4.0 * l + 6.0 * s) / (l * l),
        (6.0 * l - 12.0 * s) / l.powi(3),
        (-2.0 * l + 6.0 * s) / (l * l),
    ]
}

/// k = ∫ Bᵀ D B ds (4.34) by 3-point Gauss–Legendre quadrature (exact for these quadratic
/// integrands), local DOF order u v w θx θy θz per node, θz = v′, θy = −w′.
pub fn quadrature_local_stiffness(
    ea: f64,
    ei2: f64,
    ei3: f64,
    gj: f64,
    l: f64,
) -> nalgebra::DMatrix<f64> {
    use nalgebra::{DMatrix, DVector};
    let gauss = [
        (-(0.6f64).sqrt(), 5.0 / 9.0),
        (0.0, 8.0 / 9.0),
        ((0.6f64).sqrt(), 5.0 / 9.0),
    ];
    let d = DMatrix::from_diagonal(&DVector::from_vec(vec![ea, ei3, ei2, gj]));
    let mut k = DMatrix::<f64>::zeros(12, 12);
    for (xi, w) in gauss {
        let s = 0.5 * l * (xi + 1.0);
        let mut b = DMatrix::<f64>::zeros(4, 12);
        b[(0, 0)] = -1.0 / l;
        b[(0, 6)] = 1.0 / l;
        b[(3, 3)] = -1.0 / l;
        b[(3, 9)] = 1.0 / l;
        let h = d2_hermite(s, l);
        for (dof, hk) in [(1, h[0]), (5, h[1]), (7, h[2]), (11, h[3])] {
            b[(1, dof)] = hk;
        }
        for (dof, hk) in [(2, h[0]), (4, -h[1]), (8, h[2]), (10, -h[3])] {
            b[(2, dof)] = hk;
        }
        k += b.transpose() * &d * b * (0.5 * l * w);
    }
    k
}

/// A periodic cell of a rectangular grid with fixed junctions: `periods` = (nx, ny) periods of
/// (L_x, L_y), joints at (jx + i L_x, jy + j L_y), `sub` elements per segment between a joint and
/// a cell face; x-fibers first (ids 1…ny), then y-fibers.
pub struct GridCell {
    pub young: f64,
    pub poisson: f64,
    pub radius: f64,
    pub size: [f64; 2],
    pub joint: [f64; 2],
    pub periods: [usize; 2],
    pub sub: usize,
}

impl GridCell {
    pub fn build(&self) -> ModelDescription {
        use fibercell::model::CellSpec;
        let [lx, ly] = self.size;
        let [jx, jy] = self.joint;
        let [nx, ny] = self.periods;
        let sub = self.sub;
        let mut d = ModelDescription {
            materials: vec![MaterialSpec {
                name: "m".into(),
                young: self.young,
                poisson: Some(self.poisson),
                shear: None,
            }],
            cell: Some(CellSpec {
                size: [nx as f64 * lx, ny as f64 * ly],
                origin: Some([0.0, 0.0]),
                thickness: Some(2.0 * self.radius),
                tolerance: None,
            }),
            ..Default::default()
        };
        let mut ids = std::collections::HashMap::new();
        let mut node = |d: &mut ModelDescription, x: f64, y: f64| -> u64 {
            let key = ((x * 1e9).round() as i64, (y * 1e9).round() as i64);
            if let Some(&id) = ids.get(&key) {
                return id;
            }
            let id = d.nodes.len() as u64 + 1;
            d.nodes.push(NodeSpec { id, x: [x, y, 0.0] });
            ids.insert(key, id);
            id
        };
        let stations = |len: f64, joint: f64, n: usize| {
            let mut s = vec![0.0];
            for k in 0..n {
                s.push(k as f64 * len + joint);
            }
            s.push(n as f64 * len);
            let mut out = Vec::new();
            for w in s.windows(2) {
                for q in 0..sub {
                    out.push(w[0] + (w[1] - w[0]) * q as f64 / sub as f64);
                }
            }
            out.push(n as f64 * len);
            out
        };
        let mut fid = 0;
        for j in 0..ny {
            let y = jy + j as f64 * ly;
            let nodes: Vec<u64> = stations(lx, jx, nx)
                .into_iter()
                .map(|x| node(&mut d, x, y))
                .collect();
            fid += 1;
            d.fibers.push(FiberSpec {
                id: fid,
                nodes,
                radius: self.radius,
                material: "m".into(),
            });
        }
        for i in 0..nx {
            let x = jx + i as f64 * lx;
            let nodes: Vec<u64> = stations(ly, jy, ny)
                .into_iter()
                .map(|y| node(&mut d, x, y))
                .collect();
            fid += 1;
            d.fibers.push(FiberSpec {
                id: fid,
                nodes,
                radius: self.radius,
                material: "m".into(),
            });
        }
        d
    }
}

/// A small periodic non-woven cell: 50 fibers of 1.2 mm in 3 mm × 3 mm, elements ≤ 0.25 mm,
/// seed 7, with the generator's polypropylene defaults.
pub fn small_nonwoven() -> ModelDescription {
    use fibercell::generate::{nonwoven, FiberAmount, LengthDistribution, NonWoven};
    nonwoven(&NonWoven {
        size: [3e-3, 3e-3],
        amount: FiberAmount::Count { fibers: 50 },
        length: LengthDistribution::Fixed { length: 1.2e-3 },
        element_length: 2.5e-4,
        seed: 7,
        ..NonWoven::default()
    })
    .unwrap()
    .description
}
