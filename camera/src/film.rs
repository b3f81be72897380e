//! The film: a grid of linear RGB radiance values and the writers that turn it
//! into PNG (8-bit sRGB), OpenEXR (32-bit float, linear) or PFM (32-bit float, linear).
//! Reading images back ([`Film::load`]) is in the `read` submodule; a partly
//! rendered film with its coverage ([`PartialFilm`]) in `partial`.

mod checks;
mod depth;
mod formats;
mod partial;
mod read;

pub use checks::{MAX_EXPANSION, MAX_LOAD_SIDE};
pub use formats::FileFormat;
pub use partial::{PartialFilm, Placement, Tile};
pub use read::{AlphaChannel, ImageFile, SampleEncoding};

use glam::{UVec2, Vec3};
use std::io::{Seek, Write};
use std::path::{Path, PathBuf};

/// The on-disk formats a [`Film`] can be written in, chosen by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// 8-bit sRGB: the sRGB transfer curve is applied and values are clamped to [0, 1].
    Png,
    /// Linear 32-bit float RGB OpenEXR.
    Exr,
    /// Linear 32-bit float RGB Portable Float Map (little-endian, bottom row first).
    Pfm,
}

impl ImageFormat {
    /// The format named by `path`'s extension (case-insensitive).
    pub fn from_path(path: &Path) -> Result<Self, FilmError> {
        match lowercase_extension(path).as_deref() {
            Some("png") => Ok(Self::Png),
            Some("exr") => Ok(Self::Exr),
            Some("pfm") => Ok(Self::Pfm),
            _ => Err(FilmError::UnknownFormat(path.to_path_buf())),
        }
    }
}

/// Why a film could not be written ([`Film::save`]) or read ([`Film::load`]).
#[derive(Debug, thiserror::Error)]
pub enum FilmError {
    #[error("{}: unknown output format; expected a .png, .exr or .pfm extension", .0.display())]
    UnknownFormat(PathBuf),
    /// [`Film::load`] could not open, decode or accept the file.
    #[error("{}: cannot read the image: {message}", path.display())]
    Read { path: PathBuf, message: String },
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: could not encode the image: {message}", path.display())]
    Encode { path: PathBuf, message: String },
}

/// Linear RGB radiance per pixel, stored row by row from the top-left pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    resolution: UVec2,
    pixels: Vec<Vec3>,
}

impl Film {
    /// A black film of `resolution` (width, height) pixels.
    pub fn new(resolution: UVec2) -> Self {
        let count = resolution.x as usize * resolution.y as usize;
        Self {
            resolution,
            pixels: vec![Vec3::ZERO; count],
        }
    }

    /// A film of `resolution` holding `pixels` (row-major from the top-left
    /// corner), or `None` where their count is not `width × height`.
    pub fn from_pixels(resolution: UVec2, pixels: Vec<Vec3>) -> Option<Self> {
        let count = resolution.x as usize * resolution.y as usize;
        (pixels.len() == count).then_some(Self { resolution, pixels })
    }

    /// The pixels, row-major from the top-left corner, handed back.
    pub fn into_pixels(self) -> Vec<Vec3> {
        self.pixels
    }

    pub fn resolution(&self) -> UVec2 {
        self.resolution
    }

    /// All pixels, row-major from the top-left corner.
    pub fn pixels(&self) -> &[Vec3] {
        &self.pixels
    }

    /// All pixels, mutable, row-major from the top-left corner.
    pub fn pixels_mut(&mut self) -> &mut [Vec3] {
        &mut self.pixels
    }

    pub fn pixel(&self, x: u32, y: u32) -> Vec3 {
        self.pixels[self.index(x, y)]
    }

    pub fn set_pixel(&mut self, x: u32, y: u32, radiance: Vec3) {
        let i = self.index(x, y);
        self.pixels[i] = radiance;
    }

    fn index(&self, x: u32, y: u32) -> usize {
        assert!(x < self.resolution.x && y < self.resolution.y);
        y as usize * self.resolution.x as usize + x as usize
    }

    /// The film as 8-bit sRGB bytes (RGBRGB…), row-major from the top.
    pub fn to_srgb8(&self) -> Vec<u8> {
        self.pixels
            .iter()
            .flat_map(|p| p.to_array())
            .map(linear_to_srgb8)
            .collect()
    }

    /// Writes the film to `path` in the format its extension names.
    ///
    /// The image is written to a temporary file in the same directory and then
    /// renamed over `path`, so a failed write never leaves a partial file and
    /// never destroys what was at `path` before.
    pub fn save(&self, path: &Path) -> Result<(), FilmError> {
        let io_err = |source| FilmError::Io {
            path: path.to_path_buf(),
            source,
        };
        self.stage(path)?.persist().map_err(io_err)
    }

