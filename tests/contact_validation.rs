//! Contact validation: the thesis's Tables 5.2 and 5.3, two crossing beams against the
//! series-spring closed form, and stick/slip against the closed form of a pressed, pulled fiber.

use fibercell::contact::ContactState;
use fibercell::io;
use fibercell::model::ModelDescription;
use fibercell::solve::{
    solve_incremental, IncrementalOptions, IncrementalSolution, SolverKind, MAX_SETTLED_RESIDUAL,
};
use fibercell::{Error, Model};
use std::path::Path;

fn run(d: &ModelDescription, steps: usize) -> IncrementalSolution {
    let m = Model::from_description(d).expect("valid");
    solve_incremental(
        &m,
        &IncrementalOptions {
            steps,
            ..Default::default()
        },
    )
    .expect("solves")
}

fn with_penalty(path: &str, p: f64) -> ModelDescription {
    let mut d = io::read_description(Path::new(path)).unwrap();
    d.contact.as_mut().unwrap().penalty_normal = Some(p);
    d
}

#[test]
fn thesis_table_5_2_first_example() {
    // Table 5.2: −3.33333, −4.76190, −4.97512, −4.99750 N. Closed form for k = 1000, ū = 0.01:
    // F = −k ū (1 − (1 + k/p)/(2 + k/p)) — printed to 6 digits in the thesis, exact here.
    for (p, table) in [
        (1e3, -3.33333),
        (1e4, -4.76190),
        (1e5, -4.97512),
        (1e6, -4.99750),
    ] {
        let sol = run(&with_penalty("fixtures/ok_contact_bars1.toml", p), 1);
        let n = -sol.contact_results[0][0].normal_force;
        let k = 1000.0;
        let exact = -k * 0.01 * (1.0 - (1.0 + k / p) / (2.0 + k / p));
        assert!(
            (n - exact).abs() <= 1e-9 * exact.abs(),
            "p = {p}: {n} vs {exact}"
        );
        assert!((n - table).abs() <= 5e-6, "p = {p}: {n} vs table {table}");
        // The thesis's relative-error column, |F̄ − F| / |F̄| with F̄ = −5 N (THESIS-NOTES item 7).
        let rel = (n + 5.0).abs() / 5.0;
        let table_rel = (table + 5.0f64).abs() / 5.0;
        assert!(
            (rel - table_rel).abs() <= 2e-6,
            "p = {p}: {rel} vs {table_rel}"
        );
    }
}

#[test]
fn thesis_table_5_3_second_example_corrected() {
    // N = 2.5 p / (p + 250): 0.714286 (p = 100, the corrected misprint), 2.00000, 2.43902,
    // 2.49377, 2.49938.
    for (p, table) in [
        (1e2, 0.714286),
        (1e3, 2.00000),
        (1e4, 2.43902),
        (1e5, 2.49377),
        (1e6, 2.49938),
    ] {
        for steps in [1, 5] {
            let sol = run(&with_penalty("fixtures/ok_contact_bars2.toml", p), steps);
            let n = sol.contact_results[steps - 1][0].normal_force;
            let exact = 2.5 * p / (p + 250.0);
            assert!((n - exact).abs() <= 1e-9 * exact, "p = {p}: {n} vs {exact}");
            assert!((n - table).abs() <= 5e-6, "p = {p}: {n} vs table {table}");
        }
    }
    // Below the load that closes the gap (F·α with 2Fα < g k, i.e. α < 0.5) the contact is open.
    let sol = run(&with_penalty("fixtures/ok_contact_bars2.toml", 1e6), 4);
    assert_eq!(sol.contact_results[0][0].state, ContactState::Open);
    assert_eq!(sol.contact_results[0][0].normal_force, 0.0);
    assert!(sol.contact_results[3][0].normal_force > 0.0);
}

