//! Netpbm PPM, the format most first ray tracers write: `P6` (binary) and `P3`
//! (ASCII), any `maxval` from 1 to 65535, `#` comments in the header. Samples
//! are sRGB-encoded codes `0..=maxval`, decoded to linear with the exact curve.
//!
//! Written by hand rather than through the `image` crate: its PNM decoder keeps
//! raw codes instead of scaling by `maxval`, so a file with `maxval` 1000 would
//! read as the wrong colours.

use super::checks::{check_size, regular_file};
use super::{srgb_to_linear, Film};
use glam::{UVec2, Vec3};
use std::io::Read;
use std::path::Path;

/// The longest PPM header accepted, in bytes: room for comments.
const HEADER_LIMIT: usize = 4096;

/// A PPM header: magic, size, maxval, and the bytes before the first sample.
#[derive(Debug, PartialEq)]
struct Header {
    ascii: bool,
    width: u32,
    height: u32,
    maxval: u32,
    length: usize,
}

/// The largest code of the file at `path`, from its header: what an 8-bit
/// PPM's quantisation step is relative to.
pub(super) fn maxval(path: &Path) -> Result<u32, String> {
    regular_file(path)?;
    let mut head = Vec::with_capacity(HEADER_LIMIT);
    std::fs::File::open(path)
        .map_err(|e| e.to_string())?
        .take(HEADER_LIMIT as u64)
        .read_to_end(&mut head)
        .map_err(|e| e.to_string())?;
    Ok(parse_header(&head)?.maxval)
}

fn parse_header(bytes: &[u8]) -> Result<Header, String> {
    let ascii = match bytes.get(..2) {
        Some(b"P6") => false,
        Some(b"P3") => true,
        _ => {
            return Err(
                "not a colour PPM file: it does not start with P6 (binary) or P3 (ASCII)".into(),
            )
        }
    };
    let mut pos = 2;
    let mut number = |what: &str| -> Result<u64, String> {
        pos = skip_space_and_comments(bytes, pos)
            .ok_or_else(|| format!("the header ends before the {what}"))?;
        let digits = bytes[pos..]
            .iter()
            .take_while(|b| b.is_ascii_digit())
            .count();
        if digits == 0 {
            let found = bytes[pos..].iter().take(12).map(|&b| b as char);
            return Err(format!(
                "the {what} in the header is {:?}, not a whole number",
                found.collect::<String>()
            ));
        }
        let text = std::str::from_utf8(&bytes[pos..pos + digits]).expect("ASCII digits");
        pos += digits;
        text.parse::<u64>()
            .map_err(|_| format!("the {what} in the header, {text}, is too large"))
    };
    let width = number("width")?;
    let height = number("height")?;
    let maxval = number("maxval")?;
    check_size(width, height)?;
    if !(1..=65535).contains(&maxval) {
        return Err(format!(
            "the maxval in the header is {maxval}; expected 1 to 65535"
        ));
    }
    // Exactly one whitespace byte ends the header.
    match bytes.get(pos) {
        Some(b) if b.is_ascii_whitespace() => {}
        _ => return Err("the header does not end with a space or newline after maxval".into()),
    }
    Ok(Header {
        ascii,
        width: width as u32,
        height: height as u32,
        maxval: maxval as u32,
        length: pos + 1,
    })
}

/// The position of the next byte that is neither whitespace nor in a `#`
/// comment (which runs to the end of its line), if there is one.
fn skip_space_and_comments(bytes: &[u8], mut pos: usize) -> Option<usize> {
    loop {
        match bytes.get(pos)? {
            b'#' => pos += bytes[pos..].iter().position(|&b| b == b'\n')?,
            b if b.is_ascii_whitespace() => pos += 1,
            _ => return Some(pos),
        }
    }
}

