//! A submitted image, decoded to linear RGB, and what its file did to the
//! radiance it was written from: clamping, rounding to the step its values
//! show, and, for JPEG, the encoding the references are put through.

use crate::jpeg::JpegEncoding;
use glam::{UVec2, Vec3};
use glint_camera::{
    linear_to_srgb, srgb_to_linear, AlphaChannel, FileFormat, Film, SampleEncoding,
};
use std::path::{Path, PathBuf};

/// A submission: linear RGB per pixel and how it was stored.
#[derive(Clone, Debug)]
pub struct Submission {
    pub path: PathBuf,
    pub film: Film,
    pub encoding: SampleEncoding,
    /// Whether values above 1 were clamped: always for integer formats, and
    /// for a float image none of whose values exceeds 1.
    pub clamped: bool,
    /// What the file was read as, in words ("JPEG, quality 75, 4:2:0").
    pub format: String,
    pub alpha: AlphaChannel,
    /// The file holds one gray channel.
    pub gray: bool,
    /// The file's pixels index a palette of this many colours (those it uses).
    pub palette: Option<usize>,
    /// A JPEG's encoding (its tables and subsampling), or why Glint cannot
    /// encode its renders the same way.
    pub jpeg: Option<Result<JpegEncoding, String>>,
}

impl Submission {
    /// Reads an image file of any format Glint reads ([`Film::read`]).
    pub fn load(path: &Path) -> Result<Submission, String> {
        let file = Film::read(path).map_err(|e| e.to_string())?;
        if let Some((i, _)) = file
            .film
            .pixels()
            .iter()
            .enumerate()
            .find(|(_, p)| !p.is_finite())
        {
            let width = file.film.resolution().x as usize;
            return Err(format!(
                "{}: pixel ({}, {}) is not a finite number; a render's pixels are finite",
                path.display(),
                i % width,
                i / width
            ));
        }
        let jpeg = (file.format == FileFormat::Jpeg).then(|| JpegEncoding::from_file(path));
        let format = match &jpeg {
            Some(Ok(encoding)) => file.description_with(&encoding.details()),
            _ => file.description(),
        };
        let palette = file.indexed.then(|| distinct_colours(&file.film));
        let mut submission = Submission::new(path.to_owned(), file.film, file.encoding);
        submission.format = format;
        submission.alpha = file.alpha;
        submission.gray = file.gray;
        submission.palette = palette;
        submission.jpeg = jpeg;
        Ok(submission)
    }

    /// A submission from an image already in memory.
    pub fn new(path: PathBuf, film: Film, encoding: SampleEncoding) -> Submission {
        let clamped = match encoding {
            SampleEncoding::Srgb { .. } => true,
            _ => film.pixels().iter().all(|p| p.max_element() <= 1.0),
        };
        Submission {
            path,
            film,
            encoding,
            clamped,
            format: "an image in memory".into(),
            alpha: AlphaChannel::Absent,
            gray: false,
            palette: None,
            jpeg: None,
        }
    }

    pub fn resolution(&self) -> UVec2 {
        self.film.resolution()
    }

    /// Per pixel and channel, how far the stored value may lie from the value
    /// it was written from, in linear units: one step of what the file
    /// rounded to (an integer format's code step at that value, in the
    /// levels the data shows: rounding costs half a step, truncation up to
    /// one; two for a JPEG of an encoder other than libjpeg; a shared
    /// exponent's mantissa step), or a relative 1e-5 of a 32-bit float (a
    /// relative step of a half float).
    pub fn tolerance(&self) -> Vec<Vec3> {
        let pixels = self.film.pixels();
        match self.encoding {
            SampleEncoding::Float { mantissa_bits } => {
                let relative = 1e-5f32.max(2f32.powi(-(mantissa_bits as i32)));
                pixels
                    .iter()
                    .map(|p| p.abs() * relative + Vec3::splat(1e-7))
                    .collect()
            }
            SampleEncoding::SharedExponent => pixels
                .iter()
                .map(|p| Vec3::splat(shared_exponent_step(p.max_element()) + 1e-7))
                .collect(),
            SampleEncoding::Srgb { levels, .. } => {
                let steps = levels.map(CodeSteps::new);
                // Another encoder than libjpeg rounds otherwise than Glint's
                // re-encoding, by up to a code: one more step.
                let encoder = match &self.jpeg {
                    Some(Ok(jpeg)) if !jpeg.libjpeg_layout => 2.0,
                    _ => 1.0,
                };
                pixels
                    .iter()
                    .map(|p| Vec3::from_array(std::array::from_fn(|c| encoder * steps[c].at(p[c]))))
                    .collect()
            }
        }
    }
}

