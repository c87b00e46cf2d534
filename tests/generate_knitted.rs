//! Plain-jersey generator: every interlocking crossing is a closed contact, the cell is
//! periodic, and it homogenizes with the mirror symmetry of jersey about a wale's axis.

mod common;
use common::grid_abd::{assert_abd, elastic_abd};
use fibercell::generate::{knitted, Knit};
use fibercell::homogenize::homogenize_elastic;
use fibercell::solve::SolveOptions;
use fibercell::Model;

#[test]
fn every_interlocking_crossing_is_a_closed_contact() {
    for (wales, courses) in [(1, 2), (2, 2), (3, 2)] {
        let k = Knit {
            wales,
            courses,
            ..Knit::default()
        };
        let d = knitted(&k).unwrap();
        let m = Model::from_description(&d).unwrap();
        let s = fibercell::stats::network_stats(&m).unwrap();
        println!("{wales}x{courses}: {}", s.summary());
        assert_eq!(s.contacts, 4 * wales * courses, "four crossings per loop");
        assert_eq!(s.fibers, courses, "one yarn per course");
    }
}

#[test]
fn jersey_homogenizes_with_the_mirror_symmetry_of_a_wale() {
    // Reflecting x about a wale's axis maps the jersey onto itself (t → 2π − t) and flips the
    // signs of γ12 and κ12: every coupling of (ε11, ε22, κ11, κ22) with (γ12, κ12) vanishes.
    // (The contact jump between the touching surface points makes this hold; the centerline
    // jump of thesis Lemma 4.26 resists rigid rotations and gave D13 ≈ 0.2 D11 here.)
    let d = knitted(&Knit::default()).unwrap();
    let h = homogenize_elastic(
        &Model::from_description(&d).unwrap(),
        &SolveOptions::default(),
    )
    .unwrap();
    assert_eq!(h.contacts, 16);
    let a = h.abd;
    assert!(h.asymmetry < 1e-9, "asymmetry {:e}", h.asymmetry);
    assert!((0..6).all(|k| a[k][k] > 0.0));
    for odd in [2, 5] {
        for even in [0, 1, 3, 4] {
            let scale = (a[odd][odd] * a[even][even]).sqrt();
            assert!(
                a[odd][even].abs() <= 1e-8 * scale,
                "ABD[{odd}][{even}] = {:e} (scale {scale:e})",
                a[odd][even]
            );
        }
    }
}

#[test]
fn the_moduli_do_not_change_when_the_cell_is_turned_half_round() {
    // A rotation by π about z leaves every even-order stiffness tensor unchanged: the same
    // jersey with (x, y) → (L_x − x, L_y − y) must give the same ABD. This fails when a sticking
    // contact resists rigid rotations, since the macro curvature fields rotate every point by
    // an amount that depends on where it lies.
    let d = knitted(&Knit::default()).unwrap();
    let [lx, ly] = d.cell.as_ref().unwrap().size;
    let mut turned = d.clone();
    for n in &mut turned.nodes {
        n.x[0] = lx - n.x[0];
        n.x[1] = ly - n.x[1];
    }
    assert_abd(&elastic_abd(&turned), &elastic_abd(&d), 1e-8);
}

#[test]
fn knit_parameters_that_cannot_interlock_are_errors() {
    for (bad, field) in [
        (
            Knit {
                course_spacing: 1.2e-3,
                ..Knit::default()
            },
            "course_spacing",
        ),
        (
            Knit {
                lean: 1e-5,
                ..Knit::default()
            },
            "lean",
        ),
        (
            Knit {
                radius: f64::INFINITY,
                ..Knit::default()
            },
            "radius",
        ),
        (
            Knit {
                radius: 1.5e-4,
                ..Knit::default()
            },
            "knitted",
        ),
    ] {
        let err = knitted(&bad).unwrap_err().to_string();
        assert!(err.contains(field), "{err}");
    }
}
