//! Named textures: checkerboards, checker images and image files, read only
//! if a material uses them.

use crate::error::Problem;
use crate::format::{CheckerImageTable, ColorOrTexture, ImageTable, MaterialTable, TextureTable};
use glam::Vec3;
use glint_texture::{
    load_image, Checkerboard, ImageTexture, Texture, TextureImage, MAX_IMAGE_TEXELS,
};
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use toml::Spanned;

/// The names of the textures some material reads: only those are loaded (an
/// image nothing references is neither read nor checked).
pub(super) fn referenced(materials: &BTreeMap<String, Spanned<MaterialTable>>) -> BTreeSet<&str> {
    materials
        .values()
        .map(Spanned::get_ref)
        .flat_map(|m| [m.diffuse.as_ref(), m.specular.as_ref()])
        .flatten()
        .filter_map(|value| match value.get_ref() {
            ColorOrTexture::Texture(name) => Some(name.as_str()),
            ColorOrTexture::Color(_) => None,
        })
        .collect()
}

/// Every named texture, with image files read from `base_dir` once each.
pub(super) fn textures<'a>(
    tables: &'a BTreeMap<String, TextureTable>,
    referenced: &BTreeSet<&str>,
    base_dir: &Path,
    assets: &mut Vec<PathBuf>,
) -> Result<BTreeMap<&'a str, Texture>, Problem> {
    let mut files = ImageFiles {
        base_dir,
        assets,
        read: HashMap::new(),
    };
    let mut textures = BTreeMap::new();
    for (name, table) in tables {
        // Every texture is checked; only those a material reads are loaded.
        if let TextureTable::CheckerImage(c) = table {
            checker_image_size(name, c)?;
        }
        if !referenced.contains(name.as_str()) {
            // Kept by name only, for the list of known names in errors.
            textures.insert(name.as_str(), Texture::Constant(Vec3::ZERO));
            continue;
        }
        let texture = match table {
            TextureTable::Checkerboard(c) => Texture::Checkerboard(Checkerboard {
                analytic: c.filter.0,
                ..Checkerboard::new(c.colors[0].0, c.colors[1].0, c.checks.0)
            }),
            TextureTable::CheckerImage(c) => {
                let (checks, per_check) = (c.checks.get_ref().0, c.pixels_per_check.get_ref().0);
                let checker = Checkerboard::new(c.colors[0].0, c.colors[1].0, checks);
                let image = TextureImage::from_checkerboard(checker, per_check);
                Texture::Image(ImageTexture::new(image, c.wrap.0, c.filter.0))
            }
            TextureTable::Image(i) => {
                let image = files.image(name, i)?;
                Texture::Image(ImageTexture::new(image, i.wrap.0, i.filter.0))
            }
        };
        textures.insert(name.as_str(), texture);
    }
    Ok(textures)
}

/// Image files read from `base_dir`, each once, listed in `assets`.
struct ImageFiles<'a> {
    base_dir: &'a Path,
    assets: &'a mut Vec<PathBuf>,
    /// By canonical path.
    read: HashMap<PathBuf, Arc<TextureImage>>,
}

impl ImageFiles<'_> {
    /// The image of texture `name`, read on first use.
    fn image(&mut self, name: &str, table: &ImageTable) -> Result<Arc<TextureImage>, Problem> {
        // The same file under two spellings (./a.png, a.png) is loaded once.
        let joined = self.base_dir.join(table.file.get_ref());
        let path = std::fs::canonicalize(&joined).unwrap_or(joined.clone());
        if let Some(image) = self.read.get(&path) {
            return Ok(image.clone());
        }
        // Read under the name the scene gives, which errors then show.
        let loaded = load_image(&joined).map_err(|e| {
            Problem::new(
                table.file.span(),
                format!("textures.{name}.image.file"),
                e.to_string(),
            )
        })?;
        let image = TextureImage::new(loaded);
        self.assets.push(path.clone());
        self.read.insert(path, image.clone());
        Ok(image)
    }
}

/// A checker image's side, `checks × pixels_per_check`, within
/// [`MAX_IMAGE_TEXELS`] (in u64 and saturating: the product of two large
/// counts must not wrap).
fn checker_image_size(name: &str, c: &CheckerImageTable) -> Result<(), Problem> {
    let (checks, per_check) = (c.checks.get_ref().0, c.pixels_per_check.get_ref().0);
    let side = checks as u64 * per_check as u64;
    if side.saturating_mul(side) <= MAX_IMAGE_TEXELS {
        return Ok(());
    }
    // Point at pixels_per_check if the file set it, else at checks.
    let (key, span) = if c.pixels_per_check.span().is_empty() {
        ("checks", c.checks.span())
    } else {
        ("pixels_per_check", c.pixels_per_check.span())
    };
    Err(Problem::new(
        span,
        format!("textures.{name}.checker_image.{key}"),
        format!(
            "the image would be {side}x{side} texels (checks × pixels_per_check per side), more than the limit of {MAX_IMAGE_TEXELS} texels"
        ),
    ))
}
