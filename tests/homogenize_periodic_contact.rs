//! Contacts across the periodic boundary. Two zigzag warps (along x, slope ±s) rest on two
//! straight wefts (along y) — below the warps at x₁ = Lx/4, above them at x₂ = 3Lx/4 — and touch
//! them where the warps are inclined, so each contact normal is tilted by atan s and the two
//! contact points of a crossing lie 2r s/√(1+s²) apart in x. Cutting the cell between them puts
//! the weft near one face and the warp's contact point near the opposite one: the contact is
//! then only seen between the weft and a periodic image of the warp. Nodes sit at the contact
//! points and at the kinks, so both cells hold the same beams (an extra node on an unloaded
//! straight segment changes nothing) and the results must agree to roundoff: the elastic ABD to
//! 1e-9 of its diagonal, and the incremental solution across the boundary reproduces it. (The
//! cut leaves warp elements of 0.45 r; much shorter ones — cuts within 1 % of r of a node —
//! lose digits to the 12EI/L³ of the tiny element, not to the periodic images.)

use fibercell::contact::ContactSet;
use fibercell::homogenize::{elasto_plastic_curve, homogenize_elastic, Curve, CurveOptions};
use fibercell::model::{
    CellSpec, ContactSpec, FiberSpec, FrictionSpec, MaterialSpec, ModelDescription, NodeSpec,
};
use fibercell::solve::{IncrementalOptions, SolveOptions};
use fibercell::Model;

const L: f64 = 4e-3;
const R: f64 = 2e-4;
const SLOPE: f64 = 0.5;

/// Warp height at x (period L): valleys at 0 and L, peak at L/2.
fn warp_z(x: f64) -> f64 {
    let x = x.rem_euclid(L);
    if x <= 0.5 * L {
        SLOPE * (x - 0.25 * L)
    } else {
        -SLOPE * (x - 0.75 * L)
    }
}

/// Contact distance (a hair under 2r, so the pair is closed: the overlap is adjusted to 0) and
/// the x offset of the warp's contact point from its weft.
fn contact_geometry() -> (f64, f64) {
    let c = (1.0 + SLOPE * SLOPE).sqrt();
    let d = 2.0 * R * (1.0 - 1e-9);
    (d, d * SLOPE / c)
}

