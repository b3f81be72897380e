//! Each lane's sample points: which Sobol dimension pair a shading point's
//! 2D samples read, and the points a lane draws as its camera sample alone
//! would draw them.

use crate::context::SampleContext;
use crate::sampling::{
    DimensionPair, LaneSamples, Pcg32Lanes, PointLanes, RunLanes, SamplePattern, SamplePoints,
    SobolSequence, MAX_JOINT,
};
use crate::trace::Tracer;
use crate::DirectIntegrator;
use glam::Vec2;
use glint_geometry::lanes::{self, F32Lanes, Float, LANES};

impl DirectIntegrator {
    /// The camera samples `samples` of a chunk's lanes with each lane's own
    /// stream, as `SampleContext::begin_sample` makes it, where a pattern
    /// draws from it (grid and Sobol points draw nothing).
    pub(crate) fn lane_streams<'s>(&self, samples: &'s LaneSamples) -> LaneStreams<'s> {
        let draws = |pattern| matches!(pattern, SamplePattern::Random | SamplePattern::Stratified);
        LaneStreams {
            samples,
            live: 0,
            rngs: (draws(self.light_pattern) || draws(self.environment_pattern))
                .then(|| Pcg32Lanes::new(samples.stream_seeds())),
        }
    }

    /// Each lane's points of `pair` for the lights or the environment, as
    /// its camera sample takes them alone, the lanes `drawing` drawing from
    /// their streams where the pattern draws ([`LanePoints`]).
    #[inline(always)]
    pub(crate) fn lane_points<'s, T: Tracer>(
        &self,
        (of, pair, drawing): (PointsOf, DimensionPair, u32),
        streams: &'s mut LaneStreams,
        ctx: &mut SampleContext<T>,
    ) -> LanePoints<'s> {
        let (pattern, n) = match of {
            PointsOf::Lights => (self.light_pattern, self.light_samples),
            PointsOf::Environment => (self.environment_pattern, self.environment_samples),
        };
        let samples = streams.samples;
        match pattern {
            SamplePattern::Sobol => {
                let sequences = RunSequences::new(samples, drawing, pair, n, ctx);
                let stride = u64::from(n);
                match RunLanes::new(&sequences.runs[..sequences.count], stride, stride) {
                    // All the points hashed together and up front: the
                    // hashes of different points overlap, where one point's
                    // waits on its own long chain of products.
                    Some(together) => {
                        let mut points = std::mem::take(&mut ctx.sobol_lanes);
                        points.clear();
                        points.extend((0..n).map(|j| together.points(j)));
                        LanePoints::Hashed(points)
                    }
                    None => LanePoints::Sobol(sequences, n),
                }
            }
            SamplePattern::Grid => {
                let mut points = std::mem::take(of.buffer(ctx));
                ctx.fill_points(pattern, pair, &mut points);
                LanePoints::Grid(points, of)
            }
            SamplePattern::Random | SamplePattern::Stratified => {
                let rngs = streams
                    .rngs
                    .as_mut()
                    .expect("streams where the pattern draws");
                // Two uniforms a point: random points, and a stratified one
                // (its one cell is the whole square, and `(0 + u)·1` is `u`).
                if pattern == SamplePattern::Random || n == 1 {
                    let (before, kept) = (*rngs, streams.live & !drawing);
                    return LanePoints::Uniform(rngs, before, kept);
                }
                let n = n as usize;
                let mut points = std::mem::take(&mut ctx.lane_points);
                points.resize(LANES * n, Vec2::ZERO);
                for k in lanes::each_set(drawing) {
                    let mut rng = rngs.lane(k);
                    let sobol = samples.lane(k).sobol_points(pair, n as u32);
                    pattern.fill(&mut rng, sobol, &mut points[k * n..(k + 1) * n]);
                    rngs.set_lane(k, rng);
                }
                LanePoints::Filled(points, n)
            }
        }
    }
}

/// The camera samples of a chunk's lanes, and their streams where a pattern
/// draws from them.
pub(crate) struct LaneStreams<'a> {
    pub(crate) samples: &'a LaneSamples,
    /// The lanes whose streams are read after the term being drawn.
    pub(crate) live: u32,
    pub(crate) rngs: Option<Pcg32Lanes>,
}

/// Whose points: the lights' (and their lobes'), or the environment's.
#[derive(Clone, Copy)]
pub(crate) enum PointsOf {
    Lights,
    Environment,
}

impl PointsOf {
    /// The context's buffer for a camera sample's points.
    pub(crate) fn buffer<T: Tracer>(self, ctx: &mut SampleContext<T>) -> &mut SamplePoints {
        match self {
            Self::Lights => &mut ctx.light_points,
            Self::Environment => &mut ctx.environment_points,
        }
    }
}

