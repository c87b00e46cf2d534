//! A clamped square grid of straight fibers rigidly joined at their crossings — the structure
//! of a geotextile without its periodic cell; used by tests, benches and the example fixture.

use crate::model::{
    DofSet, FiberSpec, LoadSpec, MaterialSpec, ModelDescription, NodeSpec, SupportSpec,
};

/// Steel: E = 210 GPa, ν = 0.3.
fn steel() -> MaterialSpec {
    MaterialSpec {
        name: "steel".into(),
        young: 2.1e11,
        poisson: Some(0.3),
        shear: None,
    }
}

/// `k`×`k` straight steel fibers (k along x, k along y, `spacing` apart) joined at their crossings,
/// each edge split in `sub` elements, clamped along the x = 0 edge, loaded at the far corner.
pub fn clamped_grid(k: usize, sub: usize, spacing: f64, radius: f64) -> ModelDescription {
    let m = (k - 1) * sub + 1; // nodes per fiber
    let id = |i: usize, j: usize| (i * m + j) as u64 + 1; // grid point (i along x, j along y)
    let h = spacing / sub as f64;
    let mut nodes = Vec::new();
    for i in 0..m {
        for j in 0..m {
            // Only points on a fiber: i or j at a crossing line.
            if i % sub == 0 || j % sub == 0 {
                nodes.push(NodeSpec {
                    id: id(i, j),
                    x: [
                        i as f64 * h,
                        j as f64 * h,
                        0.01 * ((i * 7 + j * 3) % 5) as f64 * h,
                    ],
                });
            }
        }
    }
    let mut fibers = Vec::new();
    for f in 0..k {
        fibers.push(FiberSpec {
            id: f as u64 + 1,
            nodes: (0..m).map(|j| id(f * sub, j)).collect(),
            radius,
            material: "steel".into(),
        });
        fibers.push(FiberSpec {
            id: (k + f) as u64 + 1,
            nodes: (0..m).map(|i| id(i, f * sub)).collect(),
            radius,
            material: "steel".into(),
        });
    }
    let supports = (0..m)
        .map(|j| SupportSpec {
            node: id(0, j),
            dofs: vec![DofSet::All],
            value: 0.0,
        })
        .collect();
    ModelDescription {
        name: Some("grid".into()),
        materials: vec![steel()],
        nodes,
        fibers,
        supports,
        loads: vec![LoadSpec {
            node: id(m - 1, m - 1),
            force: [10.0, -20.0, 5.0],
            moment: [0.1, 0.2, -0.3],
        }],
        ..Default::default()
    }
}

/// Two layers of straight steel fibers that touch at their crossings: `k` fibers along x at
/// z = 0 and `k` along y at z = 2r, `spacing` apart, `sub` elements between crossings, every
/// fiber clamped at both ends, the upper layer pressed down by 1 mN per node, Coulomb friction
/// μ = 0.3 with automatic penalties. Contacts are found by the search (k² crossings).
pub fn crossing_grid(k: usize, sub: usize, spacing: f64, radius: f64) -> ModelDescription {
    use crate::model::{ContactSpec, FrictionSpec};
    let m = (k - 1) * sub + 1;
    let h = spacing / sub as f64;
    let mut nodes = Vec::new();
    let mut fibers = Vec::new();
    let mut supports = Vec::new();
    let mut loads = Vec::new();
    let mut id = 0u64;
    for layer in 0..2 {
        for f in 0..k {
            let mut ids = Vec::with_capacity(m);
            for j in 0..m {
                id += 1;
                let (a, b) = (f as f64 * spacing, j as f64 * h);
                let x = if layer == 0 {
                    [b, a, 0.0]
                } else {
                    [a, b, 2.0 * radius]
                };
                nodes.push(NodeSpec { id, x });
                ids.push(id);
                if layer == 1 && j > 0 && j + 1 < m {
                    loads.push(LoadSpec {
                        node: id,
                        force: [0.0, 0.0, -1e-3],
                        moment: [0.0; 3],
                    });
                }
            }
            for end in [ids[0], ids[m - 1]] {
                supports.push(SupportSpec {
                    node: end,
                    dofs: vec![DofSet::All],
                    value: 0.0,
                });
            }
            fibers.push(FiberSpec {
                id: (layer * k + f) as u64 + 1,
                nodes: ids,
                radius,
                material: "steel".into(),
            });
        }
    }
    ModelDescription {
        name: Some("crossing-grid".into()),
        materials: vec![steel()],
        nodes,
        fibers,
        supports,
        loads,
        contact: Some(ContactSpec {
            search: true,
            tolerance: Some(0.1 * radius),
            friction: FrictionSpec::Coulomb {
                mu: 0.3,
                cohesion: 0.0,
            },
            ..Default::default()
        }),
        contacts: Vec::new(),
        cell: None,
    }
}
