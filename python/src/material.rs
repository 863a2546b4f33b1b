//! Materials: load and save the JSON, ψ/∇ψ/∇²ψ over an (N, 6) array of strains z = (s_x, s_a, s_y, II00, II01,
//! II11), and fitting a material to a sample file (Algorithm C5, `hylc fit`).

use crate::arrays::{rows, shaped, Array, Rows};
use crate::convert::report as report_to_py;
use crate::errors::{detached, HyError, HyResult, Kind};
use hylc::fit::FitPreset;
use hylc::material::synthetic::default_material;
use hylc::material::{Material, PsiVgh};
use hylc::workflow::fit::{fit_samples, FitJob};
use pyo3::prelude::*;
use std::path::PathBuf;
use std::time::Instant;

/// A fitted energy density ψ(z) of the cloth (J/m²) as a function of the strain z = (s_x, s_a, s_y, II00, II01,
/// II11).
///
/// Made by :meth:`Material.load`, :meth:`Material.default` or :func:`fit`; ``psi``, ``gradient``, ``hessian``
/// and ``eval`` take one strain (6,) or a batch (N, 6).
#[pyclass(module = "hylc", name = "Material", frozen)]
pub struct PyMaterial {
    inner: Material,
}

/// Evaluate `f` at every row of `z`, each checked as `hylc material --z` checks it (finite, within the
/// admissible range: the error names the row).
fn each<T: Send>(
    py: Python<'_>,
    m: &Material,
    z: &Rows,
    f: impl Fn(PsiVgh) -> T + Sync + Send,
) -> PyResult<Vec<T>> {
    detached(py, || {
        z.iter()
            .enumerate()
            .map(|(i, r)| {
                let z6: &[f64; 6] = r.try_into().expect("rows of 6");
                m.eval_checked(z6)
                    .map(&f)
                    .map_err(|e| HyError::value(format!("z: strain #{}: {e}", i + 1)))
            })
            .collect::<HyResult<Vec<T>>>()
    })
}

impl PyMaterial {
    /// The strains of argument `z`: (6,) or (N, 6), and the leading shape of the results.
    fn strains(z: &Bound<'_, PyAny>) -> HyResult<(Rows, Vec<usize>)> {
        let r = rows(z, "z", &[6])?;
        let lead = if r.single { vec![] } else { vec![r.len()] };
        Ok((r, lead))
    }
}

#[pymethods]
impl PyMaterial {
    /// Read a material JSON file (the original HYLC format).
    ///
    /// Parameters
    /// ----------
    /// path : path-like
    ///     The material file.
    ///
    /// Returns
    /// -------
    /// Material
    ///
    /// Raises
    /// ------
    /// FileNotFoundError
    ///     The file does not exist.
    /// MaterialError
    ///     The file is not a valid material (the message names the field).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let inner = detached(py, || Ok(Material::load(&path)?))?;
        Ok(PyMaterial { inner })
    }

    /// The embedded default material (``hylc material default``).
    ///
    /// Returns
    /// -------
    /// Material
    #[staticmethod]
    fn default() -> Self {
        PyMaterial {
            inner: default_material(),
        }
    }

    /// Write the material as JSON.
    ///
    /// Parameters
    /// ----------
    /// path : path-like
    ///     The file to write.
    ///
    /// Raises
    /// ------
    /// MaterialError
    ///     The file cannot be written.
    fn save(&self, path: PathBuf) -> PyResult<()> {
        self.inner.save(&path).map_err(|e| {
            HyError::from_library(Kind::Material, &e)
                .with_prefix(&format!("{}: cannot write: ", path.display()))
        })?;
        Ok(())
    }

    /// Areal density ρ_A (kg/m²).
    #[getter]
    fn density(&self) -> f64 {
        self.inner.density
    }

    /// |z_k| limits of the admissible range.
    #[getter]
    fn admissible_limits(&self) -> Vec<f64> {
        self.inner.admissible_limits().to_vec()
    }

    /// ψ at each strain.
    ///
    /// Parameters
    /// ----------
    /// z : array_like
    ///     (6,) or (N, 6) strains (s_x, s_a, s_y, II00, II01, II11), float64.
    ///
    /// Returns
    /// -------
    /// float or numpy.ndarray
    ///     A float for (6,), an (N,) array for (N, 6).
    ///
    /// Raises
    /// ------
    /// ValueError
    ///     Another shape or dtype, a value not finite or outside the admissible range (the row is named).
    fn psi<'py>(&self, py: Python<'py>, z: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let (z, lead) = Self::strains(z)?;
        let v = each(py, &self.inner, &z, |r| r.value)?;
        if z.single {
            return Ok(v[0].into_pyobject(py)?.into_any());
        }
        Ok(shaped(py, v, &lead).into_any())
    }

    /// ∇ψ at each strain.
    ///
    /// Parameters
    /// ----------
    /// z : array_like
    ///     (6,) or (N, 6) strains.
    ///
    /// Returns
    /// -------
    /// numpy.ndarray
    ///     (6,) or (N, 6).
    ///
    /// Raises
    /// ------
    /// ValueError
    ///     As :meth:`psi`.
    fn gradient<'py>(&self, py: Python<'py>, z: &Bound<'py, PyAny>) -> PyResult<Array<'py>> {
        let (z, mut lead) = Self::strains(z)?;
        let v = each(py, &self.inner, &z, |r| r.grad)?;
        lead.push(6);
        Ok(shaped(py, v.into_iter().flatten().collect(), &lead))
    }

    /// ∇²ψ at each strain.
    ///
    /// Parameters
    /// ----------
    /// z : array_like
    ///     (6,) or (N, 6) strains.
    ///
    /// Returns
    /// -------
    /// numpy.ndarray
    ///     (6, 6) or (N, 6, 6).
    ///
    /// Raises
    /// ------
    /// ValueError
    ///     As :meth:`psi`.
    fn hessian<'py>(&self, py: Python<'py>, z: &Bound<'py, PyAny>) -> PyResult<Array<'py>> {
        let (z, mut lead) = Self::strains(z)?;
        let v = each(py, &self.inner, &z, |r| r.hess)?;
        lead.extend([6, 6]);
        Ok(shaped(
            py,
            v.into_iter().flatten().flatten().collect(),
            &lead,
        ))
    }

    /// (ψ, ∇ψ, ∇²ψ) at each strain in one pass.
    ///
    /// Parameters
    /// ----------
    /// z : array_like
    ///     (6,) or (N, 6) strains.
    ///
    /// Returns
    /// -------
    /// tuple
    ///     As :meth:`psi`, :meth:`gradient` and :meth:`hessian` return them.
    ///
    /// Raises
    /// ------
    /// ValueError
    ///     As :meth:`psi`.
    fn eval<'py>(
        &self,
        py: Python<'py>,
        z: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyAny>, Array<'py>, Array<'py>)> {
        let (z, lead) = Self::strains(z)?;
        let v = each(py, &self.inner, &z, |r| r)?;
        let psi = if z.single {
            v[0].value.into_pyobject(py)?.into_any()
        } else {
            shaped(py, v.iter().map(|r| r.value).collect(), &lead).into_any()
        };
        let mut gs = lead.clone();
        gs.push(6);
        let grad = shaped(py, v.iter().flat_map(|r| r.grad).collect(), &gs);
        let mut hs = lead;
        hs.extend([6, 6]);
        let hess = shaped(
            py,
            v.iter()
                .flat_map(|r| r.hess.into_iter().flatten())
                .collect(),
            &hs,
        );
        Ok((psi, grad, hess))
    }

    /// Benchmark helper: seconds a plain Rust loop takes for ψ (`Material::value`) at each row of an (N, 6)
    /// array already in Rust memory, and the sum of the values (so the loop is not optimised away).
    fn _rust_loop_psi(&self, py: Python<'_>, z: &Bound<'_, PyAny>) -> PyResult<(f64, f64)> {
        let (z, _) = Self::strains(z)?;
        let zs: Vec<[f64; 6]> = z.iter().map(|r| r.try_into().expect("rows of 6")).collect();
        let m = &self.inner;
        detached(py, || {
            let t = Instant::now();
            let mut sum = 0.0;
            for z in &zs {
                sum += m.value(std::hint::black_box(z));
            }
            Ok((t.elapsed().as_secs_f64(), sum))
        })
    }
}

