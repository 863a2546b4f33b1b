//! The micro problem: solves at one strain or a batch, and the derivatives of Ψ̄ at an equilibrium (envelope
//! theorem: ∂Ψ̄/∂z, ∂Ψ̄/∂θ; d²Ψ̄/dz², dy*/dz, dy*/dθ).

use crate::arrays::{rows, shaped, to_2d, Array};
use crate::errors::{detached, HyError, HyResult};
use crate::pattern::pattern_of;
use crate::yarn::{yarn_dict, yarn_of};
use hylc::micro::envelope::{
    parameter_derivatives, strain_derivatives, strain_stiffness, PARAMETER_NAMES,
};
use hylc::micro::sensitivity::equilibrium_sensitivities;
use hylc::micro::solver::world_positions;
use hylc::micro::{MacroStrain, MicroProblem, Solution, SolverOptions, StepRule};
use hylc::strain::StrainComponent;
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use std::sync::Arc;

/// A macro strain from 3 (s_x, s_a, s_y) or 5 (…, II00, II11) numbers.
fn strain_of(z: &[f64]) -> MacroStrain {
    match z.len() {
        3 => MacroStrain::in_plane(z[0], z[1], z[2]),
        _ => MacroStrain::new(z[0], z[1], z[2], z[3], z[4]),
    }
}

/// The periodic yarn problem of one pattern with yarn parameters and the solver's stopping rules.
///
/// Parameters
/// ----------
/// pattern : Pattern, str or path-like
///     A Pattern, a ``.pyp`` file or a generated kind (plain, twill, satin, basket, stockinette).
/// yarn : dict, path-like or None
///     Yarn parameters: a dict (missing keys take the defaults, :func:`yarn_defaults`), a yarn JSON file, or
///     None for the defaults.
/// tolerance : float, default 1e-8
///     Force tolerance relative to the stretching stiffness (``hylc solve --tolerance``).
/// max_steps : int, default 2000
///     Newton step limit.
/// time_limit : float, optional
///     Wall-time limit per solve (s).
/// quadrature : int, optional
///     Gauss points per segment of the contact quadrature (default the yarn's, 4).
/// inertia : bool, default True
///     The inertia-controlled Newton steps; False is ``hylc solve --no-inertia`` (the shift rule).
///
/// Raises
/// ------
/// ValueError
///     A bad yarn parameter, tolerance or quadrature; a pattern argument of another type.
/// FileNotFoundError
///     A pattern or yarn file that does not exist.
/// PatternError
///     A pattern file that is not valid.
#[pyclass(module = "hylc", name = "MicroProblem", frozen)]
pub struct PyMicroProblem {
    problem: Arc<MicroProblem>,
}

/// The result of one micro solve (:meth:`MicroProblem.solve`): its status, Ψ̄, state and derivatives.
#[pyclass(module = "hylc", name = "Solution", frozen)]
pub struct PySolution {
    problem: Arc<MicroProblem>,
    sol: Solution,
}

/// The homogenized stress ∂Ψ̄/∂z of a state (NaN where a component is not available).
fn stress_of(problem: &MicroProblem, sol: &Solution) -> HyResult<[f64; 5]> {
    Ok(strain_derivatives(problem, &sol.state)?.map(|v| v.unwrap_or(f64::NAN)))
}

/// Yarn centre-line vertices in world coordinates (home tile), row-major (N, 3).
fn positions_of(problem: &MicroProblem, sol: &Solution) -> Vec<[f64; 3]> {
    world_positions(&problem.pattern, &sol.state)
        .iter()
        .map(|v| [v.x, v.y, v.z])
        .collect()
}

