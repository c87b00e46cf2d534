//! The friction-driven elasto-plastic curve of a cell. Two x-fibers (y = Ly/4, 3Ly/4) are joined
//! by a y-fiber (x = Lx/5); a short link fiber along y at x = 3Lx/5 is clamped to the lower
//! x-fiber and touches the upper one through a node–node contact with Tresca friction. Straight
//! periodic fibers carry the affine strain by themselves, so under shear it is the link that
//! loads the contact. All stick: the curve is the elastic homogenization A^elas E exactly. With a
//! finite bound: the contact switches to slip at the strain the linear stick solution predicts,
//! the curve bends there, sliding dissipates energy, and a load–unload–reload path shows
//! hysteresis.

mod common;
use fibercell::homogenize::{elasto_plastic_curve, homogenize_elastic, Curve, CurveOptions};
use fibercell::model::{
    CellSpec, ContactPairSpec, ContactSpec, FiberSpec, FrictionSpec, MaterialSpec,
    ModelDescription, NodeSpec, SideSpec,
};
use fibercell::solve::{History, IncrementalOptions, SolveOptions};
use fibercell::{Error, Model};

const LX: f64 = 4e-3;
const LY: f64 = 5e-3;

/// The cell, with Tresca bound `bound` (N) at the link's contact.
fn cell(bound: f64) -> ModelDescription {
    let mut d = ModelDescription {
        materials: vec![MaterialSpec {
            name: "m".into(),
            young: 1e9,
            poisson: Some(0.3),
            shear: None,
        }],
        cell: Some(CellSpec {
            size: [LX, LY],
            origin: Some([0.0, 0.0]),
            thickness: Some(4e-4),
            tolerance: None,
        }),
        ..Default::default()
    };
    let add = |d: &mut ModelDescription, x: f64, y: f64| {
        let id = d.nodes.len() as u64 + 1;
        d.nodes.push(NodeSpec { id, x: [x, y, 0.0] });
        id
    };
    let (x_y, x_link, y1, y2) = (0.2 * LX, 0.6 * LX, 0.25 * LY, 0.75 * LY);
    // x-fibers through the joints at x_y and x_link, split in halves between stations.
    let x_fiber = |d: &mut ModelDescription, y: f64| -> (Vec<u64>, u64, u64) {
        let xs = [
            0.0,
            0.5 * x_y,
            x_y,
            0.5 * (x_y + x_link),
            x_link,
            0.5 * (x_link + LX),
            LX,
        ];
        let ids: Vec<u64> = xs.iter().map(|&x| add(d, x, y)).collect();
        (ids.clone(), ids[2], ids[4])
    };
    let (f1, j1, p) = x_fiber(&mut d, y1);
    let (f2, j2, q) = x_fiber(&mut d, y2);
    // The y-fiber: faces, joints with both x-fibers.
    let ys = [0.0, 0.5 * y1, y1, 0.5 * (y1 + y2), y2, 0.5 * (y2 + LY), LY];
    let yf: Vec<u64> = ys
        .iter()
        .map(|&y| {
            if y == y1 {
                j1
            } else if y == y2 {
                j2
            } else {
                add(&mut d, x_y, y)
            }
        })
        .collect();
    // The link: clamped at p on the lower fiber, its tip q2 coincides with q on the upper fiber.
    let mid = add(&mut d, x_link, 0.5 * (y1 + y2));
    let tip = add(&mut d, x_link, y2);
    for (id, nodes) in [(1, f1), (2, f2), (3, yf), (4, vec![p, mid, tip])] {
        d.fibers.push(FiberSpec {
            id,
            nodes,
            radius: 2e-4,
            material: "m".into(),
        });
    }
    d.contact = Some(ContactSpec {
        search: false,
        penalty_normal: Some(1e6),
        penalty_tangent: Some(1e6),
        friction: FrictionSpec::Tresca { bound },
        ..Default::default()
    });
    d.contacts = vec![ContactPairSpec {
        a: SideSpec::Node { node: q },
        b: SideSpec::Node { node: tip },
        normal: Some([0.0, 0.0, 1.0]),
        gap: 0.0,
        penalty_normal: None,
        penalty_tangent: None,
        penalty_rotation: None,
    }];
    d
}

