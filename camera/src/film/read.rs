//! Reading image files back into a [`Film`], whatever wrote them: PNG (8 and
//! 16 bit, RGB, gray, palette, with or without alpha), JPEG, BMP, TGA, Netpbm
//! (PPM, PGM, PBM, PAM; binary and ASCII, any maxval), Radiance HDR, OpenEXR
//! (half and float) and PFM. The format is told by the file's content, not its
//! name ([`FileFormat::sniff`]); every format but PFM is decoded by the `image`
//! crate.
//!
//! Integer formats are taken to be sRGB-encoded and decoded to linear with the
//! exact curve; float formats are kept as stored: NaN, infinite and negative
//! values stay, so that a comparison sees them. [`Film::read`] also says what
//! the file did to the radiance it was written from ([`SampleEncoding`]: the
//! step its values were rounded to, found from the data), whether it had an
//! alpha channel that is not opaque, and whether it was gray or a palette:
//! what a grader needs to allow for.

use super::checks::{check_expansion, check_size, regular_file, MAX_LOAD_SIDE};
use super::depth::CodeSet;
use super::formats::{header_layout, FileFormat, Layout};
use super::{srgb_to_linear, Film, FilmError};
use glam::{UVec2, Vec3};
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

/// How an image file stores its samples: what reading it had to undo, and so
/// how far a loaded value may lie from the radiance it was written from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleEncoding {
    /// Integer codes of the sRGB curve: values were clamped to [0, 1] and
    /// rounded, per channel (R, G, B), to `levels` steps in the encoded
    /// domain: the coarsest step the data shows, which may be coarser than
    /// the `stored` codes the file holds (8-bit data in a 16-bit PNG).
    Srgb { levels: [u32; 3], stored: u32 },
    /// Linear floats with `mantissa_bits` bits of mantissa (23 for 32-bit
    /// floats, 10 for OpenEXR's half).
    Float { mantissa_bits: u32 },
    /// Radiance RGBE: three 8-bit mantissas sharing one exponent, so each
    /// channel is rounded to 1/256 of the pixel's largest power of two.
    SharedExponent,
}

/// A file's alpha channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AlphaChannel {
    Absent,
    /// Every pixel fully opaque: nothing is lost by dropping it.
    Opaque,
    /// `pixels` pixels are not fully opaque; the film holds their colour
    /// channels as stored.
    Translucent {
        pixels: u64,
    },
}

/// An image file as [`Film::read`] found it.
#[derive(Clone, Debug)]
pub struct ImageFile {
    /// The colour channels, linear (a gray file's one channel in all three).
    pub film: Film,
    pub format: FileFormat,
    pub encoding: SampleEncoding,
    pub alpha: AlphaChannel,
    /// The file holds one gray channel.
    pub gray: bool,
    /// The file's pixels are indices into a colour map (a palette).
    pub indexed: bool,
    /// What the header says of the layout.
    layout: Layout,
    /// The file's extension, where it names another format than its content.
    pub misnamed: Option<String>,
}

impl ImageFile {
    /// What the file was read as, in words: "PNG, 16-bit RGB, values on
    /// 8-bit steps", "PPM (P3), maxval 1023", "OpenEXR, half float, alpha
    /// below 1 in 12 pixels", "TGA, 24-bit RGB, RLE (named .png)".
    pub fn description(&self) -> String {
        self.description_with(&[])
    }

    /// [`ImageFile::description`] with `details` of the format that the
    /// caller knows (a JPEG's quality and subsampling) after its layout.
    pub fn description_with(&self, details: &[String]) -> String {
        let mut parts = vec![self.layout.label.clone()];
        let channels = match (self.gray, self.indexed) {
            (_, true) => Some("palette"),
            (true, _) => Some("gray"),
            _ if self.layout.bits.is_some() => Some("RGB"),
            _ => None,
        };
        let bits = self.layout.bits.map(|b| format!("{b}-bit"));
        let words: Vec<String> = bits.into_iter().chain(channels.map(String::from)).collect();
        if !words.is_empty() {
            parts.push(words.join(" "));
        }
        parts.extend(self.layout.extras.iter().cloned());
        parts.extend(details.iter().cloned());
        match self.encoding {
            SampleEncoding::Srgb { stored, .. } if self.format == FileFormat::Pnm => {
                parts.push(format!("maxval {stored}"))
            }
            _ => {}
        }
        match self.encoding {
            SampleEncoding::Srgb { levels, stored } if levels.iter().any(|&l| l != stored) => {
                parts.push(format!("values on {}", steps_text(levels)))
            }
            SampleEncoding::Float { mantissa_bits: 10 } => parts.push("half float".into()),
            _ => {}
        }
        match self.alpha {
            AlphaChannel::Absent => {}
            AlphaChannel::Opaque => parts.push("opaque alpha".into()),
            AlphaChannel::Translucent { pixels } => {
                parts.push(format!("alpha below 1 in {pixels} pixels"))
            }
        }
        let mut text = parts.join(", ");
        if let Some(extension) = &self.misnamed {
            text += &format!(" (named .{extension})");
        }
        text
    }
}

