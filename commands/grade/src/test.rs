//! The test: is the submission's expected value Glint's, whatever its noise?
//!
//! For each region (square blocks at two scales, and each object) and each
//! channel, the submission's mean over the region's pixels, `S̄`, is compared
//! with the band its expected value must lie in under the hypothesis,
//! `[lo̅ − ε̄, hi̅ + ε̄]`:
//!
//! - `hi = M`, `lo = M` for an unclamped float image; for a clamped one
//!   `hi = min(M, 1)` and `lo = M − G` ([`hypothesis`](crate::hypothesis));
//!   for a JPEG, between its encoding of the sample reference's rounds and of
//!   `M`, `E[J(X_s)]` and `J(M)`, and a DC step wider where `M`'s DC lies at
//!   a tie ([`JpegEncoding::dc_rounding`](crate::jpeg::JpegEncoding::dc_rounding));
//! - `ε` is what storing the value may have changed it by: one step of what
//!   the file rounded to ([`Submission::tolerance`]).
//!
//! The distance `d` of `S̄` outside the band is judged against the noise of
//! `S̄`, estimated from the submission itself: the sample variance `s²` of
//! the residuals `S − (lo + hi)/2` over the region's pixels (pixels are
//! independent draws with their own means, so `s²/n` estimates the variance of
//! their mean, or overestimates it where the means differ within the region),
//! plus the references' own variance, `Σ var(M) + var(G)` over `n²`. Where
//! the submission happens to look quieter than its renderer is (a penumbra at
//! one sample, whose rare lit samples did not come up), `s²` would be too
//! small and the test too eager; so the variance is never taken below the
//! noise the submission's estimator has, `v`, measured per pixel by the sample
//! reference and scaled to the stated sample counts (or, when they are
//! unknown, by the median ratio of `s²` to `v` over the blocks, or for a
//! JPEG over neighbouring blocks' means), nor below the file's own
//! precision `q` (its rounding's, and a JPEG's DC coefficients'). The
//! statistic `t = d / √(max(s², v̄, q̄)/n + var_ref)` is referred to Student's t
//! with `n − 1` degrees of freedom, two-sided. All p-values of an image, every
//! region and channel, are tested together with Holm's step-down procedure,
//! which keeps the chance of failing a correct image at `α` or below (as
//! Nori's Student's t-tests of integrators do with Šidák's correction).

use crate::reference::{JpegReference, References, BACKGROUND};
use crate::submission::Submission;
use glam::Vec3;
use serde::Serialize;
use statrs::distribution::{ContinuousCDF, StudentsT};

/// The test's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TestOptions {
    /// The family-wise false-alarm rate: the largest chance of failing a
    /// correct submission.
    pub alpha: f64,
    /// The side of the fine blocks in pixels (the coarse ones are four times
    /// as wide); `None` picks one from the image's size.
    pub block: Option<u32>,
}

impl Default for TestOptions {
    fn default() -> Self {
        TestOptions {
            alpha: 0.01,
            block: None,
        }
    }
}

/// The fewest pixels a region must have to be tested.
pub const MIN_PIXELS: usize = 8;

/// The side of the fine blocks for an image of `width × height`: a 32nd of
/// the shorter side, at least 8 pixels (64 pixels a block).
pub fn block_side(width: u32, height: u32) -> u32 {
    (width.min(height) / 32).max(8)
}

/// Where a region is.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Place {
    /// Pixels `x0..x1 × y0..y1` (half-open, from the top left).
    Block { x0: u32, y0: u32, x1: u32, y1: u32 },
    /// Every pixel whose centre sees the object (its index in the scene's
    /// shape list, or the background).
    Object { object: Option<u32> },
}

/// A set of pixels tested together.
#[derive(Clone, Debug)]
pub struct Region {
    pub place: Place,
    pub pixels: Vec<u32>,
}