pub(super) fn read_ppm(path: &Path) -> Result<Film, String> {
    regular_file(path)?;
    let mut file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let file_len = file.metadata().map_err(|e| e.to_string())?.len();
    let mut head = Vec::with_capacity(HEADER_LIMIT);
    (&mut file)
        .take(HEADER_LIMIT as u64)
        .read_to_end(&mut head)
        .map_err(|e| e.to_string())?;
    let header = parse_header(&head)?;
    let samples = header.width as u64 * header.height as u64 * 3;
    let available = file_len.saturating_sub(header.length as u64);
    // Binary samples take one or two bytes each; ASCII ones at least a digit
    // and a separator (the last one's may be missing).
    let needed = match (header.ascii, header.maxval > 255) {
        (false, false) => samples,
        (false, true) => 2 * samples,
        (true, _) => 2 * samples - 1,
    };
    if available < needed {
        return Err(format!(
            "the file is truncated: a {}x{} {} PPM needs at least {needed} bytes of samples, it has {available}",
            header.width,
            header.height,
            if header.ascii { "ASCII (P3)" } else { "binary (P6)" },
        ));
    }
    let mut data = head.split_off(header.length.min(head.len()));
    file.read_to_end(&mut data).map_err(|e| e.to_string())?;
    let codes = match header.ascii {
        true => ascii_samples(&data, samples as usize)?,
        false => binary_samples(&data, samples as usize, header.maxval > 255)?,
    };
    let maxval = header.maxval as f32;
    let mut pixels = Vec::with_capacity(samples as usize / 3);
    for (i, rgb) in codes.chunks_exact(3).enumerate() {
        if let Some(&code) = rgb.iter().find(|&&c| c as u32 > header.maxval) {
            let (x, y) = (i as u32 % header.width, i as u32 / header.width);
            return Err(format!(
                "pixel ({x}, {y}) has the sample {code}, above the maxval {}",
                header.maxval
            ));
        }
        pixels.push(Vec3::from_array(std::array::from_fn(|c| {
            // Divided, not multiplied by 1/maxval: the same bits as the PNG reader.
            srgb_to_linear(rgb[c] as f32 / maxval)
        })));
    }
    Ok(Film {
        resolution: UVec2::new(header.width, header.height),
        pixels,
    })
}

fn binary_samples(data: &[u8], count: usize, wide: bool) -> Result<Vec<u16>, String> {
    let bytes = if wide { 2 * count } else { count };
    if data.len() < bytes {
        return Err("the file is truncated (it shrank while being read)".into());
    }
    Ok(match wide {
        true => data[..bytes]
            .chunks_exact(2)
            .map(|b| u16::from_be_bytes([b[0], b[1]]))
            .collect(),
        false => data[..bytes].iter().map(|&b| b as u16).collect(),
    })
}

fn ascii_samples(data: &[u8], count: usize) -> Result<Vec<u16>, String> {
    let mut codes = Vec::with_capacity(count);
    let mut pos = 0;
    while codes.len() < count {
        pos = skip_space_and_comments(data, pos)
            .ok_or_else(|| format!("the file ends after {} of its {count} samples", codes.len()))?;
        let digits = data[pos..]
            .iter()
            .take_while(|b| b.is_ascii_digit())
            .count();
        let text = std::str::from_utf8(&data[pos..pos + digits]).expect("ASCII digits");
        let code = text.parse::<u16>().map_err(|_| {
            let found: String = data[pos..].iter().take(12).map(|&b| b as char).collect();
            format!(
                "sample {} is {found:?}, not a whole number from 0 to 65535",
                codes.len()
            )
        })?;
        codes.push(code);
        pos += digits;
    }
    Ok(codes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_with_comments_and_both_magics_parse() {
        let h = parse_header(b"P6\n# made by a student\n3 2 # size\n255\n\x01").unwrap();
        assert_eq!(
            h,
            Header {
                ascii: false,
                width: 3,
                height: 2,
                maxval: 255,
                length: 38,
            }
        );
        let h = parse_header(b"P3 1 1 1000 1 2 3").unwrap();
        assert!(h.ascii);
        assert_eq!((h.maxval, h.length), (1000, 12));
    }

    #[test]
    fn bad_headers_say_what_is_wrong() {
        let e = |bytes: &[u8]| parse_header(bytes).unwrap_err();
        assert!(e(b"P5\n1 1\n255\n").contains("P6 (binary) or P3"));
        assert!(e(b"P6\n1 x\n255\n").contains("height in the header is \"x\\n255\\n\""));
        assert!(e(b"P6\n1 1\n0\n").contains("maxval in the header is 0"));
        assert!(e(b"P6\n1 1\n70000\n").contains("expected 1 to 65535"));
        assert!(e(b"P6\n0 1\n255\n").contains("no pixels"));
        assert!(e(b"P6\n99999 1\n255\n").contains("larger than the limit"));
        assert!(e(b"P6\n1 1\n255").contains("does not end with a space"));
        assert!(e(b"P6\n# no end").contains("ends before the width"));
    }
}
