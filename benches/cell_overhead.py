#!/usr/bin/env python3
"""The stateful cell through Rust, C and Python, side by side in one run (issue 29 point 5).

* The same 20 updates (e11 by 1e-4, tangent on) of the generated non-woven M cell through
  `Cell::update` (Rust), `fc_cell_update` (C ABI) and `fibercell.Cell.update` (Python): the
  calls should be within 5 % of each other.
* 2,000 updates of a cell without contacts (fixtures/ok_cell_grid.toml): the per-call overhead
  of C and Python over Rust, the differences of the medians (target: 10 us).
* POINTS material points of the S cell, each with its own history, updated in parallel:
  updates per second on all cores and the memory a state adds.

    cargo build --release -p fibercell-c --example cell_overhead
    VIRTUAL_ENV=... maturin develop --release -m bindings/python/Cargo.toml   # the package
    python benches/cell_overhead.py --points 1000 -o benches/results/cell-overhead.json

Needs target/release/fibercell (to generate the cells), the example and the fibercell
package in the running Python.
"""

import argparse
import json
import os
import subprocess
import sys
import time

import fibercell


def median(values):
    v = sorted(values)
    return v[len(v) // 2]


def python_updates(path, steps):
    """Per update: the wall time of the Python call and the library's time inside it."""
    cell = fibercell.Cell(fibercell.Model.load(path))
    state = cell.new_state()
    raw = cell._raw
    wall, inside = [], []
    for _ in range(steps):
        t = time.perf_counter()
        _, seconds = raw.timed_update(state, fibercell._increment([1e-4, 0.0, 0.0, 0.0, 0.0, 0.0]))
        wall.append(time.perf_counter() - t)
        inside.append(seconds)
    return wall, inside


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--points", type=int, default=100)
    parser.add_argument("--cells", default="target/bench-cells")
    parser.add_argument("-o", "--output", required=True)
    args = parser.parse_args()
    os.makedirs(args.cells, exist_ok=True)
    cells = {}
    for preset in ("S", "M"):
        path = os.path.join(args.cells, f"{preset}.toml")
        if not os.path.exists(path):
            subprocess.run(
                ["target/release/fibercell", "generate", "nonwoven", "--preset", preset,
                 "--seed", "1", "-o", path],
                check=True,
            )
        cells[preset] = path
    tiny = "fixtures/ok_cell_grid.toml"
    out = subprocess.run(
        ["target/release/examples/cell_overhead", cells["M"], tiny, cells["S"], str(args.points)],
        check=True, capture_output=True, text=True,
    )
    doc = json.loads(out.stdout)
    large_py, large_inside = python_updates(cells["M"], 20)
    tiny_py, tiny_inside = python_updates(tiny, 2000)
    doc["large"]["python_median_s"] = median(large_py)
    doc["large"]["python_total_s"] = sum(large_py)
    doc["tiny"]["python_median_s"] = median(tiny_py)
    rust = doc["large"]["rust_total_s"]
    doc["large"]["c_over_rust"] = doc["large"]["c_total_s"] / rust
    # Across processes (machine drift included), and within the Python calls themselves: the
    # wall time of each call against the library's time inside it.
    doc["large"]["python_over_rust"] = doc["large"]["python_total_s"] / rust
    doc["large"]["python_over_inside"] = sum(large_py) / sum(large_inside)
    doc["tiny"]["c_overhead_us"] = 1e6 * (doc["tiny"]["c_median_s"] - doc["tiny"]["rust_median_s"])
    doc["tiny"]["python_overhead_us"] = 1e6 * (
        doc["tiny"]["python_median_s"] - doc["tiny"]["rust_median_s"]
    )
    doc["tiny"]["python_overhead_inside_us"] = 1e6 * median(
        [w - i for w, i in zip(tiny_py, tiny_inside)]
    )
    doc["python"] = sys.version.split()[0]
    text = json.dumps(doc, indent=2)
    with open(args.output, "w") as f:
        f.write(text + "\n")
    print(text)


if __name__ == "__main__":
    main()
