#!/usr/bin/env python3
"""Ensemble throughput on this machine: realizations per hour of the S and M presets (ABD only)
with one process and with two MPI ranks, unbound (each rank sees every core) and bound to a
core each (Open MPI's default). Needs the binary built with `--features mpi` and `mpirun`.

    cargo build --release --features mpi
    python3 benches/ensemble_throughput.py --json benches/results/ensemble-throughput.json
"""

import argparse
import json
import os
import subprocess
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BINARY = os.path.join(ROOT, "target", "release", "fibercell")
MPI_ENV = {**os.environ, "OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1"}


def run(launcher, preset, n):
    with tempfile.TemporaryDirectory() as out:
        cmd = [*launcher, BINARY, "ensemble", "--preset", preset, "-n", str(n), "-d", out]
        start = time.perf_counter()
        subprocess.run(cmd, check=True, env=MPI_ENV, capture_output=True)
        seconds = time.perf_counter() - start
        doc = json.load(open(os.path.join(out, "ensemble.json")))
    failed = sum(1 for r in doc["realizations"] if r["error"] is not None)
    return {"seconds": seconds, "failed": failed,
            "per_realization_s": [r["seconds"] for r in doc["realizations"]]}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--realizations", default="S=16,M=6")
    p.add_argument("--json")
    args = p.parse_args()
    layouts = {
        "1 process": [],
        "2 ranks, unbound": ["mpirun", "-np", "2", "--bind-to", "none"],
        "2 ranks, one core each": ["mpirun", "-np", "2", "--bind-to", "core"],
    }
    rows = []
    for item in args.realizations.split(","):
        preset, n = item.split("=")
        for name, launcher in layouts.items():
            r = run(launcher, preset, int(n))
            per_hour = 3600.0 * int(n) / r["seconds"]
            rows.append({"preset": preset, "layout": name, "realizations": int(n),
                         "wall_s": round(r["seconds"], 2), "per_hour": round(per_hour),
                         "failed": r["failed"],
                         "mean_realization_s": round(sum(r["per_realization_s"])
                                                     / len(r["per_realization_s"]), 3)})
            print(f"{preset} {name}: {n} in {r['seconds']:.1f} s, {per_hour:.0f} per hour")
    if args.json:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                                capture_output=True, text=True).stdout.strip()
        with open(args.json, "w") as f:
            json.dump({"binary": f"target/release/fibercell (features mpi) at {commit}",
                       "cores": os.cpu_count(), "rows": rows}, f, indent=1)
            f.write("\n")


if __name__ == "__main__":
    main()
