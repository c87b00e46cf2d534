//! The non-woven generator: determinism per seed, periodicity (every boundary node paired,
//! contacts found across the faces), the requested volume fraction and orientation tensor,
//! contacts closed and no penetration beyond the tolerance, and a generated cell that
//! homogenizes. Tolerances are stated where the numbers are random.

use fibercell::cell::pair_boundary_nodes;
use fibercell::contact::ContactSet;
use fibercell::generate::{
    nonwoven, nonwoven_preset, FiberAmount, LengthDistribution, NonWoven, Orientation,
};
use fibercell::homogenize::homogenize_elastic;
use fibercell::solve::SolveOptions;
use fibercell::stats::network_stats;
use fibercell::{Error, Model};

fn small(seed: u64) -> NonWoven {
    NonWoven {
        size: [4e-3, 4e-3],
        amount: FiberAmount::Count { fibers: 120 },
        length: LengthDistribution::Fixed { length: 1.6e-3 },
        element_length: 2e-4,
        seed,
        ..NonWoven::default()
    }
}

/// Total plan-view (x, y) length of the elements.
fn plan_length(m: &Model) -> f64 {
    m.elements()
        .iter()
        .map(|e| {
            let [a, b] = e.nodes.map(|n| m.nodes[n].x);
            ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt()
        })
        .sum()
}

fn model(p: &NonWoven) -> Model {
    Model::from_description(&nonwoven(p).unwrap().description).unwrap()
}

#[test]
fn the_same_seed_gives_the_same_cell() {
    let a = nonwoven(&small(3)).unwrap().description;
    let b = nonwoven(&small(3)).unwrap().description;
    let c = nonwoven(&small(4)).unwrap().description;
    assert_eq!(a, b);
    assert_ne!(a, c);
}

#[test]
fn cells_are_periodic_and_contacts_cross_the_faces() {
    // A fiber leaving the cell is written as pieces, so most crossings near a face are seen
    // inside the cell, and their images are the same crossings (merged, tests/one_contact_per_crossing.rs);
    // in this cell three contacts are closest between an element and a periodic image.
    let p = small(3);
    let m = model(&p);
    let per = pair_boundary_nodes(&m).expect("every boundary node is paired");
    assert!(per.n_slaves() > 10, "fibers wrap across the faces");
    let set = ContactSet::build_with(&m, Some(&per)).unwrap();
    assert!(
        set.origins.iter().any(|o| o.shift != [0, 0]),
        "some contacts lie between an element and a periodic image"
    );
    // Every node lies in the box.
    for n in &m.nodes {
        assert!((0.0..=p.size[0]).contains(&n.x[0]) && (0.0..=p.size[1]).contains(&n.x[1]));
    }
}

#[test]
fn contacts_are_closed_and_nothing_penetrates_beyond_the_tolerance() {
    let curled = NonWoven {
        curl: 300.0,
        length: LengthDistribution::LogNormal {
            mean: 1.5e-3,
            cv: 0.3,
        },
        ..small(6)
    };
    // Tilted fibers rise off the mat (at least tan φ per unit length from their start).
    let tilted = NonWoven {
        tilt_degrees: 0.05f64.to_degrees(),
        ..curled.clone()
    };
    // Flat fibers rest on the mat, none is lifted into the air: the mean coverage
    // N L 2r / (L_x L_y) is below one layer here, so 10 diameters is a generous bound (a lift
    // that overshoots, e.g. for side-by-side fibers, breaks it). Tilted fibers may start on
    // the raised ends of earlier ones and stack up: no bound for them.
    let flat_bound = 20.0 * curled.radius;
    for (p, min_contacts_per_fiber, thickness_bound) in
        [(curled, 3.0, flat_bound), (tilted, 0.3, f64::INFINITY)]
    {
        let s = network_stats(&model(&p)).unwrap();
        let tol = p.tolerance * p.radius;
        // The search (equal to the all-pairs search, see contact_properties) finds no overlap
        // deeper than the tolerance (1e-9 relative slack for roundoff).
        assert!(
            s.worst_overlap <= tol * (1.0 + 1e-9),
            "{} > {tol}",
            s.worst_overlap
        );
        // Supports are made touching (gap −tol/2): they are the penetrating pairs, all closed.
        assert!(
            s.contacts as f64 > min_contacts_per_fiber * s.fibers as f64,
            "{} contacts for {} fibers",
            s.contacts,
            s.fibers
        );
        assert_eq!(s.contacts, s.penetrating);
        assert!(
            s.z_extent < thickness_bound,
            "tilt {}: mat {} m thick",
            p.tilt_degrees,
            s.z_extent
        );
    }
}

#[test]
fn the_requested_volume_fraction_is_reached() {
    let (fraction, thickness) = (0.02, 2e-4);
    let p = NonWoven {
        amount: FiberAmount::VolumeFraction {
            fraction,
            thickness,
        },
        ..small(7)
    };
    let g = nonwoven(&p).unwrap();
    assert_eq!(g.report.dropped, 0);
    let m = Model::from_description(&g.description).unwrap();
    let s = network_stats(&m).unwrap();
    assert_eq!(s.thickness, thickness);
    // The plan-view length is exactly the target volume / (π r²) (the last fiber is cut);
    // draping over the crossings adds the fibers' slopes: the 3D volume fraction is above the
    // target by at most 3 % for these mats (measured slopes below 0.25 rad).
    let plan = plan_length(&m);
    let target = fraction * p.size[0] * p.size[1] * thickness;
    let area = std::f64::consts::PI * p.radius * p.radius;
    assert!(
        (plan * area - target).abs() <= 1e-9 * target,
        "{} vs {target}",
        plan * area
    );
    let vf = s.volume_fraction.unwrap();
    assert!(vf >= fraction && vf <= 1.03 * fraction, "{vf}");
}

