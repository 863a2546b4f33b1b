"""Type stubs of the compiled module, with its docstrings (``python/stubdoc.py`` copies them from the built module;
``tests/test_stub.py`` checks that they agree)."""

from os import PathLike
from typing import Any, Callable, Optional, Sequence, TypedDict, Union

import numpy as np
import numpy.typing as npt

__version__: str

StrPath = Union[str, PathLike[str]]
ArrayLike = Union[npt.NDArray[np.float64], Sequence[float], Sequence[Sequence[float]]]
Yarn = Union[None, dict[str, Any], StrPath]
#: ``progress(done, total)``, called from the calling thread with the GIL held.
Progress = Optional[Callable[[int, int], object]]
#: A scene file, a built-in name, or a dict with the scene JSON's layout.
SceneArg = Union[StrPath, dict[str, Any]]
#: A built-in plan name, a plan JSON file, or a dict with the plan JSON's layout.
PlanArg = Union[StrPath, "PlanDict"]

class Error(Exception):
    """Base class of the errors hylc raises."""

class PatternError(Error):
    """A pattern file or generated pattern is not valid."""

class MicroError(Error):
    """A micro solve could not run, or a quantity needs an equilibrium."""

class MaterialError(Error):
    """A material file or strain is not valid."""

class FitError(Error):
    """Fitting a material to samples failed."""

class SimulationError(Error):
    """A cloth scene is not valid or its simulation failed."""

class SampleError(Error):
    """A sample file or plan is not valid."""

class InternalError(Error):
    """A bug in hylc (a Rust panic caught at the boundary)."""


class YarnSummary(TypedDict):
    vertices: int
    first: int
    rest_length: float

class PatternSummary(TypedDict):
    """:meth:`Pattern.summary`."""

    vertices: int
    periods: tuple[float, float]
    radius: float
    yarns: list[YarnSummary]
    crossing_x: int
    crossing_y: int
    total_rest_length: float
    total_current_length: float
    notes: list[str]

class BatchResult(TypedDict):
    """:meth:`MicroProblem.solve_batch`."""

    status: list[str]
    converged: npt.NDArray[np.bool_]
    psi: npt.NDArray[np.float64]
    stress: npt.NDArray[np.float64]
    steps: npt.NDArray[np.float64]
    gradient_norm: npt.NDArray[np.float64]
    time: npt.NDArray[np.float64]
    positions: npt.NDArray[np.float64]

class Sensitivities(TypedDict):
    """:meth:`MicroProblem.sensitivities` and :meth:`Solution.derivatives`."""

    psi: float
    steps: int
    stress: npt.NDArray[np.float64]
    dpsi_dtheta: npt.NDArray[np.float64]
    components: list[str]
    d2psi_dz2: npt.NDArray[np.float64]
    dy_dz: npt.NDArray[np.float64]
    dy_dtheta: npt.NDArray[np.float64]

class FitReport(TypedDict, total=False):
    """The fit report of :func:`fit` (the ``.fit.json`` file; the main keys)."""

    samples: Any
    plan: Any
    density: float

class PlanDict(TypedDict, total=False):
    """A sampling plan (the plan JSON's layout; docs/sampling.md)."""

    ranges: dict[str, list[float]]
    count_1d: int
    count_2d: int
    pairs: list[list[str]]
    ranges_2d: list[list[list[float]]]
    grid: dict[str, list[float]]
    counts_1d: list[int]
    counts_2d: list[list[int]]

class PlanSamples(TypedDict):
    """:func:`plan_samples`."""

    hash: str
    ids: list[str]
    z: npt.NDArray[np.float64]
    chains: int

class SampleSummary(TypedDict):
    """:func:`sample`."""

    plan_hash: str
    selected: int
    already_done: int
    written: int
    converged: int
    replayed: int
    sensitivities: int
    lacking_sensitivities: int
    sensitivities_added: int
    time: float

class DerivativeCheck(TypedDict):
    """One row of :func:`check_derivatives`."""

    name: str
    passed: bool
    cases: int
    failures: int
    fd_skipped: int
    max_value: float
    max_gradient_ad: float
    max_hessian_ad: float
    max_gradient_fd: float
    max_hessian_fd: float
    worst_ratio: float
    worst_input: list[float]

class SimulationSummary(TypedDict):
    steps: int
    triangles: int
    vertices: int
    newton_total: int
    newton_max: int
    unconverged_steps: int
    max_residual: float
    wall: float

