//! The package's exceptions (`glint/errors.py`), raised from Rust.

use glint_scene::SceneError;
use pyo3::prelude::*;

/// An exception of `glint.errors` named `kind`, made with `args`.
fn raise<'py, A: pyo3::call::PyCallArgs<'py>>(py: Python<'py>, kind: &str, args: A) -> PyErr {
    let made = py
        .import("glint.errors")
        .and_then(|m| m.getattr(kind))
        .and_then(|class| class.call1(args));
    match made {
        Ok(exception) => PyErr::from_value(exception),
        Err(e) => e,
    }
}

/// `glint.GlintError(message)`.
pub(crate) fn glint_error(py: Python<'_>, message: &str) -> PyErr {
    raise(py, "GlintError", (message,))
}

/// A scene that could not be loaded: `glint.SceneError` with its file,
/// line, column and field (a file missing when looked for is
/// `FileNotFoundError`, as Python names it).
pub(crate) fn scene_error(py: Python<'_>, error: SceneError) -> PyErr {
    let message = error.to_string();
    match error {
        SceneError::Read { path, source } if source.kind() == std::io::ErrorKind::NotFound => {
            not_found(&path)
        }
        SceneError::Read { path, .. } => raise(
            py,
            "SceneError",
            (
                message,
                path.display().to_string(),
                None::<usize>,
                None::<usize>,
                None::<String>,
            ),
        ),
        SceneError::Invalid {
            file,
            line,
            column,
            field,
            ..
        } => raise(
            py,
            "SceneError",
            (message, file, Some(line), Some(column), field),
        ),
    }
}

/// A missing file, as Python names one (`FileNotFoundError`, errno 2).
pub(crate) fn not_found(path: &std::path::Path) -> PyErr {
    let message = "No such file or directory".to_string();
    pyo3::exceptions::PyFileNotFoundError::new_err((2, message, path.display().to_string()))
}