/// "8-bit steps", "32 levels", or one per channel when they differ.
fn steps_text(levels: [u32; 3]) -> String {
    let one = |l: u32| match l {
        255 => "8-bit steps".to_string(),
        65535 => "16-bit steps".to_string(),
        l => format!("{} levels", l + 1),
    };
    if levels.iter().all(|&l| l == levels[0]) {
        one(levels[0])
    } else {
        format!(
            "{}, {} and {} (R, G, B)",
            one(levels[0]),
            one(levels[1]),
            one(levels[2])
        )
    }
}

impl Film {
    /// Reads an image file into a film of linear RGB, with what the file did
    /// to the values it was written from ([`ImageFile`]). The format is told
    /// by the content; TGA, which has no magic bytes, by its `.tga` name.
    ///
    /// - Integer formats (PNG, JPEG, BMP, TGA, Netpbm): codes taken to be
    ///   sRGB-encoded, `code / max` decoded to linear with the exact curve
    ///   ([`srgb_to_linear`]); a Netpbm file's `max` is its maxval. Gray is
    ///   replicated to RGB; alpha is dropped (and reported in
    ///   [`ImageFile::alpha`]); a palette is looked up. PNG's colour chunks
    ///   (gAMA, sRGB, iCCP) are ignored: the values are taken as sRGB.
    /// - OpenEXR (R, G, B, half or float), Radiance HDR (divided by its
    ///   EXPOSURE, if any) and PFM: linear floats kept as stored. PFM is read
    ///   as [`Film::save`] writes it (`PF`, little-endian, bottom row first),
    ///   and big-endian and gray (`Pf`) files too, multiplied by the absolute
    ///   value of the scale (±1.0, as Glint writes, keeps them bit for bit).
    ///
    /// Images wider or taller than [`MAX_LOAD_SIDE`], empty, or whose header
    /// claims more pixels than the file could hold, are refused before any
    /// pixel memory is taken; so are truncated files. Every error names the file.
    pub fn read(path: &Path) -> Result<ImageFile, FilmError> {
        let fail = |message: String| FilmError::Read {
            path: path.to_path_buf(),
            message,
        };
        let (head, tail) = ends(path).map_err(fail)?;
        let format = match FileFormat::sniff(&head, &tail) {
            Ok(format) => format,
            Err(_) if FileFormat::from_extension(path) == Some(FileFormat::Tga) => FileFormat::Tga,
            Err(message) => return Err(fail(message)),
        };
        let mut file = match format {
            FileFormat::Pfm => read_pfm(path).map(|film| ImageFile {
                film,
                format,
                encoding: SampleEncoding::Float { mantissa_bits: 23 },
                alpha: AlphaChannel::Absent,
                gray: false,
                indexed: false,
                layout: Layout {
                    label: format.name().into(),
                    ..Layout::default()
                },
                misnamed: None,
            }),
            _ => read_with_image_crate(path, format, &head),
        }
        .map_err(fail)?;
        file.misnamed = super::lowercase_extension(path)
            .filter(|_| FileFormat::from_extension(path).is_some_and(|f| f != format));
        Ok(file)
    }

    /// [`Film::read`]'s film alone.
    pub fn load(path: &Path) -> Result<Film, FilmError> {
        Ok(Film::read(path)?.film)
    }
}

/// The first and last bytes of the file at `path` (for its magic and a TGA
/// footer).
fn ends(path: &Path) -> Result<(Vec<u8>, Vec<u8>), String> {
    const SPAN: u64 = 64;
    regular_file(path)?;
    let mut file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let mut head = Vec::new();
    (&mut file)
        .take(SPAN)
        .read_to_end(&mut head)
        .map_err(|e| e.to_string())?;
    let len = file.metadata().map_err(|e| e.to_string())?.len();
    let mut tail = Vec::new();
    if len > SPAN {
        file.seek(SeekFrom::Start(len - SPAN.min(len)))
            .map_err(|e| e.to_string())?;
        file.read_to_end(&mut tail).map_err(|e| e.to_string())?;
    }
    Ok((head, tail))
}