class SimulationResult(TypedDict):
    """:func:`simulate`: the step log as arrays and the final state."""

    step: npt.NDArray[np.float64]
    time: npt.NDArray[np.float64]
    newton: npt.NDArray[np.float64]
    substeps: npt.NDArray[np.float64]
    dt_min: npt.NDArray[np.float64]
    rejected: npt.NDArray[np.float64]
    error_estimate: npt.NDArray[np.float64]
    residual: npt.NDArray[np.float64]
    energy_elastic: npt.NDArray[np.float64]
    energy_kinetic: npt.NDArray[np.float64]
    energy_gravity: npt.NDArray[np.float64]
    energy_obstacles: npt.NDArray[np.float64]
    shift: npt.NDArray[np.float64]
    wall: npt.NDArray[np.float64]
    strain_min: npt.NDArray[np.float64]
    strain_max: npt.NDArray[np.float64]
    strain_p01: npt.NDArray[np.float64]
    strain_p99: npt.NDArray[np.float64]
    handle_forces: dict[str, npt.NDArray[np.float64]]
    positions: npt.NDArray[np.float64]
    triangles: npt.NDArray[np.int64]
    summary: SimulationSummary

class GradientResult(TypedDict, total=False):
    """:func:`gradient` (the content of ``gradient.json``, numeric lists as arrays)."""

    value: float
    time: float
    residual: float
    scene: dict[str, Any]
    held: dict[str, dict[str, npt.NDArray[np.float64]]]
    obstacles: Any
    material: dict[str, Any]
    check: Any
    yarn: dict[str, float]
    yarn_chain: dict[str, Any]

class Pattern:
    """A periodic yarn pattern (one tile): vertex positions, yarns, periods and radius.

    Made by :func:`load_pattern`, :func:`read_pyp`, :func:`generate` or :func:`reference_state`; ``len(p)`` is
    the number of vertices (= edges).
    """
    @property
    def source(self) -> str:
        """Where the pattern came from: the file or generated kind."""
    @property
    def notes(self) -> list[str]:
        """Notes from loading (the file's warnings, or periods replaced by the implied ones)."""
    @property
    def periods(self) -> tuple[float, float]:
        """Tile periods (p₁, p₂) in m."""
    @property
    def radius(self) -> float:
        """Yarn radius r in m."""
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """Vertex positions in the tile, (N, 3) in m."""
    @property
    def rest_lengths(self) -> list[float]:
        """Rest lengths of the edges (edge i leaves vertex i), (N,) in m."""
    def __len__(self) -> int:
        ...
    def yarns(self) -> list[list[int]]:
        """The yarns as lists of vertex indices, in order along each yarn."""
    def save(self, path: StrPath) -> None:
        """Write the pattern as a ``.pyp`` file (exact round trip).

        Parameters
        ----------
        path : path-like
            The file to write.

        Raises
        ------
        PatternError
            The file cannot be written.
        """
    def summary(self) -> PatternSummary:
        """The summary ``hylc pattern FILE`` prints, as a dict.

        Returns
        -------
        PatternSummary
            ``vertices``, ``periods``, ``radius``, ``yarns`` (per yarn ``vertices``, ``first``,
            ``rest_length``), ``crossing_x``, ``crossing_y`` (edges crossing the tile's sides),
            ``total_rest_length``, ``total_current_length`` and ``notes``.
        """

