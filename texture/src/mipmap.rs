//! MIP maps (Williams 1983, "Pyramidal Parametrics"): an image pyramid built with an
//! exact area-weighted box filter, and the lookups pbrt-v4 offers on it (section
//! 10.4): nearest texel, bilinear, trilinear and elliptically weighted average.
//!
//! Lookups take texture coordinates `st`, where `[0, 1]²` is one copy of the image
//! and `t = 0` is the top row (see [`Image`]). They never allocate and never panic:
//! NaN or infinite inputs give a finite color.

use std::sync::OnceLock;

use glam::{Vec2, Vec3};

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

/// An image pyramid from the full-resolution image down to 1×1.
#[derive(Clone, Debug)]
pub struct MipMap {
    levels: Vec<Image>,
}

impl MipMap {
    /// [`MAX_ANISOTROPY`], reachable through the re-exported type.
    pub const MAX_ANISOTROPY: f32 = MAX_ANISOTROPY;

    /// Builds every level from `level0` (which it keeps as level 0).
    ///
    /// Level `k + 1` has sides `max(1, ⌊side_k / 2⌋)` on each axis independently, down
    /// to 1×1 (a 5×3 image gives 5×3, 2×1, 1×1). Each level is the previous one
    /// filtered by an exact area-weighted box, separably (see `BoxWeights`). No
    /// resampling to powers of two (unlike pbrt-v4's `Image::GeneratePyramid`), and
    /// every level has the same mean as level 0.
    pub fn new(level0: Image) -> Self {
        let mut levels = vec![level0];
        loop {
            let last = levels.last().expect("level 0 exists");
            if last.width() == 1 && last.height() == 1 {
                break;
            }
            let next = downsample(last);
            levels.push(next);
        }
        Self { levels }
    }

    pub fn levels(&self) -> &[Image] {
        &self.levels
    }

    pub fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// Nearest texel of `level` at st (texture coords, [0,1]² = one copy of the image),
    /// wrapped: texel `(⌊s·w⌋, ⌊t·h⌋)`. Levels past the last use the last.
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

    /// The continuous level whose texel size matches a footprint `width` (in st units,
    /// i.e. fraction of the image): level = log2(width · max(w0, h0)), clamped to
    /// [0, level_count-1]. Zero, negative or NaN widths give 0, infinite ones the last level.
    ///
    /// pbrt-v4's `MIPMap::Filter` uses `nLevels − 1 + log2(width)`, which is the same
    /// for power-of-two square images; `max(w0, h0)` also covers the other sizes.
    #[inline]
    pub fn level_for_width(&self, width: f32) -> f32 {
        let level = (width * self.max_side()).log2();
        if level >= 0.0 {
            level.min(self.last_level() as f32)
        } else {
            0.0 // also NaN
        }
    }

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

    /// Elliptically weighted average (Heckbert 1989; pbrt-v4 MIPMap::EWA, section 10.4.4).
    ///
    /// The ellipse's axes are `dst0`, `dst1` (st-space footprint of one pixel step in x
    /// and y). The longer is the major axis; if the minor is more than
    /// [`MAX_ANISOTROPY`] times shorter it is lengthened to `|major| / MAX_ANISOTROPY`
    /// (a zero minor axis becomes perpendicular to the major one, where pbrt would fall
    /// back to bilinear). The level `ℓ = log2(|minor| · max(w0, h0))` makes the minor
    /// axis about one texel; the Gaussian-weighted averages of levels `⌊ℓ⌋` and
    /// `⌊ℓ⌋ + 1` (see `ewa_in_level`) are blended by `ℓ − ⌊ℓ⌋`. A zero footprint
    /// gives bilinear at level 0.
    pub fn ewa(&self, st: Vec2, dst0: Vec2, dst1: Vec2, wrap: WrapMode) -> Vec3 {
        let Some(axes) = EwaAxes::new(dst0, dst1) else {
            return self.bilinear(0, st, wrap);
        };
        let level = self.level_for_width(axes.minor.length());
        let lower = level as usize;
        if lower >= self.last_level() {
            return self.levels[self.last_level()].texel(0, 0);
        }
        let st = reduce_st(st, wrap);
        let frac = level - lower as f32;
        let fine = ewa_in_level(&self.levels[lower], st, axes, wrap);
        let coarse = if frac > 0.0 {
            ewa_in_level(&self.levels[lower + 1], st, axes, wrap)
        } else {
            fine
        };
        match (fine, coarse) {
            (Some(fine), Some(coarse)) => lerp(fine, coarse, frac),
            _ => self.trilinear(st, axes.major.length(), wrap),
        }
    }

