//! Every class of bad input gives its typed error naming the offending item — never a panic,
//! never a silent result.

mod common;
use common::*;
use fibercell::io::{self, InputError};
use fibercell::model::{
    Dof, DofSet, FiberSpec, ModelDescription, ModelError, NodeSpec, SupportSpec,
};
use fibercell::solve::{solve_static, SolveOptions, SolverKind};
use fibercell::{Error, Model};
use std::path::Path;

fn base() -> ModelDescription {
    io::read_description(Path::new("fixtures/ok_frame3d.toml")).unwrap()
}

fn invalid(d: &ModelDescription) -> ModelError {
    Model::from_description(d).expect_err("must be rejected")
}

#[test]
fn model_validation_names_the_item() {
    let mut d = base();
    d.nodes[2].x[1] = f64::INFINITY;
    assert!(matches!(
        invalid(&d),
        ModelError::NonFiniteCoordinate { node: 2, .. }
    ));

    let mut d = base();
    d.nodes.push(NodeSpec {
        id: 99,
        x: [0.0, 0.0, 0.5],
    }); // at node 7
    d.fibers[0].nodes = vec![1, 7, 99, 2, 3, 4];
    let e = invalid(&d);
    assert_eq!(
        e,
        ModelError::ZeroLengthElement {
            fiber: 1,
            node_a: 7,
            node_b: 99
        }
    );
    assert!(e.to_string().contains("fiber 1") && e.to_string().contains("99"));

    let mut d = base();
    d.fibers.push(FiberSpec {
        id: 8,
        nodes: vec![4, 3],
        radius: 0.01,
        material: "STEEL".into(),
    });
    assert_eq!(
        invalid(&d),
        ModelError::DuplicateElement {
            node_a: 4,
            node_b: 3,
            fiber_a: 1,
            fiber_b: 8
        }
    );

    let mut d = base();
    d.fibers[1].nodes = vec![5, 42];
    let e = invalid(&d);
    assert_eq!(
        e,
        ModelError::UnknownNode {
            node: 42,
            referrer: "fiber 5".into()
        }
    );

    for r in [0.0, -1e-3, f64::NAN] {
        let mut d = base();
        d.fibers[2].radius = r;
        assert!(
            matches!(invalid(&d), ModelError::InvalidRadius { fiber: 6, .. }),
            "radius {r}"
        );
    }
    for e in [0.0, -2e11, f64::INFINITY] {
        let mut d = base();
        d.materials[1].young = e;
        assert!(
            matches!(
                invalid(&d),
                ModelError::InvalidMaterial { what: "young", .. }
            ),
            "E {e}"
        );
    }
    for nu in [0.5, -1.0, 0.7, f64::NAN] {
        let mut d = base();
        d.materials[0].poisson = Some(nu);
        let e = invalid(&d);
        assert!(
            matches!(&e, ModelError::InvalidMaterial { what: "poisson", material, .. } if material == "STEEL"),
            "ν {nu}"
        );
    }
    let mut d = base();
    d.materials[0].shear = Some(8e10);
    assert_eq!(
        invalid(&d),
        ModelError::MaterialUnderdetermined("STEEL".into())
    );

    assert_eq!(
        invalid(&ModelDescription::default()),
        ModelError::Empty("nodes")
    );
    let mut d = base();
    d.fibers.clear();
    assert_eq!(invalid(&d), ModelError::Empty("fibers"));

    let mut d = base();
    d.nodes[1].id = 1;
    assert_eq!(invalid(&d), ModelError::DuplicateNode(1));

    let mut d = base();
    d.fibers[2].material = "TITANIUM".into();
    assert_eq!(
        invalid(&d),
        ModelError::UnknownMaterial {
            fiber: 6,
            material: "TITANIUM".into()
        }
    );

    let mut d = base();
    d.nodes.push(NodeSpec {
        id: 50,
        x: [9.0, 9.0, 9.0],
    });
    assert_eq!(invalid(&d), ModelError::UnusedNode(50));

    let mut d = base();
    d.loads[0].moment[2] = f64::NAN;
    assert_eq!(
        invalid(&d),
        ModelError::NonFiniteValue {
            node: 4,
            what: "load"
        }
    );

    let mut d = base();
    d.supports.push(SupportSpec {
        node: 1,
        dofs: vec![DofSet::Uz],
        value: 0.1,
    });
    assert_eq!(
        invalid(&d),
        ModelError::ConflictingSupport {
            node: 1,
            dof: Dof::Uz
        }
    );
}