class Solution:
    """The result of one micro solve (:meth:`MicroProblem.solve`): its status, Ψ̄, state and derivatives."""
    @property
    def status(self) -> str:
        """"Converged", "Stalled", "MaxSteps" or "TimeLimit"."""
    @property
    def converged(self) -> bool:
        """Whether the solve converged (Ψ̄ is defined)."""
    @property
    def psi(self) -> Optional[float]:
        """Ψ̄ (J/m²) of a converged solve; None otherwise."""
    @property
    def strain(self) -> npt.NDArray[np.float64]:
        """The strain (s_x, s_a, s_y, II00, II11)."""
    @property
    def steps(self) -> int:
        """Newton steps taken."""
    @property
    def gradient_norm(self) -> float:
        """‖g‖∞ at the end (N)."""
    @property
    def time(self) -> float:
        """Wall time of the solve (s)."""
    @property
    def energy(self) -> dict[str, float]:
        """The tile's energy parts (J): stretch, bend, twist, contact."""
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """Yarn centre-line vertices in world coordinates (home tile), (N, 3) in m."""
    @property
    def y(self) -> npt.NDArray[np.float64]:
        """The unknowns y = (ũ, θ) in the tile's dof layout."""
    def stress(self) -> npt.NDArray[np.float64]:
        """The homogenized stress ∂Ψ̄/∂z.

        Returns
        -------
        numpy.ndarray
            (5,): s_x, s_a, s_y, II00, II11 (J/m² per unit strain), NaN for a bending component not available
            under bending along the other axis.

        Raises
        ------
        MicroError
            The derivatives could not be computed.
        """
    def parameter_derivatives(self) -> npt.NDArray[np.float64]:
        """∂Ψ̄/∂θ of the yarn parameters (envelope theorem).

        Returns
        -------
        numpy.ndarray
            (6,): θ = ``hylc.PARAMETERS`` (young, shear, bend_twist_factor, contact_stiffness,
            contact_radius_factor, radius), J/m² per unit parameter.

        Raises
        ------
        MicroError
            The solve did not converge (Ψ̄ needs an equilibrium).
        """
    def strain_stiffness(self) -> tuple[list[str], npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """The second derivatives of Ψ̄ in the strain and the equilibrium's derivative in it.

        Returns
        -------
        tuple of (list of str, numpy.ndarray, numpy.ndarray)
            The strain components of the state's family (k of them), d²Ψ̄/dz² (k, k) and dy*/dz (k, dofs).

        Raises
        ------
        MicroError
            The solve did not converge.
        """
    def equilibrium_sensitivities(self) -> npt.NDArray[np.float64]:
        """The equilibrium's derivative in the yarn parameters.

        Returns
        -------
        numpy.ndarray
            dy*/dθ (6, dofs), one row per parameter of :meth:`parameter_derivatives`.

        Raises
        ------
        MicroError
            The solve did not converge.
        """
    def derivatives(self) -> Sensitivities:
        """Every derivative at once.

        Returns
        -------
        Sensitivities
            The dict of :meth:`MicroProblem.sensitivities`.

        Raises
        ------
        MicroError
            The solve did not converge.
        """

class MicroProblem:
    """The periodic yarn problem of one pattern with yarn parameters and the solver's stopping rules.

    Parameters
    ----------
    pattern : Pattern, str or path-like
        A Pattern, a ``.pyp`` file or a generated kind (plain, twill, satin, basket, stockinette).
    yarn : dict, path-like or None
        Yarn parameters: a dict (missing keys take the defaults, :func:`yarn_defaults`), a yarn JSON file, or
        None for the defaults.
    tolerance : float, default 1e-8
        Force tolerance relative to the stretching stiffness (``hylc solve --tolerance``).
    max_steps : int, default 2000
        Newton step limit.
    time_limit : float, optional
        Wall-time limit per solve (s).
    quadrature : int, optional
        Gauss points per segment of the contact quadrature (default the yarn's, 4).
    inertia : bool, default True
        The inertia-controlled Newton steps; False is ``hylc solve --no-inertia`` (the shift rule).

    Raises
    ------
    ValueError
        A bad yarn parameter, tolerance or quadrature; a pattern argument of another type.
    FileNotFoundError
        A pattern or yarn file that does not exist.
    PatternError
        A pattern file that is not valid.
    """
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
    ) -> None:
        ...
    @property
    def yarn(self) -> dict[str, Any]:
        """The yarn parameters of the problem (the radius is the pattern's)."""
    @property
    def dofs(self) -> int:
        """Number of unknowns of the tile (4 per vertex: ũ and θ), the length of dy*/dz rows."""
    def solve(self, z: ArrayLike, start: Optional[Solution] = None) -> Solution:
        """Solve at one strain, from the reference state or from a previous solution (a warm start).

        Parameters
        ----------
        z : array_like
            3 numbers (s_x, s_a, s_y) or 5 (with II00, II11 in 1/m).
        start : Solution, optional
            A previous solution of this problem to start from.

        Returns
        -------
        Solution
            Converged or not (``status``); the GIL is released during the solve.

        Raises
        ------
        ValueError
            A strain of another shape, not finite or outside the admissible range.
        MicroError
            The solve could not run.
        """
    def solve_batch(self, z: ArrayLike, chain: bool = False) -> BatchResult:
        """Solve at every row of ``z``.

        Parameters
        ----------
        z : array_like
            (N, 3) or (N, 5) strains.
        chain : bool, default False
            False: every strain from the reference state, in parallel (each result equals ``solve(z[i])``);
            True: in order, each from the previous result (as ``hylc solve --no-predictor --z … --z …``).

        Returns
        -------
        BatchResult
            ``status`` (list of str), ``converged`` (N,), ``psi`` (N,; NaN when not converged), ``stress`` (N, 5;
            NaN when not available), ``steps``, ``gradient_norm``, ``time`` (N,), ``positions`` (N, vertices,
            3). The GIL is released during the solves.

        Raises
        ------
        ValueError
            Strains of another shape or dtype, not finite or outside the admissible range.
        """
    def sensitivities(self, z: ArrayLike) -> Sensitivities:
        """Ψ̄ at ``z`` and its derivatives, as ``hylc sensitivity`` computes them (solved from the reference state).

        Parameters
        ----------
        z : array_like
            3 or 5 numbers, as :meth:`solve` takes them.

        Returns
        -------
        Sensitivities
            ``psi``, ``steps``, ``stress`` (∂Ψ̄/∂z, 5), ``dpsi_dtheta`` (6, the parameters of
            ``hylc.PARAMETERS``), ``components`` and ``d2psi_dz2`` (k, k), ``dy_dz`` (k, dofs) and ``dy_dtheta``
            (6, dofs).

        Raises
        ------
        ValueError
            A bad strain.
        MicroError
            The solve did not converge.
        """

