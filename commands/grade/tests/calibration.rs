//! The test itself, on synthetic images whose truth is known: a correct
//! submission fails at most as often as `α` says (within three standard
//! errors of a binomial count), however skewed its noise, and a biased one is
//! caught. No rendering: the references are built by hand.

use glam::{UVec2, Vec3};
use glint_camera::{Film, SampleEncoding};
use glint_grade::jpeg::JpegEncoding;
use glint_grade::reference::{Estimate, JpegReference, SampleEstimates};
use glint_grade::{GradeScene, ReferencePlan, References, StatedSettings, Submission, TestOptions};
use glint_integrator::RenderSettings;
use rand_core::{RngCore, SeedableRng};
use rand_pcg::Pcg64;
use std::time::Duration;

const SIZE: u32 = 64;

fn uniform(rng: &mut Pcg64) -> f32 {
    (rng.next_u32() >> 8) as f32 / (1u32 << 24) as f32
}

fn standard_normal(rng: &mut Pcg64) -> f32 {
    // Box–Muller.
    let (a, b) = (uniform(rng).max(1e-12), uniform(rng));
    (-2.0 * a.ln()).sqrt() * (std::f32::consts::TAU * b).cos()
}

/// A smooth expected image: a gradient with a brighter square.
fn expected_image() -> Vec<Vec3> {
    (0..SIZE * SIZE)
        .map(|i| {
            let (x, y) = ((i % SIZE) as f32, (i / SIZE) as f32);
            let base = 0.1 + 0.5 * x / SIZE as f32 + 0.2 * y / SIZE as f32;
            let square = if (20..40).contains(&(x as u32)) && (8..24).contains(&(y as u32)) {
                0.15
            } else {
                0.0
            };
            Vec3::new(base + square, 0.8 * base, 0.5 * base + square)
        })
        .collect()
}

/// How a synthetic renderer errs around the expected value, per pixel.
#[derive(Clone, Copy)]
enum Noise {
    /// Normal, standard deviation `sigma`.
    Normal { sigma: f32 },
    /// Mostly a little below the mean, now and then far above: a penumbra at
    /// one light sample (lit with probability `p`, by `jump`).
    Rare { p: f32, jump: f32 },
}

impl Noise {
    fn variance(self) -> f32 {
        match self {
            Noise::Normal { sigma } => sigma * sigma,
            Noise::Rare { p, jump } => p * (1.0 - p) * jump * jump,
        }
    }

    fn draw(self, rng: &mut Pcg64) -> f32 {
        match self {
            Noise::Normal { sigma } => sigma * standard_normal(rng),
            Noise::Rare { p, jump } => {
                let lit = if uniform(rng) < p { 1.0 } else { 0.0 };
                jump * (lit - p)
            }
        }
    }
}

/// References whose estimator has `noise` in every pixel, with four
/// quadrant objects (0 to 3).
fn references(noise: Noise) -> References {
    let n = (SIZE * SIZE) as usize;
    let estimate = |mean: Vec<Vec3>, variance: f32| Estimate {
        mean,
        variance: vec![Vec3::splat(variance); n],
        rounds: 1,
        cached: false,
    };
    let mut plan = ReferencePlan::new(&StatedSettings::default(), &RenderSettings::default());
    plan.variance_scale = Some(1.0);
    let zeros = vec![Vec3::ZERO; n];
    References {
        resolution: UVec2::splat(SIZE),
        plan,
        mean: estimate(expected_image(), 0.0),
        samples: SampleEstimates {
            radiance: estimate(zeros.clone(), noise.variance()),
            clamped: estimate(zeros.clone(), noise.variance()),
            gap: estimate(zeros, 0.0),
        },
        objects: (0..SIZE * SIZE)
            .map(|i| (i % SIZE >= SIZE / 2) as u32 + 2 * (i / SIZE >= SIZE / 2) as u32)
            .collect(),
        render_time: Duration::ZERO,
        jpeg: Vec::new(),
    }
}

