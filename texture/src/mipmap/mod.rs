//! MIP maps (Williams 1983, "Pyramidal Parametrics"): an image pyramid built with an
//! exact area-weighted box filter, and the lookups pbrt-v4 offers on it (section
//! 10.4): nearest texel, bilinear, trilinear and elliptically weighted average.
//!
//! This file holds the [`MipMap`] type and the choice of level for a footprint width.
//! Each other concept has its own file:
//! - `pyramid`: building the levels, with an exact area-weighted box filter;
//! - `single_level`: nearest-texel and bilinear lookups in one level;
//! - `trilinear`: bilinear lookups in two levels, blended;
//! - `ewa`: the elliptically weighted average.
//!
//! Lookups take texture coordinates `st`, where `[0, 1]²` is one copy of the image
//! and `t = 0` is the top row (see [`Image`]). They never allocate (but
//! [`MipMap::ewa_explained`], which lists what it read) and never panic:
//! NaN or infinite inputs give a finite color.

mod ewa;
mod pyramid;
mod single_level;
#[cfg(test)]
mod test_support;
mod trilinear;

pub use ewa::{EwaExplained, EwaFallback, EwaRead, EwaTexel};

use crate::Image;

/// An image pyramid from the full-resolution image down to 1×1.
#[derive(Clone, Debug)]
pub struct MipMap {
    levels: Vec<Image>,
}

impl MipMap {
    pub fn levels(&self) -> &[Image] {
        &self.levels
    }

    pub fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// The continuous level whose texel size matches a footprint `width` (in st units,
    /// i.e. fraction of the image): level = log2(width · max(w0, h0)), clamped to
    /// `[0, level_count − 1]`. Zero, negative or NaN widths give 0, infinite ones the
    /// last level.
    ///
    /// pbrt-v4's `MIPMap::Filter` uses `nLevels − 1 + log2(width)`, which is the same
    /// for power-of-two square images; `max(w0, h0)` also covers the other sizes.
    #[inline]
    pub fn level_for_width(&self, width: f32) -> f32 {
        self.clamp_level((width * self.max_side()).log2())
    }

    /// A continuous `level` clamped to the pyramid, `[0, level_count − 1]`;
    /// NaN gives 0.
    #[inline]
    pub fn clamp_level(&self, level: f32) -> f32 {
        if level >= 0.0 {
            level.min(self.last_level() as f32)
        } else {
            0.0 // also NaN
        }
    }

    /// Level `level`, or the last one if `level` is past it.
    #[inline]
    fn level(&self, level: usize) -> &Image {
        &self.levels[level.min(self.last_level())]
    }

    #[inline]
    fn last_level(&self) -> usize {
        self.levels.len() - 1
    }