class Material:
    """A fitted energy density ψ(z) of the cloth (J/m²) as a function of the strain z = (s_x, s_a, s_y, II00, II01,
    II11).

    Made by :meth:`Material.load`, :meth:`Material.default` or :func:`fit`; ``psi``, ``gradient``, ``hessian``
    and ``eval`` take one strain (6,) or a batch (N, 6).
    """
    @staticmethod
    def load(path: StrPath) -> Material:
        """staticmethod(function) -> method

        Convert a function to be a static method.

        A static method does not receive an implicit first argument.
        To declare a static method, use this idiom:

             class C:
                 @staticmethod
                 def f(arg1, arg2, argN):
                     ...

        It can be called either on the class (e.g. C.f()) or on an instance
        (e.g. C().f()). Both the class and the instance are ignored, and
        neither is passed implicitly as the first argument to the method.

        Static methods in Python are similar to those found in Java or C++.
        For a more advanced concept, see the classmethod builtin.
        """
    @staticmethod
    def default() -> Material:
        """staticmethod(function) -> method

        Convert a function to be a static method.

        A static method does not receive an implicit first argument.
        To declare a static method, use this idiom:

             class C:
                 @staticmethod
                 def f(arg1, arg2, argN):
                     ...

        It can be called either on the class (e.g. C.f()) or on an instance
        (e.g. C().f()). Both the class and the instance are ignored, and
        neither is passed implicitly as the first argument to the method.

        Static methods in Python are similar to those found in Java or C++.
        For a more advanced concept, see the classmethod builtin.
        """
    @property
    def density(self) -> float:
        """Areal density ρ_A (kg/m²)."""
    @property
    def admissible_limits(self) -> list[float]:
        """|z_k| limits of the admissible range."""
    def save(self, path: StrPath) -> None:
        """Write the material as JSON.

        Parameters
        ----------
        path : path-like
            The file to write.

        Raises
        ------
        MaterialError
            The file cannot be written.
        """
    def psi(self, z: ArrayLike) -> Union[float, npt.NDArray[np.float64]]:
        """ψ at each strain.

        Parameters
        ----------
        z : array_like
            (6,) or (N, 6) strains (s_x, s_a, s_y, II00, II01, II11), float64.

        Returns
        -------
        float or numpy.ndarray
            A float for (6,), an (N,) array for (N, 6).

        Raises
        ------
        ValueError
            Another shape or dtype, a value not finite or outside the admissible range (the row is named).
        """
    def gradient(self, z: ArrayLike) -> npt.NDArray[np.float64]:
        """∇ψ at each strain.

        Parameters
        ----------
        z : array_like
            (6,) or (N, 6) strains.

        Returns
        -------
        numpy.ndarray
            (6,) or (N, 6).

        Raises
        ------
        ValueError
            As :meth:`psi`.
        """
    def hessian(self, z: ArrayLike) -> npt.NDArray[np.float64]:
        """∇²ψ at each strain.

        Parameters
        ----------
        z : array_like
            (6,) or (N, 6) strains.

        Returns
        -------
        numpy.ndarray
            (6, 6) or (N, 6, 6).

        Raises
        ------
        ValueError
            As :meth:`psi`.
        """
    def eval(
        self, z: ArrayLike
    ) -> tuple[Union[float, npt.NDArray[np.float64]], npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """(ψ, ∇ψ, ∇²ψ) at each strain in one pass.

        Parameters
        ----------
        z : array_like
            (6,) or (N, 6) strains.

        Returns
        -------
        tuple
            As :meth:`psi`, :meth:`gradient` and :meth:`hessian` return them.

        Raises
        ------
        ValueError
            As :meth:`psi`.
        """

def load_pattern(pattern: StrPath) -> Pattern:
    """Load a pattern as the micro commands do.

    Parameters
    ----------
    pattern : str or path-like
        A ``.pyp`` file (used at the periods its rest lengths imply; ``notes`` says when they were replaced) or
        a generated kind (plain, twill, satin, basket, stockinette).

    Returns
    -------
    Pattern

    Raises
    ------
    FileNotFoundError
        A ``.pyp`` file that does not exist.
    PatternError
        A file that is not a valid pattern.
    ValueError
        Neither a file nor a generated kind.
    """

def read_pyp(path: StrPath) -> Pattern:
    """Read a ``.pyp`` file strictly, as ``hylc pattern FILE`` does.

    Parameters
    ----------
    path : path-like
        The ``.pyp`` file.

    Returns
    -------
    Pattern
        At the file's periods; its checks' warnings are in ``notes``.

    Raises
    ------
    FileNotFoundError
        The file does not exist.
    PatternError
        The file is not a valid pattern (the message names the line).
    """

def generate(
    kind: str, n: Optional[int] = None, step: Optional[int] = None, vertices_per_radius: float = 1.0
) -> Pattern:
    """Generate a pattern, as ``hylc generate KIND`` does.

    Parameters
    ----------
    kind : str
        plain, twill, satin, basket or stockinette.
    n : int, optional
        The twill repeat (4), satin repeat (5) or basket group size (2).
    step : int, optional
        The satin move (2).
    vertices_per_radius : float, default 1.0
        Vertices per yarn radius of arclength.

    Returns
    -------
    Pattern

    Raises
    ------
    PatternError
        An unknown kind or bad parameters.
    """

def reference_state(
    pattern: Union[Pattern, StrPath],
    construction: Optional[str] = None,
    yarn: Yarn = None,
    equilibrate_only: bool = False,
) -> tuple[Pattern, dict[str, Any]]:
    """The reference state of a pattern (Algorithm C1), as ``hylc reference`` computes it.

    The stress-free state, the tension, the zero-stress periods and the centring.

    Parameters
    ----------
    pattern : Pattern, str or path-like
        A Pattern, a ``.pyp`` file or a generated kind.
    construction : {"knitted", "woven"}, optional
        Selects the tension factors; generated kinds know theirs, a file needs it.
    yarn : dict, path-like or None
        Yarn parameters (as :class:`MicroProblem` takes them).
    equilibrate_only : bool, default False
        Skip the stress-free state and the tension.

    Returns
    -------
    tuple of (Pattern, dict)
        The reference state and C1's report (``psi``, ``periods_out``, ...).

    Raises
    ------
    ValueError
        An unknown construction, or a file without one.
    MicroError
        A solve of C1 failed.
    """

def yarn_defaults() -> dict[str, Any]:
    """The default yarn parameters (``hylc yarn``).

    Returns
    -------
    dict
        Every key of the yarn JSON (``young``, ``shear``, ``bend_twist_factor``, ``radius``, ``density``,
        ``contact_stiffness``, ``contact_quadrature``, ``contact_exclusion``, ``contact_radius_factor``,
        ``bending``).
    """

def load_yarn(path: StrPath) -> dict[str, Any]:
    """Read a yarn JSON file (every key required).

    Parameters
    ----------
    path : path-like
        The yarn file.

    Returns
    -------
    dict
        The parameters, as :func:`yarn_defaults` gives them.

    Raises
    ------
    FileNotFoundError
        The file does not exist.
    ValueError
        A missing, unknown or invalid key.
    """

def save_yarn(yarn: dict[str, Any], path: StrPath) -> None:
    """Write yarn parameters as a yarn JSON file (for ``--yarn FILE``).

    Parameters
    ----------
    yarn : dict
        Yarn parameters; missing keys take the defaults.
    path : path-like
        The file to write.

    Raises
    ------
    ValueError
        An unknown or invalid key, or the file cannot be written.
    """

def plan(plan: Optional[PlanArg] = None, write: Optional[StrPath] = None) -> PlanDict:
    """A sampling plan as a dict (the plan JSON's layout), as ``hylc plan --write`` writes it.

    Parameters
    ----------
    plan : str, path-like or dict, default "default"
        A built-in plan: ``"default"`` (150 per 1D range, 50×50 grids), ``"reduced"`` (30 per 1D range, 10×10
        grids), ``"quick"`` (``hylc run``'s: 30 per 1D range, 6×6 grids) or ``"holdout"`` (the 9×9×9 in-plane
        grid only); or a plan JSON file, or a dict (validated and completed).
    write : path-like, optional
        Also write the plan there as JSON (pretty-printed, as ``hylc plan --write``).

    Returns
    -------
    PlanDict
        ``ranges`` (per strain [min, max]), ``count_1d``, ``count_2d``, ``pairs`` and the optional
        ``ranges_2d``, ``grid``, ``counts_1d``, ``counts_2d``; it can be changed and passed to :func:`sample`
        or :func:`plan_samples`.

    Raises
    ------
    ValueError
        A name that is neither a built-in plan nor a file.
    SampleError
        A plan file or dict that is not a valid plan (the message names the field).
    """

def plan_samples(plan: PlanArg) -> PlanSamples:
    """The samples of a plan in its order, with their ids, and its hash.

    Parameters
    ----------
    plan : str, path-like or dict
        As :func:`plan` takes it.

    Returns
    -------
    PlanSamples
        ``hash`` (the plan hash, 16 hex digits, as ``hylc plan`` prints it), ``ids`` (N,) the samples' ids
        (``HASH-INDEX``, as in the sample file), ``z`` (N, 5) the strains (s_x, s_a, s_y, II00, II11) and
        ``chains`` the number of warm-started continuation chains.

    Raises
    ------
    ValueError, SampleError
        As :func:`plan`.
    """

def sample(
    pattern: Union[Pattern, StrPath],
    out: StrPath,
    plan: Optional[PlanArg] = None,
    *,
    yarn: Yarn = None,
    cold: bool = False,
    shard: Union[None, str, tuple[int, int]] = None,
    limit: Optional[int] = None,
    predictor: str = "secant",
    starts: str = "warm",
    disagreement: Optional[float] = None,
    sensitivities: bool = False,
    tolerance: float = 1e-8,
    max_steps: int = 2000,
    time_limit: Optional[float] = None,
    crossings: Optional[str] = None,
    inertia: bool = True,
    progress: Progress = None,
) -> SampleSummary:
    """Run a sampling plan on a pattern, appending to a JSON-lines sample file, as ``hylc sample`` does.

    Chains of warm-started solves run in parallel; every record is written and synced as it is solved, and
    samples already in the file are skipped, so an interrupted run (Ctrl-C, ``limit``) resumes where it stopped
    and writes the same records as an uninterrupted one. The sidecar ``OUT.meta.json`` (pattern, plan, yarn,
    solver) is written too, for :func:`fit`.

    Parameters
    ----------
    pattern : Pattern, str or path-like
        A Pattern, a ``.pyp`` file or a generated kind (plain, twill, satin, basket, stockinette).
    out : path-like
        The sample file (JSON lines; created or appended to).
    plan : str, path-like or dict, default "default"
        As :func:`plan` takes it.
    yarn : dict, path-like or None
        Yarn parameters (a dict, missing keys the defaults; a yarn JSON file; None for the defaults).
    cold : bool, default False
        Start every sample from the reference state.
    shard : str or (int, int), optional
        Run shard k of n (``"k/n"`` or ``(k, n)``: the chains with index ≡ k mod n).
    limit : int, optional
        Stop after writing this many samples.
    predictor : {"secant", "none"}, default "secant"
        The predictor of warm starts along a chain.
    starts : {"warm", "warm+cold", "all"}, default "warm"
        The starts of every sample (docs/sampling.md, "Multi-start").
    disagreement : float, optional
        ``starts="all"``: the relative difference of the warm and cold Ψ̄ above which the reversed chain is
        tried (default 1e-6, the library's).
    sensitivities : bool, default False
        Store ∂Ψ̄/∂θ and dσ/dθ of the six yarn parameters in every converged record (and add them to the
        finished records that lack them).
    tolerance, max_steps, time_limit : float, int, float
        The micro solver's stopping rules (defaults 1e-8, 2000, none).
    crossings : {"off", "count", "reject"}, optional
        The yarn-crossing guard (default off, ``reject`` with several starts).
    inertia : bool, default True
        The inertia-controlled Newton steps (False = ``--no-inertia``, for files made before them).
    progress : callable, optional
        ``progress(done, total)``: records written by this run of those it will write, called from the calling
        thread (GIL held) with the latest counts at most every 0.05 s and at the end. An exception it raises
        stops the run after the solves in flight and is raised.

    Returns
    -------
    SampleSummary
        ``plan_hash``, ``selected`` (samples of the selected chains), ``already_done``, ``written``,
        ``converged``, ``replayed`` (re-solved for warm starts), ``sensitivities``,
        ``lacking_sensitivities``, ``sensitivities_added`` and ``time`` (s), as ``hylc sample`` prints them.

    Raises
    ------
    ValueError
        A bad argument (a plan name, ``shard``, ``starts`` with ``cold``, a yarn parameter).
    FileNotFoundError
        A pattern or plan file that does not exist.
    SampleError
        A plan that is not valid, ``starts`` other than warm with ``cold``, or a sample file of another
        problem (pattern, yarn or solver settings).
    KeyboardInterrupt
        Ctrl-C (noticed within 0.05 s; the records written so far stay, a later call resumes).
    """

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
) -> tuple[Material, FitReport]:
    """Fit a material to a sample file (Algorithm C5), as ``hylc fit SAMPLES`` does.

    Parameters
    ----------
    samples : path-like
        A sample file made by :func:`sample` or ``hylc sample`` (its sidecar gives the plan and the density).
    out : path-like, optional
        The material JSON to write (default SAMPLES with extension ``.material.json``).
    report : path-like, optional
        The JSON fit report to write (default ``.fit.json``).
    plots : path-like, optional
        A folder for the PNG plots (none without it).
    plan : str, optional
        The plan (name or file) when the sample file has no sidecar.
    density : float, optional
        The areal density (kg/m²) when the sample file has no sidecar.
    preset : {"covering", "design", "design-stockinette"}, default "covering"
        The fit's settings, as ``hylc fit --preset`` takes them (``covering`` is ``hylc run``'s).
    knots_1d, knots_2d : int, optional
        The preset's knot counts changed.

    Returns
    -------
    tuple of (Material, FitReport)
        The fitted material and the fit report (the content of the report file).

    Raises
    ------
    FileNotFoundError
        The sample file does not exist.
    ValueError
        An unknown preset; a sample file without samples.
    FitError
        The fit failed.
    """

