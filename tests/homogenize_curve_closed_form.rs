//! The elasto-plastic curve of a single-contact cell against its closed form.
//!
//! The cell (L_x × L_y) holds three straight fibers of axial stiffness EA:
//! * P along x at y = L_y/4, continuous across the cell;
//! * a fiber along x at y = 3L_y/4 cut at x = a into C (0 → a) and D (a → L_x): the cut ends
//!   are two coincident nodes joined by one contact with normal z, tangential penalty p_T and
//!   Tresca bound G; through the periodic boundary D's end is C's start, so C, the contact and
//!   D form one loop in series;
//! * Y along y at x = L_x/5, rigidly joined to P and C (percolation in y).
//!
//! Under ε11 every fiber is straight and only axial forces arise: P carries EA ε; the loop
//! stretches by ε L_x through C, the contact and D in series, k_s = 1/(L_x/EA + 1/p_T), so
//! it carries F = k_s L_x ε while stuck. Y joins P and C at one point each and only translates.
//! Hence, per unit width (L_y),
//!
//! * stick:  N11 = (EA + k_s L_x) ε / L_y, until F = G at ε* = G/(k_s L_x);
//! * slip:   N11 = (EA ε + G)/L_y (slope EA/L_y), slip s = L_x (ε − ε*), dissipation G s;
//! * unloading from ε_max: stick until F = −G at ε_max − 2ε*, then reverse sliding; at ε = 0 a
//!   residual N11 = −G/L_y remains; reloading sticks until ε = 2ε*.
//!
//! Every other resultant is zero. Tolerances: 1e-8 relative (penalty solutions are exact for
//! this discrete model; the solver's backward error is below 1e-10).

use fibercell::homogenize::{elasto_plastic_curve, homogenize_elastic, Curve, CurveOptions};
use fibercell::model::{
    CellSpec, ContactPairSpec, ContactSpec, FiberSpec, FrictionSpec, MaterialSpec,
    ModelDescription, NodeSpec, SideSpec,
};
use fibercell::solve::{IncrementalOptions, SolveOptions};
use fibercell::Model;

const LX: f64 = 4e-3;
const LY: f64 = 5e-3;
const YOUNG: f64 = 1e9;
const RADIUS: f64 = 2e-4;
const P_T: f64 = 1e5;
const BOUND: f64 = 0.5;

fn ea() -> f64 {
    YOUNG * std::f64::consts::PI * RADIUS * RADIUS
}

/// k_s L_x: the loop's force per unit macroscopic strain while stuck.
fn loop_stiffness() -> f64 {
    LX / (LX / ea() + 1.0 / P_T)
}

fn cell() -> ModelDescription {
    let mut d = ModelDescription {
        materials: vec![MaterialSpec {
            name: "m".into(),
            young: YOUNG,
            poisson: Some(0.3),
            shear: None,
        }],
        cell: Some(CellSpec {
            size: [LX, LY],
            origin: Some([0.0, 0.0]),
            thickness: Some(4.0 * RADIUS),
            tolerance: None,
        }),
        ..Default::default()
    };
    let mut add = |x: f64, y: f64| {
        let id = d.nodes.len() as u64 + 1;
        d.nodes.push(NodeSpec { id, x: [x, y, 0.0] });
        id
    };
    let (xj, a, yp, yc) = (0.2 * LX, 0.6 * LX, 0.25 * LY, 0.75 * LY);
    let p = [add(0.0, yp), add(xj, yp), add(LX, yp)];
    let c = [add(0.0, yc), add(xj, yc), add(a, yc)];
    let dd = [add(a, yc), add(0.5 * (a + LX), yc), add(LX, yc)];
    let y = [add(xj, 0.0), p[1], c[1], add(xj, LY)];
    for (id, nodes) in [
        (1, p.to_vec()),
        (2, c.to_vec()),
        (3, dd.to_vec()),
        (4, y.to_vec()),
    ] {
        d.fibers.push(FiberSpec {
            id,
            nodes,
            radius: RADIUS,
            material: "m".into(),
        });
    }
    d.contact = Some(ContactSpec {
        search: false,
        penalty_normal: Some(1e6),
        penalty_tangent: Some(P_T),
        penalty_rotation: Some(0.0),
        friction: FrictionSpec::Tresca { bound: BOUND },
        ..Default::default()
    });
    d.contacts = vec![ContactPairSpec {
        a: SideSpec::Node { node: c[2] },
        b: SideSpec::Node { node: dd[0] },
        normal: Some([0.0, 0.0, 1.0]),
        gap: 0.0,
        penalty_normal: None,
        penalty_tangent: None,
        penalty_rotation: None,
    }];
    d
}

const E_MAX: f64 = 0.02;

fn run(steps: usize, unload: bool) -> Curve {
    let m = Model::from_description(&cell()).unwrap();
    elasto_plastic_curve(
        &m,
        &CurveOptions {
            strain: [E_MAX, 0.0, 0.0, 0.0, 0.0, 0.0],
            steps,
            unload,
            incremental: IncrementalOptions::default(),
        },
    )
    .unwrap()
}