fn open(path: &Path) -> Result<BufReader<std::fs::File>, String> {
    regular_file(path)?;
    std::fs::File::open(path)
        .map(BufReader::new)
        .map_err(|e| e.to_string())
}

/// Every format but PFM, through the `image` crate: the header first (size
/// check), then the pixels.
fn read_with_image_crate(
    path: &Path,
    format: FileFormat,
    head: &[u8],
) -> Result<ImageFile, String> {
    let decoded = decode(path, format)?;
    let layout = header_layout(format, head);
    let (film, codes, alpha, gray) = pixels(decoded, stored_max(path, format)?);
    let encoding = match codes {
        // A gray file's three channels are one: its codes are evidence once.
        Some(sets) if gray => SampleEncoding::Srgb {
            levels: [sets[0].levels(); 3],
            stored: sets[0].max(),
        },
        Some(sets) => SampleEncoding::Srgb {
            levels: super::depth::levels(&sets),
            stored: sets[0].max(),
        },
        None if format == FileFormat::RadianceHdr => SampleEncoding::SharedExponent,
        None if format == FileFormat::OpenExr && exr_is_half(path) => {
            SampleEncoding::Float { mantissa_bits: 10 }
        }
        None => SampleEncoding::Float { mantissa_bits: 23 },
    };
    let film = match format {
        FileFormat::RadianceHdr => match hdr_exposure(path)? {
            Some(exposure) => film.divided_by(exposure),
            None => film,
        },
        _ => film,
    };
    Ok(ImageFile {
        film,
        format,
        encoding,
        alpha,
        gray,
        indexed: layout.indexed,
        layout,
        misnamed: None,
    })
}

impl Film {
    fn divided_by(mut self, exposure: f32) -> Film {
        self.pixels.iter_mut().for_each(|p| *p /= exposure);
        self
    }
}

/// The largest code a Netpbm file declares (its maxval); `None` for other
/// formats, whose codes fill their bytes.
fn stored_max(path: &Path, format: FileFormat) -> Result<Option<u32>, String> {
    if format != FileFormat::Pnm {
        return Ok(None);
    }
    let decoder = image::codecs::pnm::PnmDecoder::new(open(path)?).map_err(|e| e.to_string())?;
    Ok(Some(decoder.into_inner().1.maximal_sample()))
}

/// The EXPOSURE a Radiance file's header gives, where it is not 1.
fn hdr_exposure(path: &Path) -> Result<Option<f32>, String> {
    let decoder = image::codecs::hdr::HdrDecoder::new(open(path)?).map_err(|e| e.to_string())?;
    Ok(decoder
        .metadata()
        .exposure
        .filter(|&e| e.is_finite() && e > 0.0 && e != 1.0))
}

/// Whether an OpenEXR file stores its colour channels as half floats.
fn exr_is_half(path: &Path) -> bool {
    let Ok(meta) = exr::meta::MetaData::read_from_file(path, false) else {
        return false;
    };
    meta.headers.first().is_some_and(|header| {
        header.channels.list.iter().any(|channel| {
            matches!(channel.name.to_string().as_str(), "R" | "G" | "B")
                && channel.sample_type == exr::meta::attribute::SampleType::F16
        })
    })
}

/// The image at `path` decoded by the image crate, its size checked from the
/// header before any pixel memory is taken.
fn decode(path: &Path, file_format: FileFormat) -> Result<image::DynamicImage, String> {
    use image::ImageDecoder;
    let format = file_format.image_crate().expect("not PFM");
    let header = image::ImageReader::with_format(open(path)?, format)
        .into_decoder()
        .map_err(|e| decoding_error(e, file_format))?;
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
    reader.decode().map_err(|e| decoding_error(e, file_format))
}

/// An `image` crate error as one line: a file that ends early is truncated;
/// a decoder's complaint is about this file's format.
fn decoding_error(error: image::ImageError, format: FileFormat) -> String {
    use image::ImageError as E;
    match error {
        E::IoError(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
            "the file is truncated: it ends before its pixels do".into()
        }
        E::Decoding(e) => {
            let text = e.to_string();
            let reason = text.split_once(": ").map_or(text.as_str(), |(_, r)| r);
            format!("not a valid {} file: {reason}", format.name())
        }
        other => other.to_string(),
    }
}

