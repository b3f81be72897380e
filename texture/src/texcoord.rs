use glam::Vec2;

/// Where a texture is looked up, and how far that point moves per pixel.
///
/// `duvdx` and `duvdy` are the change of uv for one pixel step in x and y (from ray
/// differentials); they describe the pixel's footprint in uv space, which filtered
/// lookups average over. All zero means "a point": no filtering.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TexCoord {
    pub uv: Vec2,
    pub duvdx: Vec2,
    pub duvdy: Vec2,
}

impl TexCoord {
    /// A lookup at `uv` with no footprint.
    pub fn point(uv: Vec2) -> Self {
        Self {
            uv,
            ..Self::default()
        }
    }
}
