//! Writing images to files from Python (`kantele.write_png`).
// TODO(output): use kantele_io::output once the shared writers are on main.

use std::path::PathBuf;

use numpy::{PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::exceptions::PyOSError;
use pyo3::prelude::*;

use crate::errors::value_error;

/// Writes an 8-bit RGBA or RGB image (`uint8` (H, W, 4) or (H, W, 3), row 0 at the top) as PNG.
#[pyfunction]
pub fn write_png(py: Python<'_>, path: PathBuf, image: PyReadonlyArray3<'_, u8>) -> PyResult<()> {
    let shape = image.shape().to_vec();
    let color = match shape[2] {
        4 => image::ExtendedColorType::Rgba8,
        3 => image::ExtendedColorType::Rgb8,
        c => {
            return Err(value_error(format!(
                "{}: expected an (H, W, 3 or 4) uint8 image, got {c} channels",
                path.display()
            )))
        }
    };
    let (Ok(w), Ok(h)) = (u32::try_from(shape[1]), u32::try_from(shape[0])) else {
        return Err(value_error(format!("{}: image too large", path.display())));
    };
    let data = image.as_array().iter().copied().collect::<Vec<u8>>();
    py.detach(|| image::save_buffer_with_format(&path, &data, w, h, color, image::ImageFormat::Png))
        .map_err(|e| PyOSError::new_err(format!("{}: {e}", path.display())))
}
