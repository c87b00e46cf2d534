"""Type stubs of the compiled extension (see ``fibercell/__init__.py`` for the public API)."""

from os import PathLike
from typing import Any, Dict, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

class FibercellError(ValueError):
    """An error of fibercell: malformed or invalid input, a singular system, a failed solve."""

class Model:
    """A validated model: fibers, nodes, materials, contacts, and a periodic cell or supports."""

    @staticmethod
    def load(path: Union[str, PathLike[str]]) -> "Model": ...
    @staticmethod
    def from_toml(text: str) -> "Model": ...
    @staticmethod
    def from_json(text: str) -> "Model": ...
    @staticmethod
    def from_inp(text: str) -> "Model": ...
    def to_json(self) -> str: ...
    def to_toml(self) -> str: ...
    def save(self, path: Union[str, PathLike[str]]) -> None: ...
    @property
    def nodes(self) -> int: ...
    @property
    def fibers(self) -> int: ...
    @property
    def elements(self) -> int: ...
    @property
    def is_cell(self) -> bool: ...

class SparseSolver:
    def __init__(self, solver: str = "faer-cholesky", ordering: str = "auto") -> None: ...
    def factorize(
        self,
        n: int,
        indptr: npt.NDArray[np.int64],
        indices: npt.NDArray[np.int64],
        data: npt.NDArray[np.float64],
    ) -> None: ...
    def solve(self, b: npt.NDArray[np.float64]) -> Tuple[npt.NDArray[np.float64], float]: ...
    @property
    def backend(self) -> str: ...

class CellState:
    """One material point of a Cell: contact states, slips, energies, its factorizations."""

    @property
    def strain(self) -> npt.NDArray[np.float64]: ...
    @property
    def updates(self) -> int: ...
    def copy(self) -> "CellState": ...
    def release_caches(self) -> None: ...
    def __copy__(self) -> "CellState": ...
    def __deepcopy__(self, memo: Any) -> "CellState": ...

class Cell:
    """A periodic cell set up once for any number of states."""

    def __init__(
        self, model: Model, solver: str = "faer-cholesky", ordering: str = "auto", tangent: bool = True
    ) -> None: ...
    def new_state(self) -> CellState: ...
    def update(self, state: CellState, increment: npt.NDArray[np.float64]) -> Dict[str, Any]: ...
    def trial(self, state: CellState, increment: npt.NDArray[np.float64]) -> Dict[str, Any]: ...
    def timed_update(
        self, state: CellState, increment: npt.NDArray[np.float64]
    ) -> Tuple[Dict[str, Any], float]: ...
    @property
    def contacts(self) -> int: ...
    @property
    def area(self) -> float: ...

def generate_json(params: str) -> Model: ...
def homogenize_json(model: Model, solver: str = "faer-cholesky", ordering: str = "auto") -> str: ...
def check_json(
    model: Model,
    accuracy: Optional[float] = None,
    penalty_study: bool = True,
    max_penetration: float = 0.1,
    penetration_strain: float = 0.01,
    solver: str = "faer-cholesky",
    ordering: str = "auto",
) -> str: ...
def ensemble_json(
    params: str,
    realizations: int,
    first_seed: int = 1,
    strain: Optional[str] = None,
    steps: int = 100,
    unload: bool = False,
    directory: Optional[Union[str, PathLike[str]]] = None,
    solver: str = "faer-cholesky",
    ordering: str = "auto",
) -> str: ...
def curve_json(
    model: Model,
    strain: str,
    steps: int = 100,
    unload: bool = False,
    solver: str = "faer-cholesky",
    ordering: str = "auto",
    bonded: bool = False,
    stabilization: float = 0.0,
) -> str: ...
