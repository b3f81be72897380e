//! A partly rendered film: what an interrupted render writes, and what a
//! resumed one reads back. In OpenEXR the coverage is the alpha channel (1 for
//! a rendered pixel, 0 for one not reached), so viewers show the unfinished
//! pixels as transparent; the colour channels are the film's, 32-bit float. A
//! text naming the render (its fingerprint) goes in the header, as the string
//! attribute [`FINGERPRINT_ATTRIBUTE`].

use super::read::decode;
use super::{Film, FilmError, ImageFormat};
use glam::Vec3;
use std::path::Path;

/// The OpenEXR header attribute that holds a partial film's fingerprint.
pub const FINGERPRINT_ATTRIBUTE: &str = "glintRender";

/// A film and, per pixel (row-major from the top left), whether it was rendered.
#[derive(Clone, Debug, PartialEq)]
pub struct PartialFilm {
    pub film: Film,
    pub finished: Vec<bool>,
    /// What was being rendered, in a text of the writer's choosing (Glint's
    /// command line hashes the scene, its assets and the settings), so that a
    /// resumed render can check it continues the same one. Printable ASCII;
    /// only OpenEXR keeps it.
    pub fingerprint: Option<String>,
}

impl PartialFilm {
    /// The pixels rendered.
    pub fn finished_count(&self) -> usize {
        self.finished.iter().filter(|&&f| f).count()
    }

    /// Writes the film to `path` (atomically, as [`Film::save`]): in OpenEXR
    /// with the coverage as alpha; in PNG and PFM, which keep no coverage, with
    /// the pixels not rendered black.
    pub fn save(&self, path: &Path) -> Result<(), FilmError> {
        if ImageFormat::from_path(path)? != ImageFormat::Exr {
            let mut film = self.film.clone();
            for (pixel, &done) in film.pixels_mut().iter_mut().zip(&self.finished) {
                if !done {
                    *pixel = Vec3::ZERO;
                }
            }
            return film.save(path);
        }
        use exr::prelude::{
            AttributeValue, Encoding, Image, Layer, LayerAttributes, SpecificChannels, Text, Vec2,
            WritableImage,
        };
        let width = self.film.resolution().x as usize;
        let (pixels, finished) = (self.film.pixels(), &self.finished);
        let rgba = SpecificChannels::rgba(|at: Vec2<usize>| {
            let i = at.y() * width + at.x();
            let (p, alpha) = (pixels[i], if finished[i] { 1.0f32 } else { 0.0 });
            (p.x, p.y, p.z, alpha)
        });
        let mut attributes = LayerAttributes::default();
        if let Some(fingerprint) = &self.fingerprint {
            let printable = fingerprint
                .bytes()
                .all(|b| b.is_ascii_graphic() || b == b' ');
            let text = Text::new_or_none(fingerprint)
                .filter(|_| printable)
                .ok_or_else(|| FilmError::Encode {
                    path: path.to_path_buf(),
                    message: "the render's fingerprint is not printable ASCII".into(),
                })?;
            attributes.other.insert(
                Text::from(FINGERPRINT_ATTRIBUTE),
                AttributeValue::Text(text),
            );
        }
        let size = (width, self.film.resolution().y as usize);
        let image = Image::from_layer(Layer::new(size, attributes, Encoding::FAST_LOSSLESS, rgba));
        let io_err = |source| FilmError::Io {
            path: path.to_path_buf(),
            source,
        };
        crate::write_atomically(path, io_err, |out| {
            image
                .write()
                .to_buffered(out)
                .map_err(|e| FilmError::Encode {
                    path: path.to_path_buf(),
                    message: e.to_string(),
                })
        })
    }

