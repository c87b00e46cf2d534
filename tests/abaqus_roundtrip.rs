//! Abaqus export → import reproduces the model exactly: generated cells of every family (with
//! their contact settings and cell) and fixtures with supports and loads. A TexGen-style file —
//! the periodic `*EQUATION`s with strain-driver nodes but without fibercell's comment lines —
//! gives the same cell and the same homogenized stiffness. Malformed equations name their line.

use fibercell::generate::{
    geotextile, knitted, nonwoven, weave, FiberAmount, FiberFamily, Geotextile, Knit,
    LayerJunction, NonWoven, Weave, WeavePattern,
};
use fibercell::homogenize::homogenize_elastic;
use fibercell::io::{parse_abaqus, read_description, to_abaqus};
use fibercell::model::ModelDescription;
use fibercell::solve::SolveOptions;
use fibercell::{Error, Model};
use std::path::Path;

fn cells() -> Vec<(&'static str, ModelDescription)> {
    let family = |a, l| FiberFamily {
        angle_degrees: a,
        spacing: 5e-3,
        radius: 5e-4,
        offset: None,
        layer: l,
    };
    vec![
        ("geotextile", geotextile(&Geotextile::default()).unwrap()),
        (
            "geotextile in contact",
            geotextile(&Geotextile {
                families: vec![family(0.0, 0), family(90.0, 1)],
                layer_junction: LayerJunction::Contact { mu: 0.2 },
                ..Geotextile::default()
            })
            .unwrap(),
        ),
        (
            "twill",
            weave(&Weave {
                pattern: WeavePattern::Twill { over: 2, under: 1 },
                size: [6e-3, 6e-3],
                ..Weave::default()
            })
            .unwrap(),
        ),
        ("knit", knitted(&Knit::default()).unwrap()),
        (
            "non-woven",
            nonwoven(&NonWoven {
                amount: FiberAmount::Count { fibers: 40 },
                ..NonWoven::default()
            })
            .unwrap()
            .description,
        ),
    ]
}

/// Exactly, although every number fits the 20-character field: the nodes whose coordinates
/// had to be rounded (the non-woven's 17-digit ones below 0.01) are restored from their
/// `** fibercell-node:` comments.
#[test]
fn generated_cells_round_trip_exactly() {
    let mut restored = 0;
    for (name, d) in cells() {
        let text = to_abaqus(&d).unwrap();
        restored += text.matches("** fibercell-node:").count();
        let back = parse_abaqus(&text, name).unwrap();
        assert_eq!(back, d, "{name}");
    }
    assert!(restored > 0, "no node needed its exact coordinates");
}

