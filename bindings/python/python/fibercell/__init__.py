"""fibercell: effective mechanical properties of textiles from fiber-network cells.

A thin layer over the Rust library (``fibercell._fibercell``): models from files, strings or
dictionaries, the cell generators, the elastic homogenization (ABD), the friction-driven
elasto-plastic curve, stochastic ensembles, the stateful cell of a macro-scale code (:class:`Cell`) and the sparse
solver layer. Results are the documents the CLI prints
with ``--json`` (the same serializer, the same digits), with NumPy arrays for the matrices and
the curve's columns. Errors raise :class:`FibercellError` (a ``ValueError``) with the
library's message; every computation releases the GIL.

>>> import fibercell
>>> cell = fibercell.Model.load("fixtures/ok_cell_grid.toml")
>>> h = fibercell.homogenize(cell)
>>> round(h["abd"][0, 0])  # A11 = EA / Ly in N/m
17952
"""

from __future__ import annotations

import json
import math
import os
from typing import Any, Dict, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from ._fibercell import CellState, FibercellError, Model, __version__
from . import _fibercell

__all__ = [
    "Cell",
    "CellState",
    "FibercellError",
    "Model",
    "SparseSolver",
    "__version__",
    "check",
    "curve",
    "ensemble",
    "generate",
    "homogenize",
    "model_from_dict",
    "solve",
]

STRAIN_NAMES = ("e11", "e22", "g12", "k11", "k22", "k12")


def model_from_dict(description: Mapping[str, Any]) -> Model:
    """A model from a dictionary with the fields of a JSON model file."""
    return Model.from_json(json.dumps(description))


def generate(family: str, **params: Any) -> Model:
    """A generated periodic cell: ``family`` is "woven", "geotextile", "knitted" or
    "nonwoven"; ``params`` are the generator's fields as in ``fixtures/cells/*.params.toml``
    (those not given keep their defaults)."""
    return _fibercell.generate_json(json.dumps({"family": family, **params}))


def homogenize(model: Model, solver: str = "faer-cholesky", ordering: str = "auto") -> dict:
    """The elastic ABD of a periodic cell (thesis 5.5), its moduli and orthotropic constants:
    the document of ``fibercell homogenize --json``, with ``abd`` as a 6 × 6 array (rows and
    columns e11 e22 g12 k11 k22 k12; A in N/m, B in N, D in N·m)."""
    doc = json.loads(_fibercell.homogenize_json(model, solver=solver, ordering=ordering))
    doc["abd"] = np.array(doc["abd"], dtype=float)
    return doc


def check(
    model: Model,
    accuracy: Optional[float] = None,
    penalty_study: bool = True,
    max_penetration: float = 0.1,
    penetration_strain: float = 0.01,
    solver: str = "faer-cholesky",
    ordering: str = "auto",
) -> dict:
    """The property checks of ``fibercell check --json``: symmetry, definiteness,
    conditioning and null space of the model's system (closed contacts in stick), the
    contacts' penetration relative to the smaller radius (at most ``max_penetration``; a
    cell's under each macroscopic strain of size ``penetration_strain``) and a cell's penalty
    study (with ``accuracy``, a larger penalty error fails). ``doc["passed"]`` says whether
    every line of ``doc["checks"]`` passed; a failed check is a result, not an exception."""
    doc = json.loads(
        _fibercell.check_json(
            model,
            accuracy=accuracy,
            penalty_study=penalty_study,
            max_penetration=max_penetration,
            penetration_strain=penetration_strain,
            solver=solver,
            ordering=ordering,
        )
    )
    doc["passed"] = all(c["passed"] for c in doc["checks"])
    return doc


def _strain_text(strain: Union[str, Mapping[str, float]]) -> str:
    if isinstance(strain, str):
        return strain
    unknown = [k for k in strain if k not in STRAIN_NAMES]
    if unknown:
        raise FibercellError(
            f"unknown strain component(s) {unknown}: use {', '.join(STRAIN_NAMES)}"
        )
    return ",".join(f"{k}={float(v)!r}" for k, v in strain.items())


def curve(
    model: Model,
    strain: Union[str, Mapping[str, float]],
    steps: int = 100,
    unload: bool = False,
    solver: str = "faer-cholesky",
    ordering: str = "auto",
    bonded: bool = False,
    stabilization: float = 0.0,
) -> dict:
    """The elasto-plastic curve of a cell with frictional contacts under the macroscopic
    strain ``strain`` ({"e11": 0.01} or "e11=0.01"), ramped over ``steps`` increments (with
    ``unload``: back to zero and up again): the document of ``fibercell curve --json``, plus
    arrays over the increments — ``strain`` and ``resultant`` (n × 6), ``dissipated`` and
    ``equilibrium_residual`` (n)."""
    doc = json.loads(
        _fibercell.curve_json(
            model,
            _strain_text(strain),
            steps=steps,
            unload=unload,
            solver=solver,
            ordering=ordering,
            bonded=bonded,
            stabilization=stabilization,
        )
    )
    points = doc["points"]
    doc["arrays"] = {
        "strain": np.array([p["strain"] for p in points], dtype=float).reshape(-1, 6),
        "resultant": np.array([p["resultant"] for p in points], dtype=float).reshape(-1, 6),
        "dissipated": np.array([p["dissipated"] for p in points], dtype=float),
        "equilibrium_residual": np.array(
            [p["equilibrium_residual"] for p in points], dtype=float
        ),
    }
    return doc