/// The cell cut at x₀, with Tresca bound `bound` (N).
fn cell(x0: f64, bound: f64) -> ModelDescription {
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
fn seam() -> f64 {
    0.25 * L - 0.5 * contact_geometry().1
}

fn curve(x0: f64, bound: f64, strain: [f64; 6]) -> Curve {
    elasto_plastic_curve(
        &Model::from_description(&cell(x0, bound)).unwrap(),
        &CurveOptions {
            strain,
            steps: 20,
            unload: false,
            incremental: IncrementalOptions::default(),
        },
    )
    .unwrap()
}

#[test]
fn elastic_moduli_do_not_depend_on_a_cut_through_a_contact() {
    let opts = SolveOptions::default();
    let inside =
        homogenize_elastic(&Model::from_description(&cell(0.0, 1.0)).unwrap(), &opts).unwrap();
    let across =
        homogenize_elastic(&Model::from_description(&cell(seam(), 1.0)).unwrap(), &opts).unwrap();
    // Two warps × two wefts, found inside the cell or across its boundary.
    assert_eq!(inside.contacts, 4);
    assert_eq!(across.contacts, 4);
    let scale = inside
        .abd
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    for i in 0..6 {
        for j in 0..6 {
            let (a, b) = (inside.abd[i][j], across.abd[i][j]);
            // Bending rows scale with lengths: compare each entry with its diagonal.
            let block = inside.abd[i][i]
                .abs()
                .max(inside.abd[j][j].abs())
                .min(scale);
            assert!(
                (a - b).abs() <= 1e-9 * block,
                "ABD[{i}][{j}]: {a} inside vs {b} across the boundary"
            );
        }
    }
    assert!(inside.abd[2][2] > 0.0 && inside.asymmetry < 1e-10);
    // Without the images the cut cell sees the two crossings of the weft at x₁ only at the
    // warps' boundary nodes, off the contact point and open; with them, closed and in place.
    let cut = Model::from_description(&cell(seam(), 1.0)).unwrap();
    let cell_pairs = fibercell::cell::pair_boundary_nodes(&cut).unwrap();
    let closed = |s: &ContactSet| s.pairs.iter().filter(|p| p.gap <= 0.0).count();
    assert_eq!(closed(&ContactSet::build(&cut).unwrap()), 2);
    let set = ContactSet::build_with(&cut, Some(&cell_pairs)).unwrap();
    assert_eq!(closed(&set), 4);
    assert_eq!(set.origins.iter().filter(|o| o.shift != [0, 0]).count(), 2);
}

#[test]
fn point_contacts_let_the_yarns_roll_and_rolling_resistance_holds_them() {
    // With p_R = 0 (the thesis's point contact) nothing resists a weft spinning about its axis
    // while the warps translate: the cell problem is singular, and the error says where.
    let mut d = cell(0.0, 1.0);
    d.contact.as_mut().unwrap().penalty_rotation = Some(0.0);
    let err = homogenize_elastic(
        &Model::from_description(&d).unwrap(),
        &SolveOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("singular") && err.contains("node"), "{err}");
    // The default rolling resistance p_N (r/2)²/4 makes it well posed; stiffer rolling
    // resistance only stiffens (the moduli grow monotonically with p_R).
    let diag = |p: Option<f64>| {
        let mut d = cell(0.0, 1.0);
        d.contact.as_mut().unwrap().penalty_rotation = p;
        let h = homogenize_elastic(
            &Model::from_description(&d).unwrap(),
            &SolveOptions::default(),
        )
        .unwrap();
        (0..6).map(|k| h.abd[k][k]).collect::<Vec<_>>()
    };
    let (soft, default, stiff) = (diag(Some(1e-6)), diag(None), diag(Some(1e-1)));
    for k in 0..6 {
        assert!(soft[k] <= default[k] * (1.0 + 1e-9) && default[k] <= stiff[k] * (1.0 + 1e-9));
    }
}

#[test]
fn the_incremental_curve_across_the_boundary_is_the_elastic_one() {
    // κ22 is the case that loads these contacts (the wefts bend and drag the warps along y).
    // Each weft is held by its two contacts only, whose forces balance, so once they slide the
    // weft is free to slip along its axis: a real mechanism. With a bound above the peak force
    // everything sticks and the incremental solution through the shifted jumps (forces and
    // rolling moments in the reactions) must reproduce A^elas E at every increment.
    let strain = [0.0, 0.0, 0.0, 0.0, 10.0, 0.0];
    let opts = SolveOptions::default();
    for x0 in [0.0, seam()] {
        let m = Model::from_description(&cell(x0, 1.0)).unwrap();
        let elastic = homogenize_elastic(&m, &opts).unwrap();
        let c = curve(x0, 1.0, strain);
        assert!(c.switches.is_empty());
        let peak = c
            .solution
            .contact_results
            .last()
            .unwrap()
            .iter()
            .map(|r| r.tangential_magnitude)
            .fold(0.0, f64::max);
        assert!(peak > 1e-4, "the contacts carry the load ({peak} N)");
        let scale = elastic.abd[4][4] * strain[4];
        for p in &c.points {
            for k in 0..6 {
                let want: f64 = (0..6).map(|j| elastic.abd[k][j] * p.strain[j]).sum();
                assert!(
                    (p.resultant[k] - want).abs() <= 1e-8 * scale,
                    "cut at {x0}, step {}: M[{k}] {} vs A^elas E {want}",
                    p.step,
                    p.resultant[k]
                );
            }
        }
    }
}
