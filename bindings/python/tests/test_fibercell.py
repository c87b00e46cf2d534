"""The Python package against the CLI and SciPy: the same documents to the last digit, the
solver layer to 1e-10 of scipy.sparse.linalg.spsolve on the matrices `export-matrix` writes,
and bad input as FibercellError, never a crash. Run from the repository root (the fixtures'
paths) with FIBERCELL_BIN naming the CLI (default: target/release, else target/debug)."""

import json
import math
import os
import subprocess
import threading
from pathlib import Path

import numpy as np
import pytest
import scipy.io
import scipy.sparse
import scipy.sparse.linalg

import fibercell

ROOT = Path(__file__).resolve().parents[3]


def cli() -> Path:
    given = os.environ.get("FIBERCELL_BIN")
    if given:
        path = Path(given)
    else:
        release = ROOT / "target" / "release" / "fibercell"
        path = release if release.exists() else ROOT / "target" / "debug" / "fibercell"
    assert path.exists(), f"the fibercell CLI is not built at {path} (cargo build)"
    return path


def run_json(*args: str) -> dict:
    out = subprocess.run([str(cli()), *args, "--json"], check=True, capture_output=True, cwd=ROOT)
    return json.loads(out.stdout)


def without_timings(doc: dict) -> dict:
    return {k: v for k, v in doc.items() if k not in ("timings",)}


def test_homogenize_equals_the_cli_to_the_last_digit():
    path = "fixtures/cells/woven_small.toml"
    ours = fibercell.homogenize(fibercell.Model.load(ROOT / path))
    theirs = run_json("homogenize", path)
    assert ours["abd"].shape == (6, 6)
    assert ours["abd"].tolist() == theirs["abd"]
    ours["abd"] = ours["abd"].tolist()
    assert without_timings(ours) == without_timings(theirs)


def test_curve_equals_the_cli_to_the_last_digit():
    path = "fixtures/ok_cell_contact.toml"
    ours = fibercell.curve(fibercell.Model.load(ROOT / path), {"e11": 0.002}, steps=10)
    theirs = run_json("curve", path, "--strain", "e11=0.002", "--steps", "10", "-d",
                      str(ROOT / "target" / "pytest-curve"))
    assert ours["points"] == theirs["points"]
    assert ours["arrays"]["resultant"].shape == (10, 6)
    assert ours["arrays"]["strain"][-1, 0] == pytest.approx(0.002, rel=1e-15)
    # The dissipated energy never decreases along a loading path.
    assert np.all(np.diff(ours["arrays"]["dissipated"]) >= 0.0)


def test_check_equals_the_cli_and_fails_where_it_does():
    path = "fixtures/cells/woven_small.toml"
    ours = fibercell.check(fibercell.Model.load(ROOT / path), penalty_study=False)
    theirs = run_json("check", path, "--no-penalty-study")
    assert ours.pop("passed") is True
    assert ours == theirs
    # The thesis's two bars (p = k = 1000 N/m, ū = 1 cm): N = k ū / (2 + k/p) = 10/3 N, a
    # penetration N/p of 3.33 mm, a third of their 1 cm radius: above 0.1, not above 0.5.
    bars = fibercell.Model.load(ROOT / "fixtures/ok_contact_bars1.toml")
    doc = fibercell.check(bars)
    assert doc["passed"] is False
    worst = max(doc["penetration"]["cases"], key=lambda c: c["ratio"])
    assert math.isclose(worst["penetration"], 1e-2 / 3, rel_tol=1e-9)
    assert fibercell.check(bars, max_penetration=0.5)["passed"] is True
    with pytest.raises(fibercell.FibercellError, match="max_penetration"):
        fibercell.check(bars, max_penetration=-1.0)


