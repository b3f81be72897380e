//! Reading images back into a [`Film`]: PNG and JPEG (8- or 16-bit sRGB, decoded
//! to linear), OpenEXR and PFM (linear floats, kept exactly as stored).
//!
//! Unlike texture loading, nothing is cleaned up: NaN, infinite and negative
//! values stay as they are, so that a comparison sees them.

use super::checks::{check_expansion, check_size, regular_file, MAX_LOAD_SIDE};
use super::{srgb_to_linear, Film, FilmError};
use glam::{UVec2, Vec3};
use std::io::{BufReader, Read};
use std::path::Path;
use std::sync::OnceLock;

/// The formats [`Film::load`] reads, chosen by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum InputFormat {
    Png,
    Jpeg,
    Exr,
    Pfm,
    Ppm,
}

impl InputFormat {
    fn from_path(path: &Path) -> Result<Self, FilmError> {
        match super::lowercase_extension(path).as_deref() {
            Some("png") => Ok(Self::Png),
            Some("jpg" | "jpeg") => Ok(Self::Jpeg),
            Some("exr") => Ok(Self::Exr),
            Some("pfm") => Ok(Self::Pfm),
            Some("ppm") => Ok(Self::Ppm),
            _ => Err(FilmError::UnknownInputFormat(path.to_path_buf())),
        }
    }
}

impl Film {
    /// Reads an image file into a film of linear RGB, the format chosen by the
    /// extension (case-insensitive):
    ///
    /// - `.png`, `.jpg`, `.jpeg`: 8- or 16-bit integers, taken to be sRGB-encoded
    ///   and decoded to linear with the exact sRGB curve ([`srgb_to_linear`]);
    ///   grayscale is replicated to RGB, alpha is dropped.
    /// - `.exr`: OpenEXR with R, G and B channels (half or float), linear; alpha
    ///   is dropped.
    /// - `.pfm`: Portable Float Map as [`Film::save`] writes it (`PF`, three
    ///   channels, little-endian, bottom row first); big-endian files (a positive
    ///   scale) and grayscale `Pf` files are read too. Values are multiplied by
    ///   the absolute value of the scale (so ±1.0, as Glint writes, keeps them bit
    ///   for bit).
    /// - `.ppm`: Netpbm PPM, binary (`P6`) or ASCII (`P3`), any maxval up to
    ///   65535: codes taken to be sRGB-encoded, `code / maxval` decoded to linear.
    ///
    /// Float values are kept exactly as stored: NaN, infinite and negative values
    /// are not cleaned up. Images wider or taller than [`MAX_LOAD_SIDE`], or
    /// empty, are refused from their header, before any pixel memory is taken; so
    /// are truncated files. Every error names the file.
    pub fn load(path: &Path) -> Result<Film, FilmError> {
        let format = InputFormat::from_path(path)?;
        let fail = |message: String| FilmError::Read {
            path: path.to_path_buf(),
            message,
        };
        match format {
            InputFormat::Pfm => read_pfm(path).map_err(fail),
            InputFormat::Ppm => super::ppm::read_ppm(path).map_err(fail),
            InputFormat::Png => read_with_image_crate(path, image::ImageFormat::Png).map_err(fail),
            InputFormat::Jpeg => {
                read_with_image_crate(path, image::ImageFormat::Jpeg).map_err(fail)
            }
            InputFormat::Exr => {
                read_with_image_crate(path, image::ImageFormat::OpenExr).map_err(fail)
            }
        }
    }
}

/// How an image file stores its samples: what [`Film::load`] had to undo, and
/// so how much a loaded value can differ from the radiance it was written from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleEncoding {
    /// Integer codes `0..=max_code` of the sRGB curve (PNG, JPEG, PPM): values
    /// were clamped to [0, 1] and rounded to a step of `1 / max_code` in the
    /// encoded domain.
    Srgb { max_code: u32 },
    /// Linear floats (OpenEXR, PFM), kept as written.
    Linear,
}