const SHEAR: [f64; 6] = [0.0, 0.0, 0.01, 0.0, 0.0, 0.0];

fn run(d: &ModelDescription, options: CurveOptions) -> Curve {
    elasto_plastic_curve(&Model::from_description(d).unwrap(), &options).unwrap()
}

fn curve(d: &ModelDescription, steps: usize, unload: bool) -> Curve {
    run(
        d,
        CurveOptions {
            strain: SHEAR,
            steps,
            unload,
            incremental: IncrementalOptions::default(),
        },
    )
}

#[test]
fn all_stick_curve_is_the_elastic_homogenization() {
    let d = cell(1e6);
    let h = homogenize_elastic(
        &Model::from_description(&d).unwrap(),
        &SolveOptions::default(),
    )
    .unwrap();
    assert_eq!(h.contacts, 1);
    let c = curve(&d, 4, false);
    assert!(c.switches.is_empty());
    // The curve's own ABD (six cell problems without Θ) is homogenize_elastic's: same matrix,
    // same solves, up to rounding.
    let scale = h.abd.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    for (row, want) in c.elastic_abd.iter().zip(&h.abd) {
        for (v, w) in row.iter().zip(want) {
            assert!((v - w).abs() <= 1e-12 * scale, "{v} vs {w}");
        }
    }
    for p in &c.points {
        assert_eq!(p.stick, 1);
        for i in 0..6 {
            let want: f64 = (0..6).map(|j| h.abd[i][j] * p.strain[j]).sum();
            assert!(
                (p.resultant[i] - want).abs() <= 1e-8 * h.abd[2][2] * 0.01,
                "{i}: {} vs {want}",
                p.resultant[i]
            );
            assert!(p.plastic[i].abs() <= 1e-8 * h.abd[2][2] * 0.01);
        }
        assert_eq!(p.dissipated, 0.0);
    }
    // The contact carries load: without it the cell is softer in shear.
    let mut no_contact = d.clone();
    no_contact.contact = None;
    no_contact.contacts.clear();
    let soft = homogenize_elastic(
        &Model::from_description(&no_contact).unwrap(),
        &SolveOptions::default(),
    )
    .unwrap();
    assert!(soft.abd[2][2] < 0.99 * h.abd[2][2]);
}

#[test]
fn sliding_starts_where_the_stick_solution_predicts_and_bends_the_curve() {
    let steps = 20;
    // Tangential force of the stuck contact at the full strain (linear in α).
    let stuck = curve(&cell(1e6), 1, false);
    let f1 = stuck.solution.contact_results[0][0].tangential_magnitude;
    assert!(f1 > 0.0);
    let bound = 0.37 * f1;
    let c = curve(&cell(bound), steps, false);
    let predicted = (1..=steps)
        .find(|&n| n as f64 / steps as f64 * f1 > bound)
        .unwrap();
    assert_eq!(c.switches.len(), 1);
    assert_eq!(c.switches[0].step, predicted);
    assert_eq!((c.switches[0].from, c.switches[0].to), ("stick", "slip"));
    assert_eq!(c.segments.len(), 2);
    let (before, after) = (c.segments[0].slope[2], c.segments[1].slope[2]);
    assert!(after < before && after > 0.0, "slopes {before} → {after}");
    for p in &c.points {
        if p.step < predicted {
            assert_eq!(p.dissipated, 0.0);
            assert!(p.plastic[2].abs() <= 1e-8 * p.elastic[2].abs());
        } else {
            assert!(
                p.plastic[2] < 0.0,
                "sliding lowers the resultant below the elastic line"
            );
        }
    }
    assert!(c.points.last().unwrap().dissipated > 0.0);
    // After the switch the contact force stays at the bound.
    let last = c.solution.contact_results.last().unwrap()[0];
    assert!((last.tangential_magnitude - bound).abs() <= 1e-9 * bound);
}