def test_models_from_strings_and_dicts_are_the_file_model():
    text = (ROOT / "fixtures/ok_frame3d.toml").read_text()
    from_toml = fibercell.Model.from_toml(text)
    from_dict = fibercell.model_from_dict(json.loads(from_toml.to_json()))
    assert from_dict.to_json() == fibercell.Model.load(ROOT / "fixtures/ok_frame3d.toml").to_json()
    assert (from_dict.nodes, from_dict.fibers, from_dict.elements) == (7, 3, 6)
    assert not from_dict.is_cell


def test_generated_cells_homogenize():
    woven = fibercell.generate("woven", size=[0.004, 0.004], pattern={"kind": "plain"})
    assert woven.is_cell and woven.fibers > 0
    h = fibercell.homogenize(woven)
    # Symmetric and positive on the diagonal.
    assert np.all(np.diag(h["abd"]) > 0.0)
    assert np.max(np.abs(h["abd"] - h["abd"].T)) <= 1e-9 * np.max(np.abs(h["abd"]))
    a = fibercell.generate("nonwoven", seed=3, amount={"kind": "count", "fibers": 30})
    b = fibercell.generate("nonwoven", seed=3, amount={"kind": "count", "fibers": 30})
    assert a.to_json() == b.to_json()


def exported(tmp_path: Path, model: str):
    """The matrix and right-hand sides `export-matrix` writes for `model` (lower triangle of
    a symmetric matrix: both triangles after reading)."""
    out = tmp_path / "K.mtx"
    subprocess.run([str(cli()), "export-matrix", model, "-o", str(out)], check=True, cwd=ROOT)
    a = scipy.sparse.csc_matrix(scipy.io.mmread(str(out)))
    b = np.asarray(scipy.io.mmread(str(tmp_path / "K_rhs.mtx")))
    return a, b


@pytest.mark.parametrize("solver", ["faer-cholesky", "faer-lu", "cg"])
@pytest.mark.parametrize("model", ["fixtures/cells/woven_small.toml", "fixtures/ok_frame3d.toml"])
def test_the_solver_layer_equals_spsolve_on_exported_matrices(tmp_path, solver, model):
    """The woven cell's matrix has a condition number of 3.4e12 (penalty contacts), so any
    two backward-stable solutions differ by up to cond·ε: measured 1.3e-10 of the largest
    entry between faer and SuperLU, both at backward errors near 1e-19. The direct backends
    must agree with spsolve to 1e-9 and reach a backward error of 1e-15; CG to 1e-6."""
    a, b = exported(tmp_path, model)
    assert abs(a - a.T).max() == 0.0, "mmread gives both triangles"
    s = fibercell.SparseSolver(solver=solver)
    s.factorize(a)
    assert s.backend == solver
    direct = solver != "cg"
    for k in range(b.shape[1]):
        x, backward = s.solve(b[:, k])
        want = scipy.sparse.linalg.spsolve(a, b[:, k])
        assert backward <= (1e-15 if direct else 1e-10), (k, backward)
        tolerance = 1e-9 if direct else 1e-6
        assert np.max(np.abs(x - want)) <= tolerance * np.max(np.abs(want)), k
    # b = A·1: x = 1 up to cond·ε (measured 1.6e-8 on the woven cell).
    x, _ = fibercell.solve(a, solver=solver, ordering="amd")
    assert np.max(np.abs(x - 1.0)) <= 1e-6