    /// Reads an OpenEXR film with a coverage (alpha) channel, as
    /// [`PartialFilm::save`] writes it: alpha 1 is a rendered pixel, anything
    /// else one to render. A file without alpha is refused (it is not partial).
    pub fn load(path: &Path) -> Result<Self, FilmError> {
        let fail = |message: String| FilmError::Read {
            path: path.to_path_buf(),
            message,
        };
        if ImageFormat::from_path(path).ok() != Some(ImageFormat::Exr) {
            return Err(fail(
                "a partial render is an OpenEXR file (.exr), whose alpha channel says which pixels are rendered".into(),
            ));
        }
        let decoded = decode(path, image::ImageFormat::OpenExr).map_err(fail)?;
        let (w, h) = (decoded.width(), decoded.height());
        if !decoded.color().has_alpha() {
            return Err(fail(
                "it has no coverage (alpha) channel: not the output of an interrupted render"
                    .into(),
            ));
        }
        let rgba = decoded.into_rgba32f();
        let mut film = Film::new(glam::UVec2::new(w, h));
        let mut finished = Vec::with_capacity(film.pixels().len());
        for (pixel, p) in film.pixels_mut().iter_mut().zip(rgba.pixels()) {
            *pixel = Vec3::new(p.0[0], p.0[1], p.0[2]);
            finished.push(p.0[3] == 1.0);
        }
        let fingerprint = read_fingerprint(path).map_err(fail)?;
        Ok(Self {
            film,
            finished,
            fingerprint,
        })
    }
}

/// The fingerprint in the header of the OpenEXR file at `path`, if any.
fn read_fingerprint(path: &Path) -> Result<Option<String>, String> {
    use exr::prelude::{AttributeValue, Text};
    let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| e.to_string())?;
    let key = Text::from(FINGERPRINT_ATTRIBUTE);
    Ok(meta
        .headers
        .iter()
        .find_map(|h| match h.own_attributes.other.get(&key) {
            Some(AttributeValue::Text(t)) => Some(t.to_string()),
            _ => None,
        }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::UVec2;

    fn partial() -> PartialFilm {
        let mut film = Film::new(UVec2::new(5, 3));
        for (k, p) in film.pixels_mut().iter_mut().enumerate() {
            *p = Vec3::new(k as f32 * 0.37, -1.5e-7, f32::MAX / (k + 1) as f32);
        }
        let finished = (0..15).map(|k| k % 3 != 1).collect();
        PartialFilm {
            film,
            finished,
            fingerprint: Some("scene 0123abcd, 16 spp".into()),
        }
    }

    #[test]
    fn exr_keeps_every_value_and_the_coverage_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("partial.exr");
        let original = partial();
        original.save(&path).unwrap();
        assert_eq!(PartialFilm::load(&path).unwrap(), original);
        assert_eq!(original.finished_count(), 10);
    }

    #[test]
    fn exr_keeps_the_fingerprint_or_its_absence() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("partial.exr");
        let mut original = partial();
        original.fingerprint = None;
        original.save(&path).unwrap();
        assert_eq!(PartialFilm::load(&path).unwrap().fingerprint, None);
        original.fingerprint = Some("a".into());
        original.save(&path).unwrap();
        let written = std::fs::read(&path).unwrap();
        original.fingerprint = Some("scène".into());
        let e = original.save(&path).unwrap_err().to_string();
        assert!(e.contains("not printable ASCII"), "{e}");
        assert_eq!(
            std::fs::read(&path).unwrap(),
            written,
            "a failed write leaves the file as it was"
        );
        assert_eq!(
            PartialFilm::load(&path).unwrap().fingerprint.as_deref(),
            Some("a")
        );
    }

    #[test]
    fn png_and_pfm_leave_the_unfinished_pixels_black() {
        let dir = tempfile::tempdir().unwrap();
        let original = partial();
        for name in ["partial.pfm", "partial.png"] {
            let path = dir.path().join(name);
            original.save(&path).unwrap();
            let read = Film::load(&path).unwrap();
            for (k, (read, written)) in read.pixels().iter().zip(original.film.pixels()).enumerate()
            {
                if !original.finished[k] {
                    assert_eq!(*read, Vec3::ZERO, "{name}, pixel {k}");
                } else if name.ends_with("pfm") {
                    assert_eq!(read, written, "{name}, pixel {k}");
                }
            }
        }
    }

    #[test]
    fn a_complete_or_non_exr_image_is_not_a_partial_render() {
        let dir = tempfile::tempdir().unwrap();
        let complete = dir.path().join("complete.exr");
        partial().film.save(&complete).unwrap();
        let e = PartialFilm::load(&complete).unwrap_err().to_string();
        assert!(e.contains("no coverage (alpha) channel"), "{e}");
        let png = dir.path().join("partial.png");
        partial().save(&png).unwrap();
        let e = PartialFilm::load(&png).unwrap_err().to_string();
        assert!(e.contains("is an OpenEXR file"), "{e}");
        let e = PartialFilm::load(&dir.path().join("gone.exr"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("gone.exr: cannot read the image"), "{e}");
    }
}