    #[inline]
    fn max_side(&self) -> f32 {
        let level0 = &self.levels[0];
        level0.width().max(level0.height()) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::test_support::{assert_close, checker_image, palette_image, WRAPS};
    use super::*;
    use glam::{Vec2, Vec3};

    #[test]
    fn constant_image_is_constant_under_every_filter() {
        let c = Vec3::new(0.2, 0.5, 0.9);
        let mip = MipMap::new(Image::from_fn(7, 5, |_, _| c));
        for level in mip.levels() {
            for t in level.texels() {
                assert_close(*t, c, 1e-6, "pyramid texel");
            }
        }
        let sts = [
            Vec2::new(0.5, 0.5),
            Vec2::new(0.01, 0.99),
            Vec2::new(-0.3, 1.7),
            Vec2::new(13.37, -42.1),
            Vec2::new(f32::NAN, f32::INFINITY),
        ];
        let widths = [0.0, 1e-4, 0.03, 0.2, 0.7, 5.0, f32::NAN, f32::INFINITY];
        let footprints = [
            (Vec2::ZERO, Vec2::ZERO),
            (Vec2::new(0.01, 0.0), Vec2::new(0.0, 0.01)),
            (Vec2::new(0.3, 0.1), Vec2::new(-0.01, 0.02)),
            (Vec2::new(0.05, 0.05), Vec2::new(0.05, 0.05)),
            (Vec2::new(0.2, 0.0), Vec2::ZERO),
            (Vec2::new(3.0, -1.0), Vec2::new(0.5, 0.5)),
            (Vec2::new(f32::NAN, 1e30), Vec2::new(f32::INFINITY, 0.0)),
        ];
        for wrap in WRAPS {
            for st in sts {
                // Level 0 holds c exactly, and bilinear is nested lerps: exact.
                assert_eq!(mip.nearest(0, st, wrap), c);
                assert_eq!(mip.bilinear(0, st, wrap), c);
                // Coarser levels are c up to the rounding of the box weights.
                for level in 1..mip.level_count() + 1 {
                    assert_close(mip.nearest(level, st, wrap), c, 1e-6, "nearest");
                    assert_close(mip.bilinear(level, st, wrap), c, 1e-6, "bilinear");
                }
                for width in widths {
                    assert_close(mip.trilinear(st, width, wrap), c, 1e-6, "trilinear");
                }
                for (dst0, dst1) in footprints {
                    let what = format!("ewa {wrap:?} at {st} over {dst0}, {dst1}");
                    assert_close(mip.ewa(st, dst0, dst1, wrap), c, 1e-5, &what);
                }
            }
        }
    }

    #[test]
    fn level_for_width_matches_the_texel_size() {
        let mip = MipMap::new(checker_image(256, 8));
        assert_eq!(mip.level_count(), 9);
        assert_eq!(mip.level_for_width(1.0 / 256.0), 0.0);
        assert_eq!(mip.level_for_width(1.0 / 16.0), 4.0);
        assert!((mip.level_for_width(1.0 / 90.5) - 1.5).abs() < 1e-3);
        assert_eq!(mip.level_for_width(1.0), 8.0);
        assert_eq!(mip.level_for_width(1e6), 8.0);
        assert_eq!(mip.level_for_width(f32::INFINITY), 8.0);
        assert_eq!(mip.level_for_width(1e-3), 0.0);
        assert_eq!(mip.level_for_width(0.0), 0.0);
        assert_eq!(mip.level_for_width(-1.0), 0.0);
        assert_eq!(mip.level_for_width(f32::NAN), 0.0);
        // Non-square: the longer side sets the scale.
        let wide = MipMap::new(palette_image(64, 4));
        assert_eq!(wide.level_for_width(1.0 / 16.0), 2.0);
        // EWA picks the level of its minor axis.
        let (major, minor) = (Vec2::new(0.0, 1.0 / 32.0), Vec2::new(1.0 / 64.0, 0.0));
        assert_eq!(mip.ewa_level(major, minor), 2.0);
        assert_eq!(mip.ewa_level(minor, major), 2.0);
        // Anisotropy is clamped to 8: a needle gets a minor axis of |major| / 8.
        assert_eq!(
            mip.ewa_level(Vec2::new(0.5, 0.0), Vec2::new(0.0, 1e-6)),
            4.0
        );
        assert_eq!(mip.ewa_level(Vec2::new(0.5, 0.0), Vec2::ZERO), 4.0);
        assert_eq!(mip.ewa_level(Vec2::ZERO, Vec2::ZERO), 0.0);
        assert_eq!(mip.ewa_level(Vec2::NAN, Vec2::NAN), 0.0);
    }

    #[test]
    fn nan_and_infinite_inputs_give_finite_colors() {
        let mip = MipMap::new(palette_image(33, 17));
        let bad = [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            1e30,
            -1e30,
            f32::MAX,
        ];
        for wrap in WRAPS {
            for &a in &bad {
                for &b in &[0.5, a] {
                    let v = Vec2::new(a, b);
                    let results = [
                        mip.nearest(0, v, wrap),
                        mip.bilinear(1, v, wrap),
                        mip.trilinear(v, a, wrap),
                        mip.trilinear(Vec2::splat(0.5), a, wrap),
                        mip.ewa(v, v, v.perp(), wrap),
                        mip.ewa(Vec2::splat(0.5), v, Vec2::new(0.01, 0.0), wrap),
                        mip.ewa(Vec2::splat(0.5), v, v, wrap),
                    ];
                    for r in results {
                        assert!(r.is_finite(), "{wrap:?} {v}: {r}");
                    }
                    assert!(mip.ewa_level(v, v).is_finite());
                }
            }
        }
    }
}