def check_derivatives(
    cases: int = 1000, seed: int = 1, filter: str = "", progress: Progress = None
) -> list[DerivativeCheck]:
    """Run the derivative harness on every registered function, as ``hylc check-derivatives`` does.

    Each function's value, gradient and Hessian are compared with automatic differentiation and with
    Richardson-extrapolated central differences at ``cases`` random inputs from its own sampler
    (docs/derivative-harness.md). Functions of the original materials are skipped when ``../shared`` is absent.

    Parameters
    ----------
    cases : int, default 1000
        Random inputs per function.
    seed : int, default 1
        Seed of the input generator (each function draws its own stream from it).
    filter : str, default ""
        Only the functions whose name contains it (all when empty).
    progress : callable, optional
        ``progress(done, total)``: functions checked of those selected, called from the calling thread (GIL
        held). An exception it raises stops the run after the function in flight and is raised.

    Returns
    -------
    list of DerivativeCheck
        One dict per function, in the registry's order: ``name``, ``passed``, ``cases``, ``failures``,
        ``fd_skipped`` (cases too close to a kink for finite differences), the largest relative errors
        ``max_value``, ``max_gradient_ad``, ``max_hessian_ad``, ``max_gradient_fd``, ``max_hessian_fd``,
        ``worst_ratio`` (the largest error-to-tolerance ratio; ≤ 1 passes) and ``worst_input``.

    Raises
    ------
    ValueError
        ``cases`` is 0, or no registered function matches ``filter``.
    KeyboardInterrupt
        Ctrl-C (the run stops after the function in flight).
    """