/// A node line edited after the export keeps its own values: its comment no longer applies.
#[test]
fn an_edited_node_line_wins_over_its_exact_coordinates() {
    let d = nonwoven(&NonWoven {
        amount: FiberAmount::Count { fibers: 40 },
        ..NonWoven::default()
    })
    .unwrap()
    .description;
    let text = to_abaqus(&d).unwrap();
    let comment = text
        .lines()
        .find(|l| l.starts_with("** fibercell-node:"))
        .expect("a rounded node");
    let body: serde_json::Value =
        serde_json::from_str(comment.trim_start_matches("** fibercell-node:")).unwrap();
    let id = body["id"].as_u64().unwrap();
    // The node's line, the first that starts with its id (the nodes come first).
    let prefix = format!("{id}, ");
    let at = text.lines().position(|l| l.starts_with(&prefix)).unwrap();
    let edited: String = text
        .lines()
        .enumerate()
        .map(|(k, l)| {
            if k == at {
                format!("{id}, 0.001, 0.002, 0.0\n")
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    let back = parse_abaqus(&edited, "edited").unwrap();
    let node = back.nodes.iter().find(|n| n.id == id).unwrap();
    assert_eq!(node.x, [0.001, 0.002, 0.0]);
}

#[test]
fn fixtures_with_supports_and_loads_round_trip_to_the_same_model() {
    for f in [
        "fixtures/ok_frame3d.toml",
        "fixtures/ok_cell_contact.toml",
        "fixtures/ok_contact_bars1.toml",
    ] {
        let d = read_description(Path::new(f)).unwrap();
        let back = parse_abaqus(&to_abaqus(&d).unwrap(), f).unwrap();
        // Supports come back DOF by DOF (`1, 6` for "all"): the validated models are equal.
        assert_eq!(
            Model::from_description(&back).unwrap(),
            Model::from_description(&d).unwrap(),
            "{f}"
        );
    }
}

/// The exported text without fibercell's own comment lines: what TexGen-style tools read.
fn texgen_style(text: &str) -> String {
    text.lines()
        .filter(|l| !l.starts_with("** fibercell-"))
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn the_cell_is_read_from_equations_with_strain_drivers() {
    let d = geotextile(&Geotextile {
        size: [1.2e-2, 1e-2],
        families: vec![
            FiberFamily {
                angle_degrees: 0.0,
                spacing: 5e-3,
                radius: 5e-4,
                offset: None,
                layer: 0,
            },
            FiberFamily {
                angle_degrees: 90.0,
                spacing: 4e-3,
                radius: 5e-4,
                offset: None,
                layer: 0,
            },
        ],
        ..Geotextile::default()
    })
    .unwrap();
    let text = texgen_style(&to_abaqus(&d).unwrap());
    assert!(text.contains("ConstraintsDriver0"));
    // Every number fits the 20-character field (data lines start with a number).
    let data = text
        .lines()
        .filter(|l| l.starts_with(|c: char| c.is_ascii_digit() || c == '-'));
    assert!(data
        .flat_map(|l| l.split(','))
        .all(|f| f.trim().len() <= 20));
    let back = parse_abaqus(&text, "texgen").unwrap();
    let cell = back.cell.clone().expect("a cell from the equations");
    assert_eq!(cell.size, [1.2e-2, 1e-2]);
    assert_eq!(back.nodes.len(), d.nodes.len(), "driver nodes dropped");
    let opts = SolveOptions::default();
    let a = homogenize_elastic(&Model::from_description(&d).unwrap(), &opts).unwrap();
    let b = homogenize_elastic(&Model::from_description(&back).unwrap(), &opts).unwrap();
    for r in 0..6 {
        for c in 0..6 {
            let scale = (a.abd[r][r] * a.abd[c][c]).sqrt();
            // The file's numbers fit the 20-character field: without fibercell's comment
            // with the exact coordinates, some nodes are off by an ulp or two, which moves
            // D66 by 6e-12 of itself.
            let (x, y) = (a.abd[r][c], b.abd[r][c]);
            assert!(
                (x - y).abs() <= 1e-10 * scale,
                "ABD[{r}][{c}]: {x} against {y}"
            );
        }
    }
}

fn syntax_line(text: &str) -> usize {
    match parse_abaqus(text, "bad.inp").map(|_| ()) {
        Err(fibercell::io::InputError::Syntax { line, .. }) => line,
        other => panic!("expected a syntax error, got {other:?}"),
    }
}

#[test]
fn malformed_equations_name_their_line() {
    let head = "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 5, 5, 0\n*NODE, NSET=ConstraintsDriver0\n9, 0, 0, 0\n";
    let cases = [
        // Three terms announced, two given before the next keyword.
        (format!("{head}*EQUATION\n3\n2, 1, 1.0, 1, 1, -1.0\n*STEP\n"), 9),
        // Not a pair: both coefficients +1.
        (format!("{head}*EQUATION\n3\n2, 1, 1.0, 1, 1, 1.0, ConstraintsDriver0, 1, -1.0\n"), 9),
        // Unknown set.
        (format!("{head}*EQUATION\n3\n2, 1, 1.0, 1, 1, -1.0, NOSUCHSET, 1, -1.0\n"), 9),
        // The same driver with two different periods.
        (format!("{head}*EQUATION\n3\n2, 1, 1.0, 1, 1, -1.0, ConstraintsDriver0, 1, -1.0\n*EQUATION\n3\n3, 1, 1.0, 1, 1, -1.0, ConstraintsDriver0, 1, -1.0\n"), 12),
        // An oblique period.
        (format!("{head}*EQUATION\n3\n4, 1, 1.0, 1, 1, -1.0, ConstraintsDriver0, 1, -1.0\n"), 9),
        // A term count of zero.
        (format!("{head}*EQUATION\n0\n"), 9),
        // DOF out of range.
        (format!("{head}*EQUATION\n2\n2, 7, 1.0, 1, 7, -1.0\n"), 10),
    ];
    for (k, (text, line)) in cases.iter().enumerate() {
        assert_eq!(syntax_line(text), *line, "case {k}");
    }
}

#[test]
fn models_that_cannot_be_written_are_errors() {
    let mut d = weave(&Weave::default()).unwrap();
    d.materials[0].name = "a,b".into();
    d.fibers.iter_mut().for_each(|f| f.material = "a,b".into());
    assert!(matches!(to_abaqus(&d), Err(Error::InvalidOption(_))));
    let mut d = weave(&Weave::default()).unwrap();
    d.nodes[0].x[0] = f64::NAN;
    assert!(matches!(to_abaqus(&d), Err(Error::Model(_))));
}

/// A fiber with an element along each of the 13 axis and diagonal directions the exporter
/// tries first still gets a section direction n1 off all its elements (from the fallback
/// search over the sphere), which the importer's check accepts.
#[test]
fn a_fiber_along_every_axis_and_diagonal_still_gets_a_section_direction() {
    let r2 = 0.5f64.sqrt();
    let r3 = (1.0f64 / 3.0).sqrt();
    let mut steps = vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        for sign in [1.0, -1.0] {
            let mut d = [0.0; 3];
            d[i] = r2;
            d[j] = sign * r2;
            steps.push(d);
        }
    }
    for (sy, sz) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
        steps.push([r3, sy * r3, sz * r3]);
    }
    let mut text = String::from(
        "[[materials]]\nname = \"m\"\nyoung = 1e9\npoisson = 0.3\n\
         [[supports]]\nnode = 1\ndofs = [\"all\"]\n",
    );
    let mut x = [0.0f64; 3];
    text += "[[nodes]]\nid = 1\nx = [0.0, 0.0, 0.0]\n";
    for (k, d) in steps.iter().enumerate() {
        x = [0, 1, 2].map(|c| x[c] + 0.1 * d[c]);
        text += &format!(
            "[[nodes]]\nid = {}\nx = [{:?}, {:?}, {:?}]\n",
            k + 2,
            x[0],
            x[1],
            x[2]
        );
    }
    let ids: Vec<String> = (1..=steps.len() + 1).map(|i| i.to_string()).collect();
    text += &format!(
        "[[fibers]]\nid = 1\nnodes = [{}]\nradius = 0.001\nmaterial = \"m\"\n",
        ids.join(", ")
    );
    let d: ModelDescription = toml::from_str(&text).unwrap();
    let inp = to_abaqus(&d).unwrap();
    let back = parse_abaqus(&inp, "every direction").expect("n1 accepted on import");
    assert_eq!(back.fibers.len(), 1);
    let n1_line = inp
        .lines()
        .skip_while(|l| !l.starts_with("*BEAM SECTION"))
        .nth(2)
        .unwrap();
    let n1: Vec<f64> = n1_line
        .split(',')
        .map(|v| v.trim().parse().unwrap())
        .collect();
    assert!(
        !steps
            .iter()
            .any(|s| (0..3).all(|c| (s[c] - n1[c]).abs() < 1e-12)),
        "n1 {n1:?} is one of the first candidates"
    );
}
