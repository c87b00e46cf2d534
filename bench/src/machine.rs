//! The physical limits of the machine the benchmark runs on: dense DGEMM GFLOP/s on one and on
//! all threads (the bound of a supernodal factorization) and the memory bandwidth of a STREAM
//! triad (the bound of triangular solves, value fill and sparse products).

use faer::{linalg::matmul::matmul, Accum, Mat, Par};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// What the machine is and what it can do.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Machine {
    /// CPU model name (from /proc/cpuinfo where available).
    pub cpu: String,
    /// Threads rayon uses.
    pub threads: usize,
    /// Installed memory (GiB), where known.
    pub memory_gib: Option<f64>,
    /// Dense double-precision matrix product on one thread (GFLOP/s).
    pub dgemm_gflops_1: f64,
    /// Dense double-precision matrix product on all threads (GFLOP/s).
    pub dgemm_gflops_all: f64,
    /// STREAM triad a = b + s·c on all threads, counting 24 bytes per element (GB/s).
    pub bandwidth_gbs: f64,
}

/// Best of `repeats` timings of `f` (seconds).
pub(crate) fn best_of(repeats: usize, mut f: impl FnMut()) -> f64 {
    (0..repeats.max(1))
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

/// GFLOP/s of C = A B for n × n matrices with parallelism `par` (best of three).
pub fn dgemm_gflops(n: usize, par: Par) -> f64 {
    let a = Mat::<f64>::from_fn(n, n, |i, j| ((i * 31 + j * 17) % 97) as f64 / 97.0);
    let b = Mat::<f64>::from_fn(n, n, |i, j| ((i * 13 + j * 7) % 89) as f64 / 89.0);
    let mut c = Mat::<f64>::zeros(n, n);
    let t = best_of(3, || {
        matmul(c.as_mut(), Accum::Replace, a.as_ref(), b.as_ref(), 1.0, par);
    });
    2.0 * (n as f64).powi(3) / t / 1e9
}

/// STREAM triad bandwidth (GB/s) over arrays of `len` doubles (best of five).
pub fn triad_bandwidth(len: usize) -> f64 {
    let b = vec![1.0f64; len];
    let c = vec![2.0f64; len];
    let mut a = vec![0.0f64; len];
    let t = best_of(5, || {
        a.par_chunks_mut(1 << 16)
            .zip(b.par_chunks(1 << 16))
            .zip(c.par_chunks(1 << 16))
            .for_each(|((a, b), c)| {
                for ((x, y), z) in a.iter_mut().zip(b).zip(c) {
                    *x = y + 3.0 * z;
                }
            });
    });
    std::hint::black_box(&a);
    24.0 * len as f64 / t / 1e9
}

fn cpu_name() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|v| v.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string())
}

fn memory_gib() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/meminfo").ok()?;
    let kib: f64 = s
        .lines()
        .find(|l| l.starts_with("MemTotal:"))?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()?;
    Some(kib / (1024.0 * 1024.0))
}

/// Measures the machine: DGEMM of order `n` on one and all threads, the triad over `len`
/// doubles per array.
pub fn measure_machine(n: usize, len: usize) -> Machine {
    let threads = rayon::current_num_threads();
    Machine {
        cpu: cpu_name(),
        threads,
        memory_gib: memory_gib(),
        dgemm_gflops_1: dgemm_gflops(n, Par::Seq),
        dgemm_gflops_all: dgemm_gflops(n, Par::rayon(threads)),
        bandwidth_gbs: triad_bandwidth(len),
    }
}

/// Peak resident memory of this process so far (bytes), where the OS reports it.
pub fn peak_memory_bytes() -> Option<u64> {
    // SAFETY: getrusage writes into the zeroed struct we own.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let rc = unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) };
    (rc == 0).then(|| usage.ru_maxrss as u64 * 1024)
}
