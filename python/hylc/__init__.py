"""Homogenized yarn-level cloth from Python (the guide's chapter: docs/python.md).

The compiled module ``hylc._hylc`` does the work; this package re-exports it:

- patterns: :func:`load_pattern` (a ``.pyp`` file or a generated kind), :func:`read_pyp`, :func:`generate`,
  :class:`Pattern` (``save``, ``summary``, ``positions``, ...), :func:`reference_state` (Algorithm C1);
- micro: :class:`MicroProblem` (``solve``, ``solve_batch``, ``sensitivities``) and :class:`Solution` (``psi``,
  ``stress()``, ``positions``, ``parameter_derivatives()``, ``strain_stiffness()``,
  ``equilibrium_sensitivities()``); yarn parameters as dicts: :func:`yarn_defaults`, :func:`load_yarn`,
  :func:`save_yarn`;
- sampling (Algorithm C4): :func:`plan` (the built-in plans as dicts), :func:`plan_samples` (a plan's strains and
  ids), :func:`sample` (a plan on a pattern to a resumable sample file, with ``progress`` and Ctrl-C);
- materials: :class:`Material` (``load``, ``default``, ``save``, ``psi``, ``gradient``, ``hessian``, ``eval`` over
  (N, 6) arrays) and :func:`fit` (Algorithm C5 on a sample file);
- cloth: :func:`load_scene` (a scene file or built-in as a dict), :func:`simulate` (a scene file, built-in or
  dict; the step log as arrays and the final positions) and :func:`gradient` (dJ/dp of an observable, or a
  vector–Jacobian product, by an adjoint solve);
- the derivative harness: :func:`check_derivatives` (every registered function's derivatives against AD and
  finite differences, one dict per function).

Errors: bad arguments raise ``ValueError``, missing files ``FileNotFoundError``, failures of the library a
subclass of :class:`Error`, with the message the command line prints after ``error:``. The GIL is released while
the library works, so Python threads can run solves in parallel. The long calls (:func:`sample`,
:func:`simulate`, :func:`check_derivatives`) take ``progress=callable(done, total)`` and stop on Ctrl-C
(``KeyboardInterrupt``) after the unit of work in flight.
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
    check_derivatives,
    fit,
    generate,
    gradient,
    load_pattern,
    load_scene,
    load_yarn,
    plan,
    plan_samples,
    read_pyp,
    reference_state,
    sample,
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
    "check_derivatives",
    "fit",
    "generate",
    "gradient",
    "load_pattern",
    "load_scene",
    "load_yarn",
    "plan",
    "plan_samples",
    "read_pyp",
    "reference_state",
    "sample",
    "save_yarn",
    "simulate",
    "yarn_defaults",
]
