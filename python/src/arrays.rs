//! Rendered pixels handed to numpy: each `Vec` becomes the array's buffer, without a copy.

use numpy::ndarray::{Array2, Array3};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::render::{Pixels, RenderedView};

/// A `dict` of output name → array for one view.
pub fn view_dict<'py>(py: Python<'py>, view: RenderedView) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    for (kind, pixels) in view {
        dict.set_item(kind.name(), pixels_to_array(py, pixels)?)?;
    }
    Ok(dict)
}

fn shape_error(e: impl std::fmt::Display) -> PyErr {
    pyo3::exceptions::PyRuntimeError::new_err(format!("internal error: array shape: {e}"))
}

fn pixels_to_array(py: Python<'_>, pixels: Pixels) -> PyResult<Bound<'_, PyAny>> {
    Ok(match pixels {
        Pixels::U8(data, [h, w, c]) => Array3::from_shape_vec((h, w, c), data)
            .map_err(shape_error)?
            .into_pyarray(py)
            .into_any(),
        Pixels::F32(data, [h, w, 1]) => Array2::from_shape_vec((h, w), data)
            .map_err(shape_error)?
            .into_pyarray(py)
            .into_any(),
        Pixels::F32(data, [h, w, c]) => Array3::from_shape_vec((h, w, c), data)
            .map_err(shape_error)?
            .into_pyarray(py)
            .into_any(),
        Pixels::U32(data, [h, w, c]) => Array3::from_shape_vec((h, w, c), data)
            .map_err(shape_error)?
            .into_pyarray(py)
            .into_any(),
    })
}
