//! The texture stage of Glint: functions from surface uv to a linear RGB color.
//!
//! # Conventions
//! - Colors are **linear** RGB `f32` (no sRGB decoding happens here for procedural
//!   textures; image textures will decode sRGB once at load time).
//! - uv comes from the geometry stage: [0, 1]² on bounded shapes, world units on
//!   infinite planes. Procedural patterns repeat outside [0, 1]².
//! - Textures are a closed `enum`, evaluated by `match`: no virtual call per lookup.

mod checkerboard;

pub use checkerboard::Checkerboard;

use glam::{Vec2, Vec3};

/// A color that may vary over a surface.
#[derive(Clone, Debug, PartialEq)]
pub enum Texture {
    /// The same color everywhere.
    Constant(Vec3),
    /// The course's checkerboard of two colors.
    Checkerboard(Checkerboard),
}

impl Texture {
    /// The color at surface coordinates `uv`.
    #[inline]
    pub fn evaluate(&self, uv: Vec2) -> Vec3 {
        match self {
            Texture::Constant(c) => *c,
            Texture::Checkerboard(c) => c.evaluate(uv),
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