#[test]
fn file_errors_carry_file_line_and_key() {
    match io::load_model(Path::new("fixtures/bad_nan_coordinate.toml")) {
        Err(Error::Model(ModelError::NonFiniteCoordinate { node: 2, .. })) => {}
        other => panic!("{other:?}"),
    }
    match io::load_model(Path::new("fixtures/bad_unknown_key.json")) {
        Err(Error::Input(InputError::Syntax {
            line: 5, message, ..
        })) => assert!(message.contains("mass"), "{message}"),
        other => panic!("{other:?}"),
    }
    match io::load_model(Path::new("fixtures/bad_unsupported_keyword.inp")) {
        Err(Error::Input(InputError::UnsupportedKeyword {
            line: 9, keyword, ..
        })) => assert_eq!(keyword, "Density"),
        other => panic!("{other:?}"),
    }
    let toml_wrong_type = "[[nodes]]\nid = 1\nx = [0.0, \"a\", 0.0]\n";
    match io::parse_toml(toml_wrong_type, "t.toml") {
        Err(InputError::Syntax { line: 3, .. }) => {}
        other => panic!("{other:?}"),
    }
    let truncated = "{\"nodes\": [{\"id\": 1, \"x\": [0.0, 0.0";
    assert!(matches!(
        io::parse_json(truncated, "t.json"),
        Err(InputError::Syntax { line: 1, .. })
    ));
    assert!(matches!(
        io::load_model(Path::new("fixtures/none.toml")),
        Err(Error::Input(InputError::Read { .. }))
    ));
    assert!(matches!(
        io::load_model(Path::new("fixtures/model.xyz")),
        Err(Error::Input(InputError::UnknownFormat { .. }))
    ));
}

#[test]
fn abaqus_errors_name_the_line() {
    let cases = [
        ("*NODE\n1, 0, 0, x\n", 2, "not a number"),
        (
            "*NODE\n1, 0, 0, 0\n*ELEMENT, TYPE=B32\n1, 1, 2, 3\n",
            3,
            "TYPE=B32",
        ),
        (
            "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n*ELEMENT, TYPE=B31\n1, 1, 2\n1, 2, 1\n",
            6,
            "already defined",
        ),
        ("*BOUNDARY\nBASE, 1, 3\n", 2, "unknown node or node set"),
        ("*CLOAD\n3, 7, 1.0\n", 2, "DOF 7"),
        ("1, 2, 3\n", 1, "outside any keyword"),
        ("*STEP\n*STEP\n", 2, "one *STEP"),
        (
            "*NODE\n1,0,0,0\n2,1,0,0\n*ELEMENT, TYPE=B31\n1, 1, 2\n",
            5,
            "no *BEAM SECTION",
        ),
    ];
    for (text, line, what) in cases {
        match io::parse_abaqus(text, "m.inp") {
            Err(InputError::Syntax {
                line: l, message, ..
            }) => {
                assert_eq!(l, line, "{text:?}: {message}");
                assert!(message.contains(what), "{text:?}: {message}");
            }
            other => panic!("{text:?}: {other:?}"),
        }
    }
    match io::parse_abaqus(
        "** comment\n*Node\n1,0,0,0\n*Orientation, name=O\n",
        "m.inp",
    ) {
        Err(InputError::UnsupportedKeyword {
            line: 4, keyword, ..
        }) => assert_eq!(keyword, "Orientation"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_fiber_held_by_nothing_is_reported_by_name() {
    let m = io::load_model(Path::new("fixtures/bad_floating_fiber.toml")).unwrap();
    for kind in [SolverKind::FaerCholesky, SolverKind::FaerLu, SolverKind::Cg] {
        let e = solve_static(
            &m,
            &SolveOptions {
                solver: kind,
                ..Default::default()
            },
        )
        .unwrap_err();
        match &e {
            Error::Unsupported { fibers } => assert_eq!(fibers, &vec![2]),
            other => panic!("{kind}: {other}"),
        }
        assert!(e.to_string().contains("fiber 2 is held by nothing"), "{e}");
    }
}

#[test]
fn a_mechanism_is_reported_as_singular_at_its_node_and_dof() {
    // A straight fiber pinned (translations only) at one end: it can spin about its own axis
    // and swing about the pin. The direct solvers must refuse it and name where.
    let mut d = cantilever(
        [0.0; 3],
        [1.0, 0.0, 0.0],
        4,
        0.01,
        [0.0, 0.0, 1.0],
        [0.0; 3],
    );
    d.supports = vec![SupportSpec {
        node: 1,
        dofs: vec![DofSet::Translations],
        value: 0.0,
    }];
    let m = build(&d);
    let e = solve_static(&m, &SolveOptions::default()).unwrap_err();
    match &e {
        Error::Singular {
            node,
            fibers,
            pivot,
            ..
        } => {
            assert!((1..=5).contains(node));
            assert_eq!(fibers, &vec![1]);
            assert!(*pivot < 1e-12);
        }
        other => panic!("{other}"),
    }
    assert!(e.to_string().contains("singular at node"), "{e}");
    let lu = solve_static(
        &m,
        &SolveOptions {
            solver: SolverKind::FaerLu,
            ..Default::default()
        },
    );
    assert!(
        matches!(
            lu,
            Err(Error::Solver(
                fibercell::solver::SolverError::Singular { .. }
            ))
        ),
        "{lu:?}"
    );
}
