//! The per-pixel random streams: every number a pixel uses is a function of
//! `(seed, pixel index, sample index)`, never of a shared generator.

use super::mix::mix64;
use super::pcg::Pcg32;
use super::sobol::{DimensionPair, SobolPoints};
use glint_geometry::lanes::LANES;

/// The sample index that names a pixel's own stream (its pixel-sample pattern),
/// distinct from the streams of its individual samples `0..spp`.
pub const PIXEL_STREAM: u64 = u64::MAX;

/// The generator for `(seed, pixel, sample)`: independent of every other triple
/// and of the order in which pixels are rendered.
#[inline]
pub fn pixel_rng(seed: u64, pixel: u64, sample: u64) -> Pcg32 {
    Pcg32::new(stream_seed(seed, pixel, sample))
}

/// The seed of [`pixel_rng`]`(seed, pixel, sample)`: [`mix64`] of the
/// sample index and the pixel's [`pixel_key`].
#[inline]
pub fn stream_seed(seed: u64, pixel: u64, sample: u64) -> u64 {
    mix64(pixel_key(seed, pixel) ^ sample)
}

/// The part of [`stream_seed`] that all of a pixel's streams share, to hash
/// once per pixel.
#[inline]
pub fn pixel_key(seed: u64, pixel: u64) -> u64 {
    mix64(mix64(seed) ^ pixel)
}

/// A uniform f32 in [0, 1) from the top 24 bits of one 32-bit draw.
#[inline]
pub fn uniform(rng: &mut Pcg32) -> f32 {
    rng.uniform()
}

/// One camera sample of one pixel: it names the sample's PCG stream
/// ([`pixel_rng`]) and the points it takes of each of the pixel's Sobol sequences.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PixelSample {
    /// The render's seed.
    pub seed: u64,
    /// The pixel's index, `y · width + x`.
    pub pixel: u64,
    /// The camera sample, `0..spp`.
    pub sample: u64,
}

/// The camera samples in a chunk's [`LANES`] lanes: runs of `per_pixel`
/// samples of consecutive pixels. Run g, lanes `g·per_pixel` up to
/// `(g + 1)·per_pixel`, holds samples `first..first + per_pixel` of pixel
/// `pixels[g]`. One pixel's chunk of sixteen samples is one run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LaneSamples {
    /// The render's seed.
    pub seed: u64,
    /// The first sample of every run.
    pub first: u64,
    /// The lanes of a run.
    pub per_pixel: usize,
    /// The pixel of each run (the first `runs()` entries).
    pub pixels: [u64; LANES],
}

impl LaneSamples {
    /// Samples `first.sample..` of one pixel in all the lanes.
    pub fn of_pixel(first: PixelSample) -> Self {
        Self {
            seed: first.seed,
            first: first.sample,
            per_pixel: LANES,
            pixels: [first.pixel; LANES],
        }
    }

    /// The runs in a chunk of `used` lanes.
    #[inline]
    pub fn runs(&self, used: usize) -> usize {
        used.div_ceil(self.per_pixel)
    }

    /// The first sample of run `run`.
    #[inline]
    pub fn run_start(&self, run: usize) -> PixelSample {
        PixelSample {
            seed: self.seed,
            pixel: self.pixels[run],
            sample: self.first,
        }
    }

    /// The sample in lane `k`.
    #[inline]
    pub fn lane(&self, k: usize) -> PixelSample {
        PixelSample {
            sample: self.first + (k % self.per_pixel) as u64,
            ..self.run_start(k / self.per_pixel)
        }
    }

    /// Each lane's own PCG stream's seed ([`stream_seed`]).
    #[inline]
    pub fn stream_seeds(&self) -> [u64; LANES] {
        let mut seeds = [0; LANES];
        if self.per_pixel == LANES {
            // One pixel's: a loop the compiler vectorizes, whose seeds the
            // generators' seeding then reads from registers (written lane
            // by lane, they stall its vector loads).
            let key = pixel_key(self.seed, self.pixels[0]);
            for (k, seed) in seeds.iter_mut().enumerate() {
                *seed = mix64(key ^ (self.first + k as u64));
            }
            return seeds;
        }
        for (run, lanes) in seeds.chunks_mut(self.per_pixel).enumerate() {
            let key = pixel_key(self.seed, self.pixels[run]);
            for (k, seed) in lanes.iter_mut().enumerate() {
                *seed = mix64(key ^ (self.first + k as u64));
            }
        }
        seeds
    }
}

impl PixelSample {
    /// The sample's own PCG stream, which the light and environment patterns other
    /// than Sobol draw from.
    pub fn rng(self) -> Pcg32 {
        pixel_rng(self.seed, self.pixel, self.sample)
    }

    /// The `per_sample` points of `pair` that this camera sample uses: points
    /// `sample · per_sample` to `sample · per_sample + per_sample − 1` of the
    /// pixel's sequence for `pair`, so that the samples of all of a pixel's camera
    /// samples together are the first `spp · per_sample` points of one sequence.
    #[inline]
    pub fn sobol_points(self, pair: DimensionPair, per_sample: u32) -> SobolPoints {
        SobolPoints {
            seed: self.seed,
            pixel: self.pixel,
            pair,
            first: self.sample * per_sample as u64,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Pcg32Lanes;
    use glint_geometry::lanes::LANES;

    #[test]
    fn uniform_has_the_right_mean() {
        let mut rng = pixel_rng(0, 0, 0);
        let n = 100_000;
        let mean: f64 = (0..n).map(|_| uniform(&mut rng) as f64).sum::<f64>() / n as f64;
        assert!((mean - 0.5).abs() < 0.005, "mean {mean}");
    }

    /// Each lane's stream is its own camera sample's, for one pixel's chunk
    /// and for runs of several pixels' samples.
    #[test]
    fn lanes_streams_are_their_samples_streams() {
        let mut chunks: Vec<LaneSamples> = [(0, 0, 0), (7, 512 * 300 + 11, 32), (u64::MAX, 3, 48)]
            .map(|(seed, pixel, sample)| {
                LaneSamples::of_pixel(PixelSample {
                    seed,
                    pixel,
                    sample,
                })
            })
            .to_vec();
        for per_pixel in [1, 4] {
            chunks.push(LaneSamples {
                seed: 5,
                first: 2 * per_pixel as u64,
                per_pixel,
                pixels: std::array::from_fn(|run| 40 + 3 * run as u64),
            });
        }
        for samples in chunks {
            let (x, y) = Pcg32Lanes::new(samples.stream_seeds()).uniform2();
            for k in 0..LANES {
                let mut rng = samples.lane(k).rng();
                assert_eq!(x.to_array()[k].to_bits(), rng.uniform().to_bits());
                assert_eq!(y.to_array()[k].to_bits(), rng.uniform().to_bits());
            }
        }
    }
}
