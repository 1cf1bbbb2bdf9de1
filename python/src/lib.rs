//! `kantele._kantele`: the Python extension module behind the `kantele` package (see
//! `python/kantele/__init__.py`). It wraps the public API of `kantele` and `kantele-scene`: scenes
//! load through the same loaders and render through the same backends as the `kantele` command.

mod arrays;
mod camera;
mod errors;
mod files;
mod mesh_arrays;
mod render;
mod scene;

use std::ffi::CString;
use std::path::PathBuf;

use kantele::simd::Isa;
use pyo3::exceptions::PyRuntimeWarning;
use pyo3::prelude::*;

use camera::PyCamera;
use scene::PyScene;

/// Loads a glTF 2.0 (`.gltf`, `.glb`), OBJ, PLY or STL file into a `Scene` (the arguments as
/// `Scene.load`'s).
#[pyfunction]
#[pyo3(signature = (path, shading = "auto", environment = None, environment_intensity = 1.0, environment_rotation = 0.0, exposure = 0.0, tonemap = "pbr-neutral", *, scene = None, variant = None, animation = None, time = 0.0, cull = None))]
#[allow(clippy::too_many_arguments)]
fn load(
    py: Python<'_>,
    path: PathBuf,
    shading: &str,
    environment: Option<PathBuf>,
    environment_intensity: f32,
    environment_rotation: f32,
    exposure: f32,
    tonemap: &str,
    scene: Option<scene::NameOrIndex>,
    variant: Option<String>,
    animation: Option<scene::NameOrIndex>,
    time: f32,
    cull: Option<&str>,
) -> PyResult<PyScene> {
    let options = scene::shading_options(
        shading,
        environment,
        environment_intensity,
        environment_rotation,
        exposure,
        tonemap,
    )?;
    let options = scene::choice_options(options, scene, variant, animation, time, cull)?;
    PyScene::load_path(py, path, options)
}

/// The instruction set the CPU renderer uses in this process (`avx512`, `avx2`, `sse41`,
/// `sse2`, `neon` or `scalar`): the best one this CPU has, or the one `KANTELE_ISA` names.
#[pyfunction]
fn isa() -> &'static str {
    Isa::selected().name()
}

/// Runs the `kantele` command on `args` (its name first) and returns its exit status, with the
/// GIL released: the package's `kantele` console script (`kantele/_cli.py`) is this call.
#[pyfunction]
fn _run_cli(py: Python<'_>, args: Vec<std::ffi::OsString>) -> u8 {
    py.detach(|| kantele_cli::run_command_line(args))
}

/// Warns (`RuntimeWarning`, once, at import) when `KANTELE_ISA` names no instruction set or one
/// this CPU lacks; renders then use the best level, as the `kantele` command does.
fn warn_about_isa_env(py: Python<'_>) -> PyResult<()> {
    let message = match Isa::env_warning() {
        // The message names the variable already.
        Err(problem) => format!("{problem}; using {}", Isa::best()),
        Ok(Some(warning)) => warning,
        Ok(None) => return Ok(()),
    };
    // An environment variable holds no NUL byte, so neither does the message.
    let message = CString::new(message).unwrap_or_default();
    let category = py.get_type::<PyRuntimeWarning>();
    PyErr::warn(py, category.as_any(), &message, 1)
}

/// The extension module.
#[pymodule]
fn _kantele(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyScene>()?;
    m.add_class::<PyCamera>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(files::write_png, m)?)?;
    m.add_function(wrap_pyfunction!(isa, m)?)?;
    m.add_function(wrap_pyfunction!(_run_cli, m)?)?;
    m.add("MAX_SIZE", kantele::MAX_TARGET_SIZE)?;
    m.add(
        "OUTPUTS",
        render::OutputKind::ALL
            .iter()
            .map(|(n, _)| *n)
            .collect::<Vec<_>>(),
    )?;
    warn_about_isa_env(m.py())
}
