//! The CalculiX flavour of the Abaqus export runs in `ccx` (Debian's `calculix-ccx` 2.20; the
//! `calculix` feature, which `.ci/run` turns on after installing it): a slender cantilever
//! deflects as fibercell's beam does, to the measured difference of CalculiX's solid expansion;
//! the 3D frame fixture runs with its supports held; a periodic cell runs and its results
//! satisfy every exported `*EQUATION`.
#![cfg(feature = "calculix")]

use fibercell::io::{read_description, to_inp, InpFlavour, InpOptions};
use fibercell::model::ModelDescription;
use fibercell::solve::{solve_static, SolveOptions};
use fibercell::Model;
use std::collections::HashMap;
use std::path::Path;
use std::process::Command;

/// Per node set of a `.dat` file: node → (vx, vy, vz) of its `displacements` block.
type Displacements = HashMap<String, HashMap<u64, [f64; 3]>>;

/// Writes `d` in the CalculiX flavour, runs `ccx` on it in a fresh folder and returns the
/// displacements it printed; panics (with ccx's output) when ccx reports an error.
fn run_ccx(d: &ModelDescription) -> (String, Displacements) {
    let inp = to_inp(
        d,
        &InpOptions {
            flavour: InpFlavour::CalculiX,
            ..InpOptions::default()
        },
    )
    .expect("export");
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(dir.path().join("job.inp"), &inp).expect("write");
    let out = Command::new("ccx")
        .args(["-i", "job"])
        .current_dir(dir.path())
        .output()
        .expect("ccx runs (install calculix-ccx)");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && !stdout.contains("*ERROR") && stdout.contains("Job finished"),
        "ccx failed:\n{stdout}"
    );
    let dat = std::fs::read_to_string(dir.path().join("job.dat")).expect("job.dat");
    (inp, parse_dat(&dat))
}

/// The `displacements (vx,vy,vz) for set NAME` blocks of a `.dat` file.
fn parse_dat(dat: &str) -> Displacements {
    let mut out = Displacements::new();
    let mut current: Option<String> = None;
    for line in dat.lines() {
        let t = line.trim();
        if let Some(rest) = t.strip_prefix("displacements (vx,vy,vz) for set ") {
            let set = rest
                .split_whitespace()
                .next()
                .unwrap_or_default()
                .to_string();
            current = Some(set);
            continue;
        }
        if t.is_empty() {
            continue;
        }
        let fields: Vec<&str> = t.split_whitespace().collect();
        match (&current, fields.as_slice()) {
            (Some(set), [id, x, y, z]) if id.parse::<u64>().is_ok() => {
                let v = [x, y, z].map(|s| s.parse::<f64>().expect("a number"));
                out.entry(set.clone())
                    .or_default()
                    .insert(id.parse().unwrap(), v);
            }
            _ => current = None,
        }
    }
    out
}

/// A cantilever along x, clamped at x = 0, `elements` elements of length L/`elements`.
fn cantilever(length: f64, radius: f64, elements: usize) -> ModelDescription {
    let mut text = String::from(
        "[[materials]]\nname = \"steel\"\nyoung = 2.1e11\npoisson = 0.3\n\
         [[supports]]\nnode = 1\ndofs = [\"all\"]\n",
    );
    for i in 0..=elements {
        let x = length * i as f64 / elements as f64;
        text += &format!("[[nodes]]\nid = {}\nx = [{x:?}, 0.0, 0.0]\n", i + 1);
    }
    let ids: Vec<String> = (1..=elements + 1).map(|i| i.to_string()).collect();
    text += &format!(
        "[[fibers]]\nid = 1\nnodes = [{}]\nradius = {radius:?}\nmaterial = \"steel\"\n\
         [[loads]]\nnode = {}\nforce = [0.0, 1.0, 0.0]\n",
        ids.join(", "),
        elements + 1
    );
    toml::from_str(&text).expect("cantilever model")
}

