//! What every image reader checks before it takes pixel memory: the file is
//! a regular file, its size is within the limits, and its header does not
//! claim more pixels than the file could hold.

use std::path::Path;

/// The largest image side [`Film::load`](super::Film::load) accepts, in pixels (the largest film
/// Glint renders).
pub const MAX_LOAD_SIDE: u32 = 16384;

/// The most an image's pixels may take over its file's size. Deflate (PNG,
/// OpenEXR's ZIP) expands data at most about 1032 times, and the other
/// codecs less: a header that claims more pixels than its file could hold is
/// refused before any pixel memory is taken.
pub const MAX_EXPANSION: u64 = 2048;

/// Refuses a `width × height` image whose `decoded` bytes are more than
/// [`MAX_EXPANSION`] times the file's `file_len`.
pub(super) fn check_expansion(
    width: u32,
    height: u32,
    decoded: u64,
    file_len: u64,
) -> Result<(), String> {
    if decoded > MAX_EXPANSION.saturating_mul(file_len.max(1)) {
        return Err(format!(
            "the header says {width}x{height} pixels ({decoded} bytes decoded), more than a file of {file_len} bytes can hold"
        ));
    }
    Ok(())
}

/// Refuses an image with no pixels or a side over [`MAX_LOAD_SIDE`].
pub(super) fn check_size(width: u64, height: u64) -> Result<(), String> {
    if width == 0 || height == 0 {
        return Err(format!("the image is {width}x{height}: it has no pixels"));
    }
    let max = MAX_LOAD_SIDE as u64;
    if width > max || height > max {
        return Err(format!(
            "the image is {width}x{height}, larger than the limit of {MAX_LOAD_SIDE} pixels a side"
        ));
    }
    Ok(())
}

/// Refuses what is not a regular file: a FIFO or a device would never end.
pub(super) fn regular_file(path: &Path) -> Result<(), String> {
    match std::fs::metadata(path) {
        Ok(meta) if !meta.is_file() => {
            Err("not a regular file (a folder, FIFO or device); an image must be a file".into())
        }
        Ok(_) => Ok(()),
        Err(e) => Err(e.to_string()),
    }
}