/// A decoded image as linear RGB, with the codes each integer channel holds
/// (`None` for floats), its alpha, and whether it was gray. `maxval` is a
/// Netpbm file's: the image crate scales its codes to fill 8 or 16 bits,
/// which is undone exactly (the scaling is one to one).
fn pixels(
    decoded: image::DynamicImage,
    maxval: Option<u32>,
) -> (Film, Option<[CodeSet; 3]>, AlphaChannel, bool) {
    use image::DynamicImage as D;
    let resolution = UVec2::new(decoded.width(), decoded.height());
    let gray = matches!(
        decoded,
        D::ImageLuma8(_) | D::ImageLumaA8(_) | D::ImageLuma16(_) | D::ImageLumaA16(_)
    );
    let channels = decoded.color().channel_count() as usize;
    let (pixels, codes, alpha) = match decoded {
        D::ImageRgb32F(_) | D::ImageRgba32F(_) => {
            let has_alpha = decoded.color().has_alpha();
            let samples = decoded.into_rgba32f().into_raw();
            let opaque = samples.chunks_exact(4).map(|p| p[3] >= 1.0);
            let alpha = alpha_channel(has_alpha, opaque);
            let pixels = samples
                .chunks_exact(4)
                .map(|p| Vec3::new(p[0], p[1], p[2]))
                .collect();
            (pixels, None, alpha)
        }
        D::ImageLuma8(_) | D::ImageLumaA8(_) | D::ImageRgb8(_) | D::ImageRgba8(_) => {
            integer_pixels(&decoded.into_bytes(), channels, 255, maxval)
        }
        D::ImageLuma16(b) => integer_pixels(b.as_raw(), channels, 65535, maxval),
        D::ImageLumaA16(b) => integer_pixels(b.as_raw(), channels, 65535, maxval),
        D::ImageRgb16(b) => integer_pixels(b.as_raw(), channels, 65535, maxval),
        D::ImageRgba16(b) => integer_pixels(b.as_raw(), channels, 65535, maxval),
        other => integer_pixels(other.into_rgb16().as_raw(), 3, 65535, maxval),
    };
    (Film { resolution, pixels }, codes, alpha, gray)
}

/// Integer samples (`channels` a pixel: gray, gray and alpha, RGB or RGBA)
/// filling `0..=full`, as linear RGB; the codes of each colour channel,
/// rescaled to `0..=maxval` where a Netpbm maxval is given; and the alpha.
fn integer_pixels<T: Copy + Into<u32>>(
    samples: &[T],
    channels: usize,
    full: u32,
    maxval: Option<u32>,
) -> (Vec<Vec3>, Option<[CodeSet; 3]>, AlphaChannel) {
    let max = maxval.unwrap_or(full);
    let code = |s: T| -> u32 {
        let s: u32 = s.into();
        match max == full {
            true => s,
            false => ((s as u64 * max as u64 + full as u64 / 2) / full as u64) as u32,
        }
    };
    let table: Vec<f32> = (0..=max)
        .map(|c| srgb_to_linear(c as f32 / max as f32))
        .collect();
    let mut sets: [CodeSet; 3] = std::array::from_fn(|_| CodeSet::new(max));
    let colour = if channels >= 3 { 3 } else { 1 };
    let pixels = samples
        .chunks_exact(channels)
        .map(|p| {
            let rgb: [u32; 3] = std::array::from_fn(|c| code(p[c.min(colour - 1)]));
            for (set, &c) in sets.iter_mut().zip(&rgb) {
                set.insert(c);
            }
            Vec3::from_array(rgb.map(|c| table[c as usize]))
        })
        .collect();
    let has_alpha = channels == 2 || channels == 4;
    let opaque = samples
        .chunks_exact(channels)
        .map(|p| p[channels - 1].into() == full);
    (pixels, Some(sets), alpha_channel(has_alpha, opaque))
}

/// The alpha channel, from whether each pixel is fully opaque.
fn alpha_channel(present: bool, opaque: impl Iterator<Item = bool>) -> AlphaChannel {
    if !present {
        return AlphaChannel::Absent;
    }
    match opaque.filter(|&o| !o).count() as u64 {
        0 => AlphaChannel::Opaque,
        pixels => AlphaChannel::Translucent { pixels },
    }
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
