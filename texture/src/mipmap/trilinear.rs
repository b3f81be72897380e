//! Trilinear filtering: bilinear lookups in the two levels around a footprint width,
//! blended.

use glam::{Vec2, Vec3};

use super::MipMap;
use crate::image::{lerp, reduce_st};
use crate::WrapMode;

impl MipMap {
    /// Trilinear: bilinear lookups in the two levels around level_for_width(width),
    /// linearly blended by the fractional level (pbrt-v4 section 10.4.3, but with the
    /// caller's width as given, and blending below level 1 too).
    #[inline]
    pub fn trilinear(&self, st: Vec2, width: f32, wrap: WrapMode) -> Vec3 {
        let level = self.level_for_width(width);
        let st = reduce_st(st, wrap);
        let lower = level as usize; // level is finite and ≥ 0
        let frac = level - lower as f32;
        let fine = self.level(lower).bilinear(st, wrap);
        if frac == 0.0 {
            return fine;
        }
        lerp(fine, self.level(lower + 1).bilinear(st, wrap), frac)
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::{assert_close, palette_image};
    use super::*;

    #[test]
    fn trilinear_blends_the_two_levels_around_the_width() {
        let mip = MipMap::new(palette_image(16, 16));
        let st = Vec2::new(0.3, 0.6);
        let wrap = WrapMode::Mirror;
        // Level 1.25: three quarters level 1, a quarter level 2.
        let width = 2f32.powf(1.25) / 16.0;
        let want = mip.bilinear(1, st, wrap) * 0.75 + mip.bilinear(2, st, wrap) * 0.25;
        assert_close(mip.trilinear(st, width, wrap), want, 1e-5, "level 1.25");
        assert_eq!(
            mip.trilinear(st, 1.0 / 16.0, wrap),
            mip.bilinear(0, st, wrap)
        );
        assert_eq!(mip.trilinear(st, 100.0, wrap), mip.levels()[4].texel(0, 0));
    }
}
