//! A partly rendered film: what an interrupted render writes and a resumed
//! one reads back, and a piece of an image rendered on its own (`glint
//! render --tile` or `--crop`) that `glint assemble` puts together with the
//! others. In OpenEXR the coverage is the alpha channel (1 for a pixel the
//! file holds, 0 for one it does not), so viewers show the missing pixels as
//! transparent; the colour channels are the film's, 32-bit float. The file
//! describes itself: its data window sits where the film belongs in the
//! image's display window, and one header attribute, [`FINGERPRINT_ATTRIBUTE`],
//! names the render, followed (after `; `) by the tile (`tile 3/64`) and by
//! `interrupted` for an interrupted render's pixels. One attribute, not
//! three: the OpenEXR writer orders several in no fixed way, and a tile
//! rendered again must be the same bytes.

use super::checks::{check_expansion, check_size, regular_file};
use super::{Film, FilmError, ImageFormat};
use glam::{UVec2, Vec3};
use std::path::Path;

/// The OpenEXR header attribute that holds a partial film's fingerprint, its
/// tile and whether it is an interrupted render's.
pub const FINGERPRINT_ATTRIBUTE: &str = "glintRender";

/// What follows the fingerprint in [`FINGERPRINT_ATTRIBUTE`].
const SEPARATOR: &str = "; ";

/// A film and, per pixel (row-major from the top left), whether it holds it:
/// for an interrupted render, whether the pixel was rendered; for a piece of
/// an image, whether the piece covers it.
#[derive(Clone, Debug, PartialEq)]
pub struct PartialFilm {
    pub film: Film,
    pub finished: Vec<bool>,
    /// What was being rendered, in a text of the writer's choosing (Glint's
    /// command line hashes the scene, its assets and the settings), so that a
    /// resumed render can check it continues the same one, and pieces that
    /// they belong together. Printable ASCII; only OpenEXR keeps it.
    pub fingerprint: Option<String>,
    /// Where the film sits in the whole image: the whole image's size and the
    /// film's top-left pixel in it (OpenEXR's display and data windows).
    pub placement: Placement,
    /// Which tile of how many the film is (`glint render --tile I/N`).
    pub tile: Option<Tile>,
    /// Whether the film is an interrupted render's, for `--resume`.
    pub interrupted: bool,
}

/// Where a film sits in the image it is part of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placement {
    /// The whole image's size.
    pub image: UVec2,
    /// The film's top-left pixel in the whole image.
    pub origin: UVec2,
}

/// Tile `index` of `count`, counted from 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tile {
    pub index: u32,
    pub count: u32,
}

impl std::fmt::Display for Tile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Tile {
    /// Parses `I/N` (0 ≤ I < N).
    pub fn parse(text: &str) -> Result<Tile, String> {
        let (index, count) = text
            .split_once('/')
            .ok_or_else(|| format!("expected I/N, e.g. 3/64, got \"{text}\""))?;
        let number = |s: &str| {
            s.trim()
                .parse::<u32>()
                .map_err(|_| format!("expected I/N with whole numbers, e.g. 3/64, got \"{text}\""))
        };
        let (index, count) = (number(index)?, number(count)?);
        if count == 0 || index >= count {
            return Err(format!(
                "expected I/N with 0 ≤ I < N (tiles count from 0), got \"{text}\""
            ));
        }
        Ok(Tile { index, count })
    }

    /// Whether row `y` of the image is this tile's: rows are dealt out in
    /// turn (tile I has rows I, I + N, I + 2N, ...), so that every tile has
    /// rows from the whole height, and costs about the same.
    pub fn has_row(&self, y: u32) -> bool {
        y % self.count == self.index
    }

    /// How many of an image's `height` rows are the tile's.
    pub fn row_count(&self, height: u32) -> u32 {
        height.saturating_sub(self.index).div_ceil(self.count)
    }

    /// The tile's first and last rows plus one in an image `height` rows
    /// high, if it has any.
    pub fn row_span(&self, height: u32) -> Option<(u32, u32)> {
        if self.index >= height {
            return None;
        }
        let last = self.index + (height - 1 - self.index) / self.count * self.count;
        Some((self.index, last + 1))
    }
}

impl PartialFilm {
    /// `film` as a whole image, with the pixels `finished`, unnamed.
    pub fn new(film: Film, finished: Vec<bool>) -> Self {
        let image = film.resolution();
        Self {
            film,
            finished,
            fingerprint: None,
            placement: Placement {
                image,
                origin: UVec2::ZERO,
            },
            tile: None,
            interrupted: false,
        }
    }

    /// The pixels rendered.
    pub fn finished_count(&self) -> usize {
        self.finished.iter().filter(|&&f| f).count()
    }

    /// Writes the film to `path` (atomically, as [`Film::save`]): in OpenEXR
    /// with the coverage as alpha and the placement and attributes in the
    /// header; in PNG and PFM, which keep none of them, the film alone, with
    /// the pixels not held black.
    pub fn save(&self, path: &Path) -> Result<(), FilmError> {
        let io_err = |source| FilmError::Io {
            path: path.to_path_buf(),
            source,
        };
        self.stage(path)?.persist().map_err(io_err)
    }