def _summary_arrays(summaries: Any) -> Dict[str, np.ndarray]:
    """``mean``, ``std`` and ``ci95`` arrays of nested SampleSummary documents (an infinite
    interval, of one value, crosses JSON as null: NaN here)."""

    def field(name: str) -> np.ndarray:
        def pick(x: Any) -> Any:
            if isinstance(x, list):
                return [pick(y) for y in x]
            v = x[name]
            return math.inf if v is None and name == "ci95" else v

        return np.array(pick(summaries), dtype=float)

    return {name: field(name) for name in ("mean", "std", "ci95")}


def ensemble(
    family: str,
    realizations: int,
    first_seed: int = 1,
    strain: Union[None, str, Mapping[str, float]] = None,
    steps: int = 100,
    unload: bool = False,
    directory: Union[None, str, "os.PathLike[str]"] = None,
    solver: str = "faer-cholesky",
    ordering: str = "auto",
    **params: Any,
) -> dict:
    """The scatter of a random cell from seed to seed: ``realizations`` cells of the generator
    ``family`` with ``params`` (as for :func:`generate`; the seed is each realization's, from
    ``first_seed`` on), the six cell problems of each and, with ``strain``, its curve (as for
    :func:`curve`, with the generator's contact law). The document of ``fibercell ensemble
    --json`` — every realization (its ABD, or ``error``), the statistics and the interval's
    convergence —, plus ``arrays``: ``abd`` (N × 6 × 6, NaN for a failed realization) and
    ``abd_mean``, ``abd_std``, ``abd_ci95`` (6 × 6, the 95 % interval of the mean); with
    curves, ``curves`` (N × points × 6 resultants, NaN for a failed curve), ``curve_strain``
    (points × 6) and ``curve_mean``, ``curve_std``, ``curve_ci95`` (points × 6). With
    ``directory``, each realization is stored there as it finishes and a rerun reuses them."""
    doc = json.loads(
        _fibercell.ensemble_json(
            json.dumps({"family": family, **params}),
            realizations,
            first_seed=first_seed,
            strain=None if strain is None else _strain_text(strain),
            steps=steps,
            unload=unload,
            directory=None if directory is None else os.fspath(directory),
            solver=solver,
            ordering=ordering,
        )
    )
    nan6 = np.full((6, 6), np.nan)
    arrays = {
        "abd": np.array(
            [nan6 if r["abd"] is None else r["abd"] for r in doc["realizations"]], dtype=float
        ).reshape(-1, 6, 6),
        **{f"abd_{k}": v for k, v in _summary_arrays(doc["abd"]).items()},
    }
    stats = doc.get("curve")
    if stats is not None:
        points = stats["points"]
        n = len(points)
        missing = np.full((n, 6), np.nan)

        def resultants(r: Mapping[str, Any]) -> Any:
            c = r.get("curve")
            return missing if c is None or len(c) != n else [p["resultant"] for p in c]

        arrays["curves"] = np.array(
            [resultants(r) for r in doc["realizations"]], dtype=float
        ).reshape(-1, n, 6)
        arrays["curve_strain"] = np.array([p["strain"] for p in points], dtype=float).reshape(
            -1, 6
        )
        for k, v in _summary_arrays([p["resultant"] for p in points]).items():
            arrays[f"curve_{k}"] = v.reshape(-1, 6)
    doc["arrays"] = arrays
    return doc


def _increment(increment: Union[Sequence[float], Mapping[str, float]]) -> np.ndarray:
    if isinstance(increment, Mapping):
        unknown = [k for k in increment if k not in STRAIN_NAMES]
        if unknown:
            raise FibercellError(
                f"unknown strain component(s) {unknown}: use {', '.join(STRAIN_NAMES)}"
            )
        return np.array([float(increment.get(k, 0.0)) for k in STRAIN_NAMES])
    return np.ascontiguousarray(increment, dtype=np.float64).reshape(-1)


