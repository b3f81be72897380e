//! What the grader assumes about how a submission was rendered, and the Glint
//! renders that give its expected value under that assumption.
//!
//! A submission is one draw of its renderer's estimator `X̄`, the mean of `N`
//! camera samples per pixel, each with `L` samples of each light. A pattern
//! that places its points at random (uniform, stratified, scrambled Sobol) is
//! unbiased for the integral over the pixel and over the light, so its expected
//! value does not depend on `N`, `L` or the pattern; a **grid** places them at
//! fixed cell centres, a quadrature whose value depends on the count. So:
//!
//! - the *mean reference* `M = E[X̄]` keeps every stated grid as it is and
//!   converges every other dimension (many Sobol samples);
//! - the *sample reference* renders the submission's own estimator `X_s` as
//!   stated (the same counts and patterns; unknown ones taken as one uniform
//!   sample; counts beyond a budget cut, which keeps its samples a subset of
//!   the submission's) in many rounds. Its rounds give the noise a submission
//!   should have, pixel by pixel, and its clamp gap `G = E[(X_s − 1)⁺]`:
//!   since `min(·, 1)` is concave, an image clamped after averaging has
//!   `E[min(X̄, 1)]` between `M − G` and `min(M, 1)` (Jensen: averaging more
//!   samples only raises it).

use glint_integrator::{RenderSettings, SamplePattern};

/// What a grader knows of how a submission was rendered; `None` is unknown.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StatedSettings {
    /// Camera samples per pixel.
    pub spp: Option<u32>,
    /// Where in the pixel they fall (`--sampler`).
    pub pixel_pattern: Option<SamplePattern>,
    /// Samples per area light per camera sample.
    pub light_samples: Option<u32>,
    /// Where on the light they fall (`--light-sampler`).
    pub light_pattern: Option<SamplePattern>,
}

/// Camera samples per pixel in each round of the mean reference, where the
/// pixel is integrated (not a stated grid).
pub const MEAN_SPP: u32 = 64;
/// Light samples per camera sample in the mean reference, where the light is
/// integrated: with `MEAN_SPP` camera samples, 1024 per pixel and round.
pub const MEAN_LIGHT_SAMPLES: u32 = 16;
/// Light samples per pixel and round the mean reference aims at when the
/// pixel's samples are a stated grid (and so cannot grow).
pub const MEAN_LIGHT_PER_PIXEL: u32 = 1024;
/// Rounds of the mean reference: independent seeds, so that its own noise is
/// estimated and counted in the test.
pub const MEAN_ROUNDS: u32 = 4;
/// The most light-sample paths per pixel (`spp × light samples`) a round of
/// the sample reference renders; larger stated counts are cut to it.
pub const SAMPLE_BUDGET: u32 = 256;
/// The most rounds of the sample reference (few samples each: cheap).
pub const SAMPLE_ROUNDS: u32 = 64;
/// Light-sample paths per pixel the sample reference aims at over all its
/// rounds: enough for its per-pixel variance (at least 8 rounds) and its clamp
/// gap, a quarter of the mean reference's.
pub const SAMPLE_PATHS: u32 = 1024;
/// The fewest, for a good estimate of its per-pixel variance.
pub const MIN_SAMPLE_ROUNDS: u32 = 8;

/// Why stated settings cannot be used.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum StatedError {
    #[error("{what} must be at least 1")]
    Zero { what: &'static str },
    #[error("the grid pattern needs its count: give {flag} too")]
    GridWithoutCount { flag: &'static str },
    #[error(
        "{what} is {count}, but the {pattern} pattern needs a perfect square (1, 4, 9, 16, …)"
    )]
    NotSquare {
        what: &'static str,
        count: u32,
        pattern: &'static str,
    },
}

