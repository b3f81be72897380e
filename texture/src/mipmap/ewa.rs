//! The elliptically weighted average (Heckbert 1989; pbrt-v4 section 10.4.4): a
//! Gaussian-weighted mean of the texels inside the footprint's ellipse.

use std::sync::OnceLock;

use glam::{Vec2, Vec3};

use super::MipMap;
use crate::image::{lerp, reduce_st};
use crate::{Image, WrapMode};

/// The largest ratio of major to minor axis that [`MipMap::ewa`] filters
/// (pbrt-v4's default `maxAnisotropy`); longer ellipses get a longer minor axis.
pub const MAX_ANISOTROPY: f32 = 8.0;

/// Entries in the EWA Gaussian weight table (as in pbrt-v4).
const EWA_LUT_SIZE: usize = 128;

/// Falloff of the EWA Gaussian: `weight(r²) = exp(−α r²) − exp(−α)` (pbrt-v4).
const EWA_ALPHA: f32 = 2.0;

/// The most texels one EWA lookup in one level may scan. Clamped footprints need at
/// most ~1200 (the minor axis is ≤ 2 texels at the finer level, the major ≤ 8× that),
/// so this only guards against numerical surprises; beyond it `ewa` falls back to
/// trilinear filtering.
const EWA_MAX_TEXELS: f32 = 4096.0;

/// The longest footprint axis (in st units, i.e. copies of the image) that lookups
/// keep; longer ones are already blurred to the 1×1 level.
const MAX_FOOTPRINT: f32 = 1024.0;

impl MipMap {
    /// The largest ratio of major to minor axis that [`MipMap::ewa`] filters: 8,
    /// pbrt-v4's default `maxAnisotropy`. Longer ellipses get a longer minor axis.
    pub const MAX_ANISOTROPY: f32 = MAX_ANISOTROPY;

    /// Elliptically weighted average (Heckbert 1989; pbrt-v4 MIPMap::EWA, section 10.4.4).
    ///
    /// The ellipse's axes are `dst0`, `dst1` (st-space footprint of one pixel step in x
    /// and y). The longer is the major axis; if the minor is more than
    /// [`Self::MAX_ANISOTROPY`] times shorter it is lengthened to
    /// `|major| / MAX_ANISOTROPY` (a zero minor axis becomes perpendicular to the major
    /// one, where pbrt would fall back to bilinear). The level
    /// `ℓ = log2(|minor| · max(w0, h0))` makes the minor axis about one texel; the
    /// Gaussian-weighted averages of levels `⌊ℓ⌋` and `⌊ℓ⌋ + 1` (see `ewa_in_level`)
    /// are blended by `ℓ − ⌊ℓ⌋`. A zero footprint gives bilinear at level 0.
    pub fn ewa(&self, st: Vec2, dst0: Vec2, dst1: Vec2, wrap: WrapMode) -> Vec3 {
        self.ewa_with(st, dst0, dst1, wrap, &mut ())
    }

    /// [`MipMap::ewa`], with what it read: each texel of the ellipse in each
    /// level with its share of the result, or the filter it fell back to.
    pub fn ewa_explained(&self, st: Vec2, dst0: Vec2, dst1: Vec2, wrap: WrapMode) -> EwaExplained {
        let mut reads = EwaReads::default();
        let value = self.ewa_with(st, dst0, dst1, wrap, &mut reads);
        EwaExplained {
            value,
            reads: reads.finish(),
        }
    }

    /// [`MipMap::ewa`] telling `sink` what it reads.
    #[inline(always)]
    fn ewa_with(
        &self,
        st: Vec2,
        dst0: Vec2,
        dst1: Vec2,
        wrap: WrapMode,
        sink: &mut impl EwaSink,
    ) -> Vec3 {
        let Some(axes) = EwaAxes::new(dst0, dst1) else {
            sink.fallback(EwaFallback::Bilinear);
            return self.bilinear(0, st, wrap);
        };
        let level = self.level_for_width(axes.minor.length());
        let lower = level as usize;
        if lower >= self.last_level() {
            sink.fallback(EwaFallback::LastLevel);
            return self.levels[self.last_level()].texel(0, 0);
        }
        let st = reduce_st(st, wrap);
        let frac = level - lower as f32;
        sink.level(lower, if frac > 0.0 { 1.0 - frac } else { 1.0 });
        let fine = ewa_in_level(&self.levels[lower], st, axes, wrap, sink);
        let coarse = if frac > 0.0 {
            sink.level(lower + 1, frac);
            ewa_in_level(&self.levels[lower + 1], st, axes, wrap, sink)
        } else {
            fine
        };
        match (fine, coarse) {
            (Some(fine), Some(coarse)) => lerp(fine, coarse, frac),
            _ => {
                let width = axes.major.length();
                sink.fallback(EwaFallback::Trilinear { width });
                self.trilinear(st, width, wrap)
            }
        }
    }

