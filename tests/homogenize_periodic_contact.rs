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
mod common;
use common::zigzag::{cell, seam};
use fibercell::solve::{IncrementalOptions, SolveOptions};
use fibercell::Model;

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
    // Under κ22 the wefts bend and the warps follow; every contact stays closed and sticks, and
    // the incremental solution through the shifted jumps (forces and rolling moments in the
    // reactions) must reproduce A^elas E at every increment. (With the objective surface-point
    // jump these contacts carry almost nothing under any single macro strain that keeps them
    // closed — in-plane shear and twist pull them open, and a weft held by open contacts is a
    // mechanism — so the shifted jumps are checked mainly by the elastic ABD above, inside
    // versus across the boundary.)
    let strain = [0.0, 0.0, 0.0, 0.0, 10.0, 0.0];
    let opts = SolveOptions::default();
    for x0 in [0.0, seam()] {
        let m = Model::from_description(&cell(x0, 1.0)).unwrap();
        let elastic = homogenize_elastic(&m, &opts).unwrap();
        let c = curve(x0, 1.0, strain);
        assert!(c.switches.is_empty());
        let closed = c
            .solution
            .contact_results
            .last()
            .unwrap()
            .iter()
            .filter(|r| r.state != fibercell::contact::ContactState::Open)
            .count();
        assert_eq!(closed, 4, "every contact stays closed");
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

/// The periodic discretization's shortcut: a block of node images is the identity (T = I on
/// the nodes themselves, what `contact_pair` and the Θ load then skip forming) exactly when
/// `block_of_images` gives the nodes back with T = I. Both cells hold contacts and elements of
/// both kinds (slaves on the faces, images across the cut), and a repeated node is not one.
#[test]
fn a_block_is_the_identity_exactly_when_its_images_map_onto_themselves() {
    use fibercell::homogenize::PeriodicSystem;
    use nalgebra::DMatrix;
    for x0 in [0.0, seam()] {
        let model = Model::from_description(&cell(x0, 1.0)).unwrap();
        let sys = PeriodicSystem::new(&model).unwrap();
        let disc = &sys.discretization;
        let set = ContactSet::build_with(&model, Some(&sys.periodicity)).unwrap();
        let contacts = set
            .pairs
            .iter()
            .map(|p| (p.jump.nodes.clone(), p.jump.shifts.clone()));
        let elements = model
            .elements()
            .iter()
            .map(|e| (e.nodes.to_vec(), vec![[0, 0]; 2]));
        let repeated = (vec![0, 0], vec![[0, 0]; 2]);
        let mut seen = [0usize; 2];
        for (nodes, shifts) in contacts.chain(elements).chain([repeated]) {
            let (gnodes, t) = disc.block_of_images(&nodes, &shifts);
            let identity = gnodes == nodes && t == DMatrix::identity(t.nrows(), t.ncols());
            assert_eq!(
                disc.is_identity_block(&nodes, &shifts),
                identity,
                "nodes {nodes:?}, shifts {shifts:?}"
            );
            seen[usize::from(identity)] += 1;
        }
        assert!(seen[0] > 1 && seen[1] > 0, "x0 {x0}: {seen:?} blocks");
        if x0 != 0.0 {
            assert!(set
                .pairs
                .iter()
                .any(|p| p.jump.shifts.iter().any(|s| *s != [0, 0])));
        }
    }
}
