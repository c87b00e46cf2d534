#!/usr/bin/env python3
"""faer (fibercell's kernel), CHOLMOD, MKL PARDISO and MUMPS on the same cell matrices, in one run.

For every preset: generate the non-woven (seed 1), export the first cell problem's matrix
(`fibercell export-matrix`), then time the symbolic analysis and the numeric factorization of
each solver on it, medians of --repeats runs:

* faer: `fibercell solve-matrix A.mtx --repeats R --json` (the default backend: fibercell's
  task-parallel supernodal LLᵀ on faer's symbolic factor and dense kernels);
* CHOLMOD: the same with `--solver cholmod` (needs a build with `--features cholmod`; Debian's
  libcholmod takes the system BLAS, which must be OpenBLAS: the script records which one);
* MKL PARDISO through pypardiso's MKL (mtype 2, real SPD, upper triangle; METIS nested
  dissection, its default), called directly with 0-based int32 arrays so that no conversion
  is timed: phase 11 (analysis), 22 (numeric factorization), 33 (a solve, checked);
* MUMPS 5 (Debian's sequential build, `apt-get install libmumps-seq-dev`: SCOTCH and PORD, no
  METIS, its dense kernels on OpenBLAS's threads) through `benches/mumps_factor.c`, which the
  script compiles with `cc` (SPD, MUMPS's automatic ordering; analysis and factorization timed
  in C). Without the package the rows say why MUMPS is missing and the rest runs.

The machine's bound is measured in the same run: two-thread DGEMM of order 4096 (NumPy's
OpenBLAS). Each solver's rate is its own flop count over its factorization time; faer's is
also given as a fraction of that DGEMM rate.

    cargo build --release -p fibercell-cli --features cholmod
    apt-get install libmumps-seq-dev   # optional: the MUMPS rows
    python3 -m venv target/pyenv && target/pyenv/bin/pip install numpy scipy pypardiso
    target/pyenv/bin/python benches/factor_comparison.py --presets M,L --repeats 3 \\
        -o benches/results/factor-comparison.json

CI (`.ci/run`) runs it once on the S preset and checks that all four solvers solve.
"""

import argparse
import ctypes
import importlib.metadata
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
import scipy.io
import scipy.sparse as sp


def dgemm_gflops(n=4096, runs=3):
    """Two-thread DGEMM rate of NumPy's BLAS (best of `runs`)."""
    a = np.random.default_rng(1).standard_normal((n, n))
    b = np.random.default_rng(2).standard_normal((n, n))
    a @ b
    best = min(timed(lambda: a @ b) for _ in range(runs))
    return 2.0 * n**3 / best / 1e9


def timed(f):
    t = time.perf_counter()
    f()
    return time.perf_counter() - t


def run_json(cmd):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def fibercell_solver(binary, mtx, solver, repeats):
    r = run_json([binary, "solve-matrix", mtx, "--solver", solver, "--repeats", str(repeats), "--json"])
    return {
        "ordering": r["ordering"],
        "analyze_seconds": r["analyze_seconds"],
        "factorize_seconds": r["factorize_seconds"],
        "nnz_factor": r["nnz_factor"],
        "flops": r["flops"],
        "backward_error": r["backward_error"],
    }