#[test]
fn the_requested_orientation_tensor_is_reached() {
    // 1,500 fibers of equal length: the standard error of the length-weighted a11 is about
    // 0.3/√1500 < 0.008; tolerance 0.03.
    for (a11, a12) in [(0.5, 0.0), (0.75, 0.0), (0.6, -0.15)] {
        let p = NonWoven {
            size: [8e-3, 8e-3],
            amount: FiberAmount::Count { fibers: 1500 },
            length: LengthDistribution::Fixed { length: 1e-3 },
            element_length: 2.5e-4,
            orientation: if a11 == 0.5 && a12 == 0.0 {
                Orientation::Isotropic
            } else {
                Orientation::Tensor { a11, a12 }
            },
            seed: 11,
            ..NonWoven::default()
        };
        let s = network_stats(&model(&p)).unwrap();
        let o = s.orientation_in_plane;
        assert!(
            (o[0] - a11).abs() < 0.03 && (o[2] - a12).abs() < 0.03,
            "target ({a11}, {a12}): got {o:?}"
        );
        assert!((o[0] + o[1] - 1.0).abs() < 1e-12);
    }
}

#[test]
fn fixed_straight_fibers_have_the_requested_plan_length() {
    let p = small(8);
    let g = nonwoven(&p).unwrap();
    let m = Model::from_description(&g.description).unwrap();
    let plan = plan_length(&m);
    let LengthDistribution::Fixed { length } = p.length else {
        unreachable!()
    };
    let want = (g.report.deposited - g.report.dropped) as f64 * length;
    assert!((plan - want).abs() <= 1e-9 * want, "{plan} vs {want}");
    // No element longer than requested, none shorter than a diameter.
    for e in m.elements() {
        let [a, b] = e.nodes.map(|n| m.nodes[n].x);
        let l = ((0..3).map(|k| (b[k] - a[k]).powi(2)).sum::<f64>()).sqrt();
        assert!(
            l <= p.element_length * 1.05 && l >= 2.0 * p.radius * 0.999,
            "{l}"
        );
    }
}

#[test]
fn a_generated_cell_homogenizes() {
    let m = model(&small(9));
    let h = homogenize_elastic(&m, &SolveOptions::default()).unwrap();
    assert!(h.asymmetry < 1e-8, "{}", h.asymmetry);
    for i in 0..6 {
        assert!(h.abd[i][i] > 0.0);
    }
    // Isotropic in the mean: A11 and A22 within 40 % for 120 fibers.
    let (a, b) = (h.abd[0][0], h.abd[1][1]);
    assert!((a - b).abs() < 0.4 * a.max(b), "{a} vs {b}");
}

#[test]
fn presets_reach_their_contact_counts() {
    let s = network_stats(&model(&nonwoven_preset("S", 1).unwrap())).unwrap();
    assert_eq!(s.fibers, 200);
    assert!(s.contacts >= 1000, "{}", s.contacts);
    let e = nonwoven_preset("XXL", 1).unwrap_err();
    assert!(e.to_string().contains("unknown cell size"), "{e}");
}

/// Every preset has S's areal density of fibers (within 1 %: M's side is rounded to 0.1 mm)
/// and L's elements or coarser; XL has four times L's fibers on twice its side.
#[test]
fn presets_share_one_areal_density() {
    let density = |p: &NonWoven| {
        let FiberAmount::Count { fibers } = p.amount else {
            panic!("presets give a fiber count")
        };
        (fibers as f64 / (p.size[0] * p.size[1]), fibers)
    };
    let [s, m, l, xl] = ["S", "M", "L", "xl"].map(|n| nonwoven_preset(n, 1).unwrap());
    let (rho, _) = density(&s);
    for p in [&m, &l, &xl] {
        assert!((density(p).0 / rho - 1.0).abs() < 0.01, "{:?}", p.size);
    }
    assert_eq!(density(&xl).1, 4 * density(&l).1);
    assert_eq!(xl.size[0], 2.0 * l.size[0]);
    assert_eq!(xl.element_length, l.element_length);
}

#[test]
fn bad_parameters_name_the_field() {
    let cases: Vec<(NonWoven, &str)> = vec![
        (
            NonWoven {
                radius: -1.0,
                ..small(1)
            },
            "radius",
        ),
        (
            NonWoven {
                size: [f64::NAN, 1e-3],
                ..small(1)
            },
            "size[0]",
        ),
        (
            NonWoven {
                length: LengthDistribution::Fixed { length: 3e-3 },
                ..small(1)
            },
            "half the smaller period",
        ),
        (
            NonWoven {
                amount: FiberAmount::Count { fibers: 0 },
                ..small(1)
            },
            "fiber count",
        ),
        (
            NonWoven {
                amount: FiberAmount::VolumeFraction {
                    fraction: 1.5,
                    thickness: 1e-4,
                },
                ..small(1)
            },
            "volume fraction",
        ),
        (
            NonWoven {
                orientation: Orientation::Tensor { a11: 1.0, a12: 0.0 },
                ..small(1)
            },
            "eigenvalue",
        ),
        (
            NonWoven {
                curl: 1e5,
                ..small(1)
            },
            "curl",
        ),
        (
            NonWoven {
                element_length: 1e-6,
                ..small(1)
            },
            "element_length",
        ),
    ];
    for (p, says) in cases {
        let e = nonwoven(&p).unwrap_err();
        assert!(
            matches!(e, Error::InvalidOption(_)) && e.to_string().contains(says),
            "{says}: {e}"
        );
    }
}