/// A float submission: the expected image plus `bias` where `biased` says,
/// plus noise.
fn submission(
    noise: Noise,
    rng: &mut Pcg64,
    bias: f32,
    biased: impl Fn(u32, u32) -> bool,
) -> Submission {
    let mut film = Film::new(UVec2::splat(SIZE));
    for (i, (pixel, mean)) in film
        .pixels_mut()
        .iter_mut()
        .zip(expected_image())
        .enumerate()
    {
        let (x, y) = (i as u32 % SIZE, i as u32 / SIZE);
        let shift = if biased(x, y) { bias } else { 0.0 };
        *pixel = mean + Vec3::new(noise.draw(rng), noise.draw(rng), noise.draw(rng)) + shift;
    }
    Submission::new(
        "synthetic.pfm".into(),
        film,
        SampleEncoding::Float { mantissa_bits: 23 },
    )
}

fn scene() -> GradeScene {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-set1.toml");
    GradeScene::load(&path).unwrap()
}

/// How many of `trials` submissions fail.
fn failures(
    noise: Noise,
    trials: u64,
    alpha: f64,
    bias: f32,
    biased: impl Fn(u32, u32) -> bool + Copy,
) -> u64 {
    let (scene, refs) = (scene(), references(noise));
    let options = TestOptions {
        alpha,
        block: Some(8),
    };
    let mut rng = Pcg64::seed_from_u64(29);
    (0..trials)
        .filter(|_| {
            let s = submission(noise, &mut rng, bias, biased);
            !glint_grade::grade_image(&scene, &refs, &s, &StatedSettings::default(), &options)
                .passed
        })
        .count() as u64
}

/// At most `alpha · trials` plus three binomial standard errors.
fn assert_false_alarms_within_alpha(failed: u64, trials: u64, alpha: f64) {
    let expected = alpha * trials as f64;
    let limit = expected + 3.0 * (trials as f64 * alpha * (1.0 - alpha)).sqrt();
    assert!(
        (failed as f64) <= limit,
        "{failed} of {trials} correct submissions failed; α = {alpha} allows {limit:.1}"
    );
}

#[test]
fn correct_submissions_fail_at_most_as_often_as_alpha() {
    let (trials, alpha) = (200, 0.05);
    let normal = failures(Noise::Normal { sigma: 0.05 }, trials, alpha, 0.0, |_, _| {
        false
    });
    assert_false_alarms_within_alpha(normal, trials, alpha);
    // Skewed: a 3% chance of a jump of 0.5 per pixel; in a 64-pixel block
    // no jump at all happens 14% of the time, and the block then looks
    // quieter than it is.
    let rare = Noise::Rare { p: 0.03, jump: 0.5 };
    let skewed = failures(rare, trials, alpha, 0.0, |_, _| false);
    assert_false_alarms_within_alpha(skewed, trials, alpha);
}

#[test]
fn a_bias_hidden_in_noise_is_caught() {
    // A quarter of the image (one object) 0.02 too bright under noise of 0.05
    // per pixel: 2.5 standard errors of one 8 × 8 block, 26 of the object's.
    let quadrant = |x: u32, y: u32| x >= SIZE / 2 && y < SIZE / 2;
    let caught = failures(Noise::Normal { sigma: 0.05 }, 20, 0.01, 0.02, quadrant);
    assert_eq!(caught, 20);
    // One 8 × 8 block 0.1 too dark: 16 standard errors.
    let block = |x: u32, y: u32| (8..16).contains(&x) && (40..48).contains(&y);
    let caught = failures(Noise::Normal { sigma: 0.05 }, 20, 0.01, -0.1, block);
    assert_eq!(caught, 20);
    // The same block a hundredth as far off is lost in the noise.
    let caught = failures(Noise::Normal { sigma: 0.05 }, 20, 0.01, -0.001, block);
    assert!(caught <= 2, "{caught}");
}