    /// The continuous level `ewa` would use for these axes (for a mip-level AOV):
    /// `log2(|minor| · max(w0, h0))` of the clamped minor axis, in `[0, level_count − 1]`.
    pub fn ewa_level(&self, dst0: Vec2, dst1: Vec2) -> f32 {
        EwaAxes::new(dst0, dst1).map_or(0.0, |axes| self.level_for_width(axes.minor.length()))
    }
}

/// What an EWA lookup read ([`MipMap::ewa_explained`]).
#[derive(Clone, Debug, PartialEq)]
pub struct EwaExplained {
    /// [`MipMap::ewa`]'s result.
    pub value: Vec3,
    pub reads: EwaRead,
}

/// The texels an EWA lookup averaged, or the filter it used instead.
#[derive(Clone, Debug, PartialEq)]
pub enum EwaRead {
    /// The texels inside the ellipse in one level or two, each with its share
    /// of the result: its Gaussian weight over its level's sum, times the
    /// level's blend weight. The shares add up to 1.
    Texels(Vec<EwaTexel>),
    /// The lookup was not an ellipse average.
    Fallback(EwaFallback),
}

/// One texel of an EWA average.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EwaTexel {
    pub level: usize,
    /// Texel coordinates before wrapping.
    pub x: i64,
    pub y: i64,
    /// The texel's share of the result.
    pub weight: f32,
}

/// What an EWA lookup did instead of averaging an ellipse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EwaFallback {
    /// A zero footprint: bilinear in level 0.
    Bilinear,
    /// A footprint at or past the last level: its one texel.
    LastLevel,
    /// An ellipse whose box held more than 4096 texels (the clamps rule it
    /// out): trilinear over the major axis, `width` long.
    Trilinear { width: f32 },
}

/// Sees what [`MipMap::ewa_with`] reads; `()` sees nothing and costs nothing.
trait EwaSink {
    /// Level `level` is read next; its mean enters the result with weight `blend`.
    #[inline(always)]
    fn level(&mut self, _level: usize, _blend: f32) {}
    /// A texel of the current level with its Gaussian weight.
    #[inline(always)]
    fn texel(&mut self, _x: i64, _y: i64, _weight: f32) {}
    #[inline(always)]
    fn fallback(&mut self, _fallback: EwaFallback) {}
}

impl EwaSink for () {}

/// An [`EwaSink`] keeping every read, for [`MipMap::ewa_explained`].
#[derive(Default)]
struct EwaReads {
    /// Per level read: (level, blend, its texels with their Gaussian weights).
    levels: Vec<(usize, f32, Vec<EwaTexel>)>,
    fallback: Option<EwaFallback>,
}

impl EwaSink for EwaReads {
    fn level(&mut self, level: usize, blend: f32) {
        self.levels.push((level, blend, Vec::new()));
    }

    fn texel(&mut self, x: i64, y: i64, weight: f32) {
        if let Some((level, _, texels)) = self.levels.last_mut() {
            texels.push(EwaTexel {
                level: *level,
                x,
                y,
                weight,
            });
        }
    }

    fn fallback(&mut self, fallback: EwaFallback) {
        self.fallback = Some(fallback);
    }
}

impl EwaReads {
    /// Each texel's Gaussian weight turned into its share of the result. (A
    /// level always holds a texel of positive weight: the ellipse contains the
    /// unit disc around the lookup point, and with it a texel centre.)
    fn finish(self) -> EwaRead {
        if let Some(fallback) = self.fallback {
            return EwaRead::Fallback(fallback);
        }
        let mut shares = Vec::new();
        for (_, blend, texels) in self.levels {
            let sum: f32 = texels.iter().map(|t| t.weight).sum();
            debug_assert!(sum > 0.0, "a level without a weighted texel");
            shares.extend(texels.into_iter().map(|t| EwaTexel {
                weight: blend * t.weight / sum,
                ..t
            }));
        }
        EwaRead::Texels(shares)
    }
}

