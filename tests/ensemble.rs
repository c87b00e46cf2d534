//! Ensembles: statistics against the realizations computed one by one, failed realizations
//! reported with their seed while the others complete, and a restart — of the library run and
//! of a killed CLI run — that gives the uninterrupted result.

use fibercell::ensemble::{run_ensemble, EnsembleOptions};
use fibercell::generate::{CellParams, FiberAmount};
use fibercell::homogenize::homogenize_elastic;
use fibercell::io::read_cell_params;
use fibercell::solve::SolveOptions;
use fibercell::Model;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// The small non-woven of the fixture catalog with `fibers` fibers: at 30 some seeds do not
/// percolate (2 and 4 of 1–4), at 50 all of 1–6 do.
fn small_nonwoven(fibers: usize) -> CellParams {
    let mut p = read_cell_params(Path::new("fixtures/cells/nonwoven_small.params.toml")).unwrap();
    let CellParams::Nonwoven(n) = &mut p else {
        panic!("not a non-woven")
    };
    n.amount = FiberAmount::Count { fibers };
    p
}

fn options(params: CellParams, realizations: usize) -> EnsembleOptions {
    EnsembleOptions {
        params,
        realizations,
        first_seed: 1,
        solve: SolveOptions::default(),
    }
}

#[test]
fn failed_realizations_are_reported_and_the_others_give_the_statistics() {
    let params = small_nonwoven(30);
    let e = run_ensemble(&options(params.clone(), 4), None, None).unwrap();
    let failed = e.failed();
    assert_eq!(failed.iter().map(|f| f.0).collect::<Vec<_>>(), [2, 4]);
    assert!(
        failed.iter().all(|f| f.1.contains("percolate")),
        "{failed:?}"
    );
    // The ABD of seeds 1 and 3, computed directly.
    let abd = |seed: u64| {
        let d = params.with_seed(seed).generate().unwrap();
        homogenize_elastic(
            &Model::from_description(&d).unwrap(),
            &SolveOptions::default(),
        )
        .unwrap()
        .abd
    };
    let (a, b) = (abd(1), abd(3));
    // Two values: mean (a + b)/2, s = |a − b|/√2, ci95 = t₀.₉₇₅,₁ s/√2 with t = 12.706.
    for i in 0..6 {
        for j in 0..6 {
            let x = &e.abd[i][j];
            let scale = a[i][j].abs().max(b[i][j].abs());
            assert_eq!(x.n, 2);
            assert!((x.mean - 0.5 * (a[i][j] + b[i][j])).abs() <= 1e-12 * scale);
            let s = (a[i][j] - b[i][j]).abs() / 2f64.sqrt();
            assert!((x.std - s).abs() <= 1e-12 * scale);
            assert!((x.ci95 - 12.706 * s / 2f64.sqrt()).abs() <= 1e-4 * x.ci95.max(1e-300));
        }
    }
    assert_eq!(e.convergence.len(), 1);
}

#[test]
fn a_restarted_ensemble_reuses_the_stored_realizations_and_equals_a_fresh_one() {
    let dir = tempfile::tempdir().unwrap();
    let params = small_nonwoven(50);
    let first = run_ensemble(&options(params.clone(), 2), Some(dir.path()), None).unwrap();
    assert_eq!(first.reused, 0);
    let resumed = run_ensemble(&options(params.clone(), 4), Some(dir.path()), None).unwrap();
    assert_eq!(resumed.reused, 2);
    assert_eq!(resumed.realizations[..2], first.realizations[..]);
    // Realizations of other parameters are not reused.
    let other = run_ensemble(&options(small_nonwoven(60), 4), Some(dir.path()), None);
    let err = other.unwrap_err().to_string();
    assert!(err.contains("other generator parameters"), "{err}");
    let fresh = run_ensemble(&options(params, 4), None, None).unwrap();
    let abd = |e: &fibercell::ensemble::Ensemble| -> Vec<_> {
        e.realizations.iter().map(|r| r.abd).collect()
    };
    assert_eq!(abd(&resumed), abd(&fresh));
    assert_eq!(resumed.abd, fresh.abd);
    assert_eq!(resumed.convergence, fresh.convergence);
}

#[test]
fn a_killed_cli_run_restarts_where_it_stopped() {
    let work = tempfile::tempdir().unwrap();
    let params = work.path().join("params.toml");
    std::fs::write(&params, toml::to_string(&small_nonwoven(50)).unwrap()).unwrap();
    let run = |dir: &Path| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_fibercell"));
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
