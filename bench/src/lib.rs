//! The throughput benchmark behind `fibercell bench`: generated non-woven cells S, M and L
//! ([`fibercell::generate::nonwoven_preset`]), every stage timed separately (generation, contact
//! search, pattern, value fill, symbolic analysis, numeric factorization and solve per backend,
//! the solve after contact switches on the previous factor, the six elastic cell problems, an
//! elasto-plastic curve), with nnz(K), nnz(L), flops and peak memory, and the machine's own
//! limits (DGEMM, memory bandwidth) that each stage is reported against.

mod cell;
mod machine;
mod report;

pub use cell::{bench_cell, BackendBench, CellBench, CurveBench, MemoryBench, ReuseBench};
pub use machine::{dgemm_gflops, measure_machine, peak_memory_bytes, triad_bandwidth, Machine};
pub use report::{markdown, reproduce_command, splice_readme, README_MARKERS, REPORT_PATH};

use fibercell::Error;
use serde::{Deserialize, Serialize};

/// Default wall-clock limit of one curve (s).
pub const DEFAULT_CURVE_TIME_LIMIT: f64 = 1200.0;

/// What to run.
#[derive(Clone, Debug)]
pub struct BenchOptions {
    /// Presets to run, in order: "S", "M", "L".
    pub cells: Vec<String>,
    /// Seed of the generator.
    pub seed: u64,
    /// Repeats of each timed stage (the median is reported); the millisecond stages (contact
    /// search and set, value fills) run at least 15 times.
    pub repeats: usize,
    /// Increments of each elasto-plastic curve (0: skip them).
    pub curve_steps: usize,
    /// Macroscopic ε11 at the end of the default curve: the generated cell as it is (Coulomb
    /// friction with the bond's cohesion), no option (0: skip it).
    pub curve_strain: f64,
    /// Macroscopic ε11 at the end of the mild curve of earlier reports: Tresca friction at
    /// `tresca_bound`, bonded, stabilized by 1e-8 (0: skip it).
    pub mild_curve_strain: f64,
    /// Wall-clock limit of one curve (s): it stops after the increment that passes it and the
    /// report projects the rest (None: no limit).
    pub curve_time_limit: Option<f64>,
    /// Tresca bound of the contacts in the mild curve (N), which runs on bonded contacts (see
    /// [`fibercell::solve::IncrementalOptions::bonded`]).
    pub tresca_bound: f64,
}

impl Default for BenchOptions {
    fn default() -> Self {
        BenchOptions {
            cells: vec!["S".into(), "M".into()],
            seed: 1,
            repeats: 3,
            curve_steps: 100,
            curve_strain: 1e-2,
            mild_curve_strain: 2e-3,
            tresca_bound: 1e-4,
            curve_time_limit: Some(DEFAULT_CURVE_TIME_LIMIT),
        }
    }
}

/// Everything the benchmark measured.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BenchReport {
    /// fibercell version.
    pub version: String,
    /// The machine and its limits.
    pub machine: Machine,
    /// Seed, repeats and curve settings.
    pub seed: u64,
    /// Repeats per stage.
    pub repeats: usize,
    /// The curve's wall-clock limit (s), if any.
    #[serde(default)]
    pub curve_time_limit: Option<f64>,
    /// One entry per cell.
    pub cells: Vec<CellBench>,
}

/// Measures the machine, then every cell of `opts`; `log` hears what is being run.
pub fn run_bench(opts: &BenchOptions, log: &mut dyn FnMut(&str)) -> Result<BenchReport, Error> {
    if opts.repeats == 0 {
        return Err(Error::InvalidOption("repeats must be at least 1".into()));
    }
    if !(opts.curve_strain.is_finite()
        && opts.mild_curve_strain.is_finite()
        && opts.tresca_bound.is_finite()
        && opts.tresca_bound >= 0.0
        && opts
            .curve_time_limit
            .is_none_or(|s| s.is_finite() && s > 0.0))
    {
        return Err(Error::InvalidOption(
            "curve strains, Tresca bound and curve time limit must be finite, the bound ≥ 0, the limit > 0".into(),
        ));
    }
    for c in &opts.cells {
        fibercell::generate::nonwoven_preset(c, opts.seed)?;
    }
    log("machine: DGEMM and memory bandwidth");
    let machine = measure_machine(2048, 1 << 25);
    let mut cells = Vec::new();
    for c in &opts.cells {
        cells.push(bench_cell(c, opts, &machine, log)?);
    }
    Ok(BenchReport {
        version: env!("CARGO_PKG_VERSION").to_string(),
        machine,
        seed: opts.seed,
        repeats: opts.repeats,
        curve_time_limit: opts.curve_time_limit,
        cells,
    })
}
