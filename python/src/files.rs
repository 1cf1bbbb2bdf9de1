//! Writing images from Python with the CLI's writers (`kantele_output::output`).

use std::path::PathBuf;

use numpy::{PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::exceptions::PyOSError;
use pyo3::prelude::*;

use crate::errors::value_error;

/// Writes an 8-bit RGBA image (`uint8` (H, W, 4), row 0 at the top, e.g. the `color` output)
/// as PNG, atomically, with the encoder `kantele render` uses.
#[pyfunction]
pub fn write_png(py: Python<'_>, path: PathBuf, image: PyReadonlyArray3<'_, u8>) -> PyResult<()> {
    let shape = image.shape().to_vec();
    if shape[2] != 4 {
        return Err(value_error(format!(
            "{}: expected an (H, W, 4) uint8 image, got {} channels",
            path.display(),
            shape[2]
        )));
    }
    let (Ok(w), Ok(h)) = (u32::try_from(shape[1]), u32::try_from(shape[0])) else {
        return Err(value_error(format!("{}: image too large", path.display())));
    };
    let data: Vec<u8> = match image.as_slice() {
        Ok(slice) => slice.to_vec(),
        Err(_) => image.as_array().iter().copied().collect(),
    };
    py.detach(|| kantele_output::output::write_png_rgba8(&path, w, h, &data))
        .map_err(|e| PyOSError::new_err(e.to_string()))
}
