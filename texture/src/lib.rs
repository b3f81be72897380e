//! The texture stage of Glint: functions from surface uv to a linear RGB color, and
//! environment maps (cube maps, lat-long images) from direction to radiance.
//!
//! # Entry points
//! - [`Texture`]: a color over a surface (constant, [`Checkerboard`] or
//!   [`ImageTexture`]), evaluated with [`Texture::evaluate`] at a [`TexCoord`]
//!   (a uv and its per-pixel footprint).
//! - [`load_image`] reads a file into a linear [`Image`]; [`TextureImage::new`]
//!   shares it between textures, and [`ImageTexture::new`] maps it with a
//!   [`WrapMode`] and a [`TextureFilter`].
//! - [`MipMap`]: the image pyramid and its lookups ([`MipMap::nearest`],
//!   [`MipMap::bilinear`], [`MipMap::trilinear`], [`MipMap::ewa`]).
//! - [`Environment`]: radiance by direction from a constant, a [`CubeMap`] or a
//!   [`LatLongMap`], evaluated with [`Environment::radiance`].
//!
//! # Conventions
//! - Colors are **linear** RGB `f32`. Procedural textures are defined in linear RGB;
//!   image files are decoded once, at load time ([`load_image`]): 8/16-bit formats
//!   as sRGB, float formats as linear.
//! - uv comes from the geometry stage: \[0, 1\]² on bounded shapes, world units on
//!   infinite planes. Procedural patterns repeat outside \[0, 1\]².
//! - Textures are a closed `enum`, evaluated by `match`: no virtual call per lookup.
//! - Image texture coordinates are `st = (u, 1 − v)` (v grows up the surface, image
//!   rows grow down), so images appear upright; \[0, 1\]² is one copy of the image.
//! - MIP-map pyramids are built lazily, only for textures sampled with a filter
//!   that reads them (trilinear, EWA), and shared by every texture of the same image.

mod checkerboard;
mod environment;
mod image;
mod image_texture;
mod io;
mod lookup;
mod mipmap;
mod texcoord;

pub use crate::image::{Image, WrapMode};
pub use checkerboard::Checkerboard;
pub use environment::{
    cube_direction, cube_face_st, latlong_coordinates, latlong_direction,
    latlong_direction_and_sin_theta, latlong_direction_of, latlong_texel, latlong_uv, CubeFace,
    CubeMap, Environment, LatLongMap,
};
pub use image_texture::{ImageTexture, TextureFilter, TextureImage};
pub use io::{load_image, srgb_to_linear, ImageLoadError, MAX_IMAGE_SIDE, MAX_IMAGE_TEXELS};
pub use lookup::{LookupExplained, TexelRead};
pub use mipmap::{EwaExplained, EwaFallback, EwaRead, EwaTexel, MipMap};
pub use texcoord::TexCoord;

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

use glam::{Vec2, Vec3};

/// A color that may vary over a surface.
#[derive(Clone, Debug, PartialEq)]
pub enum Texture {
    /// The same color everywhere.
    Constant(Vec3),
    /// The course's checkerboard of two colors.
    Checkerboard(Checkerboard),
    /// An image, filtered over the pixel's footprint.
    Image(ImageTexture),
}

impl Texture {
    /// The color over the footprint described by `tc`.
    #[inline]
    pub fn evaluate(&self, tc: &TexCoord) -> Vec3 {
        match self {
            Texture::Constant(c) => *c,
            Texture::Checkerboard(c) => c.evaluate_filtered(tc),
            Texture::Image(t) => t.evaluate(tc),
        }
    }

    /// [`Self::evaluate`] at the point `uv` (a footprint of zero size), without
    /// building a [`TexCoord`]: constants and unfiltered checkerboards read
    /// nothing else.
    #[inline]
    pub fn evaluate_at(&self, uv: Vec2) -> Vec3 {
        match self {
            Texture::Constant(c) => *c,
            Texture::Checkerboard(c) if !c.analytic => c.evaluate(uv),
            _ => self.evaluate(&TexCoord::point(uv)),
        }
    }

    /// Whether [`Self::evaluate`] uses the footprint (`duvdx`, `duvdy`) at all, so
    /// callers can skip computing it.
    pub fn uses_footprint(&self) -> bool {
        match self {
            Texture::Constant(_) => false,
            Texture::Checkerboard(c) => c.analytic,
            Texture::Image(t) => t.filter.uses_pyramid(),
        }
    }

    /// The pyramid level a lookup at `tc` reads (0 where there is no pyramid).
    pub fn mip_level(&self, tc: &TexCoord) -> f32 {
        match self {
            Texture::Image(t) => t.mip_level(tc),
            _ => 0.0,
        }
    }

    /// The color if the texture is constant, so callers can skip per-hit lookups.
    pub fn as_constant(&self) -> Option<Vec3> {
        match self {
            Texture::Constant(c) => Some(*c),
            _ => None,
        }
    }
}

impl From<Vec3> for Texture {
    fn from(c: Vec3) -> Self {
        Texture::Constant(c)
    }
}

impl From<Checkerboard> for Texture {
    fn from(c: Checkerboard) -> Self {
        Texture::Checkerboard(c)
    }
}