def load_scene(scene: SceneArg) -> dict[str, Any]:
    """The scene as a dict, with every setting (defaults filled in), as `hylc simulate SCENE --print` prints it.

    Parameters
    ----------
    scene : str, path-like or dict
        A scene JSON file, an ARCSim scene file (converted), a built-in (``stretch-x``, ``stretch-y``,
        ``drape-x``, ``drape-y``, ``hanging``) or a dict with the scene JSON's layout.

    Returns
    -------
    dict
        The scene JSON's layout (``mesh``, ``material``, ``duration``, ``dt``, ``solver``, ``output``, ...);
        it can be changed and passed to :func:`simulate` or :func:`gradient`.

    Raises
    ------
    FileNotFoundError
        A scene file that does not exist.
    SimulationError
        A scene that is not valid JSON of a scene, or an unknown built-in.
    """

def simulate(
    scene: SceneArg,
    out: Optional[StrPath] = None,
    material: Optional[str] = None,
    duration: Optional[float] = None,
    dt: Optional[float] = None,
    edge: Optional[float] = None,
    time_tol: Optional[Union[float, str]] = None,
    vtu: bool = False,
    progress: Progress = None,
) -> SimulationResult:
    """Run a cloth scene as ``hylc simulate`` does, with its overrides.

    Parameters
    ----------
    scene : str, path-like or dict
        A scene JSON file, an ARCSim scene file, a built-in (``stretch-x``, ``stretch-y``, ``drape-x``,
        ``drape-y``, ``hanging``) or a dict with the scene JSON's layout (:func:`load_scene` gives one; its
        relative paths start from the working directory).
    out : path-like, optional
        A folder for the frames (``frame_NNNN.obj``), ``log.jsonl``, ``handle_forces.csv`` and
        ``provenance.json``; nothing is written without it.
    material : str, optional
        A material file (relative to the working directory) or ``"default"`` instead of the scene's.
    duration, dt : float, optional
        The simulated time and the step (s) instead of the scene's.
    edge : float, optional
        The edge length (m) of a rectangle mesh.
    time_tol : float or "off", optional
        The largest estimated local error (m) of a substep (the scene's ``solver.time_tol``); ``"off"`` makes
        substeps shorten only when Newton fails.
    vtu : bool, default False
        Also a ``frame_NNNN.vtu`` beside each OBJ frame and the series ``frames.pvd`` (``--format vtu``).
    progress : callable, optional
        ``progress(done, total)`` with the time steps done of the scene's, called from the calling thread
        (GIL held) with the latest counts at most every 0.05 s and after the last step. An exception it raises
        stops the run after the step in flight and is raised.

    Returns
    -------
    SimulationResult
        The step log as (steps,) arrays (``step``, ``time``, ``newton``, ``substeps``, ``dt_min``,
        ``rejected``, ``error_estimate``, ``residual``, ``energy_*``, ``shift``, ``wall``), ``strain_min``,
        ``strain_max``, ``strain_p01``, ``strain_p99`` (steps, 6), ``handle_forces`` (name → (steps, 3) N),
        ``positions`` (vertices, 3) and ``triangles`` (triangles, 3, int64) of the final state, and ``summary``
        (steps, triangles, vertices, Newton iterations, largest residual, wall time).

    Raises
    ------
    FileNotFoundError
        A scene file that does not exist.
    ValueError
        A bad override (``dt``, ``time_tol``, ``edge`` of a mesh file).
    SimulationError
        A scene that is not valid, or a step that fails even at the smallest substep.
    KeyboardInterrupt
        Ctrl-C during the run (noticed within 0.05 s; the run stops after the step in flight, the files written
        so far stay complete).
    """