    /// [`PartialFilm::save`] up to putting the file in place
    /// ([`StagedFile::persist`](crate::StagedFile::persist)).
    pub fn stage(&self, path: &Path) -> Result<crate::StagedFile, FilmError> {
        if ImageFormat::from_path(path)? != ImageFormat::Exr {
            let mut film = self.film.clone();
            for (pixel, &done) in film.pixels_mut().iter_mut().zip(&self.finished) {
                if !done {
                    *pixel = Vec3::ZERO;
                }
            }
            return film.stage(path);
        }
        use exr::prelude::{
            Encoding, Image, ImageAttributes, IntegerBounds, Layer, LayerAttributes,
            SpecificChannels, Vec2, WritableImage,
        };
        let width = self.film.resolution().x as usize;
        let (pixels, finished) = (self.film.pixels(), &self.finished);
        let rgba = SpecificChannels::rgba(|at: Vec2<usize>| {
            let i = at.y() * width + at.x();
            let (p, alpha) = (pixels[i], if finished[i] { 1.0f32 } else { 0.0 });
            (p.x, p.y, p.z, alpha)
        });
        let mut attributes = LayerAttributes::default();
        if self
            .fingerprint
            .as_deref()
            .is_some_and(|f| f.contains(SEPARATOR))
        {
            return Err(FilmError::Encode {
                path: path.to_path_buf(),
                message: format!("the render's fingerprint holds \"{SEPARATOR}\""),
            });
        }
        if let Some(record) = self.record() {
            insert_text(&mut attributes, FINGERPRINT_ATTRIBUTE, &record).map_err(|message| {
                FilmError::Encode {
                    path: path.to_path_buf(),
                    message,
                }
            })?;
        }
        let Placement { image, origin } = self.placement;
        attributes.layer_position = Vec2(origin.x as i32, origin.y as i32);
        let size = (width, self.film.resolution().y as usize);
        let display = IntegerBounds::new(Vec2(0, 0), (image.x as usize, image.y as usize));
        let layer = Layer::new(size, attributes, Encoding::FAST_LOSSLESS, rgba);
        let image = Image::new(ImageAttributes::new(display), layer);
        let io_err = |source| FilmError::Io {
            path: path.to_path_buf(),
            source,
        };
        crate::stage_atomically(path, io_err, |out| {
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
    /// [`PartialFilm::save`] writes it: alpha 1 is a pixel held, anything
    /// else one missing. A file without alpha is refused (it is not partial).
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
        regular_file(path).map_err(fail)?;
        check_header(path).map_err(fail)?;
        let read = exr::prelude::read_first_rgba_layer_from_file(
            path,
            |size, _| {
                (
                    size.width(),
                    vec![(0.0f32, 0.0f32, 0.0f32, 0.0f32); size.area()],
                )
            },
            |(width, pixels): &mut (usize, Vec<(f32, f32, f32, f32)>), at, rgba| {
                pixels[at.y() * *width + at.x()] = rgba;
            },
        )
        .map_err(|e| fail(e.to_string()))?;
        let layer = &read.layer_data;
        if layer.channel_data.channels.3.is_none() {
            return Err(fail(
                "it has no coverage (alpha) channel: not the output of an interrupted render"
                    .into(),
            ));
        }
        let (w, h) = (layer.size.width() as u32, layer.size.height() as u32);
        let mut film = Film::new(UVec2::new(w, h));
        let mut finished = Vec::with_capacity(film.pixels().len());
        for (pixel, &(r, g, b, a)) in film
            .pixels_mut()
            .iter_mut()
            .zip(&layer.channel_data.pixels.1)
        {
            *pixel = Vec3::new(r, g, b);
            finished.push(a == 1.0);
        }
        let display = read.attributes.display_window;
        let position = layer.attributes.layer_position - display.position;
        let (image, origin) = (display.size, position);
        let fits = origin.x() >= 0
            && origin.y() >= 0
            && origin.x() as usize + w as usize <= image.width()
            && origin.y() as usize + h as usize <= image.height();
        if !fits {
            return Err(fail(format!(
                "its pixels ({w}x{h} from {},{}) lie outside its image ({}x{})",
                origin.x(),
                origin.y(),
                image.width(),
                image.height()
            )));
        }
        let record = match layer
            .attributes
            .other
            .get(&exr::prelude::Text::from(FINGERPRINT_ATTRIBUTE))
        {
            Some(exr::prelude::AttributeValue::Text(t)) => Some(t.to_string()),
            _ => None,
        };
        let (fingerprint, tile, interrupted) = match record {
            Some(record) => {
                parse_record(&record).map_err(|e| fail(format!("{FINGERPRINT_ATTRIBUTE}: {e}")))?
            }
            None => (None, None, false),
        };
        Ok(Self {
            film,
            finished,
            fingerprint,
            placement: Placement {
                image: UVec2::new(image.width() as u32, image.height() as u32),
                origin: UVec2::new(origin.x() as u32, origin.y() as u32),
            },
            tile,
            interrupted,
        })
    }
}

impl PartialFilm {
    /// The text of [`FINGERPRINT_ATTRIBUTE`]: the fingerprint, then the tile
    /// and whether the render was interrupted; none if there is nothing to say.
    fn record(&self) -> Option<String> {
        let mut parts = vec![self.fingerprint.clone().unwrap_or_default()];
        parts.extend(self.tile.map(|t| format!("tile {t}")));
        parts.extend(self.interrupted.then(|| "interrupted".to_owned()));
        (parts.len() > 1 || !parts[0].is_empty()).then(|| parts.join(SEPARATOR))
    }
}

/// The fingerprint, tile and interruption [`PartialFilm::record`] wrote.
fn parse_record(record: &str) -> Result<(Option<String>, Option<Tile>, bool), String> {
    let mut parts = record.split(SEPARATOR);
    let fingerprint = parts.next().filter(|f| !f.is_empty()).map(str::to_owned);
    let (mut tile, mut interrupted) = (None, false);
    for part in parts {
        match part.strip_prefix("tile ") {
            Some(t) => tile = Some(Tile::parse(t)?),
            None if part == "interrupted" => interrupted = true,
            None => return Err(format!("unknown entry \"{part}\"")),
        }
    }
    Ok((fingerprint, tile, interrupted))
}

/// Refuses, before any pixel memory is taken, a file whose header claims an
/// image too large to render or more pixels than the file could hold.
fn check_header(path: &Path) -> Result<(), String> {
    let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| e.to_string())?;
    let header = meta.headers.first().ok_or("it holds no image")?;
    let file_len = std::fs::metadata(path).map_err(|e| e.to_string())?.len();
    let display = header.shared_attributes.display_window.size;
    for size in [header.layer_size, display] {
        let (w, h) = (size.width() as u64, size.height() as u64);
        check_size(w, h)?;
        // Decoded as four 32-bit floats a pixel.
        check_expansion(w as u32, h as u32, w * h * 16, file_len)?;
    }
    Ok(())
}

/// Adds the text attribute `name` = `value` (printable ASCII) to `attributes`.
fn insert_text(
    attributes: &mut exr::prelude::LayerAttributes,
    name: &str,
    value: &str,
) -> Result<(), String> {
    use exr::prelude::{AttributeValue, Text};
    let printable = value.bytes().all(|b| b.is_ascii_graphic() || b == b' ');
    let text = Text::new_or_none(value)
        .filter(|_| printable)
        .ok_or_else(|| format!("the attribute {name} is not printable ASCII"))?;
    attributes
        .other
        .insert(Text::from(name), AttributeValue::Text(text));
    Ok(())
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
            fingerprint: Some("scene 0123abcd, 16 spp".into()),
            ..PartialFilm::new(film, finished)
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

    /// A piece's place, tile and interruption survive the file, and the same
    /// piece is the same bytes every time (a re-rendered tile must be).
    #[test]
    fn exr_keeps_the_placement_tile_and_interruption_in_the_same_bytes() {
        let dir = tempfile::tempdir().unwrap();
        let mut original = partial();
        original.placement = Placement {
            image: UVec2::new(9, 40),
            origin: UVec2::new(3, 17),
        };
        original.tile = Some(Tile { index: 2, count: 7 });
        original.interrupted = true;
        let path = dir.path().join("piece.exr");
        original.save(&path).unwrap();
        let first = std::fs::read(&path).unwrap();
        assert_eq!(PartialFilm::load(&path).unwrap(), original);
        for _ in 0..8 {
            original.save(&path).unwrap();
            assert!(std::fs::read(&path).unwrap() == first, "other bytes");
        }
        for (tile, interrupted) in [(None, true), (Some(Tile { index: 0, count: 1 }), false)] {
            let piece = PartialFilm {
                tile,
                interrupted,
                fingerprint: None,
                ..original.clone()
            };
            piece.save(&path).unwrap();
            assert_eq!(PartialFilm::load(&path).unwrap(), piece);
        }
        original.fingerprint = Some("a; b".into());
        let e = original.save(&path).unwrap_err().to_string();
        assert!(e.contains("fingerprint holds"), "{e}");
    }

    #[test]
    fn tiles_deal_out_the_rows_in_turn() {
        let tile = Tile::parse("2/5").unwrap();
        let rows: Vec<u32> = (0..13).filter(|&y| tile.has_row(y)).collect();
        assert_eq!(rows, [2, 7, 12]);
        assert_eq!(tile.row_span(13), Some((2, 13)));
        assert_eq!(tile.row_span(12), Some((2, 8)));
        assert_eq!(tile.row_span(2), None);
        for height in 0..13 {
            let rows = (0..height).filter(|&y| tile.has_row(y)).count() as u32;
            assert_eq!(tile.row_count(height), rows, "{height} rows");
        }
        for bad in ["5/5", "1/0", "1", "a/2", "-1/2"] {
            assert!(Tile::parse(bad).is_err(), "{bad}");
        }
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
