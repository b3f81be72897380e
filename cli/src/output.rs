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

/// A heat map's path, before any work: a .png name, in a writable directory,
/// and not one of `inputs` (the images being compared).
pub(crate) fn check_heatmap_path(path: &Path, inputs: &[&Path]) -> Result<(), Failure> {
    let is_png = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !is_png {
        return Err(Failure::Input(format!(
            "{}: a heat map is written as PNG; expected a .png extension",
            path.display()
        )));
    }
    check_writable(path)?;
    if let Ok(target) = path.canonicalize() {
        if inputs
            .iter()
            .any(|input| input.canonicalize().is_ok_and(|i| i == target))
        {
            return Err(Failure::Input(format!(
                "{}: is one of the images being compared; choose another heat map file",
                path.display()
            )));
        }
    }
    Ok(())
}