/// References as [`references`] makes them, and through `encoding`: its
/// sample estimate from `rounds` noisy images each through the encoding.
fn jpeg_references(noise: Noise, encoding: &JpegEncoding, rounds: u32, stated: bool) -> References {
    let mut refs = references(noise);
    if !stated {
        refs.plan.variance_scale = None;
    }
    let mut rng = Pcg64::seed_from_u64(7);
    let n = (SIZE * SIZE) as usize;
    let (mut sum, mut squares) = (vec![Vec3::ZERO; n], vec![Vec3::ZERO; n]);
    for _ in 0..rounds {
        let noisy = noisy_image(noise, &mut rng, 0.0, |_, _| false);
        let coded = encoding.round_trip(&noisy, SIZE, SIZE).unwrap();
        for (i, p) in coded.into_iter().enumerate() {
            sum[i] += p;
            squares[i] += p * p;
        }
    }
    let r = rounds as f32;
    let mean: Vec<Vec3> = sum.iter().map(|s| *s / r).collect();
    let variance = (0..n)
        .map(|i| (squares[i] / r - mean[i] * mean[i]).max(Vec3::ZERO) / (r - 1.0))
        .collect();
    refs.jpeg.push(JpegReference {
        encoding: encoding.clone(),
        samples: Estimate {
            mean,
            variance,
            rounds,
            cached: false,
        },
        mean: encoding.round_trip(&refs.mean.mean, SIZE, SIZE).unwrap(),
        dc: glint_grade::reference::dc_rounding(&refs, encoding),
    });
    refs
}

/// The expected image plus `bias` where `biased` says, plus noise.
fn noisy_image(
    noise: Noise,
    rng: &mut Pcg64,
    bias: f32,
    biased: impl Fn(u32, u32) -> bool,
) -> Vec<Vec3> {
    submission(noise, rng, bias, biased).film.pixels().to_vec()
}

/// How many of `trials` JPEG submissions (the noisy image through
/// `encoding`) fail, with the sample counts stated or not.
fn jpeg_failures(
    encoding: &JpegEncoding,
    stated: bool,
    (trials, alpha): (u64, f64),
    bias: f32,
    biased: impl Fn(u32, u32) -> bool + Copy,
) -> u64 {
    let noise = Noise::Normal { sigma: 0.05 };
    let (scene, refs) = (scene(), jpeg_references(noise, encoding, 32, stated));
    let options = TestOptions {
        alpha,
        block: Some(8),
    };
    let mut rng = Pcg64::seed_from_u64(31);
    let eight_bit = SampleEncoding::Srgb {
        levels: [255; 3],
        stored: 255,
    };
    (0..trials)
        .filter(|_| {
            let noisy = noisy_image(noise, &mut rng, bias, biased);
            let coded = encoding.round_trip(&noisy, SIZE, SIZE).unwrap();
            let mut film = Film::new(UVec2::splat(SIZE));
            film.pixels_mut().copy_from_slice(&coded);
            let mut s = Submission::new("synthetic.jpg".into(), film, eight_bit);
            s.jpeg = Some(Ok(encoding.clone()));
            !glint_grade::grade_image(&scene, &refs, &s, &StatedSettings::default(), &options)
                .passed
        })
        .count() as u64
}

#[test]
fn correct_jpegs_fail_at_most_as_often_as_alpha() {
    // JPEG smooths the noise within each block and keeps each block's mean:
    // the test must neither take the smoothed spread for the noise nor the
    // Jensen shift of averaging in sRGB for a bias, whether the counts are
    // known or the noise is fitted.
    let (trials, alpha) = (100, 0.05);
    for encoding in [
        JpegEncoding::libjpeg(75, (2, 2)),
        JpegEncoding::libjpeg(95, (1, 1)),
    ] {
        for stated in [true, false] {
            let failed = jpeg_failures(&encoding, stated, (trials, alpha), 0.0, |_, _| false);
            assert_false_alarms_within_alpha(failed, trials, alpha);
        }
    }
}

#[test]
fn a_bias_through_a_jpeg_is_caught() {
    // A quarter of the image too bright under noise of 0.05 a pixel (a dozen
    // 8-bit codes), through quality 75 and 4:2:0. The band is wider than a
    // PNG's by the shift that averaging in sRGB gives each end (about 0.01
    // at this noise), and the chroma's DC steps (2 codes of blue) round at
    // random under such noise: 0.03 is caught, counts stated or not.
    let quadrant = |x: u32, y: u32| x >= SIZE / 2 && y < SIZE / 2;
    let encoding = JpegEncoding::libjpeg(75, (2, 2));
    for stated in [true, false] {
        assert_eq!(
            jpeg_failures(&encoding, stated, (10, 0.01), 0.03, quadrant),
            10
        );
    }
    // A hundredth as far off is lost in the noise.
    assert!(jpeg_failures(&encoding, true, (10, 0.01), 0.0003, quadrant) <= 1);
}