#[test]
fn load_unload_reload_shows_hysteresis() {
    let steps = 10;
    let f1 = curve(&cell(1e6), 1, false).solution.contact_results[0][0].tangential_magnitude;
    let c = curve(&cell(0.4 * f1), steps, true);
    assert_eq!(c.points.len(), 3 * steps);
    let at = |k: usize| &c.points[k - 1];
    // Back at zero strain after unloading, a residual resultant remains.
    assert_eq!(at(2 * steps).alpha, 0.0);
    assert!(at(2 * steps).resultant[2].abs() > 1e-6 * at(steps).resultant[2].abs());
    // Same strain, different resultant on the way down and on the way up (the loop).
    assert!(
        (at(steps + 5).resultant[2] - at(5).resultant[2]).abs()
            > 1e-6 * at(steps).resultant[2].abs()
    );
    // Energy is only dissipated, never returned.
    for w in c.points.windows(2) {
        assert!(w[1].dissipated >= w[0].dissipated - 1e-18);
    }
    assert!(at(3 * steps).dissipated > at(steps).dissipated);
}

#[test]
fn bad_macro_strain_is_an_error() {
    let m = Model::from_description(&cell(1.0)).unwrap();
    let mut s = SHEAR;
    s[0] = f64::NAN;
    let e = elasto_plastic_curve(
        &m,
        &CurveOptions {
            strain: s,
            steps: 5,
            unload: false,
            incremental: IncrementalOptions::default(),
        },
    )
    .unwrap_err();
    assert!(
        matches!(e, Error::InvalidOption(_)) && e.to_string().contains("not finite"),
        "{e}"
    );
}

fn curve_with(d: &ModelDescription, strain: [f64; 6], incremental: IncrementalOptions) -> Curve {
    let steps = 3;
    let unload = false;
    run(
        d,
        CurveOptions {
            strain,
            steps,
            unload,
            incremental,
        },
    )
}

/// Bonded (fixed-topology) contacts never open: under the curvature κ22, which moves the link
/// normal to the contact, the all-stick curve is A^elas E for either sign, the contact carrying
/// compression one way and tension the other; unbonded, it opens under the tensile sign.
#[test]
fn bonded_contacts_carry_tension_and_stay_linear_both_ways() {
    let d = cell(1e6);
    let h = homogenize_elastic(
        &Model::from_description(&d).unwrap(),
        &SolveOptions::default(),
    )
    .unwrap();
    let bonded = IncrementalOptions {
        bonded: true,
        ..IncrementalOptions::default()
    };
    let mut normal_signs = Vec::new();
    const BEND: [f64; 6] = [0.0, 0.0, 0.0, 0.0, 0.01, 0.0];
    for sign in [1.0, -1.0] {
        let strain = BEND.map(|v| sign * v);
        let c = curve_with(&d, strain, bonded.clone());
        for p in &c.points {
            assert_eq!(p.stick, 1);
            for i in 0..6 {
                let want: f64 = (0..6).map(|j| h.abd[i][j] * p.strain[j]).sum();
                assert!(
                    (p.resultant[i] - want).abs() <= 1e-8 * h.abd[4][4] * 0.01,
                    "{i}: {} vs {want}",
                    p.resultant[i]
                );
            }
        }
        let last = c.solution.contact_results.last().unwrap();
        normal_signs.push(last[0].normal_force.signum());
    }
    // Compression one way, tension (a negative normal force) the other.
    assert_eq!(normal_signs[0], -normal_signs[1], "{normal_signs:?}");
    let tensile = if normal_signs[0] < 0.0 { 1.0 } else { -1.0 };
    let unbonded = curve_with(&d, BEND.map(|v| tensile * v), IncrementalOptions::default());
    assert_eq!(unbonded.points.last().unwrap().open, 1);
}