impl Film {
    /// [`Film::load`], and how the file stored its samples.
    pub fn load_with_encoding(path: &Path) -> Result<(Film, SampleEncoding), FilmError> {
        let format = InputFormat::from_path(path)?;
        let film = Film::load(path)?;
        let encoding = match format {
            InputFormat::Exr | InputFormat::Pfm => SampleEncoding::Linear,
            InputFormat::Ppm => SampleEncoding::Srgb {
                max_code: super::ppm::maxval(path).map_err(|message| FilmError::Read {
                    path: path.to_path_buf(),
                    message,
                })?,
            },
            InputFormat::Png | InputFormat::Jpeg => SampleEncoding::Srgb {
                max_code: integer_max_code(path, format),
            },
        };
        Ok((film, encoding))
    }
}

/// 65535 for a 16-bit PNG, 255 otherwise (JPEG is always 8-bit).
fn integer_max_code(path: &Path, format: InputFormat) -> u32 {
    let sixteen_bit = format == InputFormat::Png
        && open(path)
            .ok()
            .and_then(|r| {
                image::ImageReader::with_format(r, image::ImageFormat::Png)
                    .into_decoder()
                    .ok()
            })
            .is_some_and(|d| {
                use image::ImageDecoder;
                d.color_type().bytes_per_pixel() / d.color_type().channel_count() == 2
            });
    if sixteen_bit {
        65535
    } else {
        255
    }
}

fn open(path: &Path) -> Result<BufReader<std::fs::File>, String> {
    regular_file(path)?;
    std::fs::File::open(path)
        .map(BufReader::new)
        .map_err(|e| e.to_string())
}

/// PNG, JPEG and OpenEXR through the `image` crate: the header first (size
/// check), then the pixels.
fn read_with_image_crate(path: &Path, format: image::ImageFormat) -> Result<Film, String> {
    Ok(from_dynamic(decode(path, format)?))
}

/// The image at `path` decoded by the image crate, its size checked from the
/// header before any pixel memory is taken.
pub(super) fn decode(
    path: &Path,
    format: image::ImageFormat,
) -> Result<image::DynamicImage, String> {
    use image::ImageDecoder;
    let header = image::ImageReader::with_format(open(path)?, format)
        .into_decoder()
        .map_err(|e| e.to_string())?;
    let (w, h) = header.dimensions();
    check_size(w as u64, h as u64)?;
    let file_len = std::fs::metadata(path).map_err(|e| e.to_string())?.len();
    check_expansion(w, h, header.total_bytes(), file_len)?;
    let mut reader = image::ImageReader::with_format(open(path)?, format);
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_LOAD_SIDE);
    limits.max_image_height = Some(MAX_LOAD_SIDE);
    // The side limit already bounds memory (an RGBA float image of the largest
    // size is 4 GiB); the default allocation limit would refuse large renders.
    limits.max_alloc = None;
    reader.limits(limits);
    reader.decode().map_err(|e| e.to_string())
}

/// A decoded image as linear RGB: integers are sRGB, floats linear and kept as is.
fn from_dynamic(decoded: image::DynamicImage) -> Film {
    use image::DynamicImage as D;
    let resolution = UVec2::new(decoded.width(), decoded.height());
    let pixels: Vec<Vec3> = match decoded {
        D::ImageLuma8(_) | D::ImageLumaA8(_) | D::ImageRgb8(_) | D::ImageRgba8(_) => {
            let lut = srgb8_table();
            decoded
                .into_rgb8()
                .pixels()
                .map(|p| Vec3::from_array(p.0.map(|c| lut[c as usize])))
                .collect()
        }
        D::ImageRgb32F(_) | D::ImageRgba32F(_) => decoded
            .into_rgb32f()
            .pixels()
            .map(|p| Vec3::from_array(p.0))
            .collect(),
        // 16-bit integers (PNG), and any other integer layout.
        _ => decoded
            .into_rgb16()
            .pixels()
            .map(|p| Vec3::from_array(p.0.map(|c| srgb_to_linear(c as f32 / 65535.0))))
            .collect(),
    };
    Film { resolution, pixels }
}

fn srgb8_table() -> &'static [f32; 256] {
    static TABLE: OnceLock<[f32; 256]> = OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0)))
}

/// The longest PFM header accepted, in bytes: generous for two sizes and a scale.
const PFM_HEADER_LIMIT: usize = 256;

/// A PFM header: `PF` (RGB) or `Pf` (gray), width, height, scale (negative:
/// little-endian), each separated by whitespace, and one whitespace byte before
/// the pixels.
struct PfmHeader {
    channels: usize,
    width: u32,
    height: u32,
    little_endian: bool,
    scale: f32,
    /// Bytes before the first pixel.
    length: usize,
}

