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
use fibercell::solve::{IncrementalOptions, SolveOptions};
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

fn curve(d: &ModelDescription, steps: usize, unload: bool) -> Curve {
    let m = Model::from_description(d).unwrap();
    elasto_plastic_curve(
        &m,
        &CurveOptions {
            strain: SHEAR,
            steps,
            unload,
            incremental: IncrementalOptions::default(),
        },
    )
    .unwrap()
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