def test_bad_input_raises_fibercell_errors():
    # Malformed text names its line and column.
    with pytest.raises(fibercell.FibercellError, match=r"<toml string>:1:\d+"):
        fibercell.Model.from_toml("nodes = [")
    bad = json.loads(fibercell.Model.load(ROOT / "fixtures/ok_frame3d.toml").to_json())
    bad["nodes"][0]["x"][0] = math.nan
    with pytest.raises(fibercell.FibercellError):
        fibercell.model_from_dict(bad)
    with pytest.raises(fibercell.FibercellError, match="cell"):
        fibercell.homogenize(fibercell.Model.load(ROOT / "fixtures/ok_frame3d.toml"))
    with pytest.raises(fibercell.FibercellError, match="unknown solver"):
        fibercell.SparseSolver(solver="mkl")
    with pytest.raises(fibercell.FibercellError, match="unknown ordering"):
        fibercell.SparseSolver(ordering="rcm")
    with pytest.raises(fibercell.FibercellError, match="square"):
        fibercell.solve(scipy.sparse.csc_matrix(np.ones((2, 3))))
    with pytest.raises(fibercell.FibercellError):
        fibercell.solve(scipy.sparse.csc_matrix(np.array([[1.0, 2.0], [2.0, 4.0]])))
    with pytest.raises(fibercell.FibercellError, match="before factorize"):
        fibercell.SparseSolver().solve(np.ones(2))
    with pytest.raises(fibercell.FibercellError, match="strain"):
        fibercell.curve(fibercell.Model.load(ROOT / "fixtures/ok_cell_contact.toml"), {"e33": 1})
    with pytest.raises(fibercell.FibercellError, match="generator parameters"):
        fibercell.generate("crochet")
    assert issubclass(fibercell.FibercellError, ValueError)


def test_computations_release_the_gil():
    """A Python thread keeps running while another thread homogenizes."""
    cell = fibercell.Model.load(ROOT / "fixtures/cells/woven_small.toml")
    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(1)

    t = threading.Thread(target=tick)
    t.start()
    try:
        for _ in range(3):
            fibercell.homogenize(cell)
    finally:
        done.set()
        t.join()
    assert len(ticks) > 100


def test_cell_updates_are_the_cli_curve():
    """Updates by E/N give `fibercell curve --strain E --steps N` to the last digit (E = 2⁻⁸,
    N = 8: every strain is an exact binary fraction either way)."""
    doc = run_json("curve", "fixtures/ok_cell_contact.toml", "--strain", "e11=0.00390625",
                   "--steps", "8", "-d", str(ROOT / "target" / "pytest-cell-curve"))
    model = fibercell.Model.load("fixtures/ok_cell_contact.toml")
    cell = fibercell.Cell(model, tangent=False)
    point = cell.new_state()
    for p in doc["points"]:
        r = cell.update(point, {"e11": 0.00390625 / 8})
        assert r["strain"].tolist() == p["strain"]
        assert r["resultant"].tolist() == p["resultant"]
        assert r["dissipated"] == p["dissipated"]
        assert (r["open"], r["stick"], r["slip"]) == (p["open"], p["stick"], p["slip"])
        assert r["tangent"] is None
    assert point.updates == len(doc["points"])