/// Each lane's points of one dimension pair, as its camera sample alone
/// takes them from its pattern: the grid's (the same in every lane); its
/// own points of its pixel's Sobol sequence; its stream's next two uniforms
/// a point, drawn in lanes (random, and stratified for one point); or the
/// pattern's points drawn lane by lane up front from each lane's stream
/// (stratified). Only the lanes named on making them draw:
/// [`LanePoints::finish`] leaves the other lanes' streams as they were, as
/// `li_at` draws nothing there, and puts the buffers back.
// On the stack for one light's samples: boxing the sequences would
// allocate per light and chunk.
#[allow(clippy::large_enum_variant)]
pub(crate) enum LanePoints<'s> {
    Grid(SamplePoints, PointsOf),
    /// Each run's points hashed from its own sequence, where some lane's
    /// points leave its sequence's first 2^16 ([`RunLanes::new`]).
    Sobol(RunSequences, u32),
    /// Every lane's points of its run's sequence, point `j` at `j`.
    Hashed(Vec<PointLanes>),
    /// The streams, where they were, and the lanes read later that do not
    /// draw.
    Uniform(&'s mut Pcg32Lanes, Pcg32Lanes, u32),
    /// Lane k's `n` points at `k·n`.
    Filled(Vec<Vec2>, usize),
}

impl LanePoints<'_> {
    /// Every lane's point `j`.
    #[inline(always)]
    pub(crate) fn get(&mut self, j: u32) -> (F32Lanes, F32Lanes) {
        match self {
            Self::Grid(points, _) => {
                let p = points.get(j as usize);
                (F32Lanes::splat(p.x), F32Lanes::splat(p.y))
            }
            Self::Sobol(sequences, n) => sequences.points(j, *n),
            Self::Hashed(points) => {
                let p = points[j as usize];
                (p.x, p.y)
            }
            Self::Uniform(rngs, _, _) => rngs.uniform2(),
            Self::Filled(points, n) => {
                let p = |k: usize| points[k * *n + j as usize];
                (lanes::from_fn(|k| p(k).x), lanes::from_fn(|k| p(k).y))
            }
        }
    }

    /// The lanes that did not draw keep their streams; the buffers go back
    /// to `ctx`.
    #[inline(always)]
    pub(crate) fn finish<T: Tracer>(self, ctx: &mut SampleContext<T>) {
        match self {
            Self::Grid(points, of) => *of.buffer(ctx) = points,
            Self::Sobol(..) => {}
            Self::Hashed(points) => ctx.sobol_lanes = points,
            Self::Uniform(rngs, before, kept) if kept != 0 => {
                *rngs = Pcg32Lanes::select(kept, &before, rngs);
            }
            Self::Uniform(..) => {}
            Self::Filled(points, _) => ctx.lane_points = points,
        }
    }
}

/// The Sobol sequences of a chunk's runs of camera samples for one pair:
/// lane k's sample j is point `(sample + k')·n + j` of its pixel's sequence,
/// `k'` its place in its run, the points each sample alone takes of it.
pub(crate) struct RunSequences {
    /// Each run's sequence, its first point, and its first lane.
    pub(crate) runs: [(SobolSequence, u64, usize); LANES],
    pub(crate) count: usize,
}

impl RunSequences {
    /// The sequences of the runs holding a lane of `lanes`.
    pub(crate) fn new<T: Tracer>(
        samples: &LaneSamples,
        lanes: u32,
        pair: DimensionPair,
        n: u32,
        ctx: &mut SampleContext<T>,
    ) -> Self {
        let used = (u32::BITS - lanes.leading_zeros()) as usize;
        let count = samples.runs(used);
        let mut start = |run: usize| {
            let sobol = samples.run_start(run).sobol_points(pair, n);
            let sequence = ctx.sequences.sequence(sobol);
            (sequence, sobol.first, run * samples.per_pixel)
        };
        let mut runs = [start(0); LANES];
        for (run, entry) in runs.iter_mut().enumerate().take(count).skip(1) {
            *entry = start(run);
        }
        Self { runs, count }
    }

    /// Every lane's light point `j` of `n`.
    #[inline]
    pub(crate) fn points(&self, j: u32, n: u32) -> (F32Lanes, F32Lanes) {
        let (sequence, first, _) = self.runs[0];
        let mut u = sequence.lanes_strided(first + u64::from(j), u64::from(n));
        for &(sequence, first, lane) in &self.runs[1..self.count] {
            let run = sequence.lanes_strided_from(first + u64::from(j), u64::from(n), lane);
            let from_run = lanes::from_bits(u32::MAX << lane);
            u.x = Float::select(from_run, run.x, u.x);
            u.y = Float::select(from_run, run.y, u.y);
        }
        (u.x, u.y)
    }
}

/// Which Sobol dimension pair each of a shading point's 2D samples reads. At the
/// camera ray's hit, the first light-like sample (area lights in scene order,
/// then the environment) that takes one sample per camera sample reads the
/// pixel's own sequence, dimensions 2 and 3 ([`DimensionPair::Joint`]):
/// stratified together with the pixel position,
/// which lowers the error of a pixel's soft shadows (measured on the Cornell
/// box's floor: about half the relative MSE at 256 samples, and a steeper
/// convergence slope, than independent pairs). Every other sample keeps its own
/// sequence.
pub(crate) struct PairAllocation {
    depth: u32,
    next_joint: u32,
}

impl PairAllocation {
    pub(crate) fn new(depth: u32) -> Self {
        Self {
            depth,
            next_joint: 1,
        }
    }

    /// The pair for a sample that would otherwise read `own`, taking
    /// `per_sample` points per camera sample.
    #[inline]
    pub(crate) fn take(&mut self, own: DimensionPair, per_sample: u32) -> DimensionPair {
        if self.depth == 0 && per_sample == 1 && self.next_joint <= MAX_JOINT {
            self.next_joint += 1;
            DimensionPair::Joint {
                k: self.next_joint - 1,
            }
        } else {
            own
        }
    }
}