/// Beam A along x and beam B along y, both clamped at both ends, crossing at their middles; B is
/// pressed down by P at the crossing. Series springs: N = P (p/k_B) / (1 + p/k_B + p/k_A) with
/// the clamped–clamped midspan stiffness k = 192 EI/L³.
fn crossing(p: Option<f64>) -> String {
    let (l, ra, rb) = (1.0, 0.01, 0.015);
    let z = ra + rb;
    let penalty = p.map_or(String::new(), |p| format!("penalty_normal = {p:e}\n"));
    format!(
        r#"
[[materials]]
name = "steel"
young = 2.0e11
poisson = 0.3
[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]
[[nodes]]
id = 2
x = [{h}, 0.0, 0.0]
[[nodes]]
id = 3
x = [{l}, 0.0, 0.0]
[[nodes]]
id = 4
x = [{h}, -{h}, {z}]
[[nodes]]
id = 5
x = [{h}, 0.0, {z}]
[[nodes]]
id = 6
x = [{h}, {h}, {z}]
[[fibers]]
id = 1
nodes = [1, 2, 3]
radius = {ra}
material = "steel"
[[fibers]]
id = 2
nodes = [4, 5, 6]
radius = {rb}
material = "steel"
[[supports]]
node = 1
dofs = ["all"]
[[supports]]
node = 3
dofs = ["all"]
[[supports]]
node = 4
dofs = ["all"]
[[supports]]
node = 6
dofs = ["all"]
[[loads]]
node = 5
force = [0.0, 0.0, -100.0]
[contact]
{penalty}"#,
        h = l / 2.0
    )
}

#[test]
fn crossing_beams_split_the_load_like_series_springs() {
    let (e, l, ra, rb, load) = (2.0e11f64, 1.0f64, 0.01f64, 0.015f64, 100.0f64);
    let pi = std::f64::consts::PI;
    let k = |r: f64| 192.0 * e * pi * r.powi(4) / 4.0 / l.powi(3);
    let (ka, kb) = (k(ra), k(rb));
    let limit = load * ka / (ka + kb);
    let mut errors = Vec::new();
    for scale in [1e1, 1e2, 1e3, 1e4] {
        let p = scale * kb;
        let d = io::parse_toml(&crossing(Some(p)), "crossing.toml").unwrap();
        let sol = run(&d, 1);
        assert_eq!(
            sol.contacts.pairs.len(),
            1,
            "one contact at the crossing, not one per element pair"
        );
        let n = sol.contact_results[0][0].normal_force;
        let exact = load * (p / kb) / (1.0 + p / kb + p / ka);
        assert!(
            (n - exact).abs() <= 1e-8 * exact,
            "p = {p:e}: {n} vs {exact}"
        );
        errors.push((limit - n) * p);
    }
    // The error against the exact split decays like 1/p: (limit − N)·p → P / (k_B S²) with
    // S = 1/k_A + 1/k_B.
    let s = 1.0 / ka + 1.0 / kb;
    let c = load / (kb * s * s);
    for (k, err) in errors.iter().enumerate() {
        let tol = [0.2, 2e-2, 2e-3, 2e-4][k];
        assert!(((err - c) / c).abs() < tol, "{errors:?} vs {c}");
    }
    // The automatic penalty gets the split within 1 %.
    let sol = run(
        &io::parse_toml(&crossing(None), "crossing.toml").unwrap(),
        1,
    );
    let n = sol.contact_results[0][0].normal_force;
    assert!((n - limit).abs() < 1e-2 * limit, "{n} vs {limit}");
}