    /// The continuous level `ewa` would use for these axes (for a mip-level AOV):
    /// `log2(|minor| · max(w0, h0))` of the clamped minor axis, in `[0, level_count − 1]`.
    pub fn ewa_level(&self, dst0: Vec2, dst1: Vec2) -> f32 {
        EwaAxes::new(dst0, dst1).map_or(0.0, |axes| self.level_for_width(axes.minor.length()))
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

// ---------------------------------------------------------------------------------
// Pyramid construction

/// The per-axis weights of the exact area-weighted box filter from `n` to `m` texels.
///
/// Output texel `i` averages the input over `[i·n/m, (i+1)·n/m)` in texel units, each
/// input texel `j` weighted by the length of `[j, j+1) ∩ [i·n/m, (i+1)·n/m)` divided
/// by the interval's length `n/m`. In units of `1/m` texel every bound is an integer:
/// the weight is `|[j·m, (j+1)·m) ∩ [i·n, (i+1)·n)| / n`. The weights of one output sum
/// to 1, and those of one input over all outputs to `m/n`, so the mean is preserved.
/// For even `n` (`m = n/2`) this is the 2-texel box `½, ½`; for `n = 5, m = 2` it is
/// `1, 1, ½ | ½, 1, 1` over 2.5.
#[derive(Debug, PartialEq)]
struct BoxWeights {
    /// Weights per output texel (the same for all; ≤ n; trailing ones may be 0).
    taps: usize,
    /// First input texel of each output texel; `first[i] + taps ≤ n`.
    first: Vec<usize>,
    /// `taps` weights for each output texel, in order.
    weights: Vec<f32>,
}

impl BoxWeights {
    fn new(n: usize, m: usize) -> Self {
        assert!((1..=n).contains(&m), "box filter reduces {n} texels to {m}");
        // Input texels overlapping [i·n, (i+1)·n) (1/m units): ⌊i·n/m⌋ to ⌈(i+1)·n/m⌉ − 1.
        let span = |i: usize| (i * n / m, ((i + 1) * n).div_ceil(m));
        let taps = (0..m).map(|i| span(i).1 - span(i).0).max().unwrap_or(1);
        let mut first = Vec::with_capacity(m);
        let mut weights = Vec::with_capacity(m * taps);
        for i in 0..m {
            let start = span(i).0.min(n - taps);
            first.push(start);
            let (lo, hi) = (i * n, (i + 1) * n);
            for j in start..start + taps {
                let overlap = hi.min((j + 1) * m).saturating_sub(lo.max(j * m));
                weights.push(overlap as f32 / n as f32);
            }
        }
        Self {
            taps,
            first,
            weights,
        }
    }

    /// Number of output texels.
    fn outputs(&self) -> usize {
        self.first.len()
    }

    /// First input texel and weights of output texel `i`.
    #[inline]
    fn output(&self, i: usize) -> (usize, &[f32]) {
        (self.first[i], &self.weights[i * self.taps..][..self.taps])
    }
}

/// The next pyramid level of `image`: sides `max(1, ⌊side / 2⌋)`, filtered by
/// [`BoxWeights`] along x (every row) and then along y (every column).
fn downsample(image: &Image) -> Image {
    let (w, h) = (image.width() as usize, image.height() as usize);
    let along_x = BoxWeights::new(w, (w / 2).max(1));
    let along_y = BoxWeights::new(h, (h / 2).max(1));
    let rows = filter_rows(image.texels(), w, &along_x);
    let texels = filter_columns(&rows, along_x.outputs(), &along_y);
    Image::new(along_x.outputs() as u32, along_y.outputs() as u32, texels)
}

/// Every row of `texels` (rows of `width`) filtered along x by `weights`.
fn filter_rows(texels: &[Vec3], width: usize, weights: &BoxWeights) -> Vec<Vec3> {
    let mut out = Vec::with_capacity(texels.len() / width * weights.outputs());
    for row in texels.chunks_exact(width) {
        for i in 0..weights.outputs() {
            let (first, w) = weights.output(i);
            let sum = row[first..]
                .iter()
                .zip(w)
                .filter(|(_, &w)| w != 0.0)
                .fold(Vec3::ZERO, |acc, (&t, &w)| acc + t * w);
            out.push(sum);
        }
    }
    out
}

/// Every column of `texels` (rows of `width`) filtered along y by `weights`, a row
/// at a time so that memory is read in order.
fn filter_columns(texels: &[Vec3], width: usize, weights: &BoxWeights) -> Vec<Vec3> {
    let mut out = vec![Vec3::ZERO; width * weights.outputs()];
    for (i, out_row) in out.chunks_exact_mut(width).enumerate() {
        let (first, w) = weights.output(i);
        for (k, &w) in w.iter().enumerate().filter(|(_, &w)| w != 0.0) {
            let row = &texels[(first + k) * width..][..width];
            for (o, &t) in out_row.iter_mut().zip(row) {
                *o += t * w;
            }
        }
    }
    out
}

// ---------------------------------------------------------------------------------
// EWA

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
fn ewa_in_level(image: &Image, st: Vec2, axes: EwaAxes, wrap: WrapMode) -> Option<Vec3> {
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
    use super::*;
    use crate::Checkerboard;
    use glint_snapfmt::{sig5, vec3};
    use std::fmt::Write;

    const WRAPS: [WrapMode; 3] = [WrapMode::Repeat, WrapMode::Clamp, WrapMode::Mirror];

    /// Deterministic, non-trivial contents: one of four colors by a hash of (x, y),
    /// scaled by a ramp along x.
    fn palette_image(w: u32, h: u32) -> Image {
        const PALETTE: [Vec3; 4] = [
            Vec3::new(0.9, 0.1, 0.1),
            Vec3::new(0.1, 0.8, 0.2),
            Vec3::new(0.2, 0.3, 0.9),
            Vec3::new(0.95, 0.9, 0.3),
        ];
        Image::from_fn(w, h, |x, y| {
            let ramp = 0.5 + 0.5 * (x + 1) as f32 / w as f32;
            PALETTE[((3 * x + 5 * y + x * y) % 4) as usize] * ramp
        })
    }

    /// The course's checkerboard (`checks` checks of black and white) sampled at
    /// texel centres.
    fn checker_image(side: u32, checks: u32) -> Image {
        let c = Checkerboard::new(Vec3::ZERO, Vec3::ONE, checks);
        Image::from_fn(side, side, |x, y| {
            c.evaluate((Vec2::new(x as f32, y as f32) + 0.5) / side as f32)
        })
    }

    fn assert_close(got: Vec3, want: Vec3, rel: f32, what: &str) {
        let tol = rel * want.abs().max_element().max(1e-3);
        assert!(
            (got - want).abs().max_element() <= tol,
            "{what}: got {got}, want {want}"
        );
    }

    fn assert_means_preserved(mip: &MipMap, what: &str) {
        let mean0 = mip.levels()[0].mean();
        for (k, level) in mip.levels().iter().enumerate() {
            assert_close(level.mean(), mean0, 1e-5, &format!("{what} level {k} mean"));
        }
    }

    #[test]
    fn pyramid_sizes_and_means() {
        let mut s = String::new();
        let cases = [
            ("5x3 palette", palette_image(5, 3)),
            ("6x6 palette", palette_image(6, 6)),
            ("256x256 checkerboard, 8 checks", checker_image(256, 8)),
        ];
        for (name, image) in cases {
            let mip = MipMap::new(image);
            assert_means_preserved(&mip, name);
            writeln!(s, "{name}: {} levels", mip.level_count()).unwrap();
            for (k, level) in mip.levels().iter().enumerate() {
                let (w, h) = (level.width(), level.height());
                writeln!(s, "  level {k}: {w}x{h}, mean {}", vec3(level.mean())).unwrap();
                if w * h <= 9 {
                    for (i, t) in level.texels().iter().enumerate() {
                        writeln!(
                            s,
                            "    texel ({}, {}): {}",
                            i as u32 % w,
                            i as u32 / w,
                            vec3(*t)
                        )
                        .unwrap();
                    }
                }
            }
        }
        insta::assert_snapshot!(s);
    }

    #[test]
    fn every_size_halves_by_floor_and_keeps_the_mean() {
        let sizes = (1..=17).flat_map(|w| (1..=9).map(move |h| (w, h))).chain([
            (257, 129),
            (1, 300),
            (300, 1),
            (1023, 7),
        ]);
        for (w, h) in sizes {
            let mip = MipMap::new(palette_image(w, h));
            let levels = mip.levels();
            for pair in levels.windows(2) {
                assert_eq!(pair[1].width(), (pair[0].width() / 2).max(1));
                assert_eq!(pair[1].height(), (pair[0].height() / 2).max(1));
            }
            let last = levels.last().unwrap();
            assert_eq!((last.width(), last.height()), (1, 1), "{w}x{h}");
            assert_eq!(mip.level_count(), 1 + w.max(h).ilog2() as usize, "{w}x{h}");
            assert_means_preserved(&mip, &format!("{w}x{h}"));
        }
    }

    #[test]
    fn even_sides_use_the_two_by_two_box() {
        let v = |x: f32| Vec3::new(x, 2.0 * x, -x);
        let texels = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0].map(v).to_vec();
        let mip = MipMap::new(Image::new(4, 2, texels));
        // (1 + 2 + 5 + 6) / 4 and (3 + 4 + 7 + 8) / 4.
        assert_eq!(mip.levels()[1].texels(), [v(3.5), v(5.5)]);
        assert_eq!(mip.levels()[2].texels(), [v(4.5)]);
        assert_eq!(
            BoxWeights::new(4, 2),
            BoxWeights {
                taps: 2,
                first: vec![0, 2],
                weights: vec![0.5; 4]
            }
        );
    }

    #[test]
    fn odd_sides_weight_texels_by_their_overlap() {
        let v = |x: f32| Vec3::splat(x);
        // 3 → 1: the mean.
        let mip = MipMap::new(Image::new(3, 1, [1.0, 2.0, 6.0].map(v).to_vec()));
        assert_eq!(mip.level_count(), 2);
        assert_close(mip.levels()[1].texel(0, 0), v(3.0), 1e-6, "3 -> 1");
        // 5 → 2: weights 1, 1, ½ | ½, 1, 1 over 2.5.
        let w = BoxWeights::new(5, 2);
        assert_eq!(w.first, [0, 2]);
        let want = [1.0, 1.0, 0.5, 0.5, 1.0, 1.0].map(|x| x / 2.5);
        assert_eq!(w.weights, want);
        let row = [1.0, 2.0, 3.0, 4.0, 5.0].map(v).to_vec();
        let mip = MipMap::new(Image::new(5, 1, row));
        let level1 = &mip.levels()[1];
        assert_close(level1.texel(0, 0), v(4.5 / 2.5), 1e-6, "5 -> 2, left");
        assert_close(level1.texel(1, 0), v(10.5 / 2.5), 1e-6, "5 -> 2, right");
        // 7 → 3: [0, 7/3), [7/3, 14/3), [14/3, 7); texel 2 splits ⅓ | ⅔.
        let w = BoxWeights::new(7, 3);
        assert_eq!(w.first, [0, 2, 4]);
        let want = [3.0, 3.0, 1.0, 2.0, 3.0, 2.0, 1.0, 3.0, 3.0].map(|x| x / 7.0);
        assert_eq!(w.weights, want);
        // A column works like a row: 1×3 → 1×1 is the mean.
        let mip = MipMap::new(Image::new(1, 3, [1.0, 2.0, 6.0].map(v).to_vec()));
        assert_close(mip.levels()[1].texel(0, 0), v(3.0), 1e-6, "1x3 -> 1x1");
    }

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

    #[test]
    fn ewa_work_is_bounded() {
        let mip = MipMap::new(checker_image(64, 4));
        let image = &mip.levels()[0];
        // An unclamped needle at level 0 would scan ~270 000 texels: refused.
        let needle = EwaAxes {
            major: Vec2::new(4.0, 4.0),
            minor: Vec2::new(0.5, -0.5),
        };
        assert!(ewa_in_level(image, Vec2::splat(0.5), needle, WrapMode::Repeat).is_none());
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
            WrapMode::Clamp
        )
        .is_some());
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

    /// Build time of a 2048×2048 pyramid. Run with
    /// `cargo test --release -p glint-texture -- --ignored --nocapture pyramid_build_time`.
    #[test]
    #[ignore]
    fn pyramid_build_time_2048() {
        let image = checker_image(2048, 8);
        let runs: Vec<f64> = (0..5)
            .map(|_| {
                let start = std::time::Instant::now();
                let mip = MipMap::new(image.clone());
                let elapsed = start.elapsed().as_secs_f64();
                assert_eq!(mip.level_count(), 12);
                elapsed
            })
            .collect();
        let best = runs.iter().cloned().fold(f64::INFINITY, f64::min);
        println!("2048x2048 pyramid build: {runs:.4?} s, best {best:.4} s");
        if !cfg!(debug_assertions) {
            assert!(best < 1.0);
        }
    }
}