    /// The film encoded as a file of `format` would hold it: the bytes
    /// [`Film::save`] writes.
    pub fn to_bytes(&self, format: ImageFormat) -> Result<Vec<u8>, FilmError> {
        let mut out = std::io::Cursor::new(Vec::new());
        self.encode(format, &mut out, Path::new("(in memory)"))?;
        Ok(out.into_inner())
    }

    /// [`Film::save`] up to putting the file in place
    /// ([`StagedFile::persist`](crate::StagedFile::persist)).
    pub fn stage(&self, path: &Path) -> Result<crate::StagedFile, FilmError> {
        let format = ImageFormat::from_path(path)?;
        let io_err = |source| FilmError::Io {
            path: path.to_path_buf(),
            source,
        };
        crate::stage_atomically(path, io_err, |out| self.encode(format, out, path))
    }

    fn encode<W: Write + Seek>(
        &self,
        format: ImageFormat,
        out: &mut W,
        path: &Path,
    ) -> Result<(), FilmError> {
        let encode_err = |e: image::ImageError| FilmError::Encode {
            path: path.to_path_buf(),
            message: e.to_string(),
        };
        let (w, h) = (self.resolution.x, self.resolution.y);
        match format {
            ImageFormat::Png => image::RgbImage::from_raw(w, h, self.to_srgb8())
                .expect("buffer matches resolution")
                .write_to(out, image::ImageFormat::Png)
                .map_err(encode_err),
            ImageFormat::Exr => {
                let data = self.pixels.iter().flat_map(|p| p.to_array()).collect();
                image::Rgb32FImage::from_raw(w, h, data)
                    .expect("buffer matches resolution")
                    .write_to(out, image::ImageFormat::OpenExr)
                    .map_err(encode_err)
            }
            ImageFormat::Pfm => self.write_pfm(out).map_err(|source| FilmError::Io {
                path: path.to_path_buf(),
                source,
            }),
        }
    }

    /// PFM: a text header `PF\nW H\n-1.0\n` (negative scale = little-endian),
    /// then rows of RGB f32 from the bottom row up.
    fn write_pfm<W: Write>(&self, out: &mut W) -> std::io::Result<()> {
        write!(
            out,
            "PF\n{} {}\n-1.0\n",
            self.resolution.x, self.resolution.y
        )?;
        for row in self.pixels.chunks(self.resolution.x as usize).rev() {
            for value in row.iter().flat_map(|p| p.to_array()) {
                out.write_all(&value.to_le_bytes())?;
            }
        }
        Ok(())
    }
}

/// The sRGB electro-optical transfer function (IEC 61966-2-1): an encoded value
/// in [0, 1] to linear. The inverse of the curve in [`linear_to_srgb8`](crate::linear_to_srgb8):
/// every 8-bit code survives `linear_to_srgb8(srgb_to_linear(code / 255))`.
pub fn srgb_to_linear(encoded: f32) -> f32 {
    if encoded <= 0.040_45 {
        encoded / 12.92
    } else {
        ((encoded + 0.055) / 1.055).powf(2.4)
    }
}

/// The sRGB opto-electronic transfer function (IEC 61966-2-1), clamped to
/// [0, 1] and quantised to 8 bits with rounding. NaN maps to 0.
pub fn linear_to_srgb8(linear: f32) -> u8 {
    let c = if linear.is_nan() {
        0.0
    } else {
        linear.clamp(0.0, 1.0)
    };
    (linear_to_srgb(c) * 255.0 + 0.5) as u8
}

