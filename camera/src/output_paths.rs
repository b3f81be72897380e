//! Output paths checked before any work: a command that will write a file or
//! a folder finds out now, not after minutes of rendering, that it cannot.

use std::path::Path;

/// The longest file or folder name accepted, in bytes: Linux's `NAME_MAX`,
/// and the limit of most file systems.
pub const MAX_NAME_BYTES: usize = 255;

/// Checks that a file can be written at `path` (atomically, by a temporary
/// file beside it): its folder exists and takes files, its name is not too
/// long, and it is not a folder. Nothing is left behind.
pub fn check_output_file(path: &Path) -> Result<(), String> {
    check_names(path)?;
    if names_a_folder(path) {
        return Err("ends in a slash, which names a folder; expected a file name".into());
    }
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty());
    if let Some(dir) = dir {
        if !dir.is_dir() {
            return Err(format!(
                "the output directory {} does not exist",
                dir.display()
            ));
        }
    }
    if path.is_dir() {
        return Err("is a directory, expected a file name".into());
    }
    probe(dir.unwrap_or(Path::new(".")))
}

/// Checks that files can be written in the folder `dir`: one that exists, or
/// one that can be made (its nearest existing ancestor is a folder that takes
/// files); not a link to nothing, no name too long. Nothing is made.
pub fn check_output_folder(dir: &Path) -> Result<(), String> {
    check_names(dir)?;
    if std::fs::symlink_metadata(dir).is_ok() && !dir.exists() {
        return Err("is a link to nothing; give a folder".into());
    }
    if dir.exists() {
        if !dir.is_dir() {
            return Err("is a file, expected a folder".into());
        }
        return probe(dir);
    }
    let existing = dir
        .ancestors()
        .skip(1)
        .map(|a| {
            if a.as_os_str().is_empty() {
                Path::new(".")
            } else {
                a
            }
        })
        .find(|a| a.exists())
        .unwrap_or(Path::new("."));
    if !existing.is_dir() {
        return Err(format!("cannot be made: {} is a file", existing.display()));
    }
    probe(existing).map_err(|e| format!("cannot be made in {}: {e}", existing.display()))
}

/// Whether `path` ends in a separator (`out/`, `h.png/`): a folder's name,
/// whatever the name before it looks like.
fn names_a_folder(path: &Path) -> bool {
    let text = path.as_os_str().as_encoded_bytes();
    text.last()
        .is_some_and(|&b| b == b'/' || (cfg!(windows) && b == b'\\'))
}

/// Every name along `path` within [`MAX_NAME_BYTES`].
fn check_names(path: &Path) -> Result<(), String> {
    match path
        .components()
        .find(|c| c.as_os_str().len() > MAX_NAME_BYTES)
    {
        Some(long) => Err(format!(
            "a name in it is {} bytes long, more than the limit of {MAX_NAME_BYTES}",
            long.as_os_str().len()
        )),
        None => Ok(()),
    }
}

/// Makes and removes a temporary file in `dir`.
fn probe(dir: &Path) -> Result<(), String> {
    tempfile::Builder::new()
        .prefix(".glint-probe-")
        .tempfile_in(dir)
        .map(drop)
        .map_err(|e| format!("cannot write there: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn files_and_folders_that_cannot_be_written_are_found_before_any_work() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        assert!(check_output_file(&d.join("out.png")).is_ok());
        assert!(check_output_folder(&d.join("new/deeper")).is_ok());
        assert!(!d.join("new").exists(), "nothing is made");
        let long = "x".repeat(300);
        assert!(check_output_file(&d.join(&long))
            .unwrap_err()
            .contains("300 bytes long"));
        assert!(check_output_folder(&d.join(&long).join("a"))
            .unwrap_err()
            .contains("300 bytes long"));
        assert!(check_output_file(&d.join("no/out.png"))
            .unwrap_err()
            .contains("does not exist"));
        assert!(check_output_file(d).unwrap_err().contains("is a directory"));
        // A trailing slash names a folder, even one that does not exist.
        for name in ["h.png/", "st/"] {
            let e = check_output_file(&d.join(name)).unwrap_err();
            assert!(e.contains("ends in a slash"), "{name}: {e}");
        }
        std::fs::write(d.join("file"), "").unwrap();
        assert!(check_output_folder(&d.join("file"))
            .unwrap_err()
            .contains("is a file"));
        assert!(check_output_folder(&d.join("file/sub"))
            .unwrap_err()
            .contains("is a file"));
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(d.join("nowhere"), d.join("dangling")).unwrap();
            assert!(check_output_folder(&d.join("dangling"))
                .unwrap_err()
                .contains("link to nothing"));
        }
        let left: Vec<_> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(left.len(), 2, "only the file and the link: {left:?}");
    }
}
