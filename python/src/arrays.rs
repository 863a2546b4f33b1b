//! Arrays in and out: a float64 array of an expected shape from any Python object (a numpy array must already be
//! float64; lists and tuples are converted), and rows of fixed width back to numpy.

use crate::errors::{HyError, HyResult};
use numpy::{PyArray1, PyArray2, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;

/// A float64 array of any shape returned to Python.
pub type Array<'py> = Bound<'py, PyArrayDyn<f64>>;

/// Rows of a float64 array, stored flat.
pub struct Rows {
    pub data: Vec<f64>,
    pub width: usize,
    /// Whether the input was one row (a 1-D array).
    pub single: bool,
}

impl Rows {
    pub fn len(&self) -> usize {
        self.data.len() / self.width
    }

    pub fn row(&self, i: usize) -> &[f64] {
        &self.data[i * self.width..(i + 1) * self.width]
    }

    pub fn iter(&self) -> impl Iterator<Item = &[f64]> {
        self.data.chunks_exact(self.width)
    }
}

/// The rows of a 1-D (one row) or 2-D float64 array whose row width is one of `widths`, checked finite; `name`
/// is the argument (named in every error).
pub fn rows(obj: &Bound<'_, PyAny>, name: &str, widths: &[usize]) -> HyResult<Rows> {
    let py = obj.py();
    let array: Bound<'_, PyArrayDyn<f64>> = match obj.cast::<PyArrayDyn<f64>>() {
        Ok(a) => a.clone(),
        Err(_) => {
            if let Ok(untyped) = obj.cast::<numpy::PyUntypedArray>() {
                return Err(HyError::value(format!(
                    "{name}: expected a float64 array, got dtype {}",
                    untyped.dtype()
                )));
            }
            let np = py
                .import("numpy")
                .map_err(|e| HyError::value(format!("{name}: numpy: {e}")))?;
            let converted = np
                .call_method1("asarray", (obj, "float64"))
                .map_err(|e| HyError::value(format!("{name}: not an array of numbers: {e}")))?;
            converted
                .cast_into::<PyArrayDyn<f64>>()
                .map_err(|e| HyError::value(format!("{name}: {e}")))?
        }
    };
    let ro = array.readonly();
    let view = ro.as_array();
    let shape = view.shape().to_vec();
    let (width, single) = match shape.as_slice() {
        [w] if widths.contains(w) => (*w, true),
        [_, w] if widths.contains(w) => (*w, false),
        _ => {
            let expected: Vec<String> = widths.iter().map(|w| format!("(N, {w})")).collect();
            return Err(HyError::value(format!(
                "{name}: expected shape {}, got {shape:?}",
                expected.join(" or ")
            )));
        }
    };
    let data: Vec<f64> = match view.as_slice() {
        Some(s) => s.to_vec(),
        None => view.iter().copied().collect(),
    };
    if let Some(k) = data.iter().position(|v| !v.is_finite()) {
        return Err(HyError::value(format!(
            "{name}: row {}, column {} is {} (expected finite numbers)",
            k / width,
            k % width,
            data[k]
        )));
    }
    Ok(Rows {
        data,
        width,
        single,
    })
}

/// Rows of equal width as an (N, W) array.
pub fn to_2d<'py, const W: usize>(py: Python<'py>, rows: &[[f64; W]]) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    PyArray1::from_vec(py, flat)
        .reshape([rows.len(), W])
        .expect("the length is N W")
}

/// A flat vector as an array of `shape`.
pub fn shaped<'py>(
    py: Python<'py>,
    flat: Vec<f64>,
    shape: &[usize],
) -> Bound<'py, PyArrayDyn<f64>> {
    PyArray1::from_vec(py, flat)
        .reshape(shape.to_vec())
        .expect("the length is the product of the shape")
}