#[pymethods]
impl PyMicroProblem {
    /// See the class.
    #[new]
    #[pyo3(signature = (pattern, yarn=None, *, tolerance=1e-8, max_steps=2000, time_limit=None, quadrature=None, inertia=true))]
    fn new(
        pattern: &Bound<'_, PyAny>,
        yarn: Option<&Bound<'_, PyAny>>,
        tolerance: f64,
        max_steps: usize,
        time_limit: Option<f64>,
        quadrature: Option<usize>,
        inertia: bool,
    ) -> PyResult<Self> {
        let p = pattern_of(pattern)?;
        let mut yarn = yarn_of(yarn)?;
        if let Some(q) = quadrature {
            if q == 0 {
                return Err(
                    HyError::value("quadrature: expected at least 1 point per segment").into(),
                );
            }
            yarn.contact_quadrature = q;
        }
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(HyError::value(format!(
                "tolerance: expected a positive number, got {tolerance}"
            ))
            .into());
        }
        let options = SolverOptions {
            tolerance,
            max_steps,
            time_limit,
            step_rule: if inertia {
                StepRule::Inertia
            } else {
                StepRule::Shift
            },
            ..Default::default()
        };
        Ok(PyMicroProblem {
            problem: Arc::new(MicroProblem::new(p.inner, &yarn, options)),
        })
    }

    /// The yarn parameters of the problem (the radius is the pattern's).
    #[getter]
    fn yarn<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        yarn_dict(py, &self.problem.material)
    }

    /// Number of unknowns of the tile (4 per vertex: ũ and θ), the length of dy*/dz rows.
    #[getter]
    fn dofs(&self) -> usize {
        4 * self.problem.pattern.len()
    }

    /// Solve at one strain, from the reference state or from a previous solution (a warm start).
    ///
    /// Parameters
    /// ----------
    /// z : array_like
    ///     3 numbers (s_x, s_a, s_y) or 5 (with II00, II11 in 1/m).
    /// start : Solution, optional
    ///     A previous solution of this problem to start from.
    ///
    /// Returns
    /// -------
    /// Solution
    ///     Converged or not (``status``); the GIL is released during the solve.
    ///
    /// Raises
    /// ------
    /// ValueError
    ///     A strain of another shape, not finite or outside the admissible range.
    /// MicroError
    ///     The solve could not run.
    #[pyo3(signature = (z, start=None))]
    fn solve(
        &self,
        py: Python<'_>,
        z: &Bound<'_, PyAny>,
        start: Option<&PySolution>,
    ) -> PyResult<PySolution> {
        let zs = rows(z, "z", &[3, 5])?;
        if !zs.single {
            return Err(HyError::value(
                "z: expected one strain (3 or 5 numbers); use solve_batch for many",
            )
            .into());
        }
        let strain = strain_of(zs.row(0));
        let problem = self.problem.clone();
        let start = start.map(|s| s.sol.state.clone());
        let sol = detached(py, || Ok(problem.solve(&strain, start.as_ref())?))?;
        Ok(PySolution {
            problem: self.problem.clone(),
            sol,
        })
    }

    /// Solve at every row of ``z``.
    ///
    /// Parameters
    /// ----------
    /// z : array_like
    ///     (N, 3) or (N, 5) strains.
    /// chain : bool, default False
    ///     False: every strain from the reference state, in parallel (each result equals ``solve(z[i])``);
    ///     True: in order, each from the previous result (as ``hylc solve --no-predictor --z … --z …``).
    ///
    /// Returns
    /// -------
    /// BatchResult
    ///     ``status`` (list of str), ``converged`` (N,), ``psi`` (N,; NaN when not converged), ``stress`` (N, 5;
    ///     NaN when not available), ``steps``, ``gradient_norm``, ``time`` (N,), ``positions`` (N, vertices,
    ///     3). The GIL is released during the solves.
    ///
    /// Raises
    /// ------
    /// ValueError
    ///     Strains of another shape or dtype, not finite or outside the admissible range.
    #[pyo3(signature = (z, chain=false))]
    fn solve_batch<'py>(
        &self,
        py: Python<'py>,
        z: &Bound<'py, PyAny>,
        chain: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let strains: Vec<MacroStrain> = rows(z, "z", &[3, 5])?.iter().map(strain_of).collect();
        let problem = self.problem.clone();
        let solved: Vec<(Solution, [f64; 5], Vec<[f64; 3]>)> = detached(py, || {
            let finish = |sol: Solution| -> HyResult<(Solution, [f64; 5], Vec<[f64; 3]>)> {
                let stress = stress_of(&problem, &sol)?;
                let x = positions_of(&problem, &sol);
                Ok((sol, stress, x))
            };
            if chain {
                let mut out: Vec<(Solution, [f64; 5], Vec<[f64; 3]>)> =
                    Vec::with_capacity(strains.len());
                for s in &strains {
                    let start = out.last().map(|(prev, _, _)| &prev.state);
                    let sol = problem.solve(s, start)?;
                    out.push(finish(sol)?);
                }
                Ok(out)
            } else {
                strains
                    .par_iter()
                    .map(|s| finish(problem.solve(s, None)?))
                    .collect()
            }
        })?;
        let n = solved.len();
        let nv = self.problem.pattern.len();
        let d = PyDict::new(py);
        let status: Vec<String> = solved
            .iter()
            .map(|(s, _, _)| s.status.to_string())
            .collect();
        let converged: Vec<bool> = solved.iter().map(|(s, _, _)| s.psi().is_ok()).collect();
        let psi: Vec<f64> = solved
            .iter()
            .map(|(s, _, _)| s.psi().unwrap_or(f64::NAN))
            .collect();
        let stress: Vec<[f64; 5]> = solved.iter().map(|(_, st, _)| *st).collect();
        let steps: Vec<f64> = solved.iter().map(|(s, _, _)| s.steps as f64).collect();
        let gnorm: Vec<f64> = solved.iter().map(|(s, _, _)| s.gradient_norm).collect();
        let time: Vec<f64> = solved.iter().map(|(s, _, _)| s.time).collect();
        let x: Vec<f64> = solved
            .iter()
            .flat_map(|(_, _, x)| x.iter().flatten().copied())
            .collect();
        d.set_item("status", status)?;
        d.set_item("converged", PyArray1::from_vec(py, converged))?;
        d.set_item("psi", PyArray1::from_vec(py, psi))?;
        d.set_item("stress", to_2d(py, &stress))?;
        d.set_item("steps", PyArray1::from_vec(py, steps))?;
        d.set_item("gradient_norm", PyArray1::from_vec(py, gnorm))?;
        d.set_item("time", PyArray1::from_vec(py, time))?;
        d.set_item("positions", shaped(py, x, &[n, nv, 3]))?;
        Ok(d)
    }

    /// Ψ̄ at ``z`` and its derivatives, as ``hylc sensitivity`` computes them (solved from the reference state).
    ///
    /// Parameters
    /// ----------
    /// z : array_like
    ///     3 or 5 numbers, as :meth:`solve` takes them.
    ///
    /// Returns
    /// -------
    /// Sensitivities
    ///     ``psi``, ``steps``, ``stress`` (∂Ψ̄/∂z, 5), ``dpsi_dtheta`` (6, the parameters of
    ///     ``hylc.PARAMETERS``), ``components`` and ``d2psi_dz2`` (k, k), ``dy_dz`` (k, dofs) and ``dy_dtheta``
    ///     (6, dofs).
    ///
    /// Raises
    /// ------
    /// ValueError
    ///     A bad strain.
    /// MicroError
    ///     The solve did not converge.
    fn sensitivities<'py>(
        &self,
        py: Python<'py>,
        z: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let sol = self.solve(py, z, None)?;
        sol.psi_checked()?;
        sol.all_derivatives(py)
    }

    fn __repr__(&self) -> String {
        format!(
            "MicroProblem({} vertices, {} dofs, tolerance {:e}, max_steps {})",
            self.problem.pattern.len(),
            4 * self.problem.pattern.len(),
            self.problem.options.tolerance,
            self.problem.options.max_steps
        )
    }
}