/// The regions of an image: fine blocks, coarse blocks, objects.
pub fn regions(width: u32, height: u32, block: u32, objects: &[u32]) -> Vec<Region> {
    let mut regions = blocks(width, height, block);
    regions.extend(blocks(width, height, block * 4));
    let mut by_object: std::collections::BTreeMap<u32, Vec<u32>> = Default::default();
    for (i, &object) in objects.iter().enumerate() {
        by_object.entry(object).or_default().push(i as u32);
    }
    regions.extend(by_object.into_iter().map(|(object, pixels)| Region {
        place: Place::Object {
            object: (object != BACKGROUND).then_some(object),
        },
        pixels,
    }));
    regions
}

/// Square blocks of `side` pixels from the top left; a last row or column
/// narrower than half a block joins the one before it.
fn blocks(width: u32, height: u32, side: u32) -> Vec<Region> {
    let cuts = |length: u32| -> Vec<u32> {
        let mut cuts: Vec<u32> = (0..length).step_by(side as usize).collect();
        if cuts.len() > 1 && length - cuts[cuts.len() - 1] < side / 2 {
            cuts.pop();
        }
        cuts.push(length);
        cuts
    };
    let (xs, ys) = (cuts(width), cuts(height));
    let mut regions = Vec::with_capacity((xs.len() - 1) * (ys.len() - 1));
    for y in ys.windows(2) {
        for x in xs.windows(2) {
            let pixels = (y[0]..y[1])
                .flat_map(|py| (x[0]..x[1]).map(move |px| py * width + px))
                .collect();
            regions.push(Region {
                place: Place::Block {
                    x0: x[0],
                    y0: y[0],
                    x1: x[1],
                    y1: y[1],
                },
                pixels,
            });
        }
    }
    regions
}

/// One region and channel, tested.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Finding {
    /// Index into the regions the test was given.
    pub region: usize,
    pub channel: usize,
    pub pixels: usize,
    /// The submission's mean, `S̄`.
    pub observed: f64,
    /// The band its expected value must lie in, `[lo̅ − ε̄, hi̅ + ε̄]`.
    pub expected: [f64; 2],
    /// How far `S̄` lies outside the band (negative: too dark); 0 inside.
    pub difference: f64,
    /// The standard error of `S̄ − expected`.
    pub standard_error: f64,
    /// `difference / standard_error` (0 inside the band).
    pub z: f64,
    pub p: f64,
    /// Whether Holm's procedure rejects it.
    pub rejected: bool,
}

/// The test of one image.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Outcome {
    /// Every region and channel tested.
    pub findings: Vec<Finding>,
    pub alpha: f64,
    /// The largest |z| of a finding that was not rejected (how close the
    /// image came to failing).
    pub largest_accepted_z: f64,
    /// Per pixel noise of the submission: the median over blocks of their
    /// residuals' standard deviation (the mean over channels).
    pub noise: f64,
}

impl Outcome {
    pub fn passed(&self) -> bool {
        !self.findings.iter().any(|f| f.rejected)
    }

    /// The rejected findings, the strongest evidence first.
    pub fn rejections(&self) -> Vec<&Finding> {
        let mut rejected: Vec<&Finding> = self.findings.iter().filter(|f| f.rejected).collect();
        rejected.sort_by(|a, b| a.p.total_cmp(&b.p).then(b.z.abs().total_cmp(&a.z.abs())));
        rejected
    }
}

/// Per pixel and channel, the band of the expected value, the variance of
/// the references behind it, and the noise of one draw of the submission's
/// estimator.
#[derive(Clone)]
pub struct Bands {
    pub lo: Vec<Vec3>,
    pub hi: Vec<Vec3>,
    pub reference_variance: Vec<Vec3>,
    /// The variance of one draw of the sample reference's estimator, before
    /// scaling to the submission's counts.
    pub noise: Vec<Vec3>,
    /// What `noise` is multiplied by (`None`: fitted to the submission).
    pub noise_scale: Option<f64>,
    /// How a noise scale is fitted to the submission.
    pub fit: NoiseFit,
    /// What the format's own rounding adds to the file's
    /// (`step² / 12` of [`Submission::tolerance`]'s step): a JPEG's DC coefficients'.
    pub precision: Option<Vec<Vec3>>,
}

