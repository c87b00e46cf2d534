//! Properties of the contact formulation and search (proptest): K_N and K_T^st symmetric
//! positive semi-definite, only K_T^sl nonsymmetric, open contacts inert, penetration ∝ 1/penalty,
//! the rolling block symmetric positive semi-definite, and the grid search (with and without
//! periodic images) equal to the all-pairs search.

use fibercell::cell::{CellGeometry, Periodicity};
use fibercell::contact::{
    closest_points, find_candidates, find_candidates_brute_force, jump_operator, tangent_basis,
    BlockState, ContactPair, ContactSide, ContactState, Friction,
};
use fibercell::model::{FiberSpec, MaterialSpec, ModelDescription, NodeSpec};
use fibercell::solve::{solve_incremental, solve_static, IncrementalOptions, SolveOptions};
use fibercell::{io, Model};
use nalgebra::{DMatrix, SymmetricEigen, Vector2, Vector3};
use proptest::prelude::*;
use std::path::Path;

fn material() -> MaterialSpec {
    MaterialSpec {
        name: "m".into(),
        young: 1e9,
        poisson: Some(0.3),
        shear: None,
    }
}

/// Straight fibers given by end points, each split into `sub` elements.
fn fibers(lines: &[([f64; 3], [f64; 3], f64)], sub: usize) -> ModelDescription {
    let mut d = ModelDescription {
        materials: vec![material()],
        ..Default::default()
    };
    let mut id = 0u64;
    for (f, (a, b, r)) in lines.iter().enumerate() {
        let mut ids = Vec::new();
        for k in 0..=sub {
            let t = k as f64 / sub as f64;
            id += 1;
            d.nodes.push(NodeSpec {
                id,
                x: [0, 1, 2].map(|i| a[i] + t * (b[i] - a[i])),
            });
            ids.push(id);
        }
        d.fibers.push(FiberSpec {
            id: f as u64 + 1,
            nodes: ids,
            radius: *r,
            material: "m".into(),
        });
    }
    d
}

fn block(pair: &ContactPair, m: &fibercell::contact::BlockMatrix) -> DMatrix<f64> {
    let n = pair.size();
    DMatrix::from_fn(n, n, |i, j| m[(i, j)])
}

fn pair_from(model: &Model, xi: [f64; 2], normal: Vector3<f64>) -> ContactPair {
    let sides = [
        ContactSide::Point {
            element: 0,
            xi: xi[0],
        },
        ContactSide::Point {
            element: 2,
            xi: xi[1],
        },
    ];
    let jump = jump_operator(model, sides[0], sides[1], [0, 0]).expect("disjoint");
    ContactPair {
        jump,
        tangents: tangent_basis(&normal, &Vector3::new(1.0, 0.2, -0.1)),
        normal,
        gap: 1e-4,
        penalty_normal: 3e5,
        penalty_tangent: 1e5,
        penalty_rotation: 2e-2,
    }
}

fn unit() -> impl Strategy<Value = Vector3<f64>> {
    prop::array::uniform3(-1.0f64..1.0)
        .prop_filter("not tiny", |v| Vector3::from(*v).norm() > 0.1)
        .prop_map(|v| Vector3::from(v).normalize())
}