/// The axes of an EWA footprint after pbrt-v4's clamping (section 10.4.4).
#[derive(Clone, Copy, Debug)]
struct EwaAxes {
    major: Vec2,
    minor: Vec2,
}

impl EwaAxes {
    /// Sorts `dst0`, `dst1` into major and minor axis and lengthens the minor axis to
    /// at least `|major| / MAX_ANISOTROPY`. NaN components count as 0 and components
    /// are clamped to `±MAX_FOOTPRINT`. `None` for a zero footprint.
    fn new(dst0: Vec2, dst1: Vec2) -> Option<Self> {
        let (mut major, mut minor) = (finite_footprint(dst0), finite_footprint(dst1));
        if major.length_squared() < minor.length_squared() {
            std::mem::swap(&mut major, &mut minor);
        }
        let major_length = major.length();
        if major_length == 0.0 {
            return None;
        }
        let min_minor = major_length / MAX_ANISOTROPY;
        if minor.length() < min_minor {
            let direction = minor.try_normalize().unwrap_or(major.perp() / major_length);
            minor = direction * min_minor;
        }
        Some(Self { major, minor })
    }
}

/// `v` with NaN components set to 0 and the others clamped to `±MAX_FOOTPRINT`.
#[inline]
fn finite_footprint(v: Vec2) -> Vec2 {
    let clean = |x: f32| {
        if x.is_nan() {
            0.0
        } else {
            x.clamp(-MAX_FOOTPRINT, MAX_FOOTPRINT)
        }
    };
    Vec2::new(clean(v.x), clean(v.y))
}

/// The EWA Gaussian weights: entry `i` is `exp(−α r²) − exp(−α)` at `r² = i / (N − 1)`,
/// α = 2 (pbrt-v4's `MIPFilterLUT`), computed once.
fn ewa_weights() -> &'static [f32; EWA_LUT_SIZE] {
    static LUT: OnceLock<[f32; EWA_LUT_SIZE]> = OnceLock::new();
    LUT.get_or_init(|| {
        std::array::from_fn(|i| {
            let r2 = i as f32 / (EWA_LUT_SIZE - 1) as f32;
            (-EWA_ALPHA * r2).exp() - (-EWA_ALPHA).exp()
        })
    })
}

/// The EWA average of `image` (one pyramid level) at reduced `st` over the ellipse
/// with `axes` (Heckbert 1989, section 3.5.8; pbrt-v4 `MIPMap::EWA`).
///
/// In this level's texel space (texel centres at integers, `p = st·res − ½`, axes
/// `a = major·res`, `b = minor·res`), the ellipse is `A x² + B x y + C y² < F` with
/// `A = a_y² + b_y² + 1`, `B = −2 (a_x a_y + b_x b_y)`, `C = a_x² + b_x² + 1`,
/// `F = A C − B²/4`: the footprint convolved with a unit-radius reconstruction filter
/// (the `+ 1`s), so it always contains the unit disc around `p`. Its bounding box has
/// half-sides `√C` in x and `√A` in y. Each texel inside, at `r² = (A x² + B x y + C y²)/F`,
/// gets the Gaussian weight from [`ewa_weights`]; the result is the weighted mean.
/// `None` if the box holds more than [`EWA_MAX_TEXELS`] texels.
/// `sink` sees each texel with its weight.
fn ewa_in_level(
    image: &Image,
    st: Vec2,
    axes: EwaAxes,
    wrap: WrapMode,
    sink: &mut impl EwaSink,
) -> Option<Vec3> {
    let res = image.size();
    let p = st * res - 0.5;
    let (a, b) = (axes.major * res, axes.minor * res);
    let ca = a.y * a.y + b.y * b.y + 1.0;
    let cb = -2.0 * (a.x * a.y + b.x * b.y);
    let cc = a.x * a.x + b.x * b.x + 1.0;
    let inv_f = 1.0 / (ca * cc - 0.25 * cb * cb);
    let half = Vec2::new(cc.sqrt(), ca.sqrt());
    let (lo, hi) = ((p - half).ceil(), (p + half).floor());
    let extent = hi - lo + 1.0;
    let texels = extent.x * extent.y;
    if texels.is_nan() || texels > EWA_MAX_TEXELS {
        return None;
    }
    let (ca, cb, cc) = (ca * inv_f, cb * inv_f, cc * inv_f);
    let lut = ewa_weights();
    let mut sum = Vec3::ZERO;
    let mut sum_weights = 0.0;
    for y in lo.y as i64..=hi.y as i64 {
        let dy = y as f32 - p.y;
        for x in lo.x as i64..=hi.x as i64 {
            let dx = x as f32 - p.x;
            let r2 = ca * dx * dx + cb * dx * dy + cc * dy * dy;
            if r2 < 1.0 {
                let weight = lut[((r2 * EWA_LUT_SIZE as f32) as usize).min(EWA_LUT_SIZE - 1)];
                sum += weight * image.texel_wrapped(x, y, wrap);
                sum_weights += weight;
                sink.texel(x, y, weight);
            }
        }
    }
    // The unit disc around p holds a texel with r² ≤ ½, so sum_weights > 0; but be safe.
    Some(if sum_weights > 0.0 {
        sum / sum_weights
    } else {
        image.bilinear(st, wrap)
    })
}

