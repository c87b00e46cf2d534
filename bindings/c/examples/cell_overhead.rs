//! What calling the stateful cell through the C ABI costs against the Rust call, and how many
//! material points a cell serves: prints one JSON document (`benches/cell_overhead.py` runs it
//! beside the Python calls and writes `benches/results/cell-overhead.json`).
//!
//! ```text
//! cargo run --release -p fibercell-c --example cell_overhead -- M.toml TINY.toml S.toml POINTS
//! ```
//!
//! * `large`: the same sequence of updates (ε11 by 10⁻⁴, tangent on) on two fresh states of
//!   the large cell, one by `Cell::update`, one by `fc_cell_update`, alternating step by step
//!   so that both see the same machine; per-update times.
//! * `tiny`: the same on a cell without contacts, many updates: the per-call overhead is the
//!   difference of the medians.
//! * `throughput`: `POINTS` states of the S cell, each with its own history (ε11 and γ12 in
//!   proportions that differ per point), updated in parallel over the cores with their caches
//!   released after each update (`CellState::release_caches`), and at most 100 with their
//!   caches kept: updates per second, and the resident memory a state adds.

use fibercell::solve::IncrementalOptions;
use fibercell::{Cell, Model};
use fibercell_c::cell::{
    fc_cell_free, fc_cell_new, fc_cell_state_free, fc_cell_state_new, fc_cell_update,
};
use fibercell_c::{FcCellResponse, FcStatus};
use fibercell_solver::median;
use rayon::prelude::*;
use std::time::Instant;

fn load(path: &str) -> Result<Model, Box<dyn std::error::Error>> {
    Ok(fibercell::io::load_model(std::path::Path::new(path))?)
}

/// Resident memory of the process now (bytes), from /proc/self/statm, after the allocator
/// returned its free memory to the system (else freed caches would still count).
fn resident_bytes() -> f64 {
    // SAFETY: malloc_trim only releases free memory of the allocator's heaps.
    unsafe { libc::malloc_trim(0) };
    std::fs::read_to_string("/proc/self/statm")
        .ok()
        .and_then(|s| s.split_whitespace().nth(1)?.parse::<f64>().ok())
        .map_or(f64::NAN, |pages| pages * 4096.0)
}

/// Per-update seconds of `steps` updates by ε11 = 10⁻⁴ through Rust and through the C ABI,
/// alternating, on fresh states of the cell `path`.
fn rust_against_c(
    path: &str,
    steps: usize,
) -> Result<(Vec<f64>, Vec<f64>), Box<dyn std::error::Error>> {
    let model = load(path)?;
    let cell = Cell::new(&model, &IncrementalOptions::default())?;
    let mut state = cell.new_state();
    let description = fibercell::io::read_description(std::path::Path::new(path))?;
    let text = std::ffi::CString::new(fibercell::io::to_json(&description)?)?;
    let (mut c_model, mut c_cell, mut c_state) = (
        std::ptr::null_mut(),
        std::ptr::null_mut(),
        std::ptr::null_mut(),
    );
    // SAFETY: valid strings and out-pointers, handles used as made.
    unsafe {
        let ok = fibercell_c::fc_model_from_string(text.as_ptr(), c"json".as_ptr(), &mut c_model)
            == FcStatus::FcOk
            && fc_cell_new(c_model, std::ptr::null(), true, &mut c_cell) == FcStatus::FcOk
            && fc_cell_state_new(c_cell, &mut c_state) == FcStatus::FcOk;
        if !ok {
            return Err("the C ABI could not set up the cell".into());
        }
    }
    let increment = [1e-4, 0.0, 0.0, 0.0, 0.0, 0.0];
    let (mut rust, mut c) = (Vec::new(), Vec::new());
    for _ in 0..steps {
        let t = Instant::now();
        cell.update(&mut state, &increment)?;
        rust.push(t.elapsed().as_secs_f64());
        let mut response = std::mem::MaybeUninit::<FcCellResponse>::uninit();
        let t = Instant::now();
        // SAFETY: handles from above, 6 doubles, a response to fill.
        let status =
            unsafe { fc_cell_update(c_cell, c_state, increment.as_ptr(), response.as_mut_ptr()) };
        c.push(t.elapsed().as_secs_f64());
        if status != FcStatus::FcOk {
            return Err("fc_cell_update failed".into());
        }
    }
    // SAFETY: handles from above, released once.
    unsafe {
        fc_cell_state_free(c_state);
        fc_cell_free(c_cell);
        fibercell_c::fc_model_free(c_model);
    }
    Ok((rust, c))
}

/// Points of the S cell updated with their caches kept (each holds its factorizations:
/// about 66 MB).
const CACHED_POINTS: usize = 100;

/// `points` states of `cell`, each with its own history (ε11 and γ12 by 10⁻⁴ in proportions
/// that differ per point), updated three times in parallel, their caches released after each
/// update or kept: updates per second per round and the resident memory a state adds.
fn throughput(
    cell: &Cell,
    points: usize,
    release: bool,
) -> Result<serde_json::Value, Box<dyn std::error::Error>> {
    let before = resident_bytes();
    let mut states: Vec<_> = (0..points).map(|_| cell.new_state()).collect();
    let increment = |p: usize| {
        let share = p as f64 / points.max(1) as f64;
        [1e-4 * (1.0 - share), 0.0, 1e-4 * share, 0.0, 0.0, 0.0]
    };
    let mut rates = Vec::new();
    for _ in 0..3 {
        let t = Instant::now();
        states.par_iter_mut().enumerate().try_for_each(|(p, s)| {
            cell.update(s, &increment(p))?;
            if release {
                s.release_caches();
            }
            Ok::<(), fibercell::Error>(())
        })?;
        rates.push(points as f64 / t.elapsed().as_secs_f64());
    }
    Ok(serde_json::json!({
        "points": points,
        "updates_per_s": rates,
        "resident_bytes_per_state": (resident_bytes() - before) / points.max(1) as f64,
    }))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [large, tiny, small, points] = args.as_slice() else {
        return Err("usage: cell_overhead LARGE.toml TINY.toml S.toml POINTS".into());
    };
    let points: usize = points.parse()?;
    let (large_rust, large_c) = rust_against_c(large, 20)?;
    let (tiny_rust, tiny_c) = rust_against_c(tiny, 2000)?;

    let model = load(small)?;
    let cell = Cell::new(&model, &IncrementalOptions::default())?;
    let released = throughput(&cell, points, true)?;
    let cached = throughput(&cell, points.min(CACHED_POINTS), false)?;
    let doc = serde_json::json!({
        "large": {
            "cell": large,
            "rust_median_s": median(large_rust.clone()),
            "c_median_s": median(large_c.clone()),
            "rust_total_s": large_rust.iter().sum::<f64>(),
            "c_total_s": large_c.iter().sum::<f64>(),
        },
        "tiny": {
            "cell": tiny,
            "rust_median_s": median(tiny_rust),
            "c_median_s": median(tiny_c),
        },
        "throughput": {
            "cell": small,
            "threads": rayon::current_num_threads(),
            "caches_released": released,
            "caches_kept": cached,
        },
    });
    println!("{}", serde_json::to_string_pretty(&doc)?);
    Ok(())
}