fn point() -> impl Strategy<Value = [f64; 3]> {
    prop::array::uniform3(-1.0f64..1.0)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn normal_and_stick_blocks_are_symmetric_psd_and_coulomb_slip_is_not_symmetric(
        a in point(), b in point(), c in point(), d in point(),
        xi in prop::array::uniform2(0.0f64..1.0), normal in unit(), dir in 0.0f64..std::f64::consts::TAU,
    ) {
        prop_assume!((Vector3::from(b) - Vector3::from(a)).norm() > 0.1 && (Vector3::from(d) - Vector3::from(c)).norm() > 0.1);
        let model = Model::from_description(&fibers(&[(a, b, 0.01), (c, d, 0.01)], 2)).unwrap();
        let pair = pair_from(&model, xi, normal);
        let (kn, _) = pair.normal();
        let (kt, _) = pair.stick(&Vector2::new(1e-5, -2e-5));
        for k in [kn, kt, pair.rotation()] {
            let m = block(&pair, &k);
            let scale = m.amax();
            prop_assert!((&m - m.transpose()).amax() <= 1e-12 * scale);
            let ev = SymmetricEigen::new(m).eigenvalues;
            prop_assert!(ev.iter().all(|&e| e >= -1e-10 * scale), "{ev}");
        }
        let d = Vector2::new(dir.cos(), dir.sin());
        let (ks, _) = pair.slip(Friction::Coulomb { mu: 0.3, cohesion: 0.0 }, &d);
        let m = block(&pair, &ks);
        // Rank one B^T E d nᵀ B: nonsymmetric because E d ⟂ n.
        prop_assert!((&m - m.transpose()).amax() > 1e-6 * m.amax());
        let (kt0, ft) = pair.slip(Friction::Tresca { bound: 2.0 }, &d);
        prop_assert!(kt0.amax() == 0.0 && ft.amax() > 0.0, "Tresca slip is a load only");
    }

    /// The fill's closed-contact block Bᵀ S B + p_R RᵀR equals K_N + K_T^st + K_R (stick) and
    /// K_N + K_R (sliding) built from the outer products, and its stick load F_N + F_T, to
    /// rounding.
    #[test]
    fn the_closed_contact_block_is_the_sum_of_its_parts(
        a in point(), b in point(), c in point(), d in point(),
        xi in prop::array::uniform2(0.0f64..1.0), normal in unit(),
    ) {
        prop_assume!((Vector3::from(b) - Vector3::from(a)).norm() > 0.1 && (Vector3::from(d) - Vector3::from(c)).norm() > 0.1);
        let model = Model::from_description(&fibers(&[(a, b, 0.01), (c, d, 0.01)], 2)).unwrap();
        let pair = pair_from(&model, xi, normal);
        let (kn, fn_) = pair.normal();
        let (kt, _) = pair.stick(&Vector2::zeros());
        let slip = Vector2::new(xi[0] - 0.5, 0.25 - xi[1]);
        let expected_load = fn_ + pair.stick(&slip).1;
        let load = pair.stick_load(&slip);
        prop_assert!((load - expected_load).amax() <= 1e-12 * expected_load.amax().max(1e-300));
        for (stick, sum) in [(true, kn + kt + pair.rotation()), (false, kn + pair.rotation())] {
            let k = pair.closed_stiffness(stick);
            let expected = block(&pair, &sum);
            let got = DMatrix::from_fn(pair.size(), pair.size(), &k);
            prop_assert!((&got - &expected).amax() <= 1e-12 * expected.amax(), "stick {stick}");
        }
        // Each spring alone from the one production formula: K_N, K_T^st, K_R.
        let (pn, pt, pr) = (pair.penalty_normal, pair.penalty_tangent, pair.penalty_rotation);
        for (name, (p, q, r), part) in [
            ("K_N", (pn, 0.0, 0.0), kn),
            ("K_T^st", (0.0, pt, 0.0), kt),
            ("K_R", (0.0, 0.0, pr), pair.rotation()),
        ] {
            let k = pair.springs(p, q, r);
            let expected = block(&pair, &part);
            let got = DMatrix::from_fn(pair.size(), pair.size(), &k);
            prop_assert!((&got - &expected).amax() <= 1e-12 * expected.amax().max(1e-300), "{name}");
        }
    }

    /// G D Gᵀ from the block coefficients equals every block the incremental solver assembles
    /// from the outer products: stick K_N + K_T^st + K_R; slip K_N + K_T^sl + K_R + k⊥ term
    /// + ε K_T^st (Tresca and Coulomb); open ε (K_N + K_T^st + K_R); to rounding.
    #[test]
    fn block_coefficients_in_the_jump_basis_give_the_assembled_blocks(
        a in point(), b in point(), c in point(), d in point(),
        xi in prop::array::uniform2(0.0f64..1.0), normal in unit(),
        dir in 0.0f64..std::f64::consts::TAU, k_perp in 0.0f64..1e5, eps in prop::sample::select(vec![0.0, 1e-8, 1e-3]),
    ) {
        prop_assume!((Vector3::from(b) - Vector3::from(a)).norm() > 0.1 && (Vector3::from(d) - Vector3::from(c)).norm() > 0.1);
        let model = Model::from_description(&fibers(&[(a, b, 0.01), (c, d, 0.01)], 2)).unwrap();
        let pair = pair_from(&model, xi, normal);
        let direction = Vector2::new(dir.cos(), dir.sin());
        let g = pair.jump_basis();
        let m = pair.size();
        let (kn, _) = pair.normal();
        let (kt, _) = pair.stick(&Vector2::zeros());
        let kr = pair.rotation();
        for friction in [Friction::Tresca { bound: 0.3 }, Friction::Coulomb { mu: 0.4, cohesion: 0.0 }, Friction::None] {
            for state in [ContactState::Stick, ContactState::Slip, ContactState::Open] {
                let s = BlockState { state, direction, k_perp };
                let coefficients = pair.block_coefficients(&s, friction, eps);
                let got = DMatrix::from_fn(m, m, |r, c| {
                    (0..6).map(|p| (0..6).map(|q| g[p][r] * coefficients[(p, q)] * g[q][c]).sum::<f64>()).sum::<f64>()
                });
                let expected = match state {
                    ContactState::Stick => kn + kt + kr,
                    ContactState::Open => (kn + kt + kr) * eps,
                    ContactState::Slip => {
                        let perp = pair.slip_perpendicular(&direction, k_perp, &Vector2::zeros()).0;
                        kn + pair.slip(friction, &direction).0 + kr + perp + kt * eps
                    }
                };
                let expected = block(&pair, &expected);
                let scale = (kn + kt + kr).amax();
                prop_assert!((&got - &expected).amax() <= 1e-12 * scale, "{friction:?} {state:?}");
                // And the load G φ against the blocks' loads.
                let anchor = Vector2::new(xi[1] - 0.3, 0.1 - xi[0]) * 1e-3;
                let slip = Vector2::new(2e-4, -1e-4);
                let phi = pair.load_coefficients(&s, &anchor, &slip, friction);
                let load: fibercell::contact::BlockVector = (0..6).map(|p| g[p] * phi[p]).sum();
                let expected_load = match state {
                    ContactState::Stick => pair.stick_load(&slip),
                    ContactState::Open => fibercell::contact::BlockVector::zeros(),
                    ContactState::Slip => {
                        pair.normal().1
                            + pair.slip(friction, &direction).1
                            + pair.slip_perpendicular(&direction, k_perp, &anchor).1
                    }
                };
                let load_scale = pair.normal().1.amax();
                prop_assert!((load - expected_load).amax() <= 1e-12 * load_scale, "load {friction:?} {state:?}");
            }
        }
    }

    #[test]
    fn grid_search_finds_exactly_the_all_pairs_candidates(
        lines in prop::collection::vec((point(), point(), 0.005f64..0.05), 2..12),
        sub in 1usize..5,
        tolerance in 0.0f64..0.05,
    ) {
        let lines: Vec<_> = lines.into_iter().filter(|(a, b, _)| (Vector3::from(*b) - Vector3::from(*a)).norm() > 0.05).collect();
        prop_assume!(lines.len() >= 2);
        let model = Model::from_description(&fibers(&lines, sub)).unwrap();
        let fast = find_candidates(&model, tolerance, None);
        let slow = find_candidates_brute_force(&model, tolerance, None);
        prop_assert_eq!(fast.len(), slow.len());
        for (x, y) in fast.iter().zip(&slow) {
            prop_assert_eq!(x.elements, y.elements);
            prop_assert!((x.distance - y.distance).abs() < 1e-14);
        }
    }

    #[test]
    fn grid_search_with_periodic_images_finds_exactly_the_all_images_candidates(
        lines in prop::collection::vec((point(), point(), 0.005f64..0.05), 2..10),
        sub in 1usize..4,
        tolerance in 0.0f64..0.05,
        period in prop::array::uniform2(0.6f64..2.5),
    ) {
        let lines: Vec<_> = lines.into_iter().filter(|(a, b, _)| (Vector3::from(*b) - Vector3::from(*a)).norm() > 0.05).collect();
        prop_assume!(lines.len() >= 2);
        let model = Model::from_description(&fibers(&lines, sub)).unwrap();
        // Every node independent: only the images differ from the plain search.
        let cell = Periodicity {
            geometry: CellGeometry {
                origin: [-1.0, -1.0],
                size: period,
                z_mid: 0.0,
                thickness: 1.0,
                tolerance: 1e-9,
            },
            master: vec![None; model.nodes.len()],
        };
        let fast = find_candidates(&model, tolerance, Some(&cell));
        let slow = find_candidates_brute_force(&model, tolerance, Some(&cell));
        prop_assert_eq!(fast.len(), slow.len());
        for (x, y) in fast.iter().zip(&slow) {
            prop_assert_eq!((x.elements, x.shift), (y.elements, y.shift));
            prop_assert!((x.distance - y.distance).abs() < 1e-14);
        }
        // Every shifted candidate really is that close: distance between the element and
        // the shifted image.
        for c in fast.iter().filter(|c| c.shift != [0, 0]) {
            let seg = |e: usize, s: [i32; 2]| {
                let el = model.elements()[e];
                el.nodes.map(|n| {
                    let x = model.nodes[n].x;
                    [x[0] + f64::from(s[0]) * period[0], x[1] + f64::from(s[1]) * period[1], x[2]]
                })
            };
            let (a, b) = (seg(c.elements[0], [0, 0]), seg(c.elements[1], c.shift));
            let d = closest_points(&a[0], &a[1], &b[0], &b[1]).distance;
            prop_assert!((d - c.distance).abs() < 1e-12);
        }
    }

    #[test]
    fn penetration_shrinks_like_one_over_the_penalty(p in 1e3f64..1e7) {
        // Table 5.2's bars: penetration = ū (k/p) / (2 + k/p), k = 1000, ū = 0.01.
        let pen = |p: f64| {
            let mut d = io::read_description(Path::new("fixtures/ok_contact_bars1.toml")).unwrap();
            d.contact.as_mut().unwrap().penalty_normal = Some(p);
            let m = Model::from_description(&d).unwrap();
            -solve_incremental(&m, &IncrementalOptions { steps: 1, ..Default::default() }).unwrap().contact_results[0][0].gap
        };
        let (a, b) = (pen(p), pen(10.0 * p));
        let exact = |p: f64| 0.01 * (1000.0 / p) / (2.0 + 1000.0 / p);
        prop_assert!((a - exact(p)).abs() <= 1e-9 * exact(p));
        prop_assert!((b / a - exact(10.0 * p) / exact(p)).abs() < 1e-9);
        prop_assert!(b / a < 0.1 + 0.5 * 1000.0 / p);
    }
}

