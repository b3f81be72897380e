//! What a thread carries from one camera sample to the next: the sample and
//! its random stream, the buffers its points are drawn into, the counters,
//! the tracer that sees each step, and the caches the lanes keep between
//! chunks (the last shadow-ray culling, the pixel's Sobol sequences).

use crate::counters::{ShadingCounters, TextureCounters};
use crate::sampling::Pcg32;
use crate::sampling::{
    DimensionPair, PixelSample, PointLanes, SamplePattern, SamplePoints, SequenceCache,
};
use crate::trace::Tracer;
use glam::{Vec2, Vec3};
use glint_geometry::Occluders;

/// Reusable per-thread state: the current camera sample and its random stream,
/// buffers for sample positions, ray counters, and the [`Tracer`] that sees
/// each step (`()`, which sees nothing at no cost, for renders).
pub struct SampleContext<T: Tracer = ()> {
    /// The camera sample being traced; names its points of the Sobol sequences.
    pub sample: PixelSample,
    /// Its PCG stream (for the patterns other than Sobol).
    pub rng: Pcg32,
    pub light_points: SamplePoints,
    pub environment_points: SamplePoints,
    /// What the integrator did so far.
    pub counters: ShadingCounters,
    /// Texture lookups by kind and level, counted when `detailed` is set.
    pub textures: TextureCounters,
    /// Whether to gather [`Self::textures`] (`--stats`).
    pub detailed: bool,
    /// Sees every step of the integrator ([`crate::trace`]).
    pub tracer: T,
    /// The last culling in the camera-sample lanes, for the next chunks near it.
    pub(crate) lane_occluders: Option<LaneOccluders>,
    /// The Sobol sequences of the pixel's pairs, hashed once for its samples.
    pub(crate) sequences: SequenceCache,
    /// Each lane's points, drawn up front, in the camera-sample lanes.
    pub(crate) lane_points: Vec<Vec2>,
    /// The camera-sample lanes' Sobol points, hashed up front.
    pub(crate) sobol_lanes: Vec<PointLanes>,
    /// The mistakes the one-ray reference integrator makes (never the lanes).
    #[cfg(any(test, feature = "mistakes"))]
    pub(crate) mistakes: crate::mistakes::Mistakes,
}

impl SampleContext {
    pub fn new(light_samples: u32, environment_samples: u32) -> Self {
        Self::with_tracer(light_samples, environment_samples, ())
    }
}

impl<T: Tracer> SampleContext<T> {
    /// [`SampleContext::new`] with `tracer` seeing every step.
    pub fn with_tracer(light_samples: u32, environment_samples: u32, tracer: T) -> Self {
        Self {
            sample: PixelSample::default(),
            rng: PixelSample::default().rng(),
            light_points: SamplePoints::new(light_samples as usize),
            environment_points: SamplePoints::new(environment_samples as usize),
            counters: ShadingCounters::default(),
            textures: TextureCounters::default(),
            detailed: false,
            tracer,
            lane_occluders: None,
            sequences: SequenceCache::default(),
            lane_points: Vec::new(),
            sobol_lanes: Vec::new(),
            #[cfg(any(test, feature = "mistakes"))]
            mistakes: crate::mistakes::Mistakes::NONE,
        }
    }

    /// Starts camera sample `sample` of pixel `pixel` (index `y · width + x`):
    /// sets [`Self::sample`] and its stream [`Self::rng`].
    pub fn begin_sample(&mut self, seed: u64, pixel: u64, sample: u64) {
        self.sample = PixelSample {
            seed,
            pixel,
            sample,
        };
        self.rng = self.sample.rng();
    }

    /// Fills `out` with this camera sample's points of `pair` in `pattern`, as
    /// [`SamplePattern::fill`] does with [`PixelSample::sobol_points`]`(pair,
    /// out.len())`.
    #[inline]
    pub(crate) fn fill_points(
        &mut self,
        pattern: SamplePattern,
        pair: DimensionPair,
        out: &mut SamplePoints,
    ) {
        let sobol = self.sample.sobol_points(pair, out.len() as u32);
        pattern.fill_lanes(&mut self.rng, sobol, &mut self.sequences, out);
    }
}

/// The last culling of shadow-ray occluders in the lanes: the shapes that
/// may block rays to light `light` from any point of `object` within `reach`
/// of `center`, kept for the chunks of the pixels around.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LaneOccluders {
    pub(crate) light: usize,
    pub(crate) object: u32,
    pub(crate) center: Vec3,
    pub(crate) reach: f32,
    pub(crate) occluders: Occluders,
}
