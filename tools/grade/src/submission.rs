//! A submitted image, decoded to linear RGB, and what its file format did to
//! the radiance it was written from: clamping and quantisation.

use glam::{UVec2, Vec3};
use glint_camera::{srgb_to_linear, Film, SampleEncoding};
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
}

impl Submission {
    /// Reads a PNG, PPM, JPEG, OpenEXR or PFM file.
    pub fn load(path: &Path) -> Result<Submission, String> {
        let (film, encoding) = Film::load_with_encoding(path).map_err(|e| e.to_string())?;
        if let Some((i, _)) = film
            .pixels()
            .iter()
            .enumerate()
            .find(|(_, p)| !p.is_finite())
        {
            let width = film.resolution().x as usize;
            return Err(format!(
                "{}: pixel ({}, {}) is not a finite number; a render's pixels are finite",
                path.display(),
                i % width,
                i / width
            ));
        }
        Ok(Submission::new(path.to_owned(), film, encoding))
    }

    /// A submission from an image already in memory.
    pub fn new(path: PathBuf, film: Film, encoding: SampleEncoding) -> Submission {
        let clamped = match encoding {
            SampleEncoding::Srgb { .. } => true,
            SampleEncoding::Linear => film.pixels().iter().all(|p| p.max_element() <= 1.0),
        };
        Submission {
            path,
            film,
            encoding,
            clamped,
        }
    }

    pub fn resolution(&self) -> UVec2 {
        self.film.resolution()
    }

    /// Per pixel and channel, how far the stored value may lie from the value
    /// it was written from, in linear units: one code step of an integer
    /// format at that value (rounding costs half a step, truncation up to one),
    /// or a relative 1e-5 of a float.
    pub fn tolerance(&self) -> Vec<Vec3> {
        match self.encoding {
            SampleEncoding::Linear => self
                .film
                .pixels()
                .iter()
                .map(|p| p.abs() * 1e-5 + Vec3::splat(1e-7))
                .collect(),
            SampleEncoding::Srgb { max_code } => {
                let steps = CodeSteps::new(max_code);
                self.film
                    .pixels()
                    .iter()
                    .map(|p| Vec3::from_array(p.to_array().map(|c| steps.at(c))))
                    .collect()
            }
        }
    }
}

/// The linear width of the code steps of an sRGB-encoded integer format.
struct CodeSteps {
    max_code: u32,
}

impl CodeSteps {
    fn new(max_code: u32) -> CodeSteps {
        CodeSteps { max_code }
    }

    fn linear(&self, code: i64) -> f32 {
        let code = code.clamp(0, self.max_code as i64);
        srgb_to_linear(code as f32 / self.max_code as f32)
    }

    /// The wider of the two steps either side of the code that decodes to
    /// `linear`.
    fn at(&self, linear: f32) -> f32 {
        let encoded = linear_to_srgb(linear.clamp(0.0, 1.0));
        let code = (encoded * self.max_code as f32).round() as i64;
        let here = self.linear(code);
        (self.linear(code + 1) - here).max(here - self.linear(code - 1))
    }
}

/// The sRGB curve, unquantised.
fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
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
    fn float_images_count_as_clamped_only_when_nothing_exceeds_one() {
        let mut film = Film::new(UVec2::new(2, 1));
        film.set_pixel(0, 0, Vec3::splat(0.5));
        let clamped = Submission::new("a.pfm".into(), film.clone(), SampleEncoding::Linear);
        assert!(clamped.clamped);
        film.set_pixel(1, 0, Vec3::new(0.0, 1.5, 0.0));
        let open = Submission::new("a.pfm".into(), film.clone(), SampleEncoding::Linear);
        assert!(!open.clamped);
        let png = Submission::new("a.png".into(), film, SampleEncoding::Srgb { max_code: 255 });
        assert!(png.clamped);
        assert!(open.tolerance()[1].y < 2e-5);
    }
}