/// How the scale of a submission's noise is fitted when its sample counts
/// are not known.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoiseFit {
    /// The median over blocks of the submission's own spread within each
    /// block against the sample reference's noise.
    WithinBlocks,
    /// From the differences of neighbouring `side × side` blocks' means
    /// against their noise: for a JPEG, which smooths the spread within a
    /// block away but keeps each block's mean and so its noise.
    BetweenBlocks { side: u32 },
}

impl Bands {
    /// The bands of `submission` under `refs` (`lo = hi = M` unclamped, else
    /// `[M − G, min(M, 1)]`), or, for a JPEG, under the references through its
    /// encoding, `jpeg`: between `E[J(X_s)]` and `J(M)`.
    pub fn new(submission: &Submission, refs: &References, jpeg: Option<&JpegReference>) -> Bands {
        if let Some(jpeg) = jpeg {
            return Bands::through_jpeg(refs, jpeg);
        }
        let (mean, samples) = (&refs.mean, &refs.samples);
        let pixels = mean.mean.len();
        let (lo, hi, reference_variance, noise) = match submission.clamped {
            true => {
                let hi: Vec<Vec3> = mean.mean.iter().map(|m| m.min(Vec3::ONE)).collect();
                let lo = (0..pixels)
                    .map(|i| (mean.mean[i] - samples.gap.mean[i]).min(hi[i]))
                    .collect();
                let variance = (0..pixels)
                    .map(|i| mean.variance[i] + samples.gap.variance[i])
                    .collect();
                let noise = (0..pixels)
                    .map(|i| samples.clamped.round_variance(i))
                    .collect();
                (lo, hi, variance, noise)
            }
            false => (
                mean.mean.clone(),
                mean.mean.clone(),
                mean.variance.clone(),
                (0..pixels)
                    .map(|i| samples.radiance.round_variance(i))
                    .collect(),
            ),
        };
        Bands {
            lo,
            hi,
            reference_variance,
            noise,
            noise_scale: refs.plan.variance_scale,
            fit: NoiseFit::WithinBlocks,
            precision: None,
        }
    }

    /// A JPEG's bands: its expected value lies between that of a file of the
    /// sample reference's estimator, `E[J(X_s)]` (its noise), and `J(M)` (no
    /// noise), as a clamped one lies between `M − G` and `min(M, 1)`. The
    /// encoding smooths each block's noise but keeps its mean, so the noise
    /// floor and the references' variance are those before it (exact for the
    /// blocks the encoding keeps; an upper bound elsewhere, since it acts as
    /// a projection).
    fn through_jpeg(refs: &References, jpeg: &JpegReference) -> Bands {
        let (a, b) = (&jpeg.samples.mean, &jpeg.mean);
        let pixels = a.len();
        // A block whose DC coefficient lies at a tie may be rounded either
        // way by the submission's encoder: its band spans both.
        let code: Vec<Vec3> = b
            .iter()
            .map(|p| Vec3::from_array(p.to_array().map(crate::submission::code_step)))
            .collect();
        let tie = |i: usize| jpeg.dc.band[i] * code[i];
        Bands {
            lo: (0..pixels).map(|i| a[i].min(b[i]) - tie(i)).collect(),
            hi: (0..pixels).map(|i| a[i].max(b[i]) + tie(i)).collect(),
            reference_variance: (0..pixels)
                .map(|i| refs.mean.variance[i] + refs.samples.clamped.variance[i])
                .collect(),
            noise: (0..pixels)
                .map(|i| refs.samples.clamped.round_variance(i))
                .collect(),
            noise_scale: refs.plan.variance_scale,
            fit: NoiseFit::BetweenBlocks {
                side: jpeg.encoding.block(),
            },
            precision: Some(
                (0..pixels)
                    .map(|i| jpeg.dc.variance[i] * code[i] * code[i])
                    .collect(),
            ),
        }
    }
}

