//! Bad contact input: invalid friction and penalties, N = 0, initially penetrating fibers
//! (reported, then adjusted or resolved), a fiber held only by open contacts, bad explicit pairs.

use fibercell::io;
use fibercell::model::{ModelError, PenetrationSpec};
use fibercell::solve::{solve_incremental, IncrementalOptions};
use fibercell::{Error, Model};
use std::path::Path;

fn crossing(z: f64, penetration: &str, support_top: bool) -> String {
    let top = if support_top {
        "[[supports]]\nnode = 4\ndofs = [\"all\"]\n[[supports]]\nnode = 6\ndofs = [\"all\"]\n"
    } else {
        ""
    };
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
x = [0.5, 0.0, 0.0]
[[nodes]]
id = 3
x = [1.0, 0.0, 0.0]
[[nodes]]
id = 4
x = [0.5, -0.5, {z}]
[[nodes]]
id = 5
x = [0.5, 0.0, {z}]
[[nodes]]
id = 6
x = [0.5, 0.5, {z}]
[[fibers]]
id = 1
nodes = [1, 2, 3]
radius = 0.01
material = "m"
[[fibers]]
id = 2
nodes = [4, 5, 6]
radius = 0.01
material = "m"
[[supports]]
node = 1
dofs = ["all"]
[[supports]]
node = 3
dofs = ["all"]
{top}
[contact]
tolerance = 0.01
initial_penetration = "{penetration}"
friction = {{ law = "coulomb", mu = 0.2 }}
"#
    )
}

fn model(text: &str) -> Result<Model, Error> {
    let d = io::parse_toml(text, "m.toml")?;
    Ok(Model::from_description(&d)?)
}

#[test]
fn invalid_friction_penalties_and_steps() {
    let base = crossing(0.02, "adjust", true);
    for (from, to, needle) in [
        ("mu = 0.2", "mu = -0.1", "mu = -0.1"),
        (
            "tolerance = 0.01",
            "tolerance = 0.01\npenalty_normal = -5.0",
            "penalty_normal = -5",
        ),
        (
            "tolerance = 0.01",
            "tolerance = 0.01\npenalty_tangent = 0.0",
            "penalty_tangent = 0",
        ),
        ("tolerance = 0.01", "tolerance = -1.0", "tolerance = -1"),
        (
            "{ law = \"coulomb\", mu = 0.2 }",
            "{ law = \"tresca\", bound = -2.0 }",
            "bound = -2",
        ),
    ] {
        match model(&base.replace(from, to)) {
            Err(Error::Model(e @ ModelError::InvalidContact { .. })) => {
                assert!(e.to_string().contains(needle), "{e}")
            }
            other => panic!("{to}: {other:?}"),
        }
    }
    let m = model(&base).unwrap();
    let e = solve_incremental(
        &m,
        &IncrementalOptions {
            steps: 0,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(matches!(e, Error::InvalidOption(_)), "{e}");
}

#[test]
fn initial_penetration_is_reported_and_adjusted_or_resolved() {
    // Centerlines 0.015 apart, radii 0.01 + 0.01: overlap 0.005.
    let m = model(&crossing(0.015, "adjust", true)).unwrap();
    assert_eq!(
        m.contact.as_ref().unwrap().initial_penetration,
        PenetrationSpec::Adjust
    );
    let sol = solve_incremental(
        &m,
        &IncrementalOptions {
            steps: 2,
            ..Default::default()
        },
    )
    .unwrap();
    let p = sol.contacts.penetration;
    assert_eq!(p.count, 1);
    assert!((p.worst_overlap - 0.005).abs() < 1e-12);
    assert!(p.adjusted);
    // Strain-free: no load, no displacement, no force.
    assert!(sol
        .displacements
        .last()
        .unwrap()
        .iter()
        .flatten()
        .all(|v| *v == 0.0));
    assert_eq!(sol.contact_results[1][0].normal_force, 0.0);
    // Resolved: the penalty pushes the fibers apart.
    let m = model(&crossing(0.015, "resolve", true)).unwrap();
    let sol = solve_incremental(
        &m,
        &IncrementalOptions {
            steps: 2,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(!sol.contacts.penetration.adjusted);
    assert!(sol.contact_results[1][0].normal_force > 0.0);
    let top = m.node_index(5).unwrap();
    let bottom = m.node_index(2).unwrap();
    assert!(sol.displacements[1][bottom][2] < 0.0 && sol.displacements[1][top][2] > 0.0);
}

#[test]
fn a_fiber_held_only_by_open_contacts_is_named() {
    // Fiber 2 hovers 0.005 above fiber 1 (within the search tolerance, so a candidate pair
    // exists) and has no support.
    let m = model(&crossing(0.025, "adjust", false)).unwrap();
    let e = solve_incremental(&m, &IncrementalOptions::default()).unwrap_err();
    match &e {
        Error::Unsupported { fibers } => assert_eq!(fibers, &vec![2]),
        other => panic!("{other}"),
    }
}

#[test]
fn bad_explicit_pairs_name_the_pair() {
    let text = std::fs::read_to_string(Path::new("fixtures/ok_contact_bars1.toml")).unwrap();
    for (from, to, needle) in [
        (
            "a = { node = 2 }",
            "a = { node = 99 }",
            "contact pair 1: unknown node 99",
        ),
        (
            "a = { node = 2 }",
            "a = { fiber = 1, segment = 3, xi = 0.5 }",
            "fiber 1 has no segment 3",
        ),
        (
            "a = { node = 2 }",
            "a = { fiber = 1, segment = 0, xi = 1.5 }",
            "xi = 1.5",
        ),
        (
            "a = { node = 2 }",
            "a = { fiber = 7, segment = 0, xi = 0.5 }",
            "unknown fiber 7",
        ),
        (
            "normal = [1.0, 0.0, 0.0]",
            "normal = [0.0, 0.0, 0.0]",
            "zero or not finite",
        ),
        ("b = { node = 3 }", "b = { node = 2 }", "share a node"),
        ("normal = [1.0, 0.0, 0.0]\n", "", "coincide"),
    ] {
        let r = model(&text.replace(from, to)).and_then(|m| {
            fibercell::contact::ContactSet::build(&m)?;
            Ok(m)
        });
        match r {
            Err(e) => assert!(e.to_string().contains(needle), "{to}: {e}"),
            Ok(_) => panic!("{to}: accepted"),
        }
    }
    let no_section = text.replace("[contact]\nsearch = false\npenalty_normal = 1000.0\n", "");
    let e = model(&no_section).unwrap_err();
    assert!(e.to_string().contains("need a [contact] section"), "{e}");
}
