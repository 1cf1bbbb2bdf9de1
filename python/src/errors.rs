//! Library errors as Python exceptions, with the library's one-line messages.

use pyo3::exceptions::{
    PyFileNotFoundError, PyOSError, PyPermissionError, PyRuntimeError, PyValueError,
};
use pyo3::PyErr;

use kantele::error::RenderError;
use kantele_scene::LoadError;

/// A loader error: unreadable files are `OSError` (`FileNotFoundError` when missing), malformed
/// or unknown files are `ValueError`.
pub fn load_error(error: LoadError) -> PyErr {
    let message = error.to_string();
    match &error {
        LoadError::Io { source, .. } if source.kind() == std::io::ErrorKind::NotFound => {
            PyFileNotFoundError::new_err(message)
        }
        LoadError::Io { .. } => PyOSError::new_err(message),
        _ => PyValueError::new_err(message),
    }
}

/// An error reading `path`: `FileNotFoundError` when it is missing, `PermissionError` when it may
/// not be read, else `OSError`, with the one-line message `PATH: problem`.
pub fn io_error(path: &std::path::Path, error: std::io::Error) -> PyErr {
    let message = format!("{}: {error}", path.display());
    match error.kind() {
        std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(message),
        std::io::ErrorKind::PermissionDenied => PyPermissionError::new_err(message),
        _ => PyOSError::new_err(message),
    }
}

/// A render error: a backend that cannot run (no GL driver, ...) is `RuntimeError`; anything
/// about the request or the scene is `ValueError`.
pub fn render_error(error: RenderError) -> PyErr {
    match &error {
        RenderError::Backend { .. } | RenderError::OutOfMemory { .. } => {
            PyRuntimeError::new_err(error.to_string())
        }
        _ => PyValueError::new_err(error.to_string()),
    }
}

/// A `ValueError` with `message`.
pub fn value_error(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}
