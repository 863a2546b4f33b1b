//! Patterns: load (a `.pyp` file or a generated kind), generate, save, summary, and the reference state (C1).

use crate::convert::report;
use crate::errors::{detached, HyError};
use crate::yarn::yarn_of;
use hylc::micro::reference::Construction;
use hylc::workflow::inputs::{load_pattern as load_arg, reference_of};
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// A periodic yarn pattern (one tile): vertex positions, yarns, periods and radius.
///
/// Made by :func:`load_pattern`, :func:`read_pyp`, :func:`generate` or :func:`reference_state`; ``len(p)`` is
/// the number of vertices (= edges).
#[pyclass(module = "hylc", name = "Pattern", frozen)]
#[derive(Clone)]
pub struct PyPattern {
    pub inner: hylc::pattern::Pattern,
    /// How it was named (a file or a generated kind); construction defaults follow it.
    pub source: String,
    notes: Vec<String>,
}

impl PyPattern {
    pub fn new(inner: hylc::pattern::Pattern, source: &str, notes: Vec<String>) -> Self {
        PyPattern {
            inner,
            source: source.to_string(),
            notes,
        }
    }
}

/// A pattern argument: a `Pattern`, or a `.pyp` path or generated kind as `hylc solve PATTERN` takes it.
pub fn pattern_of(obj: &Bound<'_, PyAny>) -> PyResult<PyPattern> {
    if let Ok(p) = obj.cast::<PyPattern>() {
        return Ok(p.get().clone());
    }
    let arg: PathBuf = obj.extract().map_err(|_| {
        HyError::value("pattern: expected a Pattern, a .pyp path or a generated kind")
    })?;
    load_pattern(obj.py(), arg)
}

#[pymethods]
impl PyPattern {
    /// Number of vertices (= edges) of the tile.
    fn __len__(&self) -> usize {
        self.inner.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "Pattern({:?}: {} vertices, {} yarns, periods {:?} m, radius {} m)",
            self.source,
            self.inner.len(),
            self.inner.yarns().len(),
            self.inner.periods,
            self.inner.radius
        )
    }

    /// Where the pattern came from: the file or generated kind.
    #[getter]
    fn source(&self) -> &str {
        &self.source
    }

    /// Notes from loading (the file's warnings, or periods replaced by the implied ones).
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.notes.clone()
    }

    /// Tile periods (p₁, p₂) in m.
    #[getter]
    fn periods(&self) -> (f64, f64) {
        (self.inner.periods[0], self.inner.periods[1])
    }

    /// Yarn radius r in m.
    #[getter]
    fn radius(&self) -> f64 {
        self.inner.radius
    }

    /// Vertex positions in the tile, (N, 3) in m.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let rows: Vec<[f64; 3]> = self
            .inner
            .positions
            .iter()
            .map(|v| [v.x, v.y, v.z])
            .collect();
        crate::arrays::to_2d(py, &rows)
    }

    /// Rest lengths of the edges (edge i leaves vertex i), (N,) in m.
    #[getter]
    fn rest_lengths(&self) -> Vec<f64> {
        self.inner.edges.iter().map(|e| e.rest_length).collect()
    }

    /// The yarns as lists of vertex indices, in order along each yarn.
    fn yarns(&self) -> Vec<Vec<usize>> {
        self.inner.yarns()
    }

    /// Write the pattern as a ``.pyp`` file (exact round trip).
    ///
    /// Parameters
    /// ----------
    /// path : path-like
    ///     The file to write.
    ///
    /// Raises
    /// ------
    /// PatternError
    ///     The file cannot be written.
    fn save(&self, path: PathBuf) -> PyResult<()> {
        self.inner.save_pyp(&path).map_err(HyError::from)?;
        Ok(())
    }

    /// The summary ``hylc pattern FILE`` prints, as a dict.
    ///
    /// Returns
    /// -------
    /// PatternSummary
    ///     ``vertices``, ``periods``, ``radius``, ``yarns`` (per yarn ``vertices``, ``first``,
    ///     ``rest_length``), ``crossing_x``, ``crossing_y`` (edges crossing the tile's sides),
    ///     ``total_rest_length``, ``total_current_length`` and ``notes``.
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let p = &self.inner;
        let d = PyDict::new(py);
        d.set_item("vertices", p.len())?;
        d.set_item("periods", (p.periods[0], p.periods[1]))?;
        d.set_item("radius", p.radius)?;
        let yarns = p.yarns();
        let mut rest_total = 0.0;
        let mut cur_total = 0.0;
        let mut list = Vec::new();
        for y in &yarns {
            let rest: f64 = y.iter().map(|&v| p.edges[v].rest_length).sum();
            let cur: f64 = y.iter().map(|&v| p.edge_vector(v).norm()).sum();
            rest_total += rest;
            cur_total += cur;
            let e = PyDict::new(py);
            e.set_item("vertices", y.len())?;
            e.set_item("first", y[0])?;
            e.set_item("rest_length", rest)?;
            list.push(e);
        }
        d.set_item("yarns", list)?;
        d.set_item(
            "crossing_x",
            p.edges.iter().filter(|e| e.offset[0] != 0).count(),
        )?;
        d.set_item(
            "crossing_y",
            p.edges.iter().filter(|e| e.offset[1] != 0).count(),
        )?;
        d.set_item("total_rest_length", rest_total)?;
        d.set_item("total_current_length", cur_total)?;
        d.set_item("notes", self.notes.clone())?;
        Ok(d)
    }
}