/// Tests `submission` in every region, every channel.
pub fn test(
    submission: &Submission,
    bands: &Bands,
    regions: &[Region],
    options: &TestOptions,
) -> Outcome {
    let values = submission.film.pixels();
    let tolerance = &submission.tolerance();
    // What the file's rounding adds to a pixel: `step² / 12` of its step (a
    // JPEG's DC coefficients add theirs), so no region is without noise.
    let mut precision: Vec<Vec3> = tolerance.iter().map(|t| *t * *t / 12.0).collect();
    if let Some(more) = &bands.precision {
        precision.iter_mut().zip(more).for_each(|(p, m)| *p += *m);
    }
    let precision = &precision;
    let sums: Vec<(usize, usize, Sums)> = regions
        .iter()
        .enumerate()
        .filter(|(_, region)| region.pixels.len() >= MIN_PIXELS)
        .flat_map(|(r, region)| {
            (0..3).map(move |c| {
                let file = (tolerance.as_slice(), precision.as_slice());
                (r, c, Sums::over(region, c, values, file, bands))
            })
        })
        .collect();
    let is_block = |r: usize| matches!(regions[r].place, Place::Block { .. });
    let scale = bands.noise_scale.unwrap_or_else(|| match bands.fit {
        NoiseFit::WithinBlocks => fitted_noise_scale(sums.iter().filter(|(r, ..)| is_block(*r))),
        NoiseFit::BetweenBlocks { side } => between_blocks_noise_scale(submission, bands, side),
    });
    let mut findings: Vec<Finding> = sums
        .iter()
        .map(|(r, c, s)| s.finding(*r, *c, scale))
        .collect();
    holm(&mut findings, options.alpha);
    let largest_accepted_z = findings
        .iter()
        .filter(|f| !f.rejected)
        .map(|f| f.z.abs())
        .fold(0.0, f64::max);
    let mut spreads: Vec<f64> = sums
        .iter()
        .filter(|(r, ..)| is_block(*r))
        .map(|(.., s)| s.residual_variance().sqrt())
        .collect();
    spreads.sort_by(f64::total_cmp);
    Outcome {
        findings,
        alpha: options.alpha,
        largest_accepted_z,
        noise: spreads.get(spreads.len() / 2).copied().unwrap_or(0.0),
    }
}

/// The median over blocks of the ratio of the submission's residual variance
/// to the sample reference's noise (blocks where that noise is not zero); 0
/// when there are none (a deterministic estimator).
fn fitted_noise_scale<'a>(blocks: impl Iterator<Item = &'a (usize, usize, Sums)>) -> f64 {
    let mut ratios: Vec<f64> = blocks
        .filter(|(.., s)| s.noise > 1e-12 * s.n)
        .map(|(.., s)| s.residual_variance() / (s.noise / s.n))
        .collect();
    ratios.sort_by(f64::total_cmp);
    ratios.get(ratios.len() / 2).copied().unwrap_or(0.0)
}

