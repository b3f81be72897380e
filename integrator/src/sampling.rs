//! Sample patterns over the unit square and the per-pixel random number streams.
//!
//! Patterns (pbrt-v4 chapter 8 has the background):
//! - `grid`: the course's uniform grid, `√N × √N` cell centres; N must be a square.
//! - `random`: N independent uniform points.
//! - `stratified`: one jittered point per cell of a `√N × √N` grid when N is a
//!   square; otherwise a Latin hypercube (N-rooks): one point in each of N columns
//!   and each of N rows, rows shuffled — still stratified in each axis, for any N.

use glam::Vec2;
use rand_core::RngCore;
use rand_pcg::Pcg32;

/// How N points are placed in [0, 1)².
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SamplePattern {
    Grid,
    Random,
    #[default]
    Stratified,
}

impl SamplePattern {
    pub const NAMES: [&'static str; 3] = ["grid", "random", "stratified"];

    /// Parses the names used in scene files and on the command line.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "grid" => Some(Self::Grid),
            "random" => Some(Self::Random),
            "stratified" => Some(Self::Stratified),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::Grid => "grid",
            Self::Random => "random",
            Self::Stratified => "stratified",
        }
    }

    /// Whether the pattern can place exactly `n` points.
    pub fn supports(self, n: u32) -> bool {
        n > 0 && (self != Self::Grid || exact_sqrt(n).is_some())
    }

    /// Fills `out` with `out.len()` points of this pattern.
    ///
    /// # Panics
    /// If the pattern does not [support](Self::supports) `out.len()` points (a grid
    /// of a non-square count); [`crate::RenderSettings::validate`] rules this out.
    pub fn fill(self, rng: &mut Pcg32, out: &mut [Vec2]) {
        let n = out.len() as u32;
        match (self, exact_sqrt(n)) {
            (Self::Grid, Some(k)) => fill_grid(k, out, |_| Vec2::splat(0.5)),
            (Self::Grid, None) => panic!("grid pattern needs a square count, got {n}"),
            (Self::Random, _) => out.iter_mut().for_each(|p| *p = uniform2(rng)),
            (Self::Stratified, Some(k)) => fill_grid(k, out, |_| uniform2(rng)),
            (Self::Stratified, None) => fill_latin_hypercube(rng, out),
        }
    }
}

fn exact_sqrt(n: u32) -> Option<u32> {
    let k = (n as f64).sqrt().round() as u64;
    (k * k == n as u64).then_some(k as u32)
}

/// Cell `(i, j)` of a `k × k` grid gets the point `((i, j) + offset) / k`.
fn fill_grid(k: u32, out: &mut [Vec2], mut offset: impl FnMut(usize) -> Vec2) {
    let scale = 1.0 / k as f32;
    for (index, p) in out.iter_mut().enumerate() {
        let cell = Vec2::new((index as u32 % k) as f32, (index as u32 / k) as f32);
        *p = ((cell + offset(index)) * scale).min(Vec2::splat(ONE_MINUS_EPSILON));
    }
}

fn fill_latin_hypercube(rng: &mut Pcg32, out: &mut [Vec2]) {
    let n = out.len();
    let scale = 1.0 / n as f32;
    for (i, p) in out.iter_mut().enumerate() {
        let jitter = uniform2(rng);
        *p = ((Vec2::splat(i as f32) + jitter) * scale).min(Vec2::splat(ONE_MINUS_EPSILON));
    }
    // Fisher–Yates on the y coordinates pairs the columns with random rows.
    for i in (1..n).rev() {
        let j = ((rng.next_u32() as u64 * (i as u64 + 1)) >> 32) as usize;
        let (yi, yj) = (out[i].y, out[j].y);
        out[i].y = yj;
        out[j].y = yi;
    }
}

/// The largest f32 below 1.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// A uniform f32 in [0, 1) from the top 24 bits of one 32-bit draw.
#[inline]
pub fn uniform(rng: &mut Pcg32) -> f32 {
    (rng.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

#[inline]
fn uniform2(rng: &mut Pcg32) -> Vec2 {
    let x = uniform(rng);
    Vec2::new(x, uniform(rng))
}

/// SplitMix64's finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mix.
#[inline]
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The sample index that names a pixel's own stream (its pixel-sample pattern),
/// distinct from the streams of its individual samples `0..spp`.
pub const PIXEL_STREAM: u64 = u64::MAX;

/// The generator for `(seed, pixel, sample)`: independent of every other triple
/// and of the order in which pixels are rendered.
pub fn pixel_rng(seed: u64, pixel: u64, sample: u64) -> Pcg32 {
    let state = mix64(mix64(mix64(seed) ^ pixel) ^ sample);
    Pcg32::new(state, 0x0a02_bdbf_7bb3_c0a7)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn points(pattern: SamplePattern, n: usize, seed: u64) -> Vec<Vec2> {
        let mut out = vec![Vec2::ZERO; n];
        pattern.fill(&mut pixel_rng(seed, 7, 0), &mut out);
        out
    }

    #[test]
    fn grid_is_the_cell_centres() {
        let p = points(SamplePattern::Grid, 4, 0);
        let expected = [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)];
        for (p, e) in p.iter().zip(expected) {
            assert_eq!((p.x, p.y), e);
        }
        assert!(!SamplePattern::Grid.supports(8));
        assert!(SamplePattern::Grid.supports(9));
        assert!(SamplePattern::Stratified.supports(8));
        assert!(!SamplePattern::Random.supports(0));
        assert!(!SamplePattern::Grid.supports(u32::MAX));
        assert!(SamplePattern::Grid.supports(65535 * 65535));
    }

    #[test]
    fn stratified_puts_one_point_per_stratum() {
        for n in [16usize, 7, 10] {
            let pts = points(SamplePattern::Stratified, n, 3);
            assert!(pts
                .iter()
                .all(|p| p.x >= 0.0 && p.x < 1.0 && p.y >= 0.0 && p.y < 1.0));
            match exact_sqrt(n as u32) {
                Some(k) => {
                    let mut seen = vec![false; n];
                    for p in &pts {
                        let cell =
                            (p.y * k as f32) as usize * k as usize + (p.x * k as f32) as usize;
                        assert!(!seen[cell], "two points in cell {cell}");
                        seen[cell] = true;
                    }
                }
                None => {
                    for axis in 0..2 {
                        let mut seen = vec![false; n];
                        for p in &pts {
                            let s = (p[axis] * n as f32) as usize;
                            assert!(!seen[s]);
                            seen[s] = true;
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let a = points(SamplePattern::Random, 8, 1);
        assert_eq!(a, points(SamplePattern::Random, 8, 1));
        assert_ne!(a, points(SamplePattern::Random, 8, 2));
        let mut x = pixel_rng(1, 2, 3);
        let mut y = pixel_rng(1, 3, 2);
        assert_ne!(x.next_u32(), y.next_u32());
    }

    #[test]
    fn uniform_has_the_right_mean() {
        let mut rng = pixel_rng(0, 0, 0);
        let n = 100_000;
        let mean: f64 = (0..n).map(|_| uniform(&mut rng) as f64).sum::<f64>() / n as f64;
        assert!((mean - 0.5).abs() < 0.005, "mean {mean}");
    }
}