impl PySolution {
    fn psi_checked(&self) -> HyResult<f64> {
        Ok(self.sol.psi()?)
    }

    fn all_derivatives<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("psi", self.psi_checked()?)?;
        d.set_item("steps", self.sol.steps)?;
        d.set_item("stress", self.stress(py)?)?;
        d.set_item("dpsi_dtheta", self.parameter_derivatives(py)?)?;
        d.set_item("parameter_names", PARAMETER_NAMES.to_vec())?;
        let (names, hess, dy) = self.strain_stiffness(py)?;
        d.set_item("components", names)?;
        d.set_item("d2psi_dz2", hess)?;
        d.set_item("dy_dz", dy)?;
        d.set_item("dy_dtheta", self.equilibrium_sensitivities(py)?)?;
        Ok(d)
    }
}

#[pymethods]
impl PySolution {
    /// "Converged", "Stalled", "MaxSteps" or "TimeLimit".
    #[getter]
    fn status(&self) -> String {
        self.sol.status.to_string()
    }

    /// Whether the solve converged (Ψ̄ is defined).
    #[getter]
    fn converged(&self) -> bool {
        self.sol.psi().is_ok()
    }

    /// Ψ̄ (J/m²) of a converged solve; None otherwise.
    #[getter]
    fn psi(&self) -> Option<f64> {
        self.sol.psi().ok()
    }