#[cfg(test)]
mod tests {
    use super::super::test_support::checker_image;
    use super::*;
    use glint_snapfmt::sig5;

    #[test]
    fn ewa_matches_trilinear_when_isotropic_and_keeps_contrast_when_not() {
        // Smooth: both filters are small blurs of a slowly varying image.
        let smooth = MipMap::new(Image::from_fn(128, 128, |x, y| {
            let (s, t) = ((x as f32 + 0.5) / 128.0, (y as f32 + 0.5) / 128.0);
            let v = (std::f32::consts::TAU * s).sin() * (std::f32::consts::TAU * t).cos();
            Vec3::new(0.5 + 0.4 * v, 0.5 - 0.3 * v, 0.5)
        }));
        let r = 4.0 / 128.0;
        for i in 0..20 {
            let st = Vec2::new(0.05 * i as f32, 0.37 + 0.031 * i as f32);
            let ewa = smooth.ewa(st, Vec2::new(r, 0.0), Vec2::new(0.0, r), WrapMode::Repeat);
            let tri = smooth.trilinear(st, r, WrapMode::Repeat);
            let diff = (ewa - tri).abs().max_element();
            assert!(diff < 0.01, "at {st}: ewa {ewa}, trilinear {tri}");
        }

        // Checks of 32 px: along the diagonal (1, 1) every check has the same color.
        // A needle footprint along that diagonal stays inside one color under EWA,
        // while trilinear (which must use the major axis) averages many checks to grey.
        let checks = MipMap::new(checker_image(256, 8));
        let major = Vec2::new(48.0, 48.0) / 256.0;
        let minor = Vec2::new(6.0, -6.0) / 256.0;
        let white = Vec2::new(48.0, 16.0) / 256.0; // centre of check (1, 0)
        let black = Vec2::new(16.0, 16.0) / 256.0; // centre of check (0, 0)
        let wrap = WrapMode::Repeat;
        let ewa_contrast =
            checks.ewa(white, major, minor, wrap).x - checks.ewa(black, major, minor, wrap).x;
        let width = major.length();
        let tri_contrast =
            checks.trilinear(white, width, wrap).x - checks.trilinear(black, width, wrap).x;
        assert!(ewa_contrast > 0.6, "EWA contrast {ewa_contrast}");
        assert!(
            tri_contrast.abs() < 0.05,
            "trilinear contrast {tri_contrast}"
        );
    }