class Pardiso:
    """MKL PARDISO for one real SPD matrix (upper triangle, 0-based CSR)."""

    def __init__(self, a_upper):
        import pypardiso

        self.lib = pypardiso.PyPardisoSolver()._mkl_pardiso
        self.a = a_upper
        self.n = a_upper.shape[0]
        self.ia = a_upper.indptr.astype(np.int32)
        self.ja = a_upper.indices.astype(np.int32)
        self.data = np.ascontiguousarray(a_upper.data, dtype=np.float64)
        self.pt = np.zeros(64, dtype=np.int64)
        self.iparm = np.zeros(64, dtype=np.int32)
        p = self.iparm
        p[0] = 1  # these values, not the defaults
        p[1] = 2  # METIS nested dissection (the default)
        p[7] = 0  # no iterative refinement
        p[9] = 8  # pivot perturbation 1e-8 (the default for symmetric matrices)
        p[17] = -1  # report nnz(L)
        p[18] = -1  # report the factorization's MFLOP
        p[34] = 1  # 0-based indices
        self.perm = np.zeros(self.n, dtype=np.int32)

    def call(self, phase, b=None):
        b = np.zeros(self.n) if b is None else np.ascontiguousarray(b, dtype=np.float64)
        x = np.zeros_like(b)
        err = ctypes.c_int32(0)
        i32 = ctypes.POINTER(ctypes.c_int32)
        f64 = ctypes.POINTER(ctypes.c_double)
        self.lib(
            self.pt.ctypes.data_as(ctypes.POINTER(ctypes.c_int64)),
            ctypes.byref(ctypes.c_int32(1)),
            ctypes.byref(ctypes.c_int32(1)),
            ctypes.byref(ctypes.c_int32(2)),
            ctypes.byref(ctypes.c_int32(phase)),
            ctypes.byref(ctypes.c_int32(self.n)),
            self.data.ctypes.data_as(f64),
            self.ia.ctypes.data_as(i32),
            self.ja.ctypes.data_as(i32),
            self.perm.ctypes.data_as(i32),
            ctypes.byref(ctypes.c_int32(1)),
            self.iparm.ctypes.data_as(i32),
            ctypes.byref(ctypes.c_int32(0)),
            b.ctypes.data_as(f64),
            x.ctypes.data_as(f64),
            ctypes.byref(err),
        )
        if err.value != 0:
            raise RuntimeError(f"PARDISO phase {phase}: error {err.value}")
        return x

    def release(self):
        self.call(-1)


def pardiso_times(mtx, repeats):
    a = scipy.io.mmread(mtx).tocsr()
    upper = sp.triu(a, format="csr")
    upper.sort_indices()
    analyze, factorize = [], []
    for _ in range(repeats):
        p = Pardiso(upper)
        analyze.append(timed(lambda: p.call(11)))
        p.release()
    p = Pardiso(upper)
    p.call(11)
    for _ in range(repeats):
        factorize.append(timed(lambda: p.call(22)))
    ones = np.ones(a.shape[0])
    b = a @ ones
    x = p.call(33, b)
    backward = np.abs(a @ x - b).max() / (abs(a).sum(axis=1).max() * np.abs(x).max() + np.abs(b).max())
    result = {
        "ordering": "metis (iparm[1] = 2)",
        "analyze_seconds": statistics.median(analyze),
        "factorize_seconds": statistics.median(factorize),
        "nnz_factor": int(p.iparm[17]),
        "flops": float(p.iparm[18]) * 1e6,
        "backward_error": float(backward),
    }
    p.release()
    return result


MUMPS_SOURCE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "mumps_factor.c")


def build_mumps(directory):
    """Compiles benches/mumps_factor.c against Debian's sequential MUMPS: (binary, None), or
    (None, why not)."""
    binary = os.path.join(directory, "mumps_factor")
    cmd = ["cc", "-O2", MUMPS_SOURCE, "-o", binary, "-I/usr/include/mumps_seq", "-ldmumps_seq", "-lm"]
    try:
        out = subprocess.run(cmd, capture_output=True, text=True)
    except OSError as e:
        return None, f"no C compiler: {e}"
    if out.returncode != 0:
        return None, "mumps_factor.c did not build (apt-get install libmumps-seq-dev): " + out.stderr.strip()[-300:]
    return binary, None


def mumps_version():
    """Debian's libmumps-seq-dev version, if dpkg knows one."""
    try:
        out = subprocess.run(["dpkg-query", "-W", "-f=${Version}", "libmumps-seq-dev"],
                             capture_output=True, text=True)
    except OSError:
        return None
    return out.stdout.strip() or None


def blas_of(binary):
    """The BLAS library the binary's CHOLMOD resolves to."""
    try:
        out = subprocess.run(["ldd", binary], capture_output=True, text=True).stdout
        libs = [l.split("=>")[1].split()[0] for l in out.splitlines() if "libblas" in l or "openblas" in l]
        return [os.path.realpath(l) for l in libs]
    except (OSError, IndexError):
        return []