/// A vertical fiber (nodes 3–4) stands on a rigid base point (node 2) with an interference
/// fit g₀ (gap −g₀, resolved by the penalty: a constant normal force N), and its top is pulled
/// sideways by δ·α. Stick: |F_t| = α T₁ with T₁ = δ k_b p_T / (k_b + p_T), k_b = 3EI/L³ (the
/// fiber is a cantilever clamped at the top); slip from α* = bound / T₁ on, then |F_t| = bound.
fn pulled(friction: &str, delta: f64) -> String {
    format!(
        r#"
[[materials]]
name = "m"
young = 1.0e9
poisson = 0.3
[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]
[[nodes]]
id = 2
x = [1.0, 0.0, 0.0]
[[nodes]]
id = 3
x = [1.0, 0.0, 0.0]
[[nodes]]
id = 4
x = [1.0, 0.0, 1.0]
[[fibers]]
id = 1
nodes = [1, 2]
radius = 0.01
material = "m"
[[fibers]]
id = 2
nodes = [3, 4]
radius = 0.01
material = "m"
[[supports]]
node = 1
dofs = ["all"]
[[supports]]
node = 2
dofs = ["all"]
[[supports]]
node = 4
dofs = ["uy", "uz", "rotations"]
[[supports]]
node = 4
dofs = ["ux"]
value = {delta}
[contact]
search = false
penalty_normal = 1.0e5
penalty_tangent = 2.0e4
# A point contact, as in the closed form: no rolling resistance.
penalty_rotation = 0.0
initial_penetration = "resolve"
friction = {friction}
[[contacts]]
a = {{ node = 2 }}
b = {{ node = 3 }}
normal = [0.0, 0.0, 1.0]
gap = -1.0e-5
"#
    )
}

struct Pulled {
    normal: f64,
    t1: f64,
}

fn pulled_closed_form(delta: f64) -> Pulled {
    let (e, r, l, pn, pt, g0) = (1.0e9, 0.01f64, 1.0, 1.0e5, 2.0e4, 1.0e-5);
    let pi = std::f64::consts::PI;
    let ka = e * pi * r * r / l;
    let kb = 3.0 * e * pi * r.powi(4) / 4.0 / l.powi(3);
    Pulled {
        normal: pn * g0 * ka / (ka + pn),
        t1: delta * kb * pt / (kb + pt),
    }
}

#[test]
fn coulomb_stick_then_slip_plateau_at_mu_n() {
    let (delta, steps, mu) = (0.02, 40, 0.3);
    let cf = pulled_closed_form(delta);
    let d = io::parse_toml(
        &pulled(&format!("{{ law = \"coulomb\", mu = {mu} }}"), delta),
        "p.toml",
    )
    .unwrap();
    let sol = run(&d, steps);
    let alpha_star = mu * cf.normal / cf.t1;
    assert!(
        alpha_star > 0.2 && alpha_star < 0.8,
        "the test should switch mid-way: α* = {alpha_star}"
    );
    let mut switched = false;
    for (n, rec) in sol.contact_results.iter().enumerate() {
        let alpha = (n + 1) as f64 / steps as f64;
        let c = rec[0];
        assert!(
            (c.normal_force - cf.normal).abs() <= 1e-9 * cf.normal,
            "N = {}",
            c.normal_force
        );
        if alpha <= alpha_star * (1.0 - 1e-9) {
            assert_eq!(c.state, ContactState::Stick, "α = {alpha}");
            assert!((c.tangential_magnitude - alpha * cf.t1).abs() <= 1e-8 * cf.t1);
        } else {
            assert_eq!(c.state, ContactState::Slip, "α = {alpha}");
            assert!(
                (c.tangential_magnitude - mu * cf.normal).abs() <= 1e-9 * cf.normal,
                "plateau"
            );
            switched = true;
        }
        assert_eq!(
            sol.increments[n].slip + sol.increments[n].stick + sol.increments[n].open,
            1
        );
    }
    assert!(switched);
    // Sliding under Coulomb friction is nonsymmetric: solved by LU, or on the symmetric stick
    // factorization with the sliding contact as a nonsymmetric low-rank correction (chosen by
    // measured cost).
    let backend = &sol.increments.last().unwrap().backend;
    assert!(backend == "faer-lu" || backend == "low-rank", "{backend}");
}

