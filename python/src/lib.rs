//! `kantele._kantele`: the Python extension module behind the `kantele` package (see
//! `python/kantele/__init__.py`). It wraps the public API of `kantele` and `kantele-io`: scenes
//! load through the same loaders and render through the same backends as the `kantele` command.

mod arrays;
mod camera;
mod errors;
mod files;
mod mesh_arrays;
mod render;
mod scene;

use std::path::PathBuf;

use pyo3::prelude::*;

use camera::PyCamera;
use scene::PyScene;

/// Loads a glTF 2.0 (`.gltf`, `.glb`) or OBJ file into a `Scene`.
#[pyfunction]
fn load(py: Python<'_>, path: PathBuf) -> PyResult<PyScene> {
    PyScene::load_path(py, path)
}

/// The extension module.
#[pymodule]
fn _kantele(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyScene>()?;
    m.add_class::<PyCamera>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(files::write_png, m)?)?;
    m.add("MAX_SIZE", kantele::MAX_TARGET_SIZE)?;
    m.add(
        "OUTPUTS",
        render::OutputKind::ALL
            .iter()
            .map(|(n, _)| *n)
            .collect::<Vec<_>>(),
    )?;
    Ok(())
}