class Cell:
    """A periodic cell set up once for any number of material points (FE²): each
    :class:`CellState` holds one point's contact states, slips and energies. ``update``
    advances a state by a macroscopic strain increment (6 values e11, e22, g12, k11, k22, k12,
    or a dict by those names) and commits it; ``trial`` gives the same response without
    committing. A response is a dict: ``strain`` and ``resultant`` (6; N/m and N), ``tangent``
    (6 × 6 consistent dN/dE, None with ``tangent=False``), ``dissipated`` and
    ``stored_energy`` (J/m²), the contact counts ``open``, ``stick``, ``slip``, and the
    increment's ``iterations``, ``cutbacks``, ``factorizations`` (the state's own: none on
    the cell's factorization at rest, which all states share), ``held``,
    ``equilibrium_residual`` and ``energy_error``. Different states may be updated from
    different threads at once.

    >>> import fibercell
    >>> grid = fibercell.Model.load("fixtures/ok_cell_grid.toml")
    >>> cell = fibercell.Cell(grid)
    >>> point = cell.new_state()
    >>> r = cell.update(point, {"e11": 1e-3})
    >>> round(float(r["resultant"][0]), 4), round(r["tangent"][0, 0])  # A11 ε11, A11 = EA / Ly
    (17.952, 17952)
    >>> _ = cell.trial(point, {"e11": 1e-3}); point.updates  # a trial commits nothing
    1
    """

    def __init__(
        self,
        model: Model,
        solver: str = "faer-cholesky",
        ordering: str = "auto",
        tangent: bool = True,
    ) -> None:
        self._raw = _fibercell.Cell(model, solver=solver, ordering=ordering, tangent=tangent)

    @property
    def contacts(self) -> int:
        """Contact pairs of the cell."""
        return self._raw.contacts

    @property
    def area(self) -> float:
        """Cell area L_x L_y (m²)."""
        return self._raw.area

    def new_state(self) -> CellState:
        """A state at rest: zero strain, closed contacts stuck."""
        return self._raw.new_state()

    def update(
        self, state: CellState, increment: Union[Sequence[float], Mapping[str, float]]
    ) -> dict:
        """Advances ``state`` by ``increment`` and commits it (on an error it stays)."""
        return self._raw.update(state, _increment(increment))

    def trial(
        self, state: CellState, increment: Union[Sequence[float], Mapping[str, float]]
    ) -> dict:
        """The response ``update`` would give, without committing it."""
        return self._raw.trial(state, _increment(increment))


def _csc_arrays(a: Any) -> Tuple[int, np.ndarray, np.ndarray, np.ndarray]:
    """(n, indptr, indices, data) of a square scipy.sparse matrix, sorted and summed."""
    try:
        shape = a.shape
        csc = a.tocsc(copy=True)
    except AttributeError as e:
        raise FibercellError(f"expected a scipy.sparse matrix, got {type(a).__name__}") from e
    if len(shape) != 2 or shape[0] != shape[1]:
        raise FibercellError(f"the matrix must be square, not {shape}")
    csc.sum_duplicates()
    csc.sort_indices()
    return (
        int(shape[0]),
        np.ascontiguousarray(csc.indptr, dtype=np.int64),
        np.ascontiguousarray(csc.indices, dtype=np.int64),
        np.ascontiguousarray(csc.data, dtype=np.float64),
    )


class SparseSolver:
    """The sparse solver layer: one backend ("faer-cholesky", "faer-lu", "cg", "cholmod" in a
    build with it) and one fill-reducing ordering ("auto", "amd", "nd", "natural").
    ``factorize`` analyzes a new sparsity pattern and factorizes; ``solve`` may then be called
    for any number of right-hand sides."""

    def __init__(self, solver: str = "faer-cholesky", ordering: str = "auto") -> None:
        self._raw = _fibercell.SparseSolver(solver=solver, ordering=ordering)

    @property
    def backend(self) -> str:
        """The backend's name."""
        return self._raw.backend

    def factorize(self, a: Any) -> None:
        """Analyzes (when its pattern is new) and factorizes the square scipy.sparse ``a``
        (both triangles of a symmetric matrix)."""
        self._raw.factorize(*_csc_arrays(a))

    def solve(self, b: np.ndarray) -> Tuple[np.ndarray, float]:
        """x with A x = b for the factorized A, and the solve's backward error (an error
        above 1e-8 raises)."""
        return self._raw.solve(np.ascontiguousarray(b, dtype=np.float64))


def solve(
    a: Any,
    b: Optional[np.ndarray] = None,
    solver: str = "faer-cholesky",
    ordering: str = "auto",
) -> Tuple[np.ndarray, float]:
    """x with A x = b for a square scipy.sparse A (both triangles of a symmetric matrix) and a
    NumPy b (default A·1, whose solution is all ones), by the backend ``solver`` with the
    ordering ``ordering``; returns x and the solve's backward error."""
    s = SparseSolver(solver=solver, ordering=ordering)
    s.factorize(a)
    if b is None:
        b = a @ np.ones(a.shape[1])
    return s.solve(b)