#[test]
fn tresca_plateau_large_mu_and_switch_increment() {
    let (delta, steps) = (0.02, 40);
    let cf = pulled_closed_form(delta);
    // Tresca: plateau at G.
    let g = 0.5 * cf.t1;
    let d = io::parse_toml(
        &pulled(&format!("{{ law = \"tresca\", bound = {g} }}"), delta),
        "p.toml",
    )
    .unwrap();
    let sol = run(&d, steps);
    let last = sol.contact_results.last().unwrap()[0];
    assert_eq!(last.state, ContactState::Slip);
    assert!((last.tangential_magnitude - g).abs() <= 1e-9 * g);
    assert_ne!(
        sol.increments.last().unwrap().backend,
        "faer-lu",
        "Tresca sliding stays symmetric"
    );
    // A large μ never lets go.
    let d = io::parse_toml(
        &pulled("{ law = \"coulomb\", mu = 100.0 }", delta),
        "p.toml",
    )
    .unwrap();
    let sol = run(&d, steps);
    assert!(sol
        .contact_results
        .iter()
        .all(|r| r[0].state == ContactState::Stick));
    // The first sliding increment is the first n with (n/N) T₁ > μ N, for several μ.
    for mu in [0.1, 0.2, 0.35, 0.5] {
        let d = io::parse_toml(
            &pulled(&format!("{{ law = \"coulomb\", mu = {mu} }}"), delta),
            "p.toml",
        )
        .unwrap();
        let sol = run(&d, steps);
        let first = sol
            .contact_results
            .iter()
            .position(|r| r[0].state == ContactState::Slip)
            .map(|n| n + 1);
        let predicted = (1..=steps).find(|&n| n as f64 / steps as f64 * cf.t1 > mu * cf.normal);
        assert_eq!(first, predicted, "μ = {mu}");
    }
}

#[test]
fn symmetric_backends_agree_on_contact_problems() {
    for kind in [SolverKind::FaerCholesky, SolverKind::Cg] {
        let m = io::load_model(Path::new("fixtures/ok_contact_bars2.toml")).unwrap();
        let mut o = IncrementalOptions {
            steps: 2,
            ..Default::default()
        };
        o.solve.solver = kind;
        let sol = solve_incremental(&m, &o).unwrap();
        let n = sol.contact_results[1][0].normal_force;
        assert!((n - 2.0).abs() < 1e-8, "{kind}: {n}");
    }
}

#[test]
fn fixed_slip_direction_variant_of_remark_4_38() {
    // The pulled fiber slides along x either way: the thesis's frictionless pre-run gives the
    // same direction as the return mapping, so the two variants agree.
    let (delta, steps, mu) = (0.02, 20, 0.3);
    let d = io::parse_toml(
        &pulled(&format!("{{ law = \"coulomb\", mu = {mu} }}"), delta),
        "p.toml",
    )
    .unwrap();
    let m = Model::from_description(&d).unwrap();
    let a = solve_incremental(
        &m,
        &IncrementalOptions {
            steps,
            ..Default::default()
        },
    )
    .unwrap();
    let b = solve_incremental(
        &m,
        &IncrementalOptions {
            steps,
            fixed_slip_direction: true,
            ..Default::default()
        },
    )
    .unwrap();
    for (x, y) in a.contact_results.iter().zip(&b.contact_results) {
        assert_eq!(x[0].state, y[0].state);
        assert!((x[0].tangential_magnitude - y[0].tangential_magnitude).abs() <= 1e-12);
    }
    // Increments that change no state reuse the factorization.
    for (k, inc) in a.increments.iter().enumerate().skip(1) {
        let same = a.contact_results[k][0].state == a.contact_results[k - 1][0].state;
        if same && inc.iterations == 1 {
            assert_eq!(inc.factorizations, 0, "increment {}", inc.step);
        }
    }
}

#[test]
fn progress_is_reported_after_every_increment() {
    use std::sync::{Arc, Mutex};
    let seen = Arc::new(Mutex::new(Vec::new()));
    let log = seen.clone();
    let m = io::load_model(Path::new("fixtures/ok_contact_bars2.toml")).unwrap();
    let opts = IncrementalOptions {
        steps: 3,
        progress: Some(fibercell::solve::Progress(Arc::new(
            move |done, total, _| log.lock().unwrap().push((done, total)),
        ))),
        ..Default::default()
    };
    solve_incremental(&m, &opts).unwrap();
    assert_eq!(*seen.lock().unwrap(), vec![(1, 3), (2, 3), (3, 3)]);
}