/// The loop force F along the path (load to E_MAX, unload to 0, reload), from the closed form.
fn loop_force(path: &[f64]) -> Vec<f64> {
    let k = loop_stiffness();
    let mut f = 0.0;
    let mut e_prev = 0.0;
    path.iter()
        .map(|&e| {
            f = (f + k * (e - e_prev)).clamp(-BOUND, BOUND);
            e_prev = e;
            f
        })
        .collect()
}

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-8 * scale
}

#[test]
fn the_all_stick_moduli_are_the_series_and_parallel_springs() {
    let h = homogenize_elastic(
        &Model::from_description(&cell()).unwrap(),
        &SolveOptions::default(),
    )
    .unwrap();
    let a11 = (ea() + loop_stiffness()) / LY;
    assert!(close(h.abd[0][0], a11, a11), "{} vs {a11}", h.abd[0][0]);
}

#[test]
fn monotonic_loading_switches_at_the_closed_form_strain_and_slope() {
    let steps = 20;
    let c = run(steps, false);
    let e_star = BOUND / loop_stiffness();
    let scale = (ea() * E_MAX + BOUND) / LY;
    let path: Vec<f64> = c.points.iter().map(|p| p.strain[0]).collect();
    for (p, f) in c.points.iter().zip(loop_force(&path)) {
        let e = p.strain[0];
        let want = (ea() * e + f) / LY;
        assert!(
            close(p.resultant[0], want, scale),
            "step {}: N11 {} vs {want}",
            p.step,
            p.resultant[0]
        );
        for i in 1..6 {
            assert!(p.resultant[i].abs() <= 1e-8 * scale, "component {i}");
        }
        let dissipated = BOUND * LX * (e - e_star).max(0.0) / (LX * LY);
        assert!(
            close(p.dissipated, dissipated, BOUND * E_MAX / LY),
            "step {}: dissipated {} vs {dissipated}",
            p.step,
            p.dissipated
        );
    }
    // One switch, in the increment that contains ε*, located at ε* by the pieces' lines.
    assert_eq!(c.switches.len(), 1);
    let s = &c.switches[0];
    assert_eq!((s.from, s.to), ("stick", "slip"));
    assert_eq!(s.step, (e_star / E_MAX * steps as f64).ceil() as usize);
    assert!(
        close(s.estimated_strain[0], e_star, e_star),
        "switch at {} vs {e_star}",
        s.estimated_strain[0]
    );
    // Two pieces with the stick and slip slopes (dN/dα = slope in ε × E_MAX).
    assert_eq!(c.segments.len(), 2);
    let stick = (ea() + loop_stiffness()) / LY * E_MAX;
    let slip = ea() / LY * E_MAX;
    assert!(close(c.segments[0].slope[0], stick, stick));
    assert!(close(c.segments[1].slope[0], slip, stick));
    // The plastic part is what sliding takes off the all-stick line.
    let last = c.points.last().unwrap();
    let plastic = (BOUND - loop_stiffness() * E_MAX) / LY;
    assert!(close(last.plastic[0], plastic, scale));
}

#[test]
fn unloading_and_reloading_follow_the_hysteresis_loop() {
    let steps = 20;
    let c = run(steps, true);
    assert_eq!(c.points.len(), 3 * steps);
    let e_star = BOUND / loop_stiffness();
    let scale = (ea() * E_MAX + BOUND) / LY;
    let path: Vec<f64> = c.points.iter().map(|p| p.strain[0]).collect();
    for (p, f) in c.points.iter().zip(loop_force(&path)) {
        let want = (ea() * p.strain[0] + f) / LY;
        assert!(
            close(p.resultant[0], want, scale),
            "step {}: N11 {} vs {want}",
            p.step,
            p.resultant[0]
        );
    }
    // Residual resultant −G/L_y at zero strain after unloading.
    let zero = &c.points[2 * steps - 1];
    assert_eq!(zero.alpha, 0.0);
    assert!(close(zero.resultant[0], -BOUND / LY, scale));
    // Slip events: loading (ε*), reversal (ε_max − 2ε*), reloading (2ε*), each located exactly.
    let to_slip: Vec<f64> = c
        .switches
        .iter()
        .filter(|s| s.to == "slip")
        .map(|s| s.estimated_strain[0])
        .collect();
    let want = [e_star, E_MAX - 2.0 * e_star, 2.0 * e_star];
    assert_eq!(to_slip.len(), 3, "{:?}", c.switches);
    for (got, want) in to_slip.iter().zip(want) {
        assert!(close(*got, want, e_star), "switch at {got} vs {want}");
    }
    // Dissipation: G × total slip = G L_x [(ε_max − ε*) + (ε_max − 2ε*) + (ε_max − 2ε*)].
    let total = BOUND * (3.0 * E_MAX - 5.0 * e_star) / LY;
    let got = c.points.last().unwrap().dissipated;
    assert!(close(got, total, total), "{got} vs {total}");
}
