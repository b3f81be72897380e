//! Writing a file so that it is never seen half-written: the bytes go to a
//! temporary file beside the target, which is flushed to disk and then renamed
//! over it. A failed or interrupted write leaves any existing file as it was.
//! A command that writes several files stages each ([`stage_atomically`])
//! and puts them in place only when all are written, so that a failure in
//! the last leaves the first as it was too.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Writes `path` through `write`, atomically. The new file gets the permissions
/// of the file it replaces, or those of any new file (the umask's), not the
/// owner-only ones of a temporary file. `write` fails with the caller's own
/// error type; `io_error` turns the file operations' errors into it.
pub fn write_atomically<E>(
    path: &Path,
    io_error: impl Fn(std::io::Error) -> E,
    write: impl FnOnce(&mut BufWriter<&mut File>) -> Result<(), E>,
) -> Result<(), E> {
    stage_atomically(path, &io_error, write)?
        .persist()
        .map_err(io_error)
}

/// A file written beside its target, not yet in its place: dropped, it is
/// removed and the target stays as it was.
#[must_use = "a staged file is removed unless it is persisted"]
pub struct StagedFile {
    tmp: tempfile::NamedTempFile,
    path: PathBuf,
}

impl StagedFile {
    /// Renames the file over its target.
    pub fn persist(self) -> std::io::Result<()> {
        self.tmp.persist(&self.path).map(drop).map_err(|e| e.error)
    }
}

/// [`write_atomically`] up to the rename: the written file, flushed to disk
/// beside `path`, to be put in place by [`StagedFile::persist`].
pub fn stage_atomically<E>(
    path: &Path,
    io_error: impl Fn(std::io::Error) -> E,
    write: impl FnOnce(&mut BufWriter<&mut File>) -> Result<(), E>,
) -> Result<StagedFile, E> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".glint-").suffix(".partial");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut tmp = builder.tempfile_in(dir).map_err(&io_error)?;
    if let Ok(existing) = std::fs::metadata(path) {
        tmp.as_file()
            .set_permissions(existing.permissions())
            .map_err(&io_error)?;
    }
    {
        let mut out = BufWriter::new(tmp.as_file_mut());
        write(&mut out)?;
        out.flush().map_err(&io_error)?;
    }
    tmp.as_file().sync_all().map_err(&io_error)?;
    Ok(StagedFile {
        tmp,
        path: path.to_owned(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_write_keeps_the_old_file_and_leaves_nothing_behind() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        let io = |e: std::io::Error| e.to_string();
        let put =
            |bytes: &'static [u8]| write_atomically(&path, io, |w| w.write_all(bytes).map_err(io));
        put(b"first").unwrap();
        let failed = write_atomically(&path, io, |w| {
            w.write_all(b"partial").map_err(io)?;
            Err("the encoder failed".to_owned())
        });
        assert_eq!(failed.unwrap_err(), "the encoder failed");
        assert_eq!(std::fs::read(&path).unwrap(), b"first");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        put(b"second").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"second");
    }

    #[test]
    fn a_staged_file_takes_its_place_only_when_persisted() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        std::fs::write(&path, b"old").unwrap();
        let io = |e: std::io::Error| e.to_string();
        let staged = stage_atomically(&path, io, |w| w.write_all(b"new").map_err(io)).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        drop(staged);
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            1,
            "nothing left"
        );
        let staged = stage_atomically(&path, io, |w| w.write_all(b"new").map_err(io)).unwrap();
        staged.persist().unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
    }
}