impl StatedSettings {
    /// Checks that counts are positive and fit their patterns.
    pub fn validate(&self) -> Result<(), StatedError> {
        let dimensions = [
            ("spp", "--spp", self.spp, self.pixel_pattern),
            (
                "light samples",
                "--light-samples",
                self.light_samples,
                self.light_pattern,
            ),
        ];
        for (what, flag, count, pattern) in dimensions {
            if count == Some(0) {
                return Err(StatedError::Zero { what });
            }
            match (pattern, count) {
                (Some(SamplePattern::Grid), None) => {
                    return Err(StatedError::GridWithoutCount { flag })
                }
                (Some(p), Some(count)) if !p.supports(count) => {
                    return Err(StatedError::NotSquare {
                        what,
                        count,
                        pattern: p.name(),
                    })
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// These settings, each unknown one taken from `preset`.
    pub fn or(&self, preset: &StatedSettings) -> StatedSettings {
        StatedSettings {
            spp: self.spp.or(preset.spp),
            pixel_pattern: self.pixel_pattern.or(preset.pixel_pattern),
            light_samples: self.light_samples.or(preset.light_samples),
            light_pattern: self.light_pattern.or(preset.light_pattern),
        }
    }

    /// Whether a stated grid fixes the pixel's samples.
    pub fn pixel_grid(&self) -> Option<u32> {
        grid_count(self.pixel_pattern, self.spp)
    }

    /// Whether a stated grid fixes the light's samples.
    pub fn light_grid(&self) -> Option<u32> {
        grid_count(self.light_pattern, self.light_samples)
    }

    /// A short description for reports: `spp 16 grid, light 4 random`, with
    /// `?` for what is unknown.
    pub fn describe(&self) -> String {
        let part = |count: Option<u32>, pattern: Option<SamplePattern>| match (count, pattern) {
            (None, None) => "unknown".to_string(),
            (c, p) => format!(
                "{} {}",
                c.map_or("?".into(), |c| c.to_string()),
                p.map_or("?", SamplePattern::name)
            ),
        };
        format!(
            "spp {}, light {}",
            part(self.spp, self.pixel_pattern),
            part(self.light_samples, self.light_pattern)
        )
    }
}

fn grid_count(pattern: Option<SamplePattern>, count: Option<u32>) -> Option<u32> {
    match pattern {
        Some(SamplePattern::Grid) => count,
        _ => None,
    }
}

/// The renders behind a grade: settings and rounds of each reference.
#[derive(Clone, Debug, PartialEq)]
pub struct ReferencePlan {
    pub mean: RenderSettings,
    pub mean_rounds: u32,
    pub samples: RenderSettings,
    pub sample_rounds: u32,
    /// How the sample reference's per-pixel variance scales to the
    /// submission's: `(spp_s · light_s) / (spp · light)` when both counts are
    /// stated; `None` when it must be fitted to the submission's own noise.
    pub variance_scale: Option<f64>,
}

impl ReferencePlan {
    /// The references for a submission rendered as `stated` says, of a scene
    /// whose own settings are `scene` (environment samples, depth, seed).
    pub fn new(stated: &StatedSettings, scene: &RenderSettings) -> ReferencePlan {
        let mut mean = scene.clone();
        mean.aov = None;
        mean.stats = false;
        let (spp, pixel) = match stated.pixel_grid() {
            Some(n) => (n, SamplePattern::Grid),
            None => (MEAN_SPP, SamplePattern::Sobol),
        };
        let (light_samples, light) = match stated.light_grid() {
            Some(l) => (l, SamplePattern::Grid),
            None => (
                (MEAN_LIGHT_PER_PIXEL / spp).clamp(MEAN_LIGHT_SAMPLES, MEAN_LIGHT_PER_PIXEL),
                SamplePattern::Sobol,
            ),
        };
        (mean.spp, mean.pixel_pattern) = (spp, pixel);
        (mean.light_samples, mean.light_pattern) = (light_samples, light);
        let environment_fixed =
            scene.environment_samples == 0 || scene.environment_pattern == SamplePattern::Grid;
        if !environment_fixed {
            mean.environment_samples = scene.environment_samples.max(16);
            mean.environment_pattern = SamplePattern::Sobol;
        }
        let deterministic =
            pixel == SamplePattern::Grid && light == SamplePattern::Grid && environment_fixed;
        let mean_rounds = if deterministic { 1 } else { MEAN_ROUNDS };

        let mut samples = mean.clone();
        (samples.spp, samples.pixel_pattern) = stated_or_one(stated.spp, stated.pixel_pattern);
        (samples.light_samples, samples.light_pattern) =
            stated_or_one(stated.light_samples, stated.light_pattern);
        within_budget(&mut samples);
        if !environment_fixed {
            samples.environment_samples = 1;
            samples.environment_pattern = SamplePattern::Random;
        }
        let per_round = samples.spp * samples.light_samples;
        let sample_rounds = if deterministic {
            1
        } else {
            (SAMPLE_PATHS / per_round).clamp(MIN_SAMPLE_ROUNDS, SAMPLE_ROUNDS)
        };
        let variance_scale = match (stated.spp, stated.light_samples) {
            (Some(n), Some(l)) => Some(per_round as f64 / (n as f64 * l as f64)),
            _ => None,
        };
        ReferencePlan {
            mean,
            mean_rounds,
            samples,
            sample_rounds,
            variance_scale,
        }
    }
}

/// A stated count and pattern, or one uniform sample where unknown.
fn stated_or_one(count: Option<u32>, pattern: Option<SamplePattern>) -> (u32, SamplePattern) {
    (count.unwrap_or(1), pattern.unwrap_or(SamplePattern::Random))
}

/// Cuts the counts of `settings` that are not grids until `spp × light
/// samples` is within [`SAMPLE_BUDGET`], the light's first: fewer samples of
/// the same estimator are a subset of the submission's.
fn within_budget(settings: &mut RenderSettings) {
    let fixed = |pattern: SamplePattern| pattern == SamplePattern::Grid;
    if settings.spp * settings.light_samples > SAMPLE_BUDGET && !fixed(settings.light_pattern) {
        settings.light_samples = (SAMPLE_BUDGET / settings.spp).max(1);
    }
    if settings.spp * settings.light_samples > SAMPLE_BUDGET && !fixed(settings.pixel_pattern) {
        settings.spp = (SAMPLE_BUDGET / settings.light_samples).max(1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stated(
        spp: Option<u32>,
        pixel: Option<&str>,
        l: Option<u32>,
        light: Option<&str>,
    ) -> StatedSettings {
        StatedSettings {
            spp,
            pixel_pattern: pixel.and_then(SamplePattern::from_name),
            light_samples: l,
            light_pattern: light.and_then(SamplePattern::from_name),
        }
    }

    #[test]
    fn unknown_settings_converge_the_mean_and_take_one_sample_for_the_noise() {
        let plan = ReferencePlan::new(&StatedSettings::default(), &RenderSettings::default());
        assert_eq!(
            (plan.mean.spp, plan.mean.pixel_pattern),
            (64, SamplePattern::Sobol)
        );
        assert_eq!(
            (plan.mean.light_samples, plan.mean.light_pattern),
            (16, SamplePattern::Sobol)
        );
        assert_eq!(plan.mean_rounds, MEAN_ROUNDS);
        assert_eq!((plan.samples.spp, plan.samples.light_samples), (1, 1));
        assert_eq!(plan.samples.pixel_pattern, SamplePattern::Random);
        assert_eq!(plan.sample_rounds, 64);
        assert_eq!(plan.variance_scale, None);
    }

    #[test]
    fn stated_settings_are_rendered_as_stated_within_the_budget() {
        let s = stated(Some(1), Some("grid"), Some(16), Some("stratified"));
        let plan = ReferencePlan::new(&s, &RenderSettings::default());
        assert_eq!(
            (plan.mean.spp, plan.mean.pixel_pattern),
            (1, SamplePattern::Grid)
        );
        // One camera sample: the light gets the pixel's whole budget.
        assert_eq!(plan.mean.light_samples, 1024);
        assert_eq!(
            (plan.samples.spp, plan.samples.pixel_pattern),
            (1, SamplePattern::Grid)
        );
        assert_eq!(
            (plan.samples.light_samples, plan.samples.light_pattern),
            (16, SamplePattern::Stratified)
        );
        assert_eq!((plan.sample_rounds, plan.variance_scale), (64, Some(1.0)));

        // 64 × 64 is over the budget: the light's count is cut first.
        let s = stated(Some(64), Some("random"), Some(64), Some("random"));
        let plan = ReferencePlan::new(&s, &RenderSettings::default());
        assert_eq!((plan.samples.spp, plan.samples.light_samples), (64, 4));
        assert_eq!(plan.variance_scale, Some(256.0 / 4096.0));
        assert_eq!(plan.sample_rounds, MIN_SAMPLE_ROUNDS);

        let s = stated(Some(16), Some("grid"), Some(64), Some("grid"));
        let scene = RenderSettings {
            environment_samples: 0,
            ..RenderSettings::default()
        };
        let plan = ReferencePlan::new(&s, &scene);
        assert_eq!(
            (plan.mean_rounds, plan.sample_rounds),
            (1, 1),
            "deterministic"
        );
        assert_eq!(plan.mean, plan.samples);
    }

    #[test]
    fn bad_statements_are_refused() {
        assert_eq!(
            stated(None, Some("grid"), None, None).validate(),
            Err(StatedError::GridWithoutCount { flag: "--spp" })
        );
        assert!(stated(Some(8), Some("grid"), None, None)
            .validate()
            .unwrap_err()
            .to_string()
            .contains("spp is 8, but the grid pattern needs a perfect square"));
        assert_eq!(
            stated(None, None, Some(0), None).validate(),
            Err(StatedError::Zero {
                what: "light samples"
            })
        );
        assert!(stated(Some(3), None, Some(3), Some("random"))
            .validate()
            .is_ok());
        assert_eq!(
            stated(Some(4), Some("grid"), None, None).describe(),
            "spp 4 grid, light unknown"
        );
    }
}