fn parse_pfm_header(bytes: &[u8]) -> Result<PfmHeader, String> {
    let not_pfm = || "not a PFM file: it does not start with PF or Pf".to_string();
    let channels = match bytes.get(..2) {
        Some(b"PF") => 3,
        Some(b"Pf") => 1,
        _ => return Err(not_pfm()),
    };
    let mut pos = 2;
    // The next whitespace-separated token, and the position just after it.
    let mut token = |what: &str| -> Result<String, String> {
        let start = pos
            + bytes[pos..]
                .iter()
                .position(|b| !b.is_ascii_whitespace())
                .ok_or_else(|| format!("the header ends before the {what}"))?;
        if start == pos {
            return Err(format!("the header has no space before the {what}"));
        }
        let len = bytes[start..]
            .iter()
            .position(|b| b.is_ascii_whitespace())
            .ok_or_else(|| format!("the header ends within the {what}"))?;
        pos = start + len;
        String::from_utf8(bytes[start..pos].to_vec())
            .map_err(|_| format!("the {what} in the header is not text"))
    };
    let size = |text: String, what: &str| -> Result<u64, String> {
        text.parse::<u64>()
            .map_err(|_| format!("the {what} in the header is {text:?}, not a whole number"))
    };
    let width = size(token("width")?, "width")?;
    let height = size(token("height")?, "height")?;
    let scale_text = token("scale")?;
    // Exactly one whitespace byte ends the header.
    let length = pos + 1;
    check_size(width, height)?;
    let scale: f32 = scale_text
        .parse()
        .ok()
        .filter(|s: &f32| s.is_finite() && *s != 0.0)
        .ok_or_else(|| {
            format!("the scale in the header is {scale_text:?}, not a non-zero number")
        })?;
    Ok(PfmHeader {
        channels,
        width: width as u32,
        height: height as u32,
        little_endian: scale < 0.0,
        scale: scale.abs(),
        length,
    })
}

fn read_pfm(path: &Path) -> Result<Film, String> {
    regular_file(path)?;
    let mut file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let file_len = file.metadata().map_err(|e| e.to_string())?.len();
    let mut head = Vec::with_capacity(PFM_HEADER_LIMIT);
    (&mut file)
        .take(PFM_HEADER_LIMIT as u64)
        .read_to_end(&mut head)
        .map_err(|e| e.to_string())?;
    let header = parse_pfm_header(&head)?;
    let (w, h) = (header.width as usize, header.height as usize);
    let data_len = (w * h * header.channels * 4) as u64;
    let available = file_len.saturating_sub(header.length as u64);
    if available < data_len {
        return Err(format!(
            "the file is truncated: a {}x{} {} PFM needs {data_len} bytes of pixels, it has {available}",
            header.width,
            header.height,
            if header.channels == 3 { "RGB" } else { "grayscale" },
        ));
    }
    // The header is small, so it was read whole: the pixels start in `head`.
    let mut data = Vec::with_capacity(data_len as usize);
    data.extend_from_slice(&head[header.length.min(head.len())..]);
    data.truncate(data_len as usize);
    let missing = data_len - data.len() as u64;
    (&mut file)
        .take(missing)
        .read_to_end(&mut data)
        .map_err(|e| e.to_string())?;
    if (data.len() as u64) < data_len {
        return Err("the file is truncated (it shrank while being read)".into());
    }
    let value = |bytes: &[u8]| {
        let bytes: [u8; 4] = bytes.try_into().expect("chunks of 4");
        let v = if header.little_endian {
            f32::from_le_bytes(bytes)
        } else {
            f32::from_be_bytes(bytes)
        };
        if header.scale == 1.0 {
            v
        } else {
            v * header.scale
        }
    };
    let mut pixels = Vec::with_capacity(w * h);
    // Rows are stored from the bottom up; the film is top-down.
    for row in data.chunks_exact(w * header.channels * 4).rev() {
        for px in row.chunks_exact(header.channels * 4) {
            pixels.push(if header.channels == 3 {
                Vec3::new(value(&px[0..4]), value(&px[4..8]), value(&px[8..12]))
            } else {
                Vec3::splat(value(px))
            });
        }
    }
    Ok(Film {
        resolution: UVec2::new(header.width, header.height),
        pixels,
    })
}