def cpu_model():
    """The CPU's model name, family and model (MKL's code paths differ between Intel and AMD)."""
    fields = {}
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                key, _, value = line.partition(":")
                fields.setdefault(key.strip(), value.strip())
    except OSError:
        pass
    if "model name" not in fields:
        return platform.processor() or platform.machine()
    return f"{fields['model name']} (family {fields.get('cpu family')}, model {fields.get('model')})"


def package_version(name):
    try:
        return importlib.metadata.version(name)
    except importlib.metadata.PackageNotFoundError:
        return None


def git_commit():
    out = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True)
    return out.stdout.strip() or None


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--presets", default="M,L")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--fibercell", default="target/release/fibercell")
    parser.add_argument("-o", "--output", help="JSON report")
    args = parser.parse_args()

    machine = {
        "cpu": cpu_model(),
        "threads": os.cpu_count(),
        "dgemm_gflops_two_threads": dgemm_gflops(),
        "cholmod_blas": blas_of(args.fibercell),
        "mkl": package_version("mkl"),
        "pypardiso": package_version("pypardiso"),
        "mumps": mumps_version(),
        "fibercell_commit": git_commit(),
    }
    print(f"DGEMM (NumPy OpenBLAS, 2 threads): {machine['dgemm_gflops_two_threads']:.1f} GFLOP/s; "
          f"CHOLMOD's BLAS: {machine['cholmod_blas']}", flush=True)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        mumps, why_not = build_mumps(tmp)
        if why_not:
            print(f"MUMPS: {why_not}", flush=True)
        for preset in args.presets.split(","):
            cell = os.path.join(tmp, f"{preset}.toml")
            mtx = os.path.join(tmp, f"{preset}.mtx")
            subprocess.run([args.fibercell, "generate", "nonwoven", "--preset", preset,
                            "--seed", str(args.seed), "-o", cell], check=True, capture_output=True)
            subprocess.run([args.fibercell, "export-matrix", cell, "-o", mtx], check=True,
                           capture_output=True)
            row = {"preset": preset, "seed": args.seed}
            row["faer"] = fibercell_solver(args.fibercell, mtx, "faer-cholesky", args.repeats)
            row["cholmod"] = fibercell_solver(args.fibercell, mtx, "cholmod", args.repeats)
            row["pardiso"] = pardiso_times(mtx, args.repeats)
            row["mumps"] = run_json([mumps, mtx, str(args.repeats)]) if mumps else {"unavailable": why_not}
            f = row["faer"]
            f["fraction_of_dgemm"] = f["flops"] / f["factorize_seconds"] / 1e9 / machine["dgemm_gflops_two_threads"]
            row["faer_over_cholmod"] = f["factorize_seconds"] / row["cholmod"]["factorize_seconds"]
            row["faer_over_pardiso"] = f["factorize_seconds"] / row["pardiso"]["factorize_seconds"]
            if mumps:
                row["faer_over_mumps"] = f["factorize_seconds"] / row["mumps"]["factorize_seconds"]
            rows.append(row)
            print_row(row)
    report = {"machine": machine, "repeats": args.repeats, "rows": rows}
    if args.output:
        with open(args.output, "w") as f:
            json.dump(report, f, indent=1)
            f.write("\n")


def print_row(row):
    print(f"\n{row['preset']} (seed {row['seed']}):")
    print("| solver | ordering | analyze | factorize | nnz(L) | flops | GFLOP/s | backward error |")
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    for name in ("faer", "cholmod", "pardiso", "mumps"):
        r = row[name]
        if "unavailable" in r:
            continue
        rate = r["flops"] / r["factorize_seconds"] / 1e9
        print(f"| {name} | {r['ordering']} | {r['analyze_seconds']:.3f} s | {r['factorize_seconds']:.3f} s | "
              f"{r['nnz_factor']:.3e} | {r['flops']:.2e} | {rate:.1f} | {r['backward_error']:.1e} |")
    mumps = f", faer / MUMPS {row['faer_over_mumps']:.2f}" if "faer_over_mumps" in row else ""
    print(f"faer / CHOLMOD {row['faer_over_cholmod']:.2f}, faer / PARDISO {row['faer_over_pardiso']:.2f}"
          f"{mumps}, faer at {100 * row['faer']['fraction_of_dgemm']:.0f} % of DGEMM", flush=True)


if __name__ == "__main__":
    sys.exit(main())
