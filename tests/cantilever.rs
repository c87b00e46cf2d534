//! Cantilever tip displacements and rotations against Euler–Bernoulli closed forms.
//! Cubic Hermite elements are exact at the nodes for end loads, so the tolerance is 1e-10.

mod common;
use common::*;
use fibercell::solve::{solve_static, SolveOptions};
use std::f64::consts::PI;

const L: f64 = 1.3;
const R: f64 = 0.01;
const TOL: f64 = 1e-10;

fn props() -> (f64, f64, f64) {
    let a = PI * R * R;
    let i = PI * R.powi(4) / 4.0;
    let j = PI * R.powi(4) / 2.0;
    let g = E / (2.0 * (1.0 + NU));
    (E * a, E * i, g * j)
}

fn tip(a: [f64; 3], b: [f64; 3], n: usize, f: [f64; 3], m: [f64; 3]) -> [f64; 6] {
    let model = build(&cantilever(a, b, n, R, f, m));
    let sol = solve_static(&model, &SolveOptions::default()).expect("solves");
    sol.displacements[n]
}

fn check(got: f64, want: f64, scale: f64, what: &str) {
    assert!(
        (got - want).abs() <= TOL * scale,
        "{what}: got {got:e}, want {want:e}"
    );
}

#[test]
fn axial_force_along_x() {
    let (ea, _, _) = props();
    let p = 1e3;
    let u = tip([0.0; 3], [L, 0.0, 0.0], 4, [p, 0.0, 0.0], [0.0; 3]);
    let want = p * L / ea;
    check(u[0], want, want, "u");
    for (k, &v) in u.iter().enumerate().skip(1) {
        check(v, 0.0, want, &format!("dof {k}"));
    }
}

#[test]
fn transverse_forces_in_both_planes() {
    let (_, ei, _) = props();
    let p = 3.0;
    let u = tip([0.0; 3], [L, 0.0, 0.0], 5, [0.0, p, 0.0], [0.0; 3]);
    let (d, th) = (p * L.powi(3) / (3.0 * ei), p * L * L / (2.0 * ei));
    check(u[1], d, d, "uy");
    check(u[5], th, th, "rz");
    let u = tip([0.0; 3], [L, 0.0, 0.0], 5, [0.0, 0.0, p], [0.0; 3]);
    check(u[2], d, d, "uz");
    check(
        u[4],
        -th,
        th,
        "ry (right-hand rule: +z load turns the tip about −y)",
    );
}

#[test]
fn torsion_and_end_moment() {
    let (_, ei, gj) = props();
    let t = 2.0;
    let u = tip([0.0; 3], [L, 0.0, 0.0], 3, [0.0; 3], [t, 0.0, 0.0]);
    check(u[3], t * L / gj, t * L / gj, "rx");
    let m = 1.5;
    let u = tip([0.0; 3], [L, 0.0, 0.0], 3, [0.0; 3], [0.0, m, 0.0]);
    check(u[4], m * L / ei, m * L / ei, "ry");
    check(u[2], -m * L * L / (2.0 * ei), m * L * L / (2.0 * ei), "uz");
}

#[test]
fn fiber_parallel_to_global_z() {
    let (ea, ei, gj) = props();
    let (p, t) = (2.0, 0.7);
    let u = tip(
        [0.0; 3],
        [0.0, 0.0, L],
        4,
        [p, 0.0, -100.0 * p],
        [0.0, 0.0, t],
    );
    let d = p * L.powi(3) / (3.0 * ei);
    check(u[0], d, d, "ux");
    check(u[4], p * L * L / (2.0 * ei), d, "ry");
    check(u[2], -100.0 * p * L / ea, 100.0 * p * L / ea, "uz");
    check(u[5], t * L / gj, t * L / gj, "rz");
}

#[test]
fn oblique_cantilever_matches_rotated_closed_form() {
    let (ea, ei, _) = props();
    // Axis e along (1, 2, 2)/3; a load with an axial part and a transverse part.
    let e = [1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0];
    let n = [2.0 / 3.0, 1.0 / 3.0, -2.0 / 3.0]; // ⟂ e
    let (pa, pt) = (500.0, 4.0);
    let f = [
        pa * e[0] + pt * n[0],
        pa * e[1] + pt * n[1],
        pa * e[2] + pt * n[2],
    ];
    let u = tip(
        [0.1, -0.2, 0.3],
        [0.1 + L * e[0], -0.2 + L * e[1], 0.3 + L * e[2]],
        6,
        f,
        [0.0; 3],
    );
    let (da, dt) = (pa * L / ea, pt * L.powi(3) / (3.0 * ei));
    for k in 0..3 {
        let want = da * e[k] + dt * n[k];
        check(u[k], want, dt, &format!("u{k}"));
    }
    // Rotation θ = PL²/(2EI) about e × n.
    let th = pt * L * L / (2.0 * ei);
    let axis = [
        e[1] * n[2] - e[2] * n[1],
        e[2] * n[0] - e[0] * n[2],
        e[0] * n[1] - e[1] * n[0],
    ];
    for k in 0..3 {
        check(u[3 + k], th * axis[k], th, &format!("r{k}"));
    }
}
