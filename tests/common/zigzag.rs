//! A woven-like cell whose contacts have tilted normals: two zigzag warps (along x, slope ±s)
//! rest on two straight wefts (along y) — below the warps at x₁ = Lx/4, above them at
//! x₂ = 3Lx/4 — touching where the warps are inclined. Nodes sit at the contact points and
//! the kinks; `cell(x0, bound)` cuts the cell at x₀.

use fibercell::model::{
    CellSpec, ContactSpec, FiberSpec, FrictionSpec, MaterialSpec, ModelDescription, NodeSpec,
};

pub const L: f64 = 4e-3;
pub const R: f64 = 2e-4;
pub const SLOPE: f64 = 0.5;

/// Warp height at x (period L): valleys at 0 and L, peak at L/2.
pub fn warp_z(x: f64) -> f64 {
    let x = x.rem_euclid(L);
    if x <= 0.5 * L {
        SLOPE * (x - 0.25 * L)
    } else {
        -SLOPE * (x - 0.75 * L)
    }
}

/// Contact distance (a hair under 2r, so the pair is closed: the overlap is adjusted to 0) and
/// the x offset of the warp's contact point from its weft.
pub fn contact_geometry() -> (f64, f64) {
    let c = (1.0 + SLOPE * SLOPE).sqrt();
    let d = 2.0 * R * (1.0 - 1e-9);
    (d, d * SLOPE / c)
}

/// The cell cut at x₀, with Tresca bound `bound` (N).
pub fn cell(x0: f64, bound: f64) -> ModelDescription {
    let (d, dx) = contact_geometry();
    let c = (1.0 + SLOPE * SLOPE).sqrt();
    let (x1, x2) = (0.25 * L, 0.75 * L);
    let mut m = ModelDescription {
        materials: vec![MaterialSpec {
            name: "yarn".into(),
            young: 2e9,
            poisson: Some(0.35),
            shear: None,
        }],
        cell: Some(CellSpec {
            size: [L, L],
            origin: Some([x0, 0.0]),
            thickness: Some(8.0 * R),
            tolerance: None,
        }),
        contact: Some(ContactSpec {
            search: true,
            penalty_normal: Some(5e5),
            friction: FrictionSpec::Tresca { bound },
            ..Default::default()
        }),
        ..Default::default()
    };
    let wrap = |x: f64| x0 + (x - x0).rem_euclid(L);
    let node = |m: &mut ModelDescription, x: [f64; 3]| {
        let id = m.nodes.len() as u64 + 1;
        m.nodes.push(NodeSpec { id, x });
        id
    };
    // Warps: kinks, contact points and the two boundary nodes, in the cell's own x range.
    let mut xs: Vec<f64> = [0.0, x1 - dx, 0.5 * L, x2 - dx].map(wrap).to_vec();
    xs.extend([x0, x0 + L]);
    xs.sort_by(f64::total_cmp);
    xs.dedup_by(|a, b| (*a - *b).abs() < 1e-12 * L);
    let mut fibers = Vec::new();
    for y in [0.2 * L, 0.6 * L] {
        let ids: Vec<u64> = xs
            .iter()
            .map(|&x| node(&mut m, [x, y, warp_z(x)]))
            .collect();
        fibers.push(ids);
    }
    // Wefts: below the warps at x₁, above them at x₂, nodes at the crossings.
    for (x, z) in [(x1, -d * c), (x2, d * c)] {
        let ids: Vec<u64> = [0.0, 0.2, 0.4, 0.6, 0.8, 1.0]
            .iter()
            .map(|&t| node(&mut m, [x, t * L, z]))
            .collect();
        fibers.push(ids);
    }
    m.fibers = fibers
        .into_iter()
        .enumerate()
        .map(|(k, nodes)| FiberSpec {
            id: k as u64 + 1,
            nodes,
            radius: R,
            material: "yarn".into(),
        })
        .collect();
    m
}

/// The seam between the weft at x₁ and the warp's contact point.
pub fn seam() -> f64 {
    0.25 * L - 0.5 * contact_geometry().1
}