/// The noise scale from neighbouring `side × side` blocks (whole ones, from
/// the top left): per channel, the difference `d` of two neighbours' mean
/// residuals has variance `λ (v₁ + v₂)` under the hypothesis (`v` the sample
/// reference's noise of a block's mean) plus the square of the difference
/// of their biases, which a smooth mistake (everything too dark) cancels and
/// an edge inflates; so `λ` is the median of `d² / (v₁ + v₂)` over all pairs
/// divided by the median of χ²₁ (0.4549). 0 when no block is noisy.
fn between_blocks_noise_scale(submission: &Submission, bands: &Bands, side: u32) -> f64 {
    let size = submission.resolution();
    let (columns, rows) = (size.x / side, size.y / side);
    let values = submission.film.pixels();
    let block = |bx: u32, by: u32, c: usize| -> (f64, f64) {
        let (mut residual, mut noise) = (0.0, 0.0);
        for y in by * side..(by + 1) * side {
            for x in bx * side..(bx + 1) * side {
                let i = (y * size.x + x) as usize;
                let mid = 0.5 * (bands.lo[i][c] + bands.hi[i][c]) as f64;
                residual += values[i][c] as f64 - mid;
                noise += bands.noise[i][c] as f64;
            }
        }
        let n = (side * side) as f64;
        (residual / n, noise / (n * n))
    };
    let mut ratios = Vec::new();
    for c in 0..3 {
        let means: Vec<(f64, f64)> = (0..rows)
            .flat_map(|by| (0..columns).map(move |bx| (bx, by)))
            .map(|(bx, by)| block(bx, by, c))
            .collect();
        let at = |bx: u32, by: u32| means[(by * columns + bx) as usize];
        for by in 0..rows {
            for bx in 0..columns {
                let neighbours = [(bx + 1, by), (bx, by + 1)];
                for (nx, ny) in neighbours
                    .into_iter()
                    .filter(|&(x, y)| x < columns && y < rows)
                {
                    let ((d1, v1), (d2, v2)) = (at(bx, by), at(nx, ny));
                    if v1 + v2 > 1e-14 {
                        ratios.push((d1 - d2).powi(2) / (v1 + v2));
                    }
                }
            }
        }
    }
    if ratios.is_empty() {
        return 0.0;
    }
    ratios.sort_by(f64::total_cmp);
    ratios[ratios.len() / 2] / MEDIAN_CHI_SQUARED_1
}

/// The median of the χ² distribution with one degree of freedom.
const MEDIAN_CHI_SQUARED_1: f64 = 0.454_936_423;

/// Running sums of one region and channel, in f64.
#[derive(Default)]
struct Sums {
    n: f64,
    observed: f64,
    lo: f64,
    hi: f64,
    tolerance: f64,
    /// The variance of the file's own rounding (`step² / 12` of [`Submission::tolerance`]'s step).
    precision: f64,
    reference_variance: f64,
    noise: f64,
    residual: f64,
    residual_squared: f64,
}

impl Sums {
    /// `file`: the file's tolerance and precision per pixel
    /// ([`Submission::tolerance`], and its rounding's variance).
    fn over(
        region: &Region,
        channel: usize,
        values: &[Vec3],
        (tolerance, precision): (&[Vec3], &[Vec3]),
        bands: &Bands,
    ) -> Sums {
        let mut s = Sums::default();
        for &i in &region.pixels {
            let i = i as usize;
            let (value, lo, hi) = (
                values[i][channel] as f64,
                bands.lo[i][channel] as f64,
                bands.hi[i][channel] as f64,
            );
            let residual = value - 0.5 * (lo + hi);
            s.n += 1.0;
            s.observed += value;
            s.lo += lo;
            s.hi += hi;
            s.tolerance += tolerance[i][channel] as f64;
            s.precision += precision[i][channel] as f64;
            s.reference_variance += bands.reference_variance[i][channel] as f64;
            s.noise += bands.noise[i][channel] as f64;
            s.residual += residual;
            s.residual_squared += residual * residual;
        }
        s
    }

    /// The residuals' sample variance, `s²`.
    fn residual_variance(&self) -> f64 {
        let mean = self.residual / self.n;
        ((self.residual_squared - self.n * mean * mean) / (self.n - 1.0)).max(0.0)
    }

