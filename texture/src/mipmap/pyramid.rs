//! Building the pyramid: level sizes, and the exact area-weighted box filter that
//! makes each level from the one before.
//!
//! The pyramid is built in full by [`MipMap::new`]; textures build it lazily, on the
//! first lookup that needs it (`TextureImage::pyramid`).

use glam::Vec3;

use super::MipMap;
use crate::Image;

impl MipMap {
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
}

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

#[cfg(test)]
mod tests {
    use super::super::test_support::{assert_close, checker_image, palette_image};
    use super::*;
    use glint_snapfmt::vec3;
    use std::fmt::Write;

    fn assert_means_preserved(mip: &MipMap, what: &str) {
        let mean0 = mip.levels()[0].mean();
        for (k, level) in mip.levels().iter().enumerate() {
            assert_close(level.mean(), mean0, 1e-5, &format!("{what} level {k} mean"));
        }
    }

    /// Each channel's standard deviation over the level's texels: what a
    /// level's filtering takes away (the mean it keeps).
    fn standard_deviation(level: &Image) -> Vec3 {
        let mean = level.mean();
        let squares = level.texels().iter().map(|&t| (t - mean) * (t - mean));
        (squares.sum::<Vec3>() / level.texels().len() as f32).powf(0.5)
    }

    /// An image with no symmetry to hide a wrong texel behind: each texel's
    /// channels from a hash of its position.
    fn hashed_image(w: u32, h: u32) -> Image {
        Image::from_fn(w, h, |x, y| {
            let hash = |c: u32| {
                let mut v = (x * 73_856_093) ^ (y * 19_349_663) ^ (c * 83_492_791);
                v ^= v >> 13;
                v = v.wrapping_mul(0x5bd1_e995);
                (v >> 8) as f32 / (1 << 24) as f32
            };
            Vec3::new(hash(1), hash(2), hash(3))
        })
    }

    /// On sides that are powers of two, every texel of level k is the plain
    /// average of the `(W/w) × (H/h)` block of level 0 under it, summed here
    /// in f64 straight from level 0 (not level by level, as the pyramid is).
    #[test]
    fn power_of_two_levels_are_the_means_of_their_blocks() {
        for (w, h) in [(16, 16), (32, 8), (4, 64), (1, 16)] {
            let image = hashed_image(w, h);
            let mip = MipMap::new(image.clone());
            for (k, level) in mip.levels().iter().enumerate() {
                let (bw, bh) = (w / level.width(), h / level.height());
                for (x, y) in
                    (0..level.height()).flat_map(|y| (0..level.width()).map(move |x| (x, y)))
                {
                    let mut sum = [0.0f64; 3];
                    for (i, j) in (0..bh).flat_map(|j| (0..bw).map(move |i| (i, j))) {
                        let t = image.texel(x * bw + i, y * bh + j);
                        for c in 0..3 {
                            sum[c] += f64::from(t[c]);
                        }
                    }
                    let want = sum.map(|c| (c / f64::from(bw * bh)) as f32);
                    let got = level.texel(x, y);
                    assert_close(
                        got,
                        Vec3::from(want),
                        1e-6,
                        &format!("{w}x{h} level {k} ({x}, {y})"),
                    );
                }
            }
        }
    }

    #[test]
    fn pyramid_sizes_and_means() {
        let mut s = String::new();
        let cases = [
            ("5x3 palette", palette_image(5, 3)),
            ("6x6 palette", palette_image(6, 6)),
            ("256x256 checkerboard, 8 checks", checker_image(256, 8)),
            ("12x7 hashed", hashed_image(12, 7)),
        ];
        for (name, image) in cases {
            let mip = MipMap::new(image);
            assert_means_preserved(&mip, name);
            writeln!(s, "{name}: {} levels", mip.level_count()).unwrap();
            for (k, level) in mip.levels().iter().enumerate() {
                let (w, h) = (level.width(), level.height());
                let (mean, sd) = (level.mean(), standard_deviation(level));
                writeln!(
                    s,
                    "  level {k}: {w}x{h}, mean {}, sd {}",
                    vec3(mean),
                    vec3(sd)
                )
                .unwrap();
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
}
