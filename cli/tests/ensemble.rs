//! `fibercell ensemble` killed mid-run restarts where it stopped and gives the uninterrupted
//! result.

use fibercell::generate::{CellParams, FiberAmount};
use fibercell::io::read_cell_params;
use std::path::Path;
use std::time::{Duration, Instant};

mod common;
use common::fibercell;

/// The small non-woven of the fixture catalog with `fibers` fibers (all of seeds 1–6 percolate
/// at 50).
fn small_nonwoven(fibers: usize) -> CellParams {
    let path = common::at_root("fixtures/cells/nonwoven_small.params.toml");
    let mut p = read_cell_params(&path).unwrap();
    let CellParams::Nonwoven(n) = &mut p else {
        panic!("not a non-woven")
    };
    n.amount = FiberAmount::Count { fibers };
    p
}

#[test]
fn a_killed_cli_run_restarts_where_it_stopped() {
    let work = tempfile::tempdir().unwrap();
    let params = work.path().join("params.toml");
    std::fs::write(&params, toml::to_string(&small_nonwoven(50)).unwrap()).unwrap();
    let run = |dir: &Path| {
        let mut c = fibercell();
        c.args(["ensemble", "--params"])
            .arg(&params)
            .args(["-n", "6", "-d"])
            .arg(dir);
        c
    };
    let (killed, whole) = (work.path().join("killed"), work.path().join("whole"));
    let mut child = run(&killed).spawn().unwrap();
    // Kill it once two realizations are stored.
    let start = Instant::now();
    while !killed.join("realizations/seed-2.json").exists() {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no realization stored"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(
        !killed.join("ensemble.json").exists(),
        "the run finished before it was killed"
    );
    let restarted = run(&killed).output().unwrap();
    assert!(restarted.status.success());
    let log = String::from_utf8_lossy(&restarted.stderr);
    assert!(
        log.contains("seed 1: reused") && log.contains("seed 2: reused"),
        "{log}"
    );
    assert!(run(&whole).output().unwrap().status.success());
    let table = |d: &Path| std::fs::read_to_string(d.join("ensemble.csv")).unwrap();
    assert_eq!(table(&killed), table(&whole));
}
