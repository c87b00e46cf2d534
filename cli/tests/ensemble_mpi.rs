//! Ensembles over the ranks of an MPI job (feature `mpi`; `mpirun` from Open MPI): every
//! realization bitwise the one of a single-process run, failed ones reported with their seed,
//! and a restart that reuses the stored realizations.
#![cfg(feature = "mpi")]

mod common;

use std::path::Path;
use std::process::{Command, Output};

/// The small non-woven of the fixture catalog with 30 fibers: seeds 2 and 4 do not percolate.
fn params_file(dir: &Path) -> std::path::PathBuf {
    let text =
        std::fs::read_to_string(common::at_root("fixtures/cells/nonwoven_small.params.toml"))
            .unwrap();
    let path = dir.join("params.toml");
    std::fs::write(&path, text.replace("fibers = 140", "fibers = 30")).unwrap();
    path
}

fn ensemble_args(params: &Path, n: &str, out: &Path) -> Vec<std::ffi::OsString> {
    let mut args: Vec<std::ffi::OsString> = ["ensemble", "--params"].map(Into::into).to_vec();
    args.push(params.into());
    args.extend(["-n", n, "--json", "-d"].map(Into::into));
    args.push(out.into());
    args
}

/// `mpirun -np 2` of the CLI. Each rank runs unbound (`--bind-to none`), so it has the
/// threads of a single process: Open MPI's default binds a rank to one core, and a
/// factorization on one thread sums in another order than on two.
fn mpirun(args: &[std::ffi::OsString]) -> Output {
    let out = Command::new("mpirun")
        .args(["-np", "2", "--oversubscribe", "--bind-to", "none"])
        .arg(env!("CARGO_BIN_EXE_fibercell"))
        .args(args)
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .output()
        .expect("mpirun (install openmpi-bin)");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn single(args: &[std::ffi::OsString]) -> Output {
    let out = common::fibercell().args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn document(out: &Output) -> serde_json::Value {
    serde_json::from_slice(&out.stdout).unwrap()
}

/// Every realization's ABD (or error) and the statistics, without the timings.
fn results(doc: &serde_json::Value) -> serde_json::Value {
    let realizations: Vec<_> = doc["realizations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| serde_json::json!([r["seed"], r["abd"], r["error"], r["contacts"]]))
        .collect();
    serde_json::json!([realizations, doc["abd"], doc["convergence"]])
}

#[test]
fn two_ranks_give_the_single_process_ensemble_bit_for_bit() {
    let work = tempfile::tempdir().unwrap();
    let params = params_file(work.path());
    let alone = single(&ensemble_args(&params, "5", &work.path().join("alone")));
    let ranks = mpirun(&ensemble_args(&params, "5", &work.path().join("ranks")));
    let (a, b) = (document(&alone), document(&ranks));
    assert_eq!(results(&a), results(&b));
    // Seeds 2 and 4 fail on either; the others complete.
    let failed: Vec<u64> = b["realizations"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| !r["error"].is_null())
        .map(|r| r["seed"].as_u64().unwrap())
        .collect();
    assert_eq!(failed, [2, 4]);
    let table = |d: &str| std::fs::read_to_string(work.path().join(d).join("ensemble.csv"));
    assert_eq!(table("alone").unwrap(), table("ranks").unwrap());
    // Only rank 0 reports.
    let stdout = String::from_utf8_lossy(&ranks.stdout);
    assert_eq!(stdout.matches("\"realizations\"").count(), 1);
}

#[test]
fn a_two_rank_run_reuses_the_stored_realizations() {
    let work = tempfile::tempdir().unwrap();
    let params = params_file(work.path());
    let out = work.path().join("run");
    mpirun(&ensemble_args(&params, "3", &out));
    let more = mpirun(&ensemble_args(&params, "6", &out));
    // Seeds 1 and 3 come back from the store, and so does seed 2's failure (reported again).
    let log = String::from_utf8_lossy(&more.stderr);
    for seed in [1, 3] {
        assert!(log.contains(&format!("seed {seed}: reused")), "{log}");
    }
    let doc = document(&more);
    assert_eq!(doc["reused"], 3);
    let fresh = single(&ensemble_args(&params, "6", &work.path().join("fresh")));
    assert_eq!(results(&doc), results(&document(&fresh)));
}