/// A cantilever of L = 1 m, r = 1 cm, E = 210 GPa under a 1 N tip load: fibercell's beam gives
/// F L³ / 3EI (Euler–Bernoulli, exact for cubic elements) to 1e-9; CalculiX deflects it
/// 0.989 times as much (measured 0.98866): it expands each B32 beam into 20-node bricks whose
/// cross-section only approximates the circle (in tension the same bar stretches 1.0145 times
/// F L / EA), so its stiffnesses differ from π r² and π r⁴/4 by about a percent.
#[test]
fn a_cantilever_in_ccx_deflects_as_fibercells_beam_to_the_measured_expansion_error() {
    let (length, radius, elements) = (1.0, 0.01, 10);
    let d = cantilever(length, radius, elements);
    let model = Model::from_description(&d).unwrap();
    let ours = solve_static(&model, &SolveOptions::default()).unwrap();
    let tip = model.node_index(elements as u64 + 1).unwrap();
    let inertia = std::f64::consts::PI * radius.powi(4) / 4.0;
    let closed_form = length.powi(3) / (3.0 * 2.1e11 * inertia);
    let fibercell = ours.displacements[tip][1];
    assert!(
        (fibercell / closed_form - 1.0).abs() <= 1e-9,
        "fibercell {fibercell} against F L³/3EI = {closed_form}"
    );
    let (_, dat) = run_ccx(&d);
    let ccx = dat["FIBERCELL-NODES"][&(elements as u64 + 1)][1];
    let ratio = ccx / fibercell;
    assert!(
        (ratio - 0.98866).abs() <= 0.002,
        "ccx tip deflection {ccx} = {ratio} × fibercell's {fibercell}"
    );
}

/// The 3D frame fixture (bent fiber, oblique braces, moments) runs; its clamped node stays put
/// and every node has a finite displacement.
#[test]
fn the_frame_fixture_runs_in_ccx() {
    let d = read_description(Path::new("fixtures/ok_frame3d.toml")).unwrap();
    let (_, dat) = run_ccx(&d);
    let nodes = &dat["FIBERCELL-NODES"];
    assert_eq!(nodes.len(), d.nodes.len());
    assert!(nodes.values().flatten().all(|v| v.is_finite()));
    assert!(
        nodes[&1].iter().all(|v| v.abs() <= 1e-15),
        "{:?}",
        nodes[&1]
    );
    assert!(nodes.values().flatten().any(|v| v.abs() > 1e-6));
}

/// A periodic grid cell under ε11 = 10⁻³ runs, and its results satisfy every translational
/// `*EQUATION` of the file (Σ c u = 0 to 1e-9 of the largest displacement): u(slave) −
/// u(master) equals the driver's displacement, L1 ε11 along x.
#[test]
fn a_periodic_cell_runs_in_ccx_and_its_equations_hold() {
    let d = read_description(Path::new("fixtures/ok_cell_grid.toml")).unwrap();
    let (inp, dat) = run_ccx(&d);
    let mut u: HashMap<u64, [f64; 3]> = HashMap::new();
    for set in dat.values() {
        u.extend(set.iter().map(|(k, v)| (*k, *v)));
    }
    let scale = u.values().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 1e-7, "the cell moved ({scale})");
    let lines: Vec<&str> = inp.lines().collect();
    let mut checked = 0;
    for k in 0..lines.len() {
        if lines[k] != "*EQUATION" {
            continue;
        }
        let terms: Vec<&str> = lines[k + 2].split(',').map(str::trim).collect();
        let dof: usize = terms[1].parse().unwrap();
        if dof > 3 {
            continue; // rotations are not printed
        }
        let sum: f64 = terms
            .chunks(3)
            .map(|t| t[2].parse::<f64>().unwrap() * u[&t[0].parse::<u64>().unwrap()][dof - 1])
            .sum();
        assert!(
            sum.abs() <= 1e-9 * scale,
            "{}: residual {sum}",
            lines[k + 2]
        );
        checked += 1;
    }
    assert!(checked >= 6, "{checked} equations checked");
    // Driver 0 carries L1 ε11 = 4 mm × 10⁻³.
    let driver = u[&(d.nodes.iter().map(|n| n.id).max().unwrap() + 1)];
    assert!((driver[0] - 4e-6).abs() <= 1e-15, "{driver:?}");
}