#[test]
fn open_contacts_contribute_nothing() {
    // The second example below the closing load: identical to the model without contact.
    let d = io::read_description(Path::new("fixtures/ok_contact_bars2.toml")).unwrap();
    let with = Model::from_description(&d).unwrap();
    let sol = solve_incremental(
        &with,
        &IncrementalOptions {
            steps: 5,
            ..Default::default()
        },
    )
    .unwrap();
    let mut plain = d.clone();
    plain.contact = None;
    plain.contacts.clear();
    let reference = solve_static(
        &Model::from_description(&plain).unwrap(),
        &SolveOptions::default(),
    )
    .unwrap();
    for step in 0..2 {
        // α = 0.2, 0.4: open (the gap closes at α = 0.5).
        assert!(sol.contact_results[step][0].normal_force == 0.0);
        let alpha = (step + 1) as f64 / 5.0;
        for (u, r) in sol.displacements[step].iter().zip(&reference.displacements) {
            for k in 0..6 {
                assert!((u[k] - alpha * r[k]).abs() <= 1e-14, "{u:?} vs {r:?}");
            }
        }
    }
}

#[test]
fn a_finely_meshed_fiber_does_not_touch_itself_but_a_folded_one_does() {
    // A U-shaped fiber: two straight legs 3r apart (surface gap r) joined by a half circle, all
    // meshed with elements much shorter than the radius.
    let r = 0.01;
    let mut d = ModelDescription {
        materials: vec![material()],
        ..Default::default()
    };
    let mut ids = Vec::new();
    let mut push = |d: &mut ModelDescription, x: [f64; 3]| {
        let id = d.nodes.len() as u64 + 1;
        d.nodes.push(NodeSpec { id, x });
        ids.push(id);
    };
    let (leg, radius_u, h) = (0.2, 1.5 * r, 0.25 * r);
    let n_leg = (leg / h) as usize;
    for k in 0..=n_leg {
        push(&mut d, [leg - k as f64 * h, -radius_u, 0.0]);
    }
    for k in 1..20 {
        let a = -std::f64::consts::FRAC_PI_2 - std::f64::consts::PI * k as f64 / 20.0;
        push(&mut d, [radius_u * a.cos(), radius_u * a.sin(), 0.0]);
    }
    for k in 0..=n_leg {
        push(&mut d, [k as f64 * h, radius_u, 0.0]);
    }
    d.fibers.push(FiberSpec {
        id: 1,
        nodes: ids,
        radius: r,
        material: "m".into(),
    });
    let model = Model::from_description(&d).unwrap();
    let found = find_candidates(&model, 1.5 * r, None);
    assert!(!found.is_empty(), "the two legs face each other");
    // Every candidate joins the two legs, never neighbours along the fiber.
    for c in &found {
        let y = |e: usize, xi: f64| {
            let el = model.elements()[e];
            let (p, q) = (model.nodes[el.nodes[0]].x[1], model.nodes[el.nodes[1]].x[1]);
            p + xi * (q - p)
        };
        assert!(
            y(c.elements[0], c.xi[0]) * y(c.elements[1], c.xi[1]) < 0.0,
            "{c:?}"
        );
    }
    // The same legs straightened out: no self-contact at all.
    let straight = fibers(&[([0.0; 3], [1.0, 0.0, 0.0], r)], 400);
    assert!(find_candidates(&Model::from_description(&straight).unwrap(), r, None).is_empty());
}

