//! Output folders (a report, test vectors), checked before any work.

use crate::GradeError;
use std::path::Path;

/// Checks that `dir` (given as `flag`) can take files: a folder, or a name
/// whose parent folder exists, where files can be made (probed with a
/// temporary file that is removed at once).
pub fn check_dir(dir: &Path, flag: &str) -> Result<(), GradeError> {
    let input = |m: String| GradeError::Input(format!("{}: {flag}: {m}", dir.display()));
    if dir.exists() && !dir.is_dir() {
        return Err(input("not a folder".into()));
    }
    let probe_in = if dir.is_dir() {
        dir.to_owned()
    } else {
        let parent = dir.parent().filter(|p| !p.as_os_str().is_empty());
        let parent = parent.unwrap_or(Path::new("."));
        if !parent.is_dir() {
            return Err(input(format!(
                "the folder it would be made in, {}, does not exist",
                parent.display()
            )));
        }
        parent.to_owned()
    };
    tempfile::Builder::new()
        .prefix(".glint-probe-")
        .tempfile_in(&probe_in)
        .map_err(|e| input(format!("cannot write there: {e}")))?;
    Ok(())
}

/// Makes `dir` if it does not exist yet.
pub fn make_dir(dir: &Path) -> Result<(), GradeError> {
    if dir.is_dir() {
        return Ok(());
    }
    std::fs::create_dir(dir).map_err(|e| {
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
