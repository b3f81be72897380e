//! Writing an export so that it is never seen half-written: the XML and the
//! assets folder are written into a temporary folder beside the output and
//! renamed into place when complete; a failure leaves what was there before.

use super::convert::{Conversion, SideContents};
use super::ExportError;
use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The file inside an assets folder that marks it as written by an export
/// (and so replaceable by the next one).
const MARKER: &str = ".glint-export";

/// The folder beside `out` for the files its XML refers to: `OUT-assets`
/// (`scene.xml` → `scene-assets`).
pub fn assets_folder(out: &Path) -> PathBuf {
    let stem = out.file_stem().unwrap_or_default().to_string_lossy();
    out.with_file_name(format!("{stem}-assets"))
}

fn directory_of(out: &Path) -> &Path {
    match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Checks, before any work, that `out` can be written: a `.xml` name, in a
/// directory that exists, not a directory itself, and no assets folder in the
/// way that an export did not write.
pub fn check_output(out: &Path) -> Result<(), ExportError> {
    let bad = |path: &Path, message: String| ExportError::Output {
        path: path.to_path_buf(),
        message,
    };
    let is_xml = out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("xml"));
    if !is_xml {
        return Err(bad(
            out,
            "expected a .xml file name for the Mitsuba scene".into(),
        ));
    }
    let dir = directory_of(out);
    if !dir.is_dir() {
        return Err(bad(
            out,
            format!("the output directory {} does not exist", dir.display()),
        ));
    }
    if out.is_dir() {
        return Err(bad(out, "is a directory, expected a .xml file name".into()));
    }
    let folder = assets_folder(out);
    if folder.symlink_metadata().is_ok() {
        if !folder.is_dir() || folder.is_symlink() {
            return Err(bad(
                &folder,
                format!(
                    "is in the way of the folder {} would refer to (not a folder); move it or choose another output name",
                    out.display()
                ),
            ));
        }
        if !folder.join(MARKER).is_file() {
            return Err(bad(
                &folder,
                format!(
                    "exists and was not written by glint export, which would replace it with {}'s \
                     meshes, images and environment; move it or choose another output name",
                    out.display()
                ),
            ));
        }
    }
    Ok(())
}

/// A folder removed (with what is left in it) when dropped.
struct TempFolder(PathBuf);

impl TempFolder {
    fn new_in(dir: &Path) -> std::io::Result<Self> {
        let pid = std::process::id();
        for n in 0u32.. {
            let path = dir.join(format!(".glint-export-{pid}-{n}"));
            match fs::create_dir(&path) {
                Ok(()) => return Ok(Self(path)),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && n < 10_000 => continue,
                Err(e) => return Err(e),
            }
        }
        unreachable!("the loop returns")
    }
}

impl Drop for TempFolder {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}

fn write_file(path: &Path, bytes: &[u8]) -> Result<(), ExportError> {
    let fail = |source| ExportError::Write {
        path: path.to_path_buf(),
        source,
    };
    let mut file = fs::File::create(path).map_err(fail)?;
    file.write_all(bytes).map_err(fail)?;
    file.sync_all().map_err(fail)
}

/// Writes the XML to `out` and the side files to `folder`, atomically.
pub(super) fn write(out: &Path, folder: &Path, conversion: &Conversion) -> Result<(), ExportError> {
    let dir = directory_of(out);
    let temp = TempFolder::new_in(dir).map_err(|e| ExportError::Output {
        path: out.to_path_buf(),
        message: format!("cannot write to the output directory: {e}"),
    })?;
    let new_folder = temp.0.join("assets");
    if !conversion.files.is_empty() {
        let fail = |source| ExportError::Write {
            path: folder.to_path_buf(),
            source,
        };
        fs::create_dir(&new_folder).map_err(fail)?;
        write_file(
            &new_folder.join(MARKER),
            format!(
                "Written by glint export --mitsuba for {}; the next export replaces this folder.\n",
                out.file_name().unwrap_or_default().to_string_lossy()
            )
            .as_bytes(),
        )?;
        for file in &conversion.files {
            let path = new_folder.join(&file.name);
            match &file.contents {
                SideContents::Bytes(bytes) => write_file(&path, bytes)?,
                SideContents::Exr(film) => film.save(&path).map_err(|e| ExportError::Write {
                    path: folder.join(&file.name),
                    source: std::io::Error::other(e.to_string()),
                })?,
            }
        }
    }
    let new_xml = temp.0.join("scene.xml");
    write_file(&new_xml, conversion.xml.as_bytes())?;
    if let Ok(existing) = fs::metadata(out) {
        // A replaced file keeps its permissions.
        let _ = fs::set_permissions(&new_xml, existing.permissions());
    }

    // Into place: the folder first (keeping the old one until the XML is in).
    let fail = |path: &Path| {
        let path = path.to_path_buf();
        move |source| ExportError::Write { path, source }
    };
    let previous = temp.0.join("previous");
    let had_folder = !conversion.files.is_empty() && folder.is_dir();
    if !conversion.files.is_empty() {
        if had_folder {
            fs::rename(folder, &previous).map_err(fail(folder))?;
        }
        if let Err(e) = fs::rename(&new_folder, folder) {
            if had_folder {
                let _ = fs::rename(&previous, folder);
            }
            return Err(fail(folder)(e));
        }
    }
    if let Err(e) = fs::rename(&new_xml, out) {
        if !conversion.files.is_empty() {
            let _ = fs::rename(folder, temp.0.join("failed"));
            if had_folder {
                let _ = fs::rename(&previous, folder);
            }
        }
        return Err(fail(out)(e));
    }
    if let Ok(dir) = fs::File::open(dir) {
        let _ = dir.sync_all();
    }
    Ok(())
}
