//! Glint's textures as Mitsuba textures: constants, `checkerboard`s, and
//! `bitmap`s of EXR files beside the XML.

use super::{Converter, SideContents, SideFile};
use crate::mitsuba::xml::Xml;
use glam::{Affine2, Vec2};
use glint_camera::Film;
use glint_texture::{Checkerboard, ImageTexture, Texture, TextureFilter, WrapMode};

impl Converter<'_> {
    /// `texture` as the property `property`, read at Glint's uv `uv(Mitsuba uv)`.
    pub(super) fn texture(
        &mut self,
        xml: &mut Xml,
        property: &str,
        texture: &Texture,
        uv: Affine2,
        material: &str,
    ) {
        match texture {
            Texture::Constant(c) => xml.rgb(property, *c),
            Texture::Checkerboard(c) => checkerboard(xml, property, c, uv),
            Texture::Image(image) => match image.image.pattern() {
                // A rasterised checkerboard repeats as the pattern does only when
                // it repeats and has an even number of checks.
                Some(pattern) if image.wrap == WrapMode::Repeat && pattern.checks % 2 == 0 => {
                    checkerboard(xml, property, pattern, uv)
                }
                _ => self.bitmap(xml, property, image, uv, material),
            },
        }
    }

    pub(super) fn bitmap(
        &mut self,
        xml: &mut Xml,
        property: &str,
        texture: &ImageTexture,
        uv: Affine2,
        material: &str,
    ) {
        let key = std::sync::Arc::as_ptr(&texture.image) as usize;
        let file = match self.images.get(&key) {
            Some(file) => file.clone(),
            None => {
                let file = format!("texture-{}.exr", self.images.len());
                let image = texture.image.image();
                let mut film = Film::new(glam::UVec2::new(image.width(), image.height()));
                film.pixels_mut().copy_from_slice(image.texels());
                self.files.push(SideFile {
                    name: file.clone(),
                    contents: SideContents::Exr(film),
                });
                self.images.insert(key, file.clone());
                file
            }
        };
        if matches!(
            texture.filter,
            TextureFilter::Trilinear | TextureFilter::Ewa
        ) {
            self.unfiltered.insert(material.to_owned());
        }
        xml.open("texture", &[("type", "bitmap"), ("name", property)]);
        xml.string("filename", &format!("{}/{file}", self.assets));
        xml.string(
            "filter_type",
            match texture.filter {
                TextureFilter::Nearest => "nearest",
                _ => "bilinear",
            },
        );
        xml.string(
            "wrap_mode",
            match texture.wrap {
                WrapMode::Repeat => "repeat",
                WrapMode::Clamp => "clamp",
                WrapMode::Mirror => "mirror",
            },
        );
        // Glint reads images at st = (u, 1 − v) with row 0 at the top, as Mitsuba
        // reads its uv (row 0 at v = 0).
        xml.texture_transform(Affine2::from_cols(Vec2::X, -Vec2::Y, Vec2::Y) * uv);
        xml.close("texture");
    }
}

/// A checkerboard as Mitsuba's `checkerboard`: its pattern has 2 × 2 checks
/// over the unit square (`color0` where `frac(u) > ½` equals `frac(v) > ½`),
/// which is Glint's N × N (first color where the check's indices sum to an
/// even number) once uv is scaled by N/2.
pub(super) fn checkerboard(xml: &mut Xml, property: &str, c: &Checkerboard, uv: Affine2) {
    xml.open("texture", &[("type", "checkerboard"), ("name", property)]);
    xml.rgb("color0", c.colors[0]);
    xml.rgb("color1", c.colors[1]);
    xml.texture_transform(Affine2::from_scale(Vec2::splat(c.checks as f32 / 2.0)) * uv);
    xml.close("texture");
}