/// A rigid rotation moves the two contact points together: the jump of every contact found
/// by the search vanishes to round-off (10⁻¹² |ω| r) for u = ω × x, θ = ω — also for tilted
/// normals on sloped elements (a jersey), and for the overlapping fibers of a generated
/// non-woven, where the points divide the overlap in proportion to the radii (with levers
/// r_I, r_II alone they were the overlap apart, a jump of |ω × g n|). The centerline jump
/// would be ω × d n.
#[test]
fn a_rigid_rotation_gives_no_contact_jump() {
    let omega = nalgebra::Vector3::new(0.3, -0.2, 0.5);
    let nonwoven =
        fibercell::io::read_description(std::path::Path::new("fixtures/cells/nonwoven_small.toml"))
            .unwrap();
    for mut d in [
        fibercell::generate::crossing_grid(3, 2, 1e-2, 1e-3),
        fibercell::generate::knitted(&fibercell::generate::Knit::default()).unwrap(),
        nonwoven,
    ] {
        // Without the cell: no periodic images, whose jumps carry the macroscopic field.
        d.cell = None;
        let m = fibercell::Model::from_description(&d).unwrap();
        let set = fibercell::contact::ContactSet::build(&m).unwrap();
        assert!(!set.pairs.is_empty());
        for pair in &set.pairs {
            let mut q = nalgebra::SVector::<f64, 30>::zeros();
            for (k, &n) in pair.jump.nodes.iter().enumerate() {
                let u = omega.cross(&nalgebra::Vector3::from(m.nodes[n].x));
                for i in 0..3 {
                    q[6 * k + i] = u[i];
                    q[6 * k + 3 + i] = omega[i];
                }
            }
            let jump = pair.jump.b * q;
            let r = m
                .fibers
                .iter()
                .map(|f| f.section.radius)
                .fold(f64::MAX, f64::min);
            assert!(
                jump.norm() <= 1e-12 * omega.norm() * r,
                "{jump:?}, gap {}",
                pair.gap
            );
        }
    }
}
