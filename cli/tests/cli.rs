//! The `fibercell` binary: outputs, JSON on stdout, Matrix Market export, one-line errors with
//! a non-zero exit code.

use std::path::Path;
use std::process::Output;

mod common;
use common::{at_root, fibercell};

fn run(args: &[&str]) -> Output {
    fibercell().args(args).output().expect("runs")
}

/// `generate nonwoven --params PARAMS -o OUT`, which must succeed.
fn generate_nonwoven_from(params: &Path, out: &Path) -> Output {
    let o = run(&[
        "generate",
        "nonwoven",
        "--params",
        params.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

fn tmpdir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("fibercell-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// The command fails with a non-zero exit and its error contains `needle`.
fn fails_saying(args: &[&str], needle: &str) {
    let o = run(args);
    assert!(!o.status.success(), "{args:?}");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains(needle), "{args:?}: {err}");
}

#[test]
fn solve_writes_csv_json_vtp_and_prints_json() {
    let out = tmpdir("solve");
    let o = run(&[
        "solve",
        "fixtures/ok_frame3d.inp",
        "--json",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let doc: serde_json::Value =
        serde_json::from_slice(&o.stdout).expect("stdout is one JSON document");
    let disp = doc["displacements"].as_object().unwrap();
    assert_eq!(disp.len(), 7);
    assert_eq!(disp["1"].as_array().unwrap().len(), 6);
    assert!(disp["1"]
        .as_array()
        .unwrap()
        .iter()
        .all(|v| v.as_f64() == Some(0.0)));
    assert_eq!(doc["solver"]["backend"], "faer-cholesky");
    assert!(doc["solver"]["relative_residual"].as_f64().unwrap() < 1e-9);
    assert!(doc["solver"]["timings"]["factorize"].as_f64().is_some());
    let csv = std::fs::read_to_string(out.join("displacements.csv")).unwrap();
    assert_eq!(csv.lines().count(), 8);
    assert!(csv.starts_with("node,ux [m],uy [m],uz [m],rx [rad],ry [rad],rz [rad]\n"));
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("displacements.json")).unwrap())
            .unwrap();
    assert_eq!(file["displacements"], doc["displacements"]);
    // One poly line per fiber, reference coordinates and the displacement (7 nodes, 3 fibers).
    let vtp = std::fs::read_to_string(out.join("network.vtp")).unwrap();
    assert!(
        vtp.contains("NumberOfPoints=\"7\" NumberOfLines=\"3\"")
            && vtp.contains("Name=\"radius\"")
            && vtp.contains("Points are the reference")
    );
    // Only the three outputs, no temporary leftovers.
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 3);
}

#[test]
fn export_matrix_writes_the_lower_triangle() {
    let out = tmpdir("mtx");
    std::fs::create_dir_all(&out).unwrap();
    let f = out.join("K.mtx");
    let o = run(&[
        "export-matrix",
        "fixtures/ok_frame3d.toml",
        "-o",
        f.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&f).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('%'));
    assert!(text.starts_with("%%MatrixMarket matrix coordinate real symmetric\n"));
    let header: Vec<usize> = lines
        .next()
        .unwrap()
        .split_whitespace()
        .map(|x| x.parse().unwrap())
        .collect();
    // Compare with the library's reduced system.
    let m = fibercell::io::load_model(&at_root("fixtures/ok_frame3d.toml")).unwrap();
    let sys = fibercell::solve::ReducedSystem::assemble(&m, Default::default()).unwrap();
    let a = sys.matrix().unwrap();
    assert_eq!(header[0], a.nrows());
    let lower = (a.nnz() + a.ncols()) / 2;
    assert_eq!(header[2], lower);
    let mut count = 0;
    for l in lines {
        let p: Vec<&str> = l.split_whitespace().collect();
        let (i, j, v): (usize, usize, f64) = (
            p[0].parse().unwrap(),
            p[1].parse().unwrap(),
            p[2].parse().unwrap(),
        );
        assert!(i >= j);
        let (rows, vals) = a.col(j - 1);
        let k = rows.binary_search(&(i - 1)).unwrap();
        assert_eq!(v, vals[k], "entries are written exactly");
        count += 1;
    }
    assert_eq!(count, lower);
}

#[test]
fn errors_are_one_line_with_a_non_zero_exit() {
    for (args, needle) in [
        (
            vec!["solve", "fixtures/bad_floating_fiber.toml"],
            "fiber 2 is held by nothing",
        ),
        (vec!["solve", "fixtures/bad_nan_coordinate.toml"], "node 2"),
        (
            vec!["solve", "fixtures/bad_unknown_key.json"],
            "bad_unknown_key.json:5",
        ),
        (
            vec!["solve", "fixtures/bad_unsupported_keyword.inp"],
            "bad_unsupported_keyword.inp:9: unsupported Abaqus keyword *Density",
        ),
        (vec!["solve", "fixtures/missing.toml"], "cannot read"),
    ] {
        let o = run(&args);
        assert!(!o.status.success(), "{args:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(o.stdout.is_empty());
    }
    let o = run(&["solve", "fixtures/ok_frame3d.toml", "--solver", "pardiso"]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("invalid value 'pardiso'")
            && err.contains("possible values: faer-cholesky, faer-lu, cg, cholmod"),
        "{err}"
    );
    let o = run(&[
        "solve",
        "fixtures/ok_frame3d.toml",
        "--solver",
        "cholmod",
        "-o",
        tmpdir("ch").to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.success(),
        cfg!(feature = "cholmod"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

#[test]
fn solve_with_contact_writes_increments_contacts_and_a_vtk_series() {
    let out = tmpdir("contact");
    let o = run(&[
        "solve",
        "fixtures/ok_contact_bars2.toml",
        "--steps",
        "4",
        "--json",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let doc: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let inc = doc["increments"].as_array().unwrap();
    assert_eq!(inc.len(), 4);
    assert_eq!(inc[1]["open"], 1);
    assert_eq!(inc[3]["open"], 0);
    assert_eq!(inc[3]["alpha"], 1.0);
    let c = &doc["contacts"][0];
    assert_eq!(c["a"]["node"], 4);
    // Table 5.3 with p = 1000: N = 2.0 N.
    assert!((c["normal_force"].as_f64().unwrap() - 2.0).abs() < 1e-9);
    assert_eq!(doc["displacements"].as_object().unwrap().len(), 6);
    for f in [
        "increments.csv",
        "contacts.csv",
        "solution.pvd",
        "step_0004.vtp",
        "contacts_0004.vtp",
        "displacements.csv",
    ] {
        assert!(out.join(f).exists(), "{f}");
    }
    let pvd = std::fs::read_to_string(out.join("solution.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 8);
    let csv = std::fs::read_to_string(out.join("increments.csv")).unwrap();
    assert_eq!(csv.lines().count(), 5);
    let contacts = std::fs::read_to_string(out.join("contacts.csv")).unwrap();
    assert_eq!(
        contacts.lines().count(),
        5,
        "one contact × four increments + header"
    );
    assert!(contacts.lines().nth(1).unwrap().contains(",open,"));
    assert!(contacts.lines().nth(4).unwrap().contains(",slip,"));
    let o = run(&[
        "solve",
        "fixtures/ok_contact_bars2.toml",
        "--steps",
        "0",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("at least 1"));
}

#[test]
fn homogenize_prints_abd_and_writes_the_cell_problems() {
    let out = tmpdir("homog");
    let o = run(&[
        "homogenize",
        "fixtures/ok_cell_grid.toml",
        "--json",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let doc: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    // A11 = EA/Ly with E = 1 GPa, r = 0.2 mm, Ly = 7 mm.
    let a11 = doc["abd"][0][0].as_f64().unwrap();
    let want = 1e9 * std::f64::consts::PI * 4e-8 / 7e-3;
    assert!((a11 - want).abs() <= 1e-9 * want, "{a11} vs {want}");
    assert!(doc["asymmetry"].as_f64().unwrap() < 1e-10);
    assert_eq!(doc["orthotropic"]["e1"], doc["abd"][0][0]);
    for k in ["e11", "e22", "g12", "k11", "k22", "k12"] {
        assert!(out.join(format!("case_{k}.vtp")).exists());
    }
    let o = run(&["homogenize", "fixtures/ok_frame3d.toml"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("no [cell] section"));
}

/// Checks `curve --log`'s stderr: one line per increment, with the counts `curve.json`
/// records for it.
fn check_increment_log(stderr: &str, points: &[serde_json::Value]) {
    let lines: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("increment "))
        .collect();
    assert_eq!(lines.len(), points.len(), "{stderr}");
    let n = points.len();
    for (k, (line, p)) in lines.iter().zip(points).enumerate() {
        assert!(
            line.starts_with(&format!("increment {}/{n} ", k + 1)),
            "{line}"
        );
        let rest = &line[line.find(": ").unwrap() + 2..];
        let iterations: u64 = rest.split(' ').next().unwrap().parse().unwrap();
        assert_eq!(iterations, p["iterations"].as_u64().unwrap(), "{line}");
        let counts: Vec<u64> = line
            .split("open/stick/slip ")
            .nth(1)
            .unwrap()
            .split(',')
            .next()
            .unwrap()
            .split('/')
            .map(|c| c.parse().unwrap())
            .collect();
        let expected: Vec<u64> = ["open", "stick", "slip"]
            .iter()
            .map(|s| p[*s].as_u64().unwrap())
            .collect();
        assert_eq!(counts, expected, "{line}");
        assert!(line.contains(" factorizations, ") && line.contains(" low-rank solves "));
    }
}

/// `curve` writes its files; with `--log` it prints one line per increment on stderr.
#[test]
fn curve_writes_csv_switches_json_svg_and_png() {
    let out = tmpdir("curve");
    let o = run(&[
        "curve",
        "fixtures/ok_cell_contact.toml",
        "--strain",
        "g12=0.01",
        "--steps",
        "20",
        "--unload",
        "--log",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("curve.csv")).unwrap();
    assert_eq!(csv.lines().count(), 61, "header + load, unload, reload");
    let switches = std::fs::read_to_string(out.join("switches.csv")).unwrap();
    assert!(switches.lines().nth(1).unwrap().contains(",stick,slip,"));
    let svg = std::fs::read_to_string(out.join("curve.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("<polyline") && svg.contains("<circle"));
    let png = std::fs::read(out.join("curve.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("curve.json")).unwrap()).unwrap();
    assert_eq!(doc["points"].as_array().unwrap().len(), 60);
    check_increment_log(
        &String::from_utf8_lossy(&o.stderr),
        doc["points"].as_array().unwrap(),
    );
    for (args, needle) in [
        (
            vec![
                "curve",
                "fixtures/ok_cell_contact.toml",
                "--strain",
                "e33=0.1",
            ],
            "unknown strain component",
        ),
        (
            vec![
                "curve",
                "fixtures/ok_cell_contact.toml",
                "--strain",
                "e11=nan",
            ],
            "not finite",
        ),
        (
            vec!["curve", "fixtures/ok_frame3d.toml", "--strain", "e11=0.01"],
            "no [cell] section",
        ),
    ] {
        fails_saying(&args, needle);
    }
}

#[test]
fn generate_nonwoven_writes_a_cell_that_stats_reads() {
    let out = tmpdir("generate");
    std::fs::create_dir_all(&out).unwrap();
    let cell = out.join("nw.toml");
    let o = run(&[
        "generate",
        "nonwoven",
        "--size",
        "4e-3,4e-3",
        "--fibers",
        "80",
        "--length",
        "1.5e-3",
        "--orientation",
        "tensor:0.7,0.0",
        "--seed",
        "2",
        "-o",
        cell.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let printed = String::from_utf8_lossy(&o.stdout);
    assert!(printed.contains("80 fibers deposited") && printed.contains("contacts"));
    let rose = out.join("rose");
    let o = run(&[
        "stats",
        cell.to_str().unwrap(),
        "--json",
        "--rose",
        rose.to_str().unwrap(),
    ]);
    assert!(out.join("rose.svg").exists() && out.join("rose.png").exists());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let doc: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(doc["fibers"], 80);
    assert!(doc["contacts"].as_u64().unwrap() > 80);
    // The same kind of cell from a parameter file (the fields of generate::NonWoven).
    let params = out.join("params.toml");
    std::fs::write(
        &params,
        "size = [4e-3, 4e-3]\namount = { kind = \"count\", fibers = 60 }\n\
         length = { kind = \"log_normal\", mean = 1.2e-3, cv = 0.2 }\nradius = 1e-5\n\
         orientation = { kind = \"isotropic\" }\ntilt_degrees = 0.0\ncurl = 0.0\n\
         element_length = 2e-4\ntolerance = 1e-3\nyoung = 1e9\npoisson = 0.3\nmu = 0.2\nseed = 4\n",
    )
    .unwrap();
    let from_file = out.join("from_file.json");
    let o = generate_nonwoven_from(&params, &from_file);
    assert!(String::from_utf8_lossy(&o.stdout).contains("60 fibers deposited"));
    assert!(from_file.exists());
    for (args, needle) in [
        (
            vec!["generate", "nonwoven", "--radius=-1", "-o", "x.toml"],
            "radius",
        ),
        (
            vec![
                "generate",
                "nonwoven",
                "--orientation",
                "spiral",
                "-o",
                "x.toml",
            ],
            "unknown orientation",
        ),
        (
            vec!["generate", "nonwoven", "--preset", "XXL", "-o", "x.toml"],
            "unknown cell size",
        ),
        (
            vec![
                "generate",
                "nonwoven",
                "--params",
                "fixtures/bad_nonwoven_params.toml",
                "-o",
                "x.toml",
            ],
            "bad_nonwoven_params.toml:3:1: unknown field `fibres`",
        ),
        (
            vec![
                "generate",
                "nonwoven",
                "--params",
                "fixtures/missing.toml",
                "-o",
                "x.toml",
            ],
            "cannot read fixtures/missing.toml",
        ),
        (
            vec!["generate", "nonwoven", "--fibers", "10", "-o", "x.vtu"],
            "must be a .toml or .json",
        ),
    ] {
        fails_saying(&args, needle);
    }
    assert!(!at_root("x.toml").exists() && !at_root("x.vtu").exists());
}

#[test]
fn every_generator_writes_a_cell_and_prints_its_statistics() {
    let out = tmpdir("generators");
    std::fs::create_dir_all(&out).unwrap();
    for (args, fibers) in [
        (
            vec!["woven", "--pattern", "twill:2/1", "--size", "6e-3,6e-3"],
            6,
        ),
        (
            vec![
                "geotextile",
                "--family",
                "0,5e-3,5e-4",
                "--family",
                "90,5e-3,5e-4,1",
            ],
            8, // four fibers and four connector beams
        ),
        (vec!["knitted", "--wales", "3", "--courses", "2"], 2),
        (
            vec!["from", "fixtures/cells/geotextile_small.params.toml"],
            4,
        ),
    ] {
        let path = out.join(format!("{}.toml", args[0]));
        let mut all = vec!["generate"];
        all.extend(&args);
        all.extend(["-o", path.to_str().unwrap()]);
        let o = run(&all);
        assert!(
            o.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(
            text.contains(&format!("{fibers} fibers")),
            "{args:?}: {text}"
        );
        assert!(
            text.contains("contacts") && text.contains("mean free segment"),
            "{text}"
        );
        assert!(path.exists());
    }
    fails_saying(
        &[
            "generate",
            "geotextile",
            "--family",
            "30,5e-3,5e-4",
            "-o",
            "x.toml",
        ],
        "families[0]",
    );
    fails_saying(
        &["generate", "woven", "--pattern", "satin", "-o", "x.toml"],
        "twill:OVER/UNDER",
    );
}

#[test]
fn convert_round_trips_through_abaqus_and_writes_paraview_files() {
    let out = tmpdir("convert");
    std::fs::create_dir_all(&out).unwrap();
    let inp = out.join("cell.inp");
    let toml = out.join("cell.toml");
    for (from, to) in [
        ("fixtures/cells/knitted_small.toml", inp.to_str().unwrap()),
        (inp.to_str().unwrap(), toml.to_str().unwrap()),
    ] {
        let o = run(&["convert", from, to]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let a = fibercell::io::read_description(&at_root("fixtures/cells/knitted_small.toml")).unwrap();
    let b = fibercell::io::read_description(&toml).unwrap();
    assert_eq!(a, b);
    let pvd = out.join("cell.pvd");
    let o = run(&[
        "convert",
        "fixtures/cells/knitted_small.toml",
        pvd.to_str().unwrap(),
    ]);
    assert!(o.status.success());
    let contacts = std::fs::read_to_string(out.join("cell_contacts.vtp")).unwrap();
    assert!(
        contacts.contains("NumberOfPoints=\"16\""),
        "16 closed crossings"
    );
    assert!(std::fs::read_to_string(out.join("cell_fibers.vtp"))
        .unwrap()
        .contains("radius"));
    fails_saying(
        &["convert", "fixtures/ok_frame3d.toml", "x.stl"],
        "unknown output format",
    );
    fails_saying(
        &["convert", "fixtures/bad_nan_coordinate.toml", "x.inp"],
        "node 2",
    );
}

/// `--solver` and `--ordering` on every command that solves, with the accepted values in
/// `--help`; CG on a cell (it failed on every cell with "preconditioner blocks must start at
/// 0" before the cell jobs passed their node blocks).
#[test]
fn every_solving_command_takes_solver_and_ordering() {
    for command in ["solve", "homogenize", "curve"] {
        let o = run(&[command, "--help"]);
        let help = String::from_utf8_lossy(&o.stdout);
        assert!(
            help.contains("[possible values: faer-cholesky, faer-lu, cg, cholmod]")
                && help.contains("[possible values: auto, amd, nd, natural]"),
            "{command}: {help}"
        );
    }
    let o = run(&[
        "homogenize",
        "fixtures/woven_plain.toml",
        "--solver",
        "cg",
        "--ordering",
        "amd",
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let doc: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(doc["backend"], "cg");
    assert!(doc["backward_error"].as_f64().is_some_and(|b| b <= 1e-10));
    assert!(doc["relative_residual"].as_f64().is_some());
}

/// A matrix written by `export-matrix` is read back by `solve-matrix` and solved by every
/// backend of the build: with b = A·1 the solution is all ones to 1e-8 (measured: 4e-12 with
/// Cholesky, 1e-12 with LU, 7e-10 with CG) at a backward error of 1e-12 at most. A file that breaks the format fails naming its line; a triangle stored as a
/// general matrix is refused by the symmetric backends with the remedy.
#[test]
fn solve_matrix_reads_what_export_matrix_writes() {
    let dir = tmpdir("solve-matrix");
    std::fs::create_dir_all(&dir).expect("dir");
    let k = dir.join("K.mtx");
    let k = k.to_str().expect("utf-8 path");
    let o = run(&["export-matrix", "fixtures/ok_frame3d.toml", "-o", k]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for solver in ["faer-cholesky", "faer-lu", "cg"] {
        let o = run(&["solve-matrix", k, "--solver", solver, "--json"]);
        assert!(
            o.status.success(),
            "{solver}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let doc: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
        assert_eq!(doc["backend"], solver);
        assert_eq!(doc["n"], 29);
        let be = doc["backward_error"].as_f64().expect("backward error");
        let ones = doc["error_against_ones"]
            .as_f64()
            .expect("error against ones");
        assert!(be <= 1e-12 && ones <= 1e-8, "{solver}: {be:e} {ones:e}");
        // A 29-unknown matrix gets faer's simplicial factor: its stored values are its
        // structure, 8 bytes each. LU and CG report no factor size.
        match (doc["nnz_factor"].as_u64(), doc["factor_bytes"].as_u64()) {
            (Some(nnz), Some(bytes)) if solver == "faer-cholesky" => assert_eq!(bytes, 8 * nnz),
            (_, bytes) => assert!(solver != "faer-cholesky" && bytes.is_none(), "{solver}"),
        }
    }
    let bad = dir.join("bad.mtx");
    std::fs::write(
        &bad,
        "%%MatrixMarket matrix coordinate real general\n2 2 2\n1 1 1\n3 1 1\n",
    )
    .expect("write");
    fails_saying(&["solve-matrix", bad.to_str().expect("path")], "line 4");
    let lower = dir.join("lower.mtx");
    std::fs::write(
        &lower,
        "%%MatrixMarket matrix coordinate real general\n2 2 3\n1 1 2\n2 1 -1\n2 2 2\n",
    )
    .expect("write");
    fails_saying(
        &["solve-matrix", lower.to_str().expect("path")],
        "both triangles",
    );
    let o = run(&[
        "solve-matrix",
        lower.to_str().expect("path"),
        "--solver",
        "faer-lu",
    ]);
    assert!(
        o.status.success(),
        "LU takes a triangle as the matrix it is"
    );
}

/// `solve-matrix` solves the six cell problems `export-matrix` writes for a cell (before, it
/// took one right-hand side only and refused the exported ones) and writes X with `-o`: read
/// back, each column satisfies A x = b to a normwise backward error of 1e-14, computed here
/// from the files alone. B with the wrong number of rows fails naming the sizes, and no X is
/// written.
#[test]
fn solve_matrix_solves_every_exported_right_hand_side_and_writes_x() {
    let dir = tmpdir("solve-many");
    std::fs::create_dir_all(&dir).expect("dir");
    let path = |name: &str| dir.join(name).to_str().expect("utf-8 path").to_string();
    let (k, b, x) = (path("K.mtx"), path("K_rhs.mtx"), path("X.mtx"));
    let o = run(&["export-matrix", "fixtures/woven_plain.toml", "-o", &k]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = run(&["solve-matrix", &k, "--rhs", &b, "-o", &x, "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let doc: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(doc["columns"], 6);
    assert!(doc["error_against_ones"].is_null());
    let read = |p: &str| std::fs::read_to_string(p).expect("file");
    let a = fibercell::solver::read_matrix_market(&read(&k)).expect("A");
    let (n, columns, rhs) = fibercell::solver::read_matrix_market_dense(&read(&b)).expect("B");
    let (xn, xcolumns, sol) = fibercell::solver::read_matrix_market_dense(&read(&x)).expect("X");
    assert_eq!((xn, xcolumns), (n, columns));
    assert_eq!(columns, 6);
    let a = a.as_ref();
    let inf = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let a_inf = (0..n)
        .map(|j| a.col(j).1.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0f64, f64::max); // the column sums: A is symmetric
    for c in 0..columns {
        let (xc, bc) = (&sol[c * n..(c + 1) * n], &rhs[c * n..(c + 1) * n]);
        let mut ax = vec![0.0; n];
        a.mul_vec(xc, &mut ax);
        let r: Vec<f64> = ax.iter().zip(bc).map(|(p, q)| p - q).collect();
        let eta = inf(&r) / (a_inf * inf(xc) + inf(bc));
        assert!(inf(bc) > 0.0 && eta <= 1e-14, "column {c}: {eta:e}");
    }
    let short = path("short.mtx");
    std::fs::write(
        &short,
        "%%MatrixMarket matrix array real general\n2 1\n1\n2\n",
    )
    .expect("b");
    let x2 = path("X2.mtx");
    fails_saying(
        &["solve-matrix", &k, "--rhs", &short, "-o", &x2],
        "one or more columns",
    );
    assert!(!Path::new(&x2).exists(), "no X on an error");
}

/// `export-matrix` of a periodic cell writes the matrix of its six cell problems (periodic
/// elimination, anchor, contacts in stick) — before, the unconstrained, singular element
/// stiffness — with the six right-hand sides and the row map beside it, into a folder it
/// creates. Read back, it equals the library's `cell_problem` exactly, it is as large as
/// `homogenize`'s unknowns, and its first cell problem solves to a backward error of 1e-14.
#[test]
fn export_matrix_of_a_cell_writes_its_cell_problems() {
    let dir = tmpdir("cell-mtx").join("new").join("folder");
    let k = dir.join("K.mtx");
    let o = run(&[
        "export-matrix",
        "fixtures/woven_plain.toml",
        "-o",
        k.to_str().expect("path"),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let a = fibercell::solver::read_matrix_market(&std::fs::read_to_string(&k).expect("K"))
        .expect("reads back");
    let (n, columns, rhs) = fibercell::solver::read_matrix_market_dense(
        &std::fs::read_to_string(dir.join("K_rhs.mtx")).expect("rhs"),
    )
    .expect("reads back");
    let model = fibercell::io::load_model(&at_root("fixtures/woven_plain.toml")).expect("model");
    let want = fibercell::homogenize::cell_problem(&model).expect("cell problem");
    // The lower triangle is written exactly (the upper one mirrors it; the assembled one
    // equals it to roundoff).
    let (got, exact) = (a.as_ref(), want.matrix.as_ref());
    assert_eq!(got.col_ptr(), exact.col_ptr(), "the pattern");
    assert_eq!(got.row_idx(), exact.row_idx(), "the pattern");
    for j in 0..got.ncols() {
        let ((rows, x), (_, y)) = (got.col(j), exact.col(j));
        for ((&i, x), y) in rows.iter().zip(x).zip(y) {
            if i >= j {
                assert_eq!(x, y, "entry ({i}, {j})");
            }
        }
    }
    assert_eq!((n, columns), (want.dofs.len(), 6));
    assert_eq!(rhs, want.rhs, "the right-hand sides are written exactly");
    let h = fibercell::homogenize::homogenize_elastic(&model, &Default::default()).expect("ABD");
    assert_eq!(n, h.free_dofs);
    let map = std::fs::read_to_string(dir.join("K_dofs.csv")).expect("map");
    assert_eq!(map.lines().count(), n + 1);
    assert!(map.starts_with("row,node,dof\n1,"));
    // The exported first cell problem is nonsingular and solves to a backward error of 1e-14.
    let config = fibercell::solve::SolverConfig::default();
    let (_, r) = fibercell::solve::solve_matrix(a.as_ref(), Some(&rhs[..n]), &config, 1)
        .expect("the cell matrix is not singular");
    assert!(r.backward_error <= 1e-14, "{}", r.backward_error);
}

/// `solve` on a periodic cell points to the commands that solve cells instead of calling its
/// fibers "held by nothing".
#[test]
fn solve_on_a_cell_points_to_homogenize() {
    for cell in ["fixtures/woven_plain.toml", "fixtures/ok_cell_grid.toml"] {
        let out = tmpdir("solve-cell");
        fails_saying(
            &["solve", cell, "-o", out.to_str().expect("path")],
            "run `fibercell homogenize`",
        );
    }
}

/// Every column of every CSV the CLI writes is a count, an id or a label, or carries its unit
/// as `name [unit]`.
#[test]
fn every_csv_column_says_its_unit() {
    const UNITLESS: [&str; 13] = [
        "step",
        "node",
        "contact",
        "fiber_a",
        "fiber_b",
        "state",
        "iterations",
        "factorizations",
        "open",
        "stick",
        "slip",
        "from",
        "to",
    ];
    let out = tmpdir("units");
    let solve = run(&[
        "solve",
        "fixtures/ok_contact_bars2.toml",
        "--steps",
        "2",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(solve.status.success());
    let curve = run(&[
        "curve",
        "fixtures/cells/woven_small.toml",
        "--strain",
        "e11=0.001,k11=1",
        "--steps",
        "2",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(curve.status.success());
    let files = [
        "displacements.csv",
        "increments.csv",
        "contacts.csv",
        "curve.csv",
        "switches.csv",
    ];
    for f in files {
        let text = std::fs::read_to_string(out.join(f)).unwrap();
        let header = text.lines().next().unwrap();
        for column in header.split(',') {
            let unit = column
                .split_once(" [")
                .and_then(|(_, u)| u.strip_suffix(']'));
            assert!(
                UNITLESS.contains(&column) || unit.is_some_and(|u| !u.is_empty()),
                "{f}: column \"{column}\" has no unit"
            );
        }
    }
    let curve_header = std::fs::read_to_string(out.join("curve.csv")).unwrap();
    assert!(curve_header.starts_with("step,alpha [-],e11 [-],e22 [-],g12 [-],k11 [1/m]"));
    assert!(curve_header.lines().next().unwrap().contains(",M11 [N],"));
}

/// Angles are degrees on the CLI and in parameter files alike: `--tilt 20` and
/// `tilt_degrees = 20.0` (with von Mises `mean_angle_degrees` and `vonmises:30,2`, the other
/// parameters the CLI's defaults) generate the same cell, and the radian-era key `tilt` is refused naming `tilt_degrees`. Results go to
/// `-d DIR` (`--out-dir`), files to `-o FILE`.
#[test]
fn angles_are_degrees_and_outputs_say_dir_or_file() {
    let out = tmpdir("degrees");
    std::fs::create_dir_all(&out).unwrap();
    let (cli, file) = (out.join("cli.toml"), out.join("file.toml"));
    let o = run(&[
        "generate",
        "nonwoven",
        "--fibers",
        "30",
        "--tilt",
        "20",
        "--orientation",
        "vonmises:30,2",
        "--seed",
        "3",
        "-o",
        cli.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let params = out.join("params.toml");
    std::fs::write(
        &params,
        "size = [5e-3, 5e-3]\namount = { kind = \"count\", fibers = 30 }\n\
         length = { kind = \"fixed\", length = 2e-3 }\nradius = 1e-5\n\
         orientation = { kind = \"von_mises\", mean_angle_degrees = 30.0, concentration = 2.0 }\n\
         tilt_degrees = 20.0\ncurl = 0.0\nelement_length = 1e-4\ntolerance = 1e-3\n\
         young = 1.5e9\npoisson = 0.4\nmu = 0.3\nseed = 3\n",
    )
    .unwrap();
    generate_nonwoven_from(&params, &file);
    let (a, b) = (
        std::fs::read_to_string(&cli).unwrap(),
        std::fs::read_to_string(&file).unwrap(),
    );
    assert!(a.contains("[[fibers]]") && a == b, "the two cells differ");
    std::fs::write(&params, "tilt = 0.3\n").unwrap();
    fails_saying(
        &[
            "generate",
            "nonwoven",
            "--params",
            params.to_str().unwrap(),
            "-o",
            "x.toml",
        ],
        "tilt_degrees",
    );
    let results = out.join("results");
    let o = run(&[
        "homogenize",
        "fixtures/cells/woven_small.toml",
        "--out-dir",
        results.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(results.join("homogenized.json").exists());
    let help = run(&["curve", "--help"]);
    assert!(String::from_utf8_lossy(&help.stdout).contains("-d, --out-dir <DIR>"));
}

/// A run killed midway leaves no `.fibercell-*.tmp` files, and no JSON document of an earlier
/// run that would make its folder look complete (the JSON is written last).
#[test]
#[cfg(unix)]
fn an_interrupted_run_leaves_no_temporary_files_nor_an_old_json() {
    let out = tmpdir("interrupted");
    std::fs::create_dir_all(&out).unwrap();
    let stale = out.join("curve.json");
    std::fs::write(&stale, "{\"from\": \"an earlier run\"}").unwrap();
    let child = fibercell()
        .args([
            "curve",
            "fixtures/cells/nonwoven_small.toml",
            "--strain",
            "e11=0.01",
            "--steps",
            "20000",
            "-d",
            out.to_str().unwrap(),
        ])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // The old JSON goes as soon as the results folder is prepared, before the curve runs.
    let started = std::time::Instant::now();
    while stale.exists() && started.elapsed().as_secs() < 60 {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    assert!(
        !stale.exists(),
        "the earlier run's curve.json is still there"
    );
    // SAFETY: kill(2) with the child's pid and SIGTERM.
    unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
    let o = child.wait_with_output().unwrap();
    assert_eq!(
        o.status.code(),
        Some(130),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(String::from_utf8_lossy(&o.stderr).contains("interrupted"));
    let left: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(left.iter().all(|n| !n.ends_with(".tmp")), "{left:?}");
    assert!(!left.iter().any(|n| n == "curve.json"), "{left:?}");
}

/// A target that cannot be written (here: a directory of that name) is named in the error,
/// never the temporary file the output was written to first.
#[test]
fn write_errors_name_the_target_not_a_temporary_file() {
    let out = tmpdir("unwritable");
    let matrix = out.join("K.mtx");
    std::fs::create_dir_all(&matrix).unwrap();
    let marker = out.join("curve.json");
    std::fs::create_dir_all(&marker).unwrap();
    for (args, target) in [
        (
            vec![
                "export-matrix",
                "fixtures/ok_frame3d.toml",
                "-o",
                matrix.to_str().unwrap(),
            ],
            matrix.display().to_string(),
        ),
        (
            vec![
                "curve",
                "fixtures/cells/woven_small.toml",
                "--strain",
                "e11=0.001",
                "--steps",
                "2",
                "-d",
                out.to_str().unwrap(),
            ],
            marker.display().to_string(),
        ),
    ] {
        let o = run(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert!(err.contains(&format!("cannot write {target}")), "{err}");
        assert!(
            !err.contains(".tmp") && !err.contains(".fibercell-"),
            "{err}"
        );
    }
}