/// Stabilizing springs of relative stiffness ε change nothing when every contact sticks (they
/// act on open and sliding contacts only), and change a sliding curve by ε k_T s, where the slip
/// s is here about 10³ times the elastic tangential jump at the onset: 1e-4 of the resultants
/// for ε = 1e-8.
#[test]
fn stabilization_springs_perturb_the_curve_by_order_epsilon() {
    for bound in [1e6, 1e-3] {
        let d = cell(bound);
        let plain = curve_with(&d, SHEAR, IncrementalOptions::default());
        let stabilized = curve_with(
            &d,
            SHEAR,
            IncrementalOptions {
                stabilization: 1e-8,
                ..IncrementalOptions::default()
            },
        );
        let scale = plain
            .points
            .iter()
            .flat_map(|p| p.resultant)
            .fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(scale > 0.0);
        let sliding = plain.points.last().unwrap().slip;
        assert_eq!(sliding, usize::from(bound < 1.0), "bound {bound}");
        let tol = if bound > 1.0 { 0.0 } else { 1e-4 * scale };
        for (a, b) in plain.points.iter().zip(&stabilized.points) {
            assert_eq!((a.stick, a.slip), (b.stick, b.slip));
            for i in 0..6 {
                assert!(
                    (a.resultant[i] - b.resultant[i]).abs() <= tol,
                    "bound {bound}: {i}: {} vs {}",
                    a.resultant[i],
                    b.resultant[i]
                );
            }
        }
    }
    let bad = IncrementalOptions {
        stabilization: f64::NAN,
        ..IncrementalOptions::default()
    };
    let m = Model::from_description(&cell(1.0)).unwrap();
    let err = elasto_plastic_curve(
        &m,
        &CurveOptions {
            strain: SHEAR,
            steps: 2,
            unload: false,
            incremental: bad,
        },
    )
    .unwrap_err();
    assert!(
        matches!(err, Error::InvalidOption(ref s) if s.contains("stabilization")),
        "{err}"
    );
}

/// A deadline already past stops the curve after its first increment; without one every
/// increment runs, and the first point is the same either way.
#[test]
fn a_past_deadline_stops_the_curve_after_one_increment() {
    let d = cell(1e6);
    let full = curve_with(&d, SHEAR, IncrementalOptions::default());
    let boxed = curve_with(
        &d,
        SHEAR,
        IncrementalOptions {
            deadline: Some(std::time::Instant::now()),
            ..IncrementalOptions::default()
        },
    );
    assert_eq!(full.points.len(), 3);
    assert_eq!(boxed.points.len(), 1);
    assert_eq!(boxed.points[0].resultant, full.points[0].resultant);
}

/// A curve keeps the full outputs (displacements, contact records) of its last increment only,
/// unless asked for all: the points, switches and every increment's contact states are the
/// same either way, the last increment's outputs too, and the earlier ones are empty. Here
/// one contact slides from the eighth of 20 increments, so the states show the switch.
#[test]
fn a_curve_keeps_the_last_increments_outputs_unless_asked_for_all() {
    let d = cell(
        0.37 * curve(&cell(1e6), 1, false).solution.contact_results[0][0].tangential_magnitude,
    );
    let with = |history| {
        run(
            &d,
            CurveOptions {
                strain: SHEAR,
                steps: 20,
                unload: true,
                incremental: IncrementalOptions {
                    history,
                    ..IncrementalOptions::default()
                },
            },
        )
    };
    let (last, all) = (with(History::Auto), with(History::All));
    assert_eq!(last.points, all.points);
    assert_eq!(last.switches.len(), all.switches.len());
    assert!(!all.switches.is_empty());
    let (l, a) = (&last.solution, &all.solution);
    assert_eq!(l.contact_states, a.contact_states);
    assert_eq!(l.contact_states.len(), 60);
    let n = l.increments.len();
    assert_eq!((l.displacements.len(), l.contact_results.len()), (n, n));
    assert!(l.displacements[..n - 1].iter().all(Vec::is_empty));
    assert!(l.contact_results[..n - 1].iter().all(Vec::is_empty));
    assert_eq!(l.displacements[n - 1], a.displacements[n - 1]);
    assert_eq!(l.contact_results[n - 1], a.contact_results[n - 1]);
    assert!(a.displacements.iter().all(|u| !u.is_empty()));
    // The 59 emptied increments' outputs are what the run no longer holds.
    let record = size_of::<fibercell::solve::ContactRecord>();
    let per = 48 * a.displacements[0].len() + record * a.contact_results[0].len();
    assert!(per > 0);
    assert!(a.memory_bytes() - l.memory_bytes() >= (n - 1) * per);
    assert!(l.memory_bytes() >= per);
}
