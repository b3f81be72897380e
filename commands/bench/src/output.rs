//! Writing result files: each goes to a temporary file beside its target and is
//! renamed into place, so a failed or interrupted bench never leaves a partial
//! file and never destroys the previous one.

use std::io::Write;
use std::path::Path;

/// Writes `bytes` to `path` atomically (temporary file, then rename), with the
/// permissions of an ordinary new file.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let fail = |e: std::io::Error| format!("{}: {e}", path.display());
    glint_camera::write_atomically(path, fail, |out| out.write_all(bytes).map_err(fail))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_whole_files_and_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        write_atomically(&path, b"first").unwrap();
        write_atomically(&path, b"second").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"second");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        let missing = dir.path().join("no-such-dir").join("out.txt");
        assert!(write_atomically(&missing, b"x")
            .unwrap_err()
            .contains("out.txt"));
    }
}
