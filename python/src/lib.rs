//! The `hylc` Python module (the guide's Python chapter, docs/python.md): patterns, micro solves and their
//! sensitivities, sampling plans and sample files, materials and fitting, cloth scenes, the derivative harness,
//! with numpy arrays in and out. The Python package `hylc` (`python/hylc/__init__.py`) re-exports
//! everything here. Every entry point releases the GIL while the library works, turns a panic into
//! `hylc.InternalError` and a library error into the exception class of `errors`, with the command line's message;
//! the long calls (`progress`) poll Ctrl-C and report progress from the calling thread.

mod arrays;
mod checks;
mod cloth;
mod convert;
mod errors;
mod gradient;
mod material;
mod micro;
mod pattern;
mod progress;
mod sample;
mod scene;
mod yarn;

use pyo3::prelude::*;

/// Test hook: panics inside the boundary, which must raise `hylc.InternalError` (never abort the interpreter).
#[pyfunction]
fn _panic_at_the_boundary(py: Python<'_>) -> PyResult<()> {
    errors::detached(py, || -> errors::HyResult<()> {
        panic!("a panic raised on purpose")
    })
}

#[pymodule]
fn _hylc(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    m.add_class::<pattern::PyPattern>()?;
    m.add_class::<micro::PyMicroProblem>()?;
    m.add_class::<micro::PySolution>()?;
    m.add_class::<material::PyMaterial>()?;
    m.add_function(wrap_pyfunction!(pattern::load_pattern, m)?)?;
    m.add_function(wrap_pyfunction!(pattern::read_pyp, m)?)?;
    m.add_function(wrap_pyfunction!(pattern::generate, m)?)?;
    m.add_function(wrap_pyfunction!(pattern::reference_state, m)?)?;
    m.add_function(wrap_pyfunction!(yarn::yarn_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(yarn::load_yarn, m)?)?;
    m.add_function(wrap_pyfunction!(yarn::save_yarn, m)?)?;
    m.add_function(wrap_pyfunction!(material::fit, m)?)?;
    m.add_function(wrap_pyfunction!(sample::plan, m)?)?;
    m.add_function(wrap_pyfunction!(sample::plan_samples, m)?)?;
    m.add_function(wrap_pyfunction!(sample::sample, m)?)?;
    m.add_function(wrap_pyfunction!(checks::check_derivatives, m)?)?;
    m.add_function(wrap_pyfunction!(scene::load_scene, m)?)?;
    m.add_function(wrap_pyfunction!(cloth::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(gradient::gradient, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_at_the_boundary, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