/// Fit a material to a sample file (Algorithm C5), as ``hylc fit SAMPLES`` does.
///
/// Parameters
/// ----------
/// samples : path-like
///     A sample file made by :func:`sample` or ``hylc sample`` (its sidecar gives the plan and the density).
/// out : path-like, optional
///     The material JSON to write (default SAMPLES with extension ``.material.json``).
/// report : path-like, optional
///     The JSON fit report to write (default ``.fit.json``).
/// plots : path-like, optional
///     A folder for the PNG plots (none without it).
/// plan : str, optional
///     The plan (name or file) when the sample file has no sidecar.
/// density : float, optional
///     The areal density (kg/m²) when the sample file has no sidecar.
/// preset : {"covering", "design", "design-stockinette"}, default "covering"
///     The fit's settings, as ``hylc fit --preset`` takes them (``covering`` is ``hylc run``'s).
/// knots_1d, knots_2d : int, optional
///     The preset's knot counts changed.
///
/// Returns
/// -------
/// tuple of (Material, FitReport)
///     The fitted material and the fit report (the content of the report file).
///
/// Raises
/// ------
/// FileNotFoundError
///     The sample file does not exist.
/// ValueError
///     An unknown preset; a sample file without samples.
/// FitError
///     The fit failed.
#[pyfunction]
#[pyo3(signature = (samples, out=None, report=None, plots=None, plan=None, density=None, preset="covering", knots_1d=None, knots_2d=None))]
#[allow(clippy::too_many_arguments)]
pub fn fit<'py>(
    py: Python<'py>,
    samples: PathBuf,
    out: Option<PathBuf>,
    report: Option<PathBuf>,
    plots: Option<PathBuf>,
    plan: Option<String>,
    density: Option<f64>,
    preset: &str,
    knots_1d: Option<usize>,
    knots_2d: Option<usize>,
) -> PyResult<(PyMaterial, Bound<'py, PyAny>)> {
    let preset: FitPreset = preset
        .parse()
        .map_err(|e: String| HyError::new(Kind::Value, format!("preset: {e}")))?;
    if !samples.exists() {
        return Err(HyError::new(
            Kind::NotFound,
            format!("samples: {}: no such sample file", samples.display()),
        )
        .into());
    }
    let beside = FitJob::beside(&samples);
    let mut options = preset.options();
    options.n_knots_1d = knots_1d.unwrap_or(options.n_knots_1d);
    options.n_knots_2d = knots_2d.unwrap_or(options.n_knots_2d);
    let job = FitJob {
        out: out.unwrap_or(beside.out),
        report: report.unwrap_or(beside.report),
        write_plots: plots.is_some(),
        plots: plots.unwrap_or(beside.plots),
        plan,
        density,
        options,
        ..beside
    };
    let (rep, material) = detached(py, || {
        let rep = fit_samples(&job, &mut |_| {})?;
        let material = Material::load(&job.out)?;
        Ok((rep, material))
    })?;
    Ok((PyMaterial { inner: material }, report_to_py(py, &rep)?))
}