    /// The strain (s_x, s_a, s_y, II00, II11).
    #[getter]
    fn strain<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.sol.state.strain.0.to_vec())
    }

    /// Newton steps taken.
    #[getter]
    fn steps(&self) -> usize {
        self.sol.steps
    }

    /// ‖g‖∞ at the end (N).
    #[getter]
    fn gradient_norm(&self) -> f64 {
        self.sol.gradient_norm
    }

    /// Wall time of the solve (s).
    #[getter]
    fn time(&self) -> f64 {
        self.sol.time
    }

    /// The tile's energy parts (J): stretch, bend, twist, contact.
    #[getter]
    fn energy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let e = &self.sol.energy;
        let d = PyDict::new(py);
        d.set_item("stretch", e.stretch)?;
        d.set_item("bend", e.bend)?;
        d.set_item("twist", e.twist)?;
        d.set_item("contact", e.contact)?;
        Ok(d)
    }

    /// Yarn centre-line vertices in world coordinates (home tile), (N, 3) in m.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        to_2d(py, &positions_of(&self.problem, &self.sol))
    }

    /// The unknowns y = (ũ, θ) in the tile's dof layout.
    #[getter]
    fn y<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.sol.state.y.clone())
    }

    /// The homogenized stress ∂Ψ̄/∂z.
    ///
    /// Returns
    /// -------
    /// numpy.ndarray
    ///     (5,): s_x, s_a, s_y, II00, II11 (J/m² per unit strain), NaN for a bending component not available
    ///     under bending along the other axis.
    ///
    /// Raises
    /// ------
    /// MicroError
    ///     The derivatives could not be computed.
    fn stress<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (problem, sol) = (&self.problem, &self.sol);
        let s = detached(py, || stress_of(problem, sol))?;
        Ok(PyArray1::from_vec(py, s.to_vec()))
    }

    /// ∂Ψ̄/∂θ of the yarn parameters (envelope theorem).
    ///
    /// Returns
    /// -------
    /// numpy.ndarray
    ///     (6,): θ = ``hylc.PARAMETERS`` (young, shear, bend_twist_factor, contact_stiffness,
    ///     contact_radius_factor, radius), J/m² per unit parameter.
    ///
    /// Raises
    /// ------
    /// MicroError
    ///     The solve did not converge (Ψ̄ needs an equilibrium).
    fn parameter_derivatives<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (problem, sol) = (&self.problem, &self.sol);
        let d = detached(py, || Ok(parameter_derivatives(problem, sol)?))?;
        Ok(PyArray1::from_vec(py, d.to_vec()))
    }

    /// The second derivatives of Ψ̄ in the strain and the equilibrium's derivative in it.
    ///
    /// Returns
    /// -------
    /// tuple of (list of str, numpy.ndarray, numpy.ndarray)
    ///     The strain components of the state's family (k of them), d²Ψ̄/dz² (k, k) and dy*/dz (k, dofs).
    ///
    /// Raises
    /// ------
    /// MicroError
    ///     The solve did not converge.
    fn strain_stiffness<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Vec<&'static str>, Array<'py>, Array<'py>)> {
        let (problem, sol) = (&self.problem, &self.sol);
        let st = detached(py, || Ok(strain_stiffness(problem, &sol.state)?))?;
        let k = st.components.len();
        let names = st
            .components
            .iter()
            .map(|&i| StrainComponent::NAMES[i])
            .collect();
        let hess: Vec<f64> = (0..k)
            .flat_map(|i| (0..k).map(move |j| (i, j)))
            .map(|(i, j)| st.hessian[(i, j)])
            .collect();
        let nd = st.dy.first().map_or(0, Vec::len);
        let dy: Vec<f64> = st.dy.into_iter().flatten().collect();
        Ok((names, shaped(py, hess, &[k, k]), shaped(py, dy, &[k, nd])))
    }

    /// The equilibrium's derivative in the yarn parameters.
    ///
    /// Returns
    /// -------
    /// numpy.ndarray
    ///     dy*/dθ (6, dofs), one row per parameter of :meth:`parameter_derivatives`.
    ///
    /// Raises
    /// ------
    /// MicroError
    ///     The solve did not converge.
    fn equilibrium_sensitivities<'py>(&self, py: Python<'py>) -> PyResult<Array<'py>> {
        let (problem, sol) = (&self.problem, &self.sol);
        let dy = detached(py, || Ok(equilibrium_sensitivities(problem, sol)?))?;
        let nd = dy.first().map_or(0, Vec::len);
        let rows = dy.len();
        Ok(shaped(py, dy.into_iter().flatten().collect(), &[rows, nd]))
    }

    /// Every derivative at once.
    ///
    /// Returns
    /// -------
    /// Sensitivities
    ///     The dict of :meth:`MicroProblem.sensitivities`.
    ///
    /// Raises
    /// ------
    /// MicroError
    ///     The solve did not converge.
    fn derivatives<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.all_derivatives(py)
    }

    fn __repr__(&self) -> String {
        format!(
            "Solution(z = {}: {} in {} steps; psi = {})",
            self.sol.state.strain,
            self.sol.status,
            self.sol.steps,
            self.sol.psi().map_or("None".into(), |v| format!("{v:.6e}"))
        )
    }
}
