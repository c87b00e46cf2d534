//! `fibercell check`: the table and its exit code, the JSON document, refused options.

use fibercell::check::{check_model, CheckOptions};
use fibercell::io::load_model;

mod common;
use common::fibercell;

const PINNED_FIBER: &str = r#"
[[materials]]
name = "steel"
young = 2.1e11
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
[[fibers]]
id = 7
nodes = [1, 2, 3]
radius = 0.01
material = "steel"
[[supports]]
node = 1
dofs = ["translations"]
"#;

/// A fiber pinned at one end spins and swings: the check names the singular node and fiber
/// and fails, and the CLI exits non-zero after printing the table.
#[test]
fn a_mechanism_fails_definiteness_by_name() {
    let dir = std::env::temp_dir().join(format!("fibercell-check-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("pinned.toml");
    std::fs::write(&path, PINNED_FIBER).unwrap();
    let model = load_model(&path).expect("model loads");
    let r = check_model(&model, &CheckOptions::default()).unwrap();
    assert!(!r.passed());
    assert!(!r.matrix.positive_definite);
    let why = r.matrix.definiteness_error.as_ref().unwrap();
    assert!(
        why.contains("singular at node") && why.contains("fiber 7"),
        "{why}"
    );
    let o = fibercell()
        .args(["check", path.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!o.status.success());
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("FAIL positive definite"), "{out}");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("check failed"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The CLI: a passing model exits 0 with a JSON document; a nonsense accuracy is refused.
#[test]
fn cli_check_json_and_options() {
    let o = fibercell()
        .args(["check", "fixtures/ok_frame3d.toml", "--json"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let doc: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON");
    assert_eq!(doc["matrix"]["positive_definite"], true);
    assert!(doc["checks"]
        .as_array()
        .unwrap()
        .iter()
        .all(|c| c["passed"] == true));
    let o = fibercell()
        .args(["check", "fixtures/ok_frame3d.toml", "--accuracy", "2"])
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--accuracy"));
}
