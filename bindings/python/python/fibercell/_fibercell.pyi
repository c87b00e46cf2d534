"""Type stubs of the compiled extension (see ``fibercell/__init__.py`` for the public API)."""

from os import PathLike
from typing import Tuple, Union

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

def generate_json(params: str) -> Model: ...
def homogenize_json(model: Model, solver: str = "faer-cholesky", ordering: str = "auto") -> str: ...
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
