#!/usr/bin/env python3
"""The default friction curve on every generated cell, as a new user runs it.

For each cell (non-woven presets × seeds, and the woven, twill, knitted and geotextile
generators with their defaults) and each load (e11, e22, g12 to 1 % and e11 with --unload),
run `fibercell curve CELL --strain X --steps 100` with no other flag and record: exit code,
wall time, peak RSS, state iterations (total, worst increment), contacts held, increments
halved, the largest equilibrium residual and energy-balance error. Issue 28 point 1 asks all of these to run to
completion with residual <= 1e-8.

    python3 benches/curve_matrix.py --presets S,M --seeds 1,2,3 -o benches/results/curve-matrix.json
    python3 benches/curve_matrix.py --presets L --seeds 3 --loads g12 --merge -o benches/results/curve-matrix.json

The table is rewritten after every run; with --merge the rows already in it stay, those of the
same cell and load replaced.

Standard library only; the binary is target/release/fibercell (build it first).
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

LOADS = {
    "e11": ["--strain", "e11=0.01"],
    "e22": ["--strain", "e22=0.01"],
    "g12": ["--strain", "g12=0.01"],
    "e11-unload": ["--strain", "e11=0.01", "--unload"],
}
OTHER_CELLS = {
    "woven-plain": ["woven", "--pattern", "plain"],
    "woven-twill": ["woven", "--pattern", "twill:2/1"],
    "knitted": ["knitted"],
    "geotextile": ["geotextile"],
}


def run(cmd):
    """Runs cmd; returns (exit code, wall seconds, peak RSS of the child in MB or None, stderr
    tail). The peak RSS comes from GNU time (/usr/bin/time) where it is installed."""
    timed = os.path.exists("/usr/bin/time")
    rss_file = tempfile.NamedTemporaryFile(suffix=".rss", delete=False).name
    full = ["/usr/bin/time", "-f", "%M", "-o", rss_file, *cmd] if timed else cmd
    t0 = time.perf_counter()
    p = subprocess.run(full, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    rss = None
    if timed:
        with open(rss_file) as f:
            lines = f.read().split()
        rss = int(lines[-1]) / 1024.0 if lines and lines[-1].isdigit() else None
    os.unlink(rss_file)
    return p.returncode, wall, rss, p.stderr.strip().splitlines()[-3:]


def summarize(curve):
    pts = curve["points"]
    return {
        "increments": len(pts),
        "iterations": sum(p["iterations"] for p in pts),
        "worst_increment_iterations": max(p["iterations"] for p in pts),
        "max_held": max(p["held"] for p in pts),
        "cutbacks": sum(p["cutbacks"] for p in pts),
        "increments_with_held": sum(1 for p in pts if p["held"] > 0),
        "max_residual": max(p["equilibrium_residual"] for p in pts),
        "max_energy_error": max(abs(p["energy_error"]) for p in pts),
        "final_slip": pts[-1]["slip"],
        "final_open": pts[-1]["open"],
    }


def merged(kept, rows):
    """kept's rows in their order with those of the same cell and load replaced by rows',
    then rows' new ones."""
    new = {(r["cell"], r["load"]): r for r in rows}
    out = [new.pop((r["cell"], r["load"]), r) for r in kept]
    return out + [r for r in rows if (r["cell"], r["load"]) in new]


def write_table(path, binary, rows):
    """Writes the table whole or not at all (a temporary file renamed over path), so a run
    stopped midway leaves the rows finished so far."""
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        json.dump({"binary": binary, "rows": rows}, f, indent=1)
    os.replace(tmp, path)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--presets", default="S,M", help="non-woven presets, comma-separated (S,M,L)")
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--loads", default=",".join(LOADS), help="subset of " + ",".join(LOADS))
    ap.add_argument("--other-cells", action="store_true", help="also the woven, knitted and geotextile cells")
    ap.add_argument("--binary", default="target/release/fibercell")
    ap.add_argument("-o", "--output", help="JSON file for the table (rewritten after every run)")
    ap.add_argument(
        "--merge",
        action="store_true",
        help="keep the rows of an existing --output file, replacing those of the same cell and load",
    )
    args = ap.parse_args()

    cells = []
    for preset in filter(None, args.presets.split(",")):
        for seed in args.seeds.split(","):
            cells.append((f"nonwoven-{preset}-seed{seed}", ["nonwoven", "--preset", preset, "--seed", seed]))
    if args.other_cells:
        cells += list(OTHER_CELLS.items())

    kept = []
    if args.merge and args.output and os.path.exists(args.output):
        with open(args.output) as f:
            kept = json.load(f)["rows"]
    rows = []
    failed = 0
    with tempfile.TemporaryDirectory() as work:
        for name, gen in cells:
            model = os.path.join(work, name + ".toml")
            code, _, _, err = run([args.binary, "generate", *gen, "-o", model])
            if code != 0:
                sys.exit(f"generate {name} failed: {err}")
            for load in args.loads.split(","):
                out = os.path.join(work, f"{name}-{load}")
                code, wall, rss, err = run([args.binary, "curve", model, *LOADS[load], "--steps", "100", "-d", out])
                row = {"cell": name, "load": load, "exit": code, "wall_s": round(wall, 2), "peak_rss_mb": rss and round(rss)}
                if code == 0:
                    with open(os.path.join(out, "curve.json")) as f:
                        row.update(summarize(json.load(f)))
                else:
                    row["error"] = err
                ok = code == 0 and row["max_residual"] <= 1e-8
                failed += not ok
                rows.append(row)
                print(json.dumps(row), flush=True)
                if args.output:
                    write_table(args.output, args.binary, merged(kept, rows))

    print(f"{len(rows) - failed} within 1e-8, {failed} not")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
