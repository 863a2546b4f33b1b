"""Homogenized yarn-level cloth from Python (issue 21).

The compiled module ``hylc._hylc`` does the work; this package re-exports it:

- patterns: :func:`load_pattern` (a ``.pyp`` file or a generated kind), :func:`read_pyp`, :func:`generate`,
  :class:`Pattern` (``save``, ``summary``, ``positions``, ...), :func:`reference_state` (Algorithm C1);
- micro: :class:`MicroProblem` (``solve``, ``solve_batch``, ``sensitivities``) and :class:`Solution` (``psi``,
  ``stress()``, ``positions``, ``parameter_derivatives()``, ``strain_stiffness()``,
  ``equilibrium_sensitivities()``); yarn parameters as dicts: :func:`yarn_defaults`, :func:`load_yarn`,
  :func:`save_yarn`;
- materials: :class:`Material` (``load``, ``default``, ``save``, ``psi``, ``gradient``, ``hessian``, ``eval`` over
  (N, 6) arrays) and :func:`fit` (Algorithm C5 on a sample file);
- cloth: :func:`simulate` (a scene file or built-in; the step log as arrays and the final positions) and
  :func:`gradient` (dJ/dp of an observable of a quasi-static scene, or a vector–Jacobian product, by one adjoint
  solve).

Errors: bad arguments raise ``ValueError``, missing files ``FileNotFoundError``, failures of the library a
subclass of :class:`Error`, with the message the command line prints after ``error:``. The GIL is released while
the library works, so Python threads can run solves in parallel.
"""

from ._hylc import (
    Error,
    FitError,
    InternalError,
    Material,
    MaterialError,
    MicroError,
    MicroProblem,
    Pattern,
    PatternError,
    SampleError,
    SimulationError,
    Solution,
    __version__,
    fit,
    generate,
    gradient,
    load_pattern,
    load_yarn,
    read_pyp,
    reference_state,
    save_yarn,
    simulate,
    yarn_defaults,
)

#: Names of the strain components of a micro solve, in the order of ``z`` and of ``Solution.stress()``.
MICRO_STRAIN = ("s_x", "s_a", "s_y", "II00", "II11")
#: Names of the strain components of a material, in the order of the columns of ``z``.
MATERIAL_STRAIN = ("s_x", "s_a", "s_y", "II00", "II01", "II11")
#: Yarn parameters θ of ``Solution.parameter_derivatives()`` and the rows of ``equilibrium_sensitivities()``.
PARAMETERS = ("young", "shear", "bend_twist_factor", "contact_stiffness", "contact_radius_factor", "radius")

__all__ = [
    "Error",
    "FitError",
    "InternalError",
    "Material",
    "MaterialError",
    "MicroError",
    "MicroProblem",
    "Pattern",
    "PatternError",
    "SampleError",
    "SimulationError",
    "Solution",
    "MICRO_STRAIN",
    "MATERIAL_STRAIN",
    "PARAMETERS",
    "__version__",
    "fit",
    "generate",
    "gradient",
    "load_pattern",
    "load_yarn",
    "read_pyp",
    "reference_state",
    "save_yarn",
    "simulate",
    "yarn_defaults",
]
