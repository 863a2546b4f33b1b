"""Type stubs of the compiled module (the docstrings are on the objects themselves: ``help(hylc.MicroProblem)``)."""

from os import PathLike
from typing import Any, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

StrPath = Union[str, PathLike[str]]
ArrayLike = Union[npt.NDArray[np.float64], Sequence[float], Sequence[Sequence[float]]]
Yarn = Union[None, dict[str, float], StrPath]

class Error(Exception): ...
class PatternError(Error): ...
class MicroError(Error): ...
class MaterialError(Error): ...
class FitError(Error): ...
class SimulationError(Error): ...
class SampleError(Error): ...
class InternalError(Error): ...

class Pattern:
    source: str
    notes: list[str]
    periods: tuple[float, float]
    radius: float
    positions: npt.NDArray[np.float64]
    rest_lengths: list[float]
    def __len__(self) -> int: ...
    def yarns(self) -> list[list[int]]: ...
    def save(self, path: StrPath) -> None: ...
    def summary(self) -> dict[str, Any]: ...

class Solution:
    status: str
    converged: bool
    psi: Optional[float]
    strain: npt.NDArray[np.float64]
    steps: int
    gradient_norm: float
    time: float
    energy: dict[str, float]
    positions: npt.NDArray[np.float64]
    y: npt.NDArray[np.float64]
    def stress(self) -> npt.NDArray[np.float64]: ...
    def parameter_derivatives(self) -> npt.NDArray[np.float64]: ...
    def strain_stiffness(self) -> tuple[list[str], npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    def equilibrium_sensitivities(self) -> npt.NDArray[np.float64]: ...
    def derivatives(self) -> dict[str, Any]: ...

class MicroProblem:
    yarn: dict[str, float]
    dofs: int
    def __init__(
        self,
        pattern: Union[Pattern, StrPath],
        yarn: Yarn = None,
        *,
        tolerance: float = 1e-8,
        max_steps: int = 2000,
        time_limit: Optional[float] = None,
        quadrature: Optional[int] = None,
        inertia: bool = True,
    ) -> None: ...
    def solve(self, z: ArrayLike, start: Optional[Solution] = None) -> Solution: ...
    def solve_batch(self, z: ArrayLike, chain: bool = False) -> dict[str, Any]: ...
    def sensitivities(self, z: ArrayLike) -> dict[str, Any]: ...

class Material:
    density: float
    admissible_limits: list[float]
    @staticmethod
    def load(path: StrPath) -> Material: ...
    @staticmethod
    def default() -> Material: ...
    def save(self, path: StrPath) -> None: ...
    def psi(self, z: ArrayLike) -> Union[float, npt.NDArray[np.float64]]: ...
    def gradient(self, z: ArrayLike) -> npt.NDArray[np.float64]: ...
    def hessian(self, z: ArrayLike) -> npt.NDArray[np.float64]: ...
    def eval(
        self, z: ArrayLike
    ) -> tuple[Union[float, npt.NDArray[np.float64]], npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...

def load_pattern(pattern: StrPath) -> Pattern: ...
def read_pyp(path: StrPath) -> Pattern: ...
def generate(kind: str, n: Optional[int] = None, step: Optional[int] = None, vertices_per_radius: float = 1.0) -> Pattern: ...
def reference_state(
    pattern: Union[Pattern, StrPath],
    construction: Optional[str] = None,
    yarn: Yarn = None,
    equilibrate_only: bool = False,
) -> tuple[Pattern, dict[str, Any]]: ...
def yarn_defaults() -> dict[str, float]: ...
def load_yarn(path: StrPath) -> dict[str, float]: ...
def save_yarn(yarn: dict[str, float], path: StrPath) -> None: ...
def fit(
    samples: StrPath,
    out: Optional[StrPath] = None,
    report: Optional[StrPath] = None,
    plots: Optional[StrPath] = None,
    plan: Optional[str] = None,
    density: Optional[float] = None,
    preset: str = "covering",
    knots_1d: Optional[int] = None,
    knots_2d: Optional[int] = None,
) -> tuple[Material, dict[str, Any]]: ...
def simulate(
    scene: str,
    out: Optional[StrPath] = None,
    material: Optional[str] = None,
    duration: Optional[float] = None,
    dt: Optional[float] = None,
    edge: Optional[float] = None,
    time_tol: Optional[Union[float, str]] = None,
) -> dict[str, Any]: ...
def gradient(
    scene: str,
    observable: Optional[str] = None,
    cotangent: Optional[Any] = None,
    at: Optional[float] = None,
    material: Optional[str] = None,
    out: Optional[StrPath] = None,
    check: bool = False,
    samples: Optional[StrPath] = None,
    yarn: Yarn = None,
) -> dict[str, Any]: ...