/// The sRGB opto-electronic transfer function (IEC 61966-2-1), unquantised:
/// a linear value in [0, 1] to its encoding in [0, 1].
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// `path`'s extension in lower case, which names its image format.
fn lowercase_extension(path: &Path) -> Option<String> {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gradient() -> Film {
        let mut film = Film::new(UVec2::new(3, 2));
        for y in 0..2 {
            for x in 0..3 {
                film.set_pixel(x, y, Vec3::new(x as f32 * 0.5, y as f32, 0.25));
            }
        }
        film
    }

    /// The film's 8-bit quantisation: each code's linear value, and where a
    /// linear value starts to round to it (found by bisection on
    /// [`linear_to_srgb8`]), to six significant digits.
    #[test]
    fn srgb8_codes_and_their_linear_boundaries() {
        let first_linear_of = |code: u8| {
            let (mut lo, mut hi) = (0.0f32, 1.0f32);
            for _ in 0..64 {
                let mid = 0.5 * (lo + hi);
                match linear_to_srgb8(mid) < code {
                    true => lo = mid,
                    false => hi = mid,
                }
            }
            hi
        };
        let mut text = String::from("code  linear       from\n");
        for code in (0..=255u8).step_by(15).chain([1, 2, 254]) {
            let linear = srgb_to_linear(code as f32 / 255.0);
            assert_eq!(linear_to_srgb8(linear), code);
            let from = if code == 0 {
                0.0
            } else {
                first_linear_of(code)
            };
            text += &format!("{code:>4}  {linear:<11.5e}  {from:.5e}\n");
        }
        insta::assert_snapshot!(text);
    }

    #[test]
    fn srgb_curve_matches_known_values() {
        assert_eq!(linear_to_srgb8(0.0), 0);
        assert_eq!(linear_to_srgb8(1.0), 255);
        assert_eq!(linear_to_srgb8(7.5), 255);
        assert_eq!(linear_to_srgb8(-1.0), 0);
        assert_eq!(linear_to_srgb8(f32::NAN), 0);
        // 0.5 linear is 0.7354 in sRGB: 187.5 -> 188.
        assert_eq!(linear_to_srgb8(0.5), 188);
        assert_eq!(linear_to_srgb8(0.214_041_14), 128);
        assert_eq!(linear_to_srgb8(0.002), 7);
    }

    #[test]
    fn png_round_trips_through_the_image_crate() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.png");
        gradient().save(&path).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (3, 2));
        assert_eq!(img.get_pixel(1, 0).0, [188, 0, 137]);
        assert_eq!(img.get_pixel(2, 1).0, [255, 255, 137]);
    }

    #[test]
    fn exr_keeps_linear_floats() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.exr");
        gradient().save(&path).unwrap();
        let img = image::open(&path).unwrap().to_rgb32f();
        assert_eq!(img.get_pixel(2, 1).0, [1.0, 1.0, 0.25]);
        assert_eq!(img.get_pixel(1, 0).0, [0.5, 0.0, 0.25]);
    }

    #[test]
    fn pfm_is_bottom_up_little_endian() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.pfm");
        gradient().save(&path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let header = b"PF\n3 2\n-1.0\n";
        assert_eq!(&bytes[..header.len()], header);
        let floats: Vec<f32> = bytes[header.len()..]
            .chunks(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(floats.len(), 18);
        // First stored row is the bottom row (y = 1).
        assert_eq!(&floats[..3], &[0.0, 1.0, 0.25]);
        assert_eq!(&floats[9..12], &[0.0, 0.0, 0.25]);
    }

    #[test]
    fn unknown_extension_is_rejected_before_anything_is_written() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.bmp");
        assert!(matches!(
            gradient().save(&path),
            Err(FilmError::UnknownFormat(_))
        ));
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[cfg(unix)]
    #[test]
    fn written_files_get_ordinary_permissions_and_keep_existing_ones() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let fresh = dir.path().join("fresh.png");
        gradient().save(&fresh).unwrap();
        let mode = std::fs::metadata(&fresh).unwrap().permissions().mode() & 0o777;
        // Whatever the umask, a new image is readable by its owner and not owner-only
        // by accident of the temporary file (which is created 0600).
        assert_eq!(mode & 0o600, 0o600);
        let umask_allows_group_read = {
            let probe = dir.path().join("probe");
            std::fs::write(&probe, b"").unwrap();
            std::fs::metadata(&probe).unwrap().permissions().mode() & 0o040 != 0
        };
        assert_eq!(mode & 0o040 != 0, umask_allows_group_read);

        let existing = dir.path().join("existing.pfm");
        std::fs::write(&existing, b"old").unwrap();
        std::fs::set_permissions(&existing, std::fs::Permissions::from_mode(0o640)).unwrap();
        gradient().save(&existing).unwrap();
        let mode = std::fs::metadata(&existing).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o640);
    }

    #[test]
    fn failed_write_keeps_the_existing_file() {
        let dir = tempfile::tempdir().unwrap();
        let missing_dir = dir.path().join("no-such-dir").join("out.png");
        assert!(matches!(
            gradient().save(&missing_dir),
            Err(FilmError::Io { .. })
        ));
        let existing = dir.path().join("keep.png");
        std::fs::write(&existing, b"precious").unwrap();
        gradient().save(&existing).unwrap();
        assert_ne!(std::fs::read(&existing).unwrap(), b"precious");
    }
}