def gradient(
    scene: SceneArg,
    observable: Optional[str] = None,
    cotangent: Optional[ArrayLike] = None,
    at: Optional[float] = None,
    material: Optional[str] = None,
    out: Optional[StrPath] = None,
    check: bool = False,
    samples: Optional[StrPath] = None,
    yarn: Yarn = None,
) -> GradientResult:
    """Sensitivities dJ/dp of a scene's observable at one step, as ``hylc gradient`` computes them.

    A quasi-static equilibrium is differentiated by one adjoint solve, a dynamic run by the discrete adjoint of
    its implicit Euler substeps (docs/sensitivities.md).

    Parameters
    ----------
    scene : str, path-like or dict
        A scene JSON file, an ARCSim scene, a built-in or a dict with the scene JSON's layout.
    observable : str, optional
        ``com-x``, ``com-y``, ``com-z``, ``energy``, ``handle-force:NAME:x|y|z`` or ``target:FILE.obj``.
    cotangent : array_like, optional
        Instead of ``observable``: weights w (vertices, 3), J = Σ w_v · x_v, so that the result is the
        vector–Jacobian product wᵀ dx*/dp.
    at : float, optional
        The time (s) of the step to differentiate (the nearest step; default the last).
    material : str, optional
        A material file or ``"default"`` instead of the scene's.
    out : path-like, optional
        A folder for the frames, the log and ``gradient.json`` (a temporary folder, removed, by default).
    check : bool, default False
        Also central differences of re-solves for a few coefficients (``check`` in the result).
    samples : path-like, optional
        The sample file the material was fitted to (made with ``sensitivities=True``): adds dJ/dθ of the yarn
        parameters through the fit (``yarn``, ``yarn_chain``).
    yarn : dict, path-like or None
        The yarn parameters of ``samples`` (a dict, a yarn JSON file, or None for the defaults).

    Returns
    -------
    GradientResult
        The content of ``gradient.json`` with numeric lists as numpy arrays: ``value``, ``time``, ``residual``,
        ``scene`` (``stiffness``, ``bending_scale``, ``mass``, ``gravity``), ``held`` (per held set
        ``translation`` (3,) and ``keyframes`` (k, 3)), ``obstacles``, ``material`` (the material file's layout
        with dJ/dc in place of each coefficient), ``check``, and with ``samples`` ``yarn`` (name → dJ/dθ) and
        ``yarn_chain``.

    Raises
    ------
    ValueError
        Not exactly one of ``observable`` and ``cotangent``; a cotangent of the wrong shape; ``yarn`` without
        ``samples``; a scene the adjoint does not cover (e.g. damping).
    FileNotFoundError
        A scene or sample file that does not exist.
    SimulationError
        A scene that is not valid or whose step did not converge.
    """