    fn finding(&self, region: usize, channel: usize, noise_scale: f64) -> Finding {
        let n = self.n;
        let observed = self.observed / n;
        let expected = [
            (self.lo - self.tolerance) / n,
            (self.hi + self.tolerance) / n,
        ];
        let difference = if observed > expected[1] {
            observed - expected[1]
        } else if observed < expected[0] {
            observed - expected[0]
        } else {
            0.0
        };
        // Never below the estimator's noise, nor below the file's own
        // rounding: a region where both the submission and the references
        // are constant (a light, the background) still has the precision of
        // its format, so a difference far inside a code step is no failure.
        let pixel_variance = self
            .residual_variance()
            .max(noise_scale * self.noise / n)
            .max(self.precision / n);
        let variance = pixel_variance / n + self.reference_variance / (n * n);
        let standard_error = variance.sqrt();
        let (z, p) = match (difference == 0.0, standard_error > 0.0) {
            (true, _) => (0.0, 1.0),
            (false, true) => {
                let z = difference / standard_error;
                (z, two_sided_p(z, n - 1.0))
            }
            (false, false) => (difference.signum() * f64::INFINITY, 0.0),
        };
        Finding {
            region,
            channel,
            pixels: n as usize,
            observed,
            expected,
            difference,
            standard_error,
            z,
            p,
            rejected: false,
        }
    }
}

/// `P(|T| ≥ |t|)` for Student's t with `dof` degrees of freedom.
fn two_sided_p(t: f64, dof: f64) -> f64 {
    let distribution = StudentsT::new(0.0, 1.0, dof.max(1.0)).expect("positive degrees of freedom");
    (2.0 * distribution.sf(t.abs())).min(1.0)
}

/// Holm's step-down procedure: with the `m` p-values sorted, reject the
/// `k`-th smallest while `p₍ₖ₎ ≤ α / (m − k + 1)`.
fn holm(findings: &mut [Finding], alpha: f64) {
    let m = findings.len();
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| findings[a].p.total_cmp(&findings[b].p));
    for (k, &i) in order.iter().enumerate() {
        if findings[i].p > alpha / (m - k) as f64 {
            break;
        }
        findings[i].rejected = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_tile_the_image_and_thin_edges_join_their_neighbour() {
        let b = blocks(19, 9, 8);
        // Columns 0..8, 8..19 (a 3-pixel remainder joins); rows 0..9 (1 joins).
        let places: Vec<_> = b.iter().map(|r| r.place.clone()).collect();
        assert_eq!(
            places,
            [
                Place::Block {
                    x0: 0,
                    y0: 0,
                    x1: 8,
                    y1: 9
                },
                Place::Block {
                    x0: 8,
                    y0: 0,
                    x1: 19,
                    y1: 9
                },
            ]
        );
        let mut covered: Vec<u32> = b.iter().flat_map(|r| r.pixels.clone()).collect();
        covered.sort();
        assert_eq!(covered, (0..171).collect::<Vec<_>>());
        // A remainder of at least half a block is a block of its own.
        assert_eq!(blocks(12, 8, 8).len(), 2);
    }

    #[test]
    fn holm_rejects_step_down() {
        let finding = |p: f64| Finding {
            region: 0,
            channel: 0,
            pixels: 10,
            observed: 0.0,
            expected: [0.0, 0.0],
            difference: 0.0,
            standard_error: 1.0,
            z: 0.0,
            p,
            rejected: false,
        };
        // m = 4, α = 0.05: thresholds 0.0125, 0.0167, 0.025, 0.05.
        let mut f: Vec<Finding> = [0.01, 0.04, 0.016, 0.3].map(finding).to_vec();
        holm(&mut f, 0.05);
        let rejected: Vec<bool> = f.iter().map(|f| f.rejected).collect();
        assert_eq!(rejected, [true, false, true, false]);
        let mut f: Vec<Finding> = [0.02, 0.001].map(finding).to_vec();
        holm(&mut f, 0.01);
        assert_eq!(f.iter().filter(|f| f.rejected).count(), 1);
    }

    #[test]
    fn the_p_value_is_students() {
        // t = 2.228 is the two-sided 5% point with 10 degrees of freedom.
        assert!((two_sided_p(2.228, 10.0) - 0.05).abs() < 1e-3);
        assert!((two_sided_p(-1.96, 1e6) - 0.05).abs() < 1e-3);
    }
}