/// Load a pattern as the micro commands do.
///
/// Parameters
/// ----------
/// pattern : str or path-like
///     A ``.pyp`` file (used at the periods its rest lengths imply; ``notes`` says when they were replaced) or
///     a generated kind (plain, twill, satin, basket, stockinette).
///
/// Returns
/// -------
/// Pattern
///
/// Raises
/// ------
/// FileNotFoundError
///     A ``.pyp`` file that does not exist.
/// PatternError
///     A file that is not a valid pattern.
/// ValueError
///     Neither a file nor a generated kind.
#[pyfunction]
pub fn load_pattern(py: Python<'_>, pattern: PathBuf) -> PyResult<PyPattern> {
    let arg = pattern.display().to_string();
    let loaded = detached(py, || Ok(load_arg(&arg)?))?;
    let notes = loaded.note(&arg).into_iter().collect();
    Ok(PyPattern::new(loaded.pattern, &arg, notes))
}

/// Read a ``.pyp`` file strictly, as ``hylc pattern FILE`` does.
///
/// Parameters
/// ----------
/// path : path-like
///     The ``.pyp`` file.
///
/// Returns
/// -------
/// Pattern
///     At the file's periods; its checks' warnings are in ``notes``.
///
/// Raises
/// ------
/// FileNotFoundError
///     The file does not exist.
/// PatternError
///     The file is not a valid pattern (the message names the line).
#[pyfunction]
pub fn read_pyp(py: Python<'_>, path: PathBuf) -> PyResult<PyPattern> {
    let (p, warnings) = detached(py, || Ok(hylc::pattern::Pattern::load_pyp(&path)?))?;
    let notes = warnings.iter().map(|w| w.to_string()).collect();
    Ok(PyPattern::new(p, &path.display().to_string(), notes))
}

/// Generate a pattern, as ``hylc generate KIND`` does.
///
/// Parameters
/// ----------
/// kind : str
///     plain, twill, satin, basket or stockinette.
/// n : int, optional
///     The twill repeat (4), satin repeat (5) or basket group size (2).
/// step : int, optional
///     The satin move (2).
/// vertices_per_radius : float, default 1.0
///     Vertices per yarn radius of arclength.
///
/// Returns
/// -------
/// Pattern
///
/// Raises
/// ------
/// PatternError
///     An unknown kind or bad parameters.
#[pyfunction]
#[pyo3(signature = (kind, n=None, step=None, vertices_per_radius=1.0))]
pub fn generate(
    py: Python<'_>,
    kind: &str,
    n: Option<usize>,
    step: Option<usize>,
    vertices_per_radius: f64,
) -> PyResult<PyPattern> {
    let p = detached(py, || {
        hylc::generate::generate_kind(kind, n, step, vertices_per_radius).map_err(|e| {
            HyError::new(
                crate::errors::Kind::Pattern,
                format!("generate {kind}: {e}"),
            )
        })
    })?;
    Ok(PyPattern::new(p, kind, Vec::new()))
}

/// The reference state of a pattern (Algorithm C1), as ``hylc reference`` computes it.
///
/// The stress-free state, the tension, the zero-stress periods and the centring.
///
/// Parameters
/// ----------
/// pattern : Pattern, str or path-like
///     A Pattern, a ``.pyp`` file or a generated kind.
/// construction : {"knitted", "woven"}, optional
///     Selects the tension factors; generated kinds know theirs, a file needs it.
/// yarn : dict, path-like or None
///     Yarn parameters (as :class:`MicroProblem` takes them).
/// equilibrate_only : bool, default False
///     Skip the stress-free state and the tension.
///
/// Returns
/// -------
/// tuple of (Pattern, dict)
///     The reference state and C1's report (``psi``, ``periods_out``, ...).
///
/// Raises
/// ------
/// ValueError
///     An unknown construction, or a file without one.
/// MicroError
///     A solve of C1 failed.
#[pyfunction]
#[pyo3(signature = (pattern, construction=None, yarn=None, equilibrate_only=false))]
pub fn reference_state<'py>(
    py: Python<'py>,
    pattern: &Bound<'py, PyAny>,
    construction: Option<&str>,
    yarn: Option<&Bound<'py, PyAny>>,
    equilibrate_only: bool,
) -> PyResult<(PyPattern, Bound<'py, PyAny>)> {
    let p = pattern_of(pattern)?;
    let yarn = yarn_of(yarn)?;
    let given = match construction {
        None => None,
        Some("knitted" | "knit") => Some(Construction::Knitted),
        Some("woven" | "weave") => Some(Construction::Woven),
        Some(other) => {
            return Err(HyError::value(format!(
                "construction: expected \"knitted\" or \"woven\", got {other:?}"
            ))
            .into())
        }
    };
    let (q, rep, _) = detached(py, || {
        Ok(reference_of(
            &p.source,
            &p.inner,
            &yarn,
            given,
            equilibrate_only,
        )?)
    })?;
    Ok((PyPattern::new(q, &p.source, Vec::new()), report(py, &rep)?))
}