    #[test]
    fn ewa_work_is_bounded() {
        let mip = MipMap::new(checker_image(64, 4));
        let image = &mip.levels()[0];
        // An unclamped needle at level 0 would scan ~270 000 texels: refused.
        let needle = EwaAxes {
            major: Vec2::new(4.0, 4.0),
            minor: Vec2::new(0.5, -0.5),
        };
        assert!(ewa_in_level(image, Vec2::splat(0.5), needle, WrapMode::Repeat, &mut ()).is_none());
        // Through `ewa` the clamps keep it small: the same lookup still gives a
        // finite blur of the two colors.
        let v = mip.ewa(Vec2::splat(0.5), needle.major, Vec2::ZERO, WrapMode::Repeat);
        assert!(v.is_finite() && v.min_element() >= 0.0 && v.max_element() <= 1.0);
        // Nearly parallel long axes: clamped by length only, still within the bound.
        let axes = EwaAxes::new(Vec2::new(0.25, 0.25), Vec2::new(0.03, 0.0301)).unwrap();
        let level = mip.level_for_width(axes.minor.length()) as usize;
        assert!(ewa_in_level(
            &mip.levels()[level],
            Vec2::splat(0.5),
            axes,
            WrapMode::Clamp,
            &mut ()
        )
        .is_some());
    }

    #[test]
    fn explained_lookups_are_the_lookups_and_their_shares_make_the_value() {
        let mip = MipMap::new(Image::from_fn(16, 16, |x, y| {
            Vec3::new(x as f32, y as f32, ((x * 5 + y * 3) % 7) as f32)
        }));
        let footprints = [
            // Level 0.68: two levels blended.
            (Vec2::new(0.2, 0.0), Vec2::new(0.0, 0.1)),
            // A needle across a corner, level 1.3.
            (Vec2::new(0.5, 0.45), Vec2::new(-0.12, 0.13)),
            // Exactly level 1: one level read.
            (Vec2::new(0.125, 0.0), Vec2::new(0.0, 0.125)),
        ];
        for wrap in [WrapMode::Repeat, WrapMode::Clamp] {
            for (k, (d0, d1)) in footprints.into_iter().enumerate() {
                let st = Vec2::new(0.03 + 0.41 * k as f32, 0.97 - 0.3 * k as f32);
                let explained = mip.ewa_explained(st, d0, d1, wrap);
                let value = mip.ewa(st, d0, d1, wrap);
                assert_eq!(explained.value.to_array(), value.to_array());
                let EwaRead::Texels(texels) = explained.reads else {
                    panic!("footprint {k} fell back");
                };
                let levels: Vec<usize> = texels.iter().map(|t| t.level).collect();
                let (first, last) = (levels[0], levels[levels.len() - 1]);
                let expected = [(0, 1), (1, 2), (1, 1)][k];
                assert_eq!((first, last), expected, "footprint {k}");
                let mut sum = Vec3::ZERO;
                let mut shares = 0.0;
                for t in &texels {
                    sum += t.weight * mip.levels()[t.level].texel_wrapped(t.x, t.y, wrap);
                    shares += t.weight;
                }
                assert!((shares - 1.0).abs() < 1e-5, "footprint {k}: {shares}");
                assert!(
                    (sum - value).abs().max_element() < 1e-4 * value.max_element(),
                    "footprint {k}: {sum} against {value}"
                );
            }
        }
        // A zero footprint falls back to bilinear, a huge one to the last level.
        let zero = mip.ewa_explained(Vec2::splat(0.3), Vec2::ZERO, Vec2::ZERO, WrapMode::Repeat);
        assert_eq!(zero.reads, EwaRead::Fallback(EwaFallback::Bilinear));
        let huge = Vec2::new(3.0, 0.0);
        let last = mip.ewa_explained(Vec2::splat(0.3), huge, huge.perp(), WrapMode::Repeat);
        assert_eq!(last.reads, EwaRead::Fallback(EwaFallback::LastLevel));
    }

    #[test]
    fn ewa_weight_table_falls_from_one_minus_e_minus_two_to_zero() {
        let lut = ewa_weights();
        assert!((lut[0] - (1.0 - (-2.0f32).exp())).abs() < 1e-6);
        assert!((lut[64] - ((-2.0 * 64.0 / 127.0f32).exp() - (-2.0f32).exp())).abs() < 1e-6);
        assert!(lut[EWA_LUT_SIZE - 1].abs() < 1e-7);
        assert!(lut.windows(2).all(|w| w[0] > w[1]));
        assert_eq!(sig5(lut[1]), "0.84904"); // pbrt-v4's table: 0.849040031
    }
}