/// The penalty limit of a contact force across twelve decades: the crossing beams above with
/// p = 10⁰ … 10¹² × the default penalty (1000 × the stiffer element's 12EI/L³). The force is
/// the closed form N(p) = P (p/k_B)/(1 + p/k_B + p/k_A) up to round-off, which grows with p:
/// measured |N − N(p)|/N(p) = 5·10⁻¹³ at 10⁰, 10⁻⁸ at 10⁴, 2·10⁻⁶ at 10⁷, 6·10⁻⁵ at 10⁸, 100 %
/// at 10¹² (the penetration N/p is then below the displacements' round-off). The increment's
/// equilibrium residual ‖R‖/‖F‖ tracks it in every decade (the elements carry the force the
/// displacements give, the law the one the penetration gives; their difference is R at the
/// contact): |N − N(p)| ≤ 2 ‖R‖ ‖F‖, measured 1.3, ‖F‖ = P. Where the residual passes
/// [`MAX_SETTLED_RESIDUAL`] (10⁻⁶: from 10⁸, 7·10⁻⁶) the run is refused with
/// `Error::RoundOff` instead of returning the force. Up to 10³ the force is the closed form to
/// 10⁻⁹; up to 10², where round-off is far below the penalty error, the distance to the rigid
/// limit P k_A/(k_A + k_B) falls like 1/p.
#[test]
fn the_contact_force_reaches_its_rigid_limit_across_twelve_decades() {
    let (e, l, ra, rb, load) = (2.0e11f64, 1.0f64, 0.01f64, 0.015f64, 100.0f64);
    let pi = std::f64::consts::PI;
    let k = |r: f64| 192.0 * e * pi * r.powi(4) / 4.0 / l.powi(3);
    let (ka, kb) = (k(ra), k(rb));
    let limit = load * ka / (ka + kb);
    let default = run(
        &io::parse_toml(&crossing(None), "crossing.toml").unwrap(),
        1,
    )
    .contacts
    .pairs[0]
        .penalty_normal;
    let mut penalty_errors = Vec::new();
    let mut refused = Vec::new();
    for j in 0..=12 {
        let p = default * 10f64.powi(j);
        let d = io::parse_toml(&crossing(Some(p)), "crossing.toml").unwrap();
        let m = Model::from_description(&d).unwrap();
        let options = IncrementalOptions {
            steps: 1,
            ..Default::default()
        };
        let sol = match solve_incremental(&m, &options) {
            Ok(sol) => sol,
            Err(Error::RoundOff { residual, .. }) => {
                assert!(residual > MAX_SETTLED_RESIDUAL);
                refused.push(j);
                continue;
            }
            Err(e) => panic!("10^{j}: {e}"),
        };
        let n = sol.contact_results[0][0].normal_force;
        let exact = load * (p / kb) / (1.0 + p / kb + p / ka);
        let residual = sol.increments[0].equilibrium_residual;
        assert!(residual <= MAX_SETTLED_RESIDUAL);
        assert!(
            (n - exact).abs() <= 2.0 * residual * load + 1e-12 * load,
            "10^{j}: N {n} against {exact}, residual {residual:e}"
        );
        if j <= 3 {
            assert!((n - exact).abs() <= 1e-9 * exact, "10^{j}: {n} vs {exact}");
        }
        if j <= 2 {
            penalty_errors.push((limit - n) * p);
        }
    }
    assert_eq!(refused, (8..=12).collect::<Vec<_>>());
    // (limit − N) p is constant (P / (k_B S²), S = 1/k_A + 1/k_B) up to O(1/p).
    let s = 1.0 / ka + 1.0 / kb;
    let c = load / (kb * s * s);
    for (j, err) in penalty_errors.iter().enumerate() {
        let tol = 2.0 * kb / (default * 10f64.powi(j as i32)) + 1e-4;
        assert!(((err - c) / c).abs() <= tol, "10^{j}: {err} vs {c}");
    }
}
