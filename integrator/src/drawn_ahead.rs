//! Environment samples drawn ahead for a chunk's camera samples.
//!
//! Sampling an environment map is a chain of dependent memory reads (a row's
//! search, then a column's, then the texels), each likely a cache miss: alone,
//! a sample waits on each in turn. Where a chunk's camera samples are shaded
//! one by one, their first hits' environment samples are drawn first, all of
//! them together ([`EnvironmentLight::sample_each`]), so that the reads of
//! different samples overlap; each shading point then takes its own.
//!
//! The samples are those [`DirectIntegrator::environment_light`] would draw:
//! the same points (the pair it takes at a first hit, after the lights'), and
//! `sample_each` gives each what `sample` gives it alone. Only points that no
//! random stream draws (Sobol) can be drawn out of turn, and only a map's
//! samples do not depend on the shading normal, which is not known yet.

use crate::direct::PairAllocation;
use crate::sampling::{DimensionPair, LaneSamples, PixelSample, SamplePattern};
use crate::trace::Tracer;
use crate::{DirectIntegrator, SampleContext, Scene};
use glam::{Vec2, Vec3};
use glint_geometry::lanes::{self, LANES};
use glint_lighting::{EnvironmentLight, EnvironmentSample, Light, ShadingModel};

/// From this many environment samples a point on, each point draws its own.
const DRAWN_ALONE_FROM: u32 = LANES as u32 / 2;

/// The environment samples of some camera samples at their first hits:
/// `samples[i·n..(i + 1)·n]` are those of `keys[i]`, for the pair `pair`.
#[derive(Clone, Debug, Default)]
pub(crate) struct DrawnAhead {
    pair: Option<DimensionPair>,
    keys: Vec<PixelSample>,
    samples: Vec<EnvironmentSample>,
}

impl DrawnAhead {
    /// Where camera sample `sample`'s samples of `pair` are, if drawn.
    #[inline]
    pub(crate) fn find(&self, sample: PixelSample, pair: DimensionPair) -> Option<usize> {
        if self.pair != Some(pair) {
            return None;
        }
        self.keys.iter().position(|&key| key == sample)
    }

    /// The `n` samples of the `i`th camera sample drawn.
    #[inline]
    pub(crate) fn samples_of(&self, i: usize, n: usize) -> &[EnvironmentSample] {
        &self.samples[i * n..(i + 1) * n]
    }

    /// Draws the pending points, the first `len` of `points`.
    fn draw(&mut self, env: &EnvironmentLight, points: &[Vec2; LANES], len: usize) {
        let drawn = env.sample_each(Vec3::Y, points, len);
        self.samples.extend_from_slice(&drawn[..len]);
    }
}

impl DirectIntegrator {
    /// Whether the environment samples at first hits are drawn ahead: a map
    /// to sample, with Sobol points, and fewer than half a chunk's worth
    /// a point (with more, one point's own samples overlap enough: measured
    /// on `physical-textured-ground`, 0.86× the time at 1 sample a point,
    /// 0.96× at 4, and 1.01× at 16 on `physical-environment`; AMD EPYC).
    pub(crate) fn draws_environment_ahead(&self, scene: &Scene) -> bool {
        (1..DRAWN_ALONE_FROM).contains(&self.environment_samples)
            && self.environment_pattern == SamplePattern::Sobol
            && self.samples_environment_by_map(scene)
    }

    /// The dimension pair of the environment's samples at a point `depth`
    /// reflections deep: the one `shade_with` gives it after the lights that
    /// sample take theirs.
    pub(crate) fn environment_pair(&self, scene: &Scene, depth: u32) -> DimensionPair {
        let mut pairs = PairAllocation::new(depth);
        for (index, light) in scene.lights.iter().enumerate() {
            let samples = match light {
                Light::Area(_) => true,
                Light::Sphere(_) => scene.shading == ShadingModel::Physical,
                Light::Point(_) => false,
            };
            if samples {
                self.light_pair(&mut pairs, index, depth);
            }
        }
        let own = DimensionPair::Environment { depth };
        pairs.take(own, self.environment_samples)
    }

    /// Draws the environment samples at the first hits of the camera samples
    /// `samples.lane(k)` for the lanes `k` of `lanes`, all together, for
    /// [`Self::environment_light`] to take. Only where
    /// [`Self::draws_environment_ahead`] holds.
    pub(crate) fn draw_environment_ahead<T: Tracer>(
        &self,
        scene: &Scene,
        samples: &LaneSamples,
        lanes: u32,
        ctx: &mut SampleContext<T>,
    ) {
        let env = scene.environment.as_ref().expect("draws_environment_ahead");
        let pair = self.environment_pair(scene, 0);
        let mut ahead = std::mem::take(&mut ctx.drawn_ahead);
        let mut points = std::mem::take(&mut ctx.environment_points);
        ahead.pair = Some(pair);
        ahead.keys.clear();
        ahead.samples.clear();
        let (mut pending, mut len) = ([Vec2::ZERO; LANES], 0);
        for k in lanes::each_set(lanes) {
            let sample = samples.lane(k);
            ctx.sample = sample;
            ctx.fill_points(self.environment_pattern, pair, &mut points);
            ahead.keys.push(sample);
            for u in points.iter() {
                pending[len] = u;
                len += 1;
                if len == LANES {
                    ahead.draw(env, &pending, len);
                    len = 0;
                }
            }
        }
        ahead.draw(env, &pending, len);
        ctx.environment_points = points;
        ctx.drawn_ahead = ahead;
    }
}
