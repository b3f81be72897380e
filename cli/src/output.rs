//! Output paths, checked before any work: a failed check costs nothing, and a
//! run that fails later never leaves a partial file (every writer writes to a
//! temporary file beside the target and renames it into place).

use crate::Failure;
use std::path::Path;

/// Checks that `path` can be written: its directory exists, it is not itself a
/// directory, and we may create files there (probed with a temporary file that is
/// removed at once, so an interrupted run leaves nothing behind).
pub(crate) fn check_writable(path: &Path) -> Result<(), Failure> {
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty());
    if let Some(dir) = dir {
        if !dir.is_dir() {
            return Err(Failure::Input(format!(
                "{}: the output directory {} does not exist",
                path.display(),
                dir.display()
            )));
        }
    }
    if path.is_dir() {
        return Err(Failure::Input(format!(
            "{}: is a directory, expected an image file name",
            path.display()
        )));
    }
    tempfile::Builder::new()
        .prefix(".glint-probe-")
        .tempfile_in(dir.unwrap_or(Path::new(".")))
        .map_err(|e| {
            Failure::Input(format!(
                "{}: cannot write to the output directory: {e}",
                path.display()
            ))
        })?;
    Ok(())
}

/// Writes `text` to `path` atomically.
pub(crate) fn write_text(path: &Path, text: &str) -> Result<(), Failure> {
    use std::io::Write;
    let fail = |e: std::io::Error| Failure::Other(format!("{}: {e}", path.display()));
    glint_camera::write_atomically(path, fail, |out| {
        out.write_all(text.as_bytes()).map_err(fail)
    })
}