/// The number of distinct colours in `film`.
fn distinct_colours(film: &Film) -> usize {
    let colours: std::collections::HashSet<[u32; 3]> = film
        .pixels()
        .iter()
        .map(|p| p.to_array().map(f32::to_bits))
        .collect();
    colours.len()
}

/// One mantissa step of a Radiance RGBE pixel whose largest channel is
/// `top`: its 8 bits span the power of two above `top`.
fn shared_exponent_step(top: f32) -> f32 {
    if top <= 0.0 || !top.is_finite() {
        return 0.0;
    }
    2f32.powi(top.log2().floor() as i32 + 1 - 8)
}

/// The linear width of an 8-bit code step at `linear` (the wider of those
/// either side).
pub(crate) fn code_step(linear: f32) -> f32 {
    static EIGHT_BIT: std::sync::OnceLock<CodeSteps> = std::sync::OnceLock::new();
    EIGHT_BIT.get_or_init(|| CodeSteps::new(255)).at(linear)
}

/// The linear width of the code steps of an sRGB-encoded integer format,
/// for each code (the wider of the two either side).
struct CodeSteps {
    max_code: u32,
    widths: Vec<f32>,
}

impl CodeSteps {
    fn new(max_code: u32) -> CodeSteps {
        let linear = |code: i64| {
            let code = code.clamp(0, max_code as i64);
            srgb_to_linear(code as f32 / max_code as f32)
        };
        let widths = (0..=max_code as i64)
            .map(|code| {
                let here = linear(code);
                (linear(code + 1) - here).max(here - linear(code - 1))
            })
            .collect();
        CodeSteps { max_code, widths }
    }

    /// The wider of the two steps either side of the code that decodes to
    /// `linear`.
    fn at(&self, linear: f32) -> f32 {
        let encoded = linear_to_srgb(linear.clamp(0.0, 1.0));
        let code = (encoded * self.max_code as f32).round() as usize;
        self.widths[code.min(self.max_code as usize)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tolerance_is_one_code_step() {
        let steps = CodeSteps::new(255);
        let step = |code: u32| srgb_to_linear(code as f32 / 255.0);
        // Code 128 (linear 0.2158): the step above is the wider.
        let at = steps.at(step(128));
        assert!((at - (step(129) - step(128))).abs() < 1e-7, "{at}");
        // At the ends the one step that exists.
        assert!((steps.at(0.0) - step(1)).abs() < 1e-9);
        assert!((steps.at(1.0) - (1.0 - step(254))).abs() < 1e-7);
        // 16-bit steps are 257 times narrower near the middle.
        let wide = CodeSteps::new(65535).at(step(128));
        assert!((at / wide - 257.0).abs() < 3.0, "{}", at / wide);
    }

    #[test]
    fn the_tolerance_follows_the_levels_the_data_shows() {
        let mut film = Film::new(UVec2::new(1, 1));
        film.set_pixel(0, 0, Vec3::splat(0.2));
        let step = |levels: u32| {
            let stored = 65535;
            let encoding = SampleEncoding::Srgb {
                levels: [levels; 3],
                stored,
            };
            Submission::new("a.png".into(), film.clone(), encoding).tolerance()[0].x
        };
        let ratio = step(255) / step(65535);
        assert!((ratio - 257.0).abs() < 3.0, "{ratio}");
        // A half float's step is 2⁻¹⁰ of the value, a 32-bit float's 1e-5.
        let half = Submission::new(
            "a.exr".into(),
            film.clone(),
            SampleEncoding::Float { mantissa_bits: 10 },
        );
        assert!((half.tolerance()[0].x - 0.2 / 1024.0 - 1e-7).abs() < 1e-9);
        // RGBE: 1/256 of the power of two above the pixel's largest channel.
        film.set_pixel(0, 0, Vec3::new(0.3, 0.1, 0.01));
        let rgbe = Submission::new("a.hdr".into(), film, SampleEncoding::SharedExponent);
        assert_eq!(rgbe.tolerance()[0], Vec3::splat(0.5 / 256.0 + 1e-7));
    }

    #[test]
    fn float_images_count_as_clamped_only_when_nothing_exceeds_one() {
        let mut film = Film::new(UVec2::new(2, 1));
        film.set_pixel(0, 0, Vec3::splat(0.5));
        let float = SampleEncoding::Float { mantissa_bits: 23 };
        let clamped = Submission::new("a.pfm".into(), film.clone(), float);
        assert!(clamped.clamped);
        film.set_pixel(1, 0, Vec3::new(0.0, 1.5, 0.0));
        let open = Submission::new("a.pfm".into(), film.clone(), float);
        assert!(!open.clamped);
        let png = Submission::new(
            "a.png".into(),
            film,
            SampleEncoding::Srgb {
                levels: [255; 3],
                stored: 255,
            },
        );
        assert!(png.clamped);
        assert!(open.tolerance()[1].y < 2e-5);
    }
}
