//! Lookups in one pyramid level: the nearest texel and bilinear interpolation.

use glam::{Vec2, Vec3};

use super::MipMap;
use crate::WrapMode;

impl MipMap {
    /// Nearest texel of `level` at st (texture coords, `[0, 1]²` = one copy of the
    /// image), wrapped: texel `(⌊s·w⌋, ⌊t·h⌋)`. Levels past the last use the last.
    #[inline]
    pub fn nearest(&self, level: usize, st: Vec2, wrap: WrapMode) -> Vec3 {
        self.level(level).nearest(st, wrap)
    }

    /// Bilinear interpolation of `level` at st (texel centres at (i+0.5)/n), wrapped.
    ///
    /// With `(x, y) = (s·w − ½, t·h − ½)`, blends the four texels around `(x, y)` by
    /// the fractional parts of `x` and `y` (pbrt-v4 `Image::Bilerp`, section 10.4.3).
    #[inline]
    pub fn bilinear(&self, level: usize, st: Vec2, wrap: WrapMode) -> Vec3 {
        self.level(level).bilinear(st, wrap)
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::{assert_close, palette_image, WRAPS};
    use super::*;

    #[test]
    fn bilinear_hits_texels_at_centres_and_averages_between() {
        let image = palette_image(4, 2);
        let mip = MipMap::new(image.clone());
        let centre = |x: u32, y: u32| Vec2::new((x as f32 + 0.5) / 4.0, (y as f32 + 0.5) / 2.0);
        for wrap in WRAPS {
            for y in 0..2 {
                for x in 0..4 {
                    assert_eq!(mip.bilinear(0, centre(x, y), wrap), image.texel(x, y));
                    assert_eq!(mip.nearest(0, centre(x, y), wrap), image.texel(x, y));
                }
            }
        }
        // Halfway between texels (1, 0) and (2, 0).
        let half = Vec2::new(0.5, 0.25);
        let want = (image.texel(1, 0) + image.texel(2, 0)) / 2.0;
        assert_close(
            mip.bilinear(0, half, WrapMode::Clamp),
            want,
            1e-6,
            "halfway",
        );
        // Halfway between texels (1, 0) and (1, 1).
        let quarter = Vec2::new(0.375, 0.5);
        let want = (image.texel(1, 0) + image.texel(1, 1)) / 2.0;
        assert_close(
            mip.bilinear(0, quarter, WrapMode::Clamp),
            want,
            1e-6,
            "vertical",
        );
        // Across the left edge: Repeat blends the last and first texels, Clamp keeps
        // the first, Mirror blends the first with itself.
        let edge = Vec2::new(0.0, 0.25);
        let (first, last) = (image.texel(0, 0), image.texel(3, 0));
        assert_close(
            mip.bilinear(0, edge, WrapMode::Repeat),
            (first + last) / 2.0,
            1e-6,
            "repeat",
        );
        assert_close(mip.bilinear(0, edge, WrapMode::Clamp), first, 1e-6, "clamp");
        assert_close(
            mip.bilinear(0, edge, WrapMode::Mirror),
            first,
            1e-6,
            "mirror",
        );
        // The same point one period away.
        let far = edge + Vec2::new(3.0, -2.0);
        assert_close(
            mip.bilinear(0, far, WrapMode::Repeat),
            (first + last) / 2.0,
            1e-6,
            "far",
        );
        // Nearest wraps too.
        assert_eq!(
            mip.nearest(0, Vec2::new(-0.1, 0.25), WrapMode::Repeat),
            last
        );
        assert_eq!(
            mip.nearest(0, Vec2::new(-0.1, 0.25), WrapMode::Mirror),
            first
        );
        assert_eq!(
            mip.nearest(0, Vec2::new(1.1, 0.75), WrapMode::Clamp),
            image.texel(3, 1)
        );
    }
}
