//! Reading the files a scene names, with limits: only regular files (a FIFO
//! or a device would never end), and no larger than a documented size, so
//! that what a parse allocates is bounded by a small multiple of it.

use std::path::Path;

/// The largest scene file read, in bytes. A scene file describes shapes and
/// names its meshes and images; it is never near this. Parsing takes at most
/// about 80 times a file's size (a file of one array of a million numbers:
/// 75 MB), so this also bounds what a parse can allocate.
pub const MAX_SCENE_BYTES: u64 = 1 << 20;

/// The largest OBJ or MTL file read, in bytes (about 10 million triangles).
pub const MAX_MESH_BYTES: u64 = 1 << 30;

/// The largest other text document a command reads, in bytes: a class's
/// manifest, a student's answers or explained pixel, a course index.
pub const MAX_DOCUMENT_BYTES: u64 = 16 << 20;

/// Checks that `path` is a regular file of at most `limit` bytes (`what` names
/// it in the message: "the scene file").
pub fn check_regular(path: &Path, limit: u64, what: &str) -> Result<(), String> {
    let meta = std::fs::metadata(path).map_err(|e| e.to_string())?;
    if !meta.is_file() {
        return Err(format!(
            "not a regular file (a folder, FIFO or device); {what} must be a file"
        ));
    }
    if meta.len() > limit {
        return Err(format!(
            "it is {} bytes, more than the limit of {limit} bytes for {what}",
            meta.len()
        ));
    }
    Ok(())
}

/// `bytes` as text, or where its first byte that is not UTF-8 is: the 1-based
/// line and column (in characters) and the byte.
pub fn utf8(bytes: &[u8]) -> Result<&str, (usize, usize, String)> {
    std::str::from_utf8(bytes).map_err(|e| {
        let valid = std::str::from_utf8(&bytes[..e.valid_up_to()]).expect("valid up to here");
        let line = valid.matches('\n').count() + 1;
        let column = valid.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        let byte = bytes[e.valid_up_to()];
        (
            line,
            column,
            format!("the byte 0x{byte:02x} is not UTF-8 text"),
        )
    })
}

/// The text of the regular file `path` of at most `limit` bytes (`what`
/// names it in messages: "a manifest"), UTF-8, or why not, in one line.
pub fn read_text(path: &Path, limit: u64, what: &str) -> Result<String, String> {
    check_regular(path, limit, what)?;
    let bytes = std::fs::read(path).map_err(|e| e.to_string())?;
    match utf8(&bytes) {
        Ok(_) => Ok(String::from_utf8(bytes).expect("checked")),
        Err((line, column, message)) => Err(format!("line {line}, column {column}: {message}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_byte_that_is_not_utf8_is_located() {
        assert_eq!(utf8(b"a = 1\n"), Ok("a = 1\n"));
        let (line, column, message) = utf8(b"a = 1\nb\xc3\xa9 = \xff2\n").unwrap_err();
        assert_eq!((line, column), (2, 6));
        assert_eq!(message, "the byte 0xff is not UTF-8 text");
    }

    #[test]
    fn folders_and_oversized_files_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let e = check_regular(dir.path(), 10, "the scene file").unwrap_err();
        assert!(e.starts_with("not a regular file"), "{e}");
        let file = dir.path().join("a.toml");
        std::fs::write(&file, "0123456789a").unwrap();
        let e = check_regular(&file, 10, "the scene file").unwrap_err();
        assert_eq!(
            e,
            "it is 11 bytes, more than the limit of 10 bytes for the scene file"
        );
        assert!(check_regular(&file, 11, "the scene file").is_ok());
    }
}