def test_cell_trial_copy_threads_and_errors():
    """On the grid cell (linear, A11 = E A / Ly): N11 = A11 ε11 and the tangent's A11 to 1e-9;
    a trial commits nothing; a copy continues like the original, all on the cell's
    factorization at rest; states updated from two
    threads at once equal serial ones; bad increments and foreign states raise."""
    grid = fibercell.Model.load("fixtures/ok_cell_grid.toml")
    cell = fibercell.Cell(grid)
    a11 = 1e9 * math.pi * 2e-4 ** 2 / 7e-3
    point = cell.new_state()
    r = cell.update(point, [1e-3, 0, 0, 0, 0, 0])
    assert abs(r["resultant"][0] / (a11 * 1e-3) - 1) <= 1e-9
    assert r["tangent"].shape == (6, 6) and abs(r["tangent"][0, 0] / a11 - 1) <= 1e-9
    t = cell.trial(point, {"e22": 1e-3})
    assert point.updates == 1 and point.strain.tolist() == [1e-3, 0, 0, 0, 0, 0]
    copy = point.copy()
    copy.release_caches()
    a = cell.update(point, {"e22": 1e-3})
    b = cell.update(copy, {"e22": 1e-3})
    assert abs(a["resultant"][1] / t["resultant"][1] - 1) <= 1e-12
    assert abs(b["resultant"][1] / a["resultant"][1] - 1) <= 1e-12
    # All of them on the cell's factorization at rest: none of their own.
    assert (r["factorizations"], a["factorizations"], b["factorizations"]) == (0, 0, 0)

    states = [cell.new_state() for _ in range(2)]
    steps = [{"e11": 1e-3}, {"g12": 1e-3}]
    serial = [cell.update(cell.new_state(), s)["resultant"].tolist() for s in steps]
    results = [None, None]

    def run(k):
        results[k] = cell.update(states[k], steps[k])["resultant"].tolist()

    threads = [threading.Thread(target=run, args=(k,)) for k in range(2)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert results == serial

    other = fibercell.Cell(grid, tangent=False)
    with pytest.raises(fibercell.FibercellError, match="another cell"):
        other.update(point, {"e11": 1e-3})
    with pytest.raises(fibercell.FibercellError, match="has 2 values: give 6"):
        cell.update(point, [1e-3, 0])
    with pytest.raises(fibercell.FibercellError, match="not finite"):
        cell.update(point, [math.nan, 0, 0, 0, 0, 0])
    with pytest.raises(fibercell.FibercellError, match="unknown strain"):
        cell.update(point, {"e33": 1e-3})
    assert point.updates == 2


def test_ensemble_statistics_are_those_of_its_realizations(tmp_path):
    import tomllib

    import scipy.stats

    params = tomllib.loads((ROOT / "fixtures/cells/nonwoven_small.params.toml").read_text())
    family = params.pop("family")
    params.pop("seed")
    params["amount"] = {"kind": "count", "fibers": 50}
    # This cell's bonds hold to e11 ≈ 1 %: at 5 % its contacts slide.
    run = lambda: fibercell.ensemble(  # noqa: E731
        family, 3, strain={"e11": 0.05}, steps=5, directory=tmp_path, **params
    )
    doc = run()
    a = doc["arrays"]
    assert a["abd"].shape == (3, 6, 6) and a["curves"].shape == (3, 5, 6)
    # Each realization's ABD is its seed's cell's, to the last digit.
    for k, seed in enumerate((1, 2, 3)):
        cell = fibercell.generate(family, seed=seed, **params)
        assert a["abd"][k].tolist() == fibercell.homogenize(cell)["abd"].tolist()
    # Mean, sample deviation and the interval t(0.975, n − 1) s / √n, entry by entry.
    t = scipy.stats.t.ppf(0.975, 2)
    scale = np.abs(a["abd"]).max(axis=0)
    assert np.all(np.abs(a["abd_mean"] - a["abd"].mean(axis=0)) <= 1e-13 * scale)
    assert np.all(np.abs(a["abd_std"] - a["abd"].std(axis=0, ddof=1)) <= 1e-12 * scale)
    assert np.allclose(a["abd_ci95"], t * a["abd_std"] / np.sqrt(3), rtol=1e-6)
    curve_scale = np.abs(a["curves"]).max(axis=(0, 1))
    assert np.all(np.abs(a["curve_mean"] - a["curves"].mean(axis=0)) <= 1e-13 * curve_scale)
    assert np.all(
        np.abs(a["curve_std"] - a["curves"].std(axis=0, ddof=1)) <= 1e-12 * curve_scale
    )
    assert np.allclose(a["curve_ci95"], t * a["curve_std"] / np.sqrt(3), rtol=1e-6)
    assert a["curve_strain"][:, 0] == pytest.approx([0.01, 0.02, 0.03, 0.04, 0.05], rel=1e-14)
    # Sliding: the mean's secant at 5 % is below the mean elastic slope A11.
    assert a["curve_mean"][-1, 0] < 0.9 * 0.05 * a["abd_mean"][0, 0]
    # A rerun on the same directory reuses every realization.
    again = run()
    assert again["reused"] == 3
    assert np.array_equal(again["arrays"]["curves"], a["curves"])
