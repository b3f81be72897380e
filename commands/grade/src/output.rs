//! Output folders (a report, test vectors), checked before any work.

use crate::GradeError;
use std::path::Path;

/// Checks that `dir` (given as `flag`) can take files: a folder, or one
/// that can be made ([`glint_camera::check_output_folder`]).
pub fn check_dir(dir: &Path, flag: &str) -> Result<(), GradeError> {
    glint_camera::check_output_folder(dir)
        .map_err(|e| GradeError::Input(format!("{}: {flag}: {e}", dir.display())))
}

/// Makes `dir`, and the folders it is in, if they do not exist yet.
pub fn make_dir(dir: &Path) -> Result<(), GradeError> {
    std::fs::create_dir_all(dir).map_err(|e| {
        GradeError::Internal(format!("{}: cannot make the folder: {e}", dir.display()))
    })
}

/// Writes `text` to `path` atomically.
pub fn write_text(path: &Path, text: &str) -> Result<(), GradeError> {
    let fail = |e: std::io::Error| GradeError::Internal(format!("{}: {e}", path.display()));
    glint_camera::write_atomically(path, fail, |out| {
        std::io::Write::write_all(out, text.as_bytes()).map_err(fail)
    })
}
