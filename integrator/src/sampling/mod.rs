//! Sample patterns over the unit square, and the per-pixel streams they draw from.
//!
//! # Patterns
//! (pbrt-v4 chapter 8 has the background.)
//! - `grid`: the course's uniform grid, `√N × √N` cell centres; N must be a square.
//! - `random`: N independent uniform points.
//! - `stratified`: one jittered point per cell of a `√N × √N` grid when N is a
//!   square; otherwise a Latin hypercube (N-rooks): one point in each of N columns
//!   and each of N rows, rows shuffled — still stratified in each axis, for any N.
//! - `sobol`: consecutive points of an Owen-scrambled Sobol sequence (Burley,
//!   "Practical Hash-based Owen Scrambling", JCGT 9(4), 2020, through the
//!   `sobol_burley` crate), one sequence per pixel and dimension pair; any N, best
//!   at powers of two, where the points of a pixel form a (0, k, 2)-net: every
//!   elementary interval of area 1/N holds exactly one.
//!
//! # Streams
//! Every number a pixel uses is a function of `(seed, pixel index, sample index)`,
//! never of a shared generator, so an image is bit-identical for any thread count
//! and tile order.
//!
//! The PCG32 streams ([`pixel_rng`]) feed `random` and `stratified` (`grid` draws
//! nothing): the pixel's own stream `pixel_rng(seed, pixel, PIXEL_STREAM)` fills
//! the pixel pattern, and camera sample `s` has the stream `pixel_rng(seed, pixel,
//! s)`, from which the light and environment patterns draw in the order the
//! integrator shades (each area light in scene order, then the environment, at the
//! first hit and then at each mirror reflection's hit).
//!
//! # Sobol dimensions ("padding")
//! Rather than one high-dimensional Sobol sequence, every 2D *dimension pair*
//! ([`DimensionPair`]) of every pixel gets its own sequence: Sobol dimensions 0
//! and 1 of `sobol_burley::sample(index, dimension, seed)`, whose 32-bit seed is a
//! hash (SplitMix64's finaliser, folded to 32 bits) of the render seed, the pixel
//! index and the pair. `sobol_burley`'s seed both Owen-scrambles the dimensions
//! and shuffles the index, so each pair is a (0, 2)-sequence and different pairs,
//! and the same pair in different pixels, are statistically independent (Burley
//! 2020 §4; pbrt-v4 §8.7, whose `PaddedSobolSampler` does the same). The pairs, for
//! `spp` camera samples with `m` light and `e` environment samples each:
//!
//! | pair | points camera sample `s` takes |
//! |---|---|
//! | [`DimensionPair::Pixel`]: the position in the pixel | point `s` (all: `0..spp`) |
//! | [`DimensionPair::Light`] `{ light: l, depth: d }`: area light `l` at reflection depth `d` | `s·m .. s·m + m` (all: `0..spp·m`) |
//! | [`DimensionPair::Environment`] `{ depth: d }`: environment directions at depth `d` | `s·e .. s·e + e` (all: `0..spp·e`) |
//!
//! So all of a pixel's samples of one light at one depth are the first `spp·m`
//! points of one sequence: stratified together, and each camera sample's `m`
//! points stratified too when `m` is a power of two.
//!
//! One exception: at the camera ray's hit, the first area light (or, without
//! one, the environment) taking one sample per camera sample reads
//! [`DimensionPair::Joint`], Sobol dimensions 2 and 3 of the pixel's own
//! sequence, point `s`. Pixel position and light sample are then one 4D Sobol
//! point, a (t, 4)-sequence with t ≤ 3 for the first 2^10 points, stratified
//! together; padded pairs are only randomly paired, and the pixel × light
//! interaction of a soft shadow then converges at the Monte Carlo rate. On the
//! Cornell box's floor shadows this halves the relative MSE at 256 samples. A sequence has 2^16 points;
//! point `i ≥ 2^16` is point `i mod 2^16` of a fresh, independent sequence whose
//! seed is re-hashed with `i / 2^16` ([`SobolSequence::block_seed`]).
//!
//! The points are computed with `sobol_burley::parts` and tables of the two
//! dimensions' generator matrices, bit for bit equal to `sobol_burley::sample`'s
//! (see `sobol`'s documentation; the tests compare every index).
//!
//! Patterns can be mixed (e.g. a `sobol` pixel pattern with `random` light
//! samples): the patterns other than `sobol` draw from the PCG streams exactly as
//! they would without it.
//!
//! # Files
//! - `pattern`: [`SamplePattern`] and how each fills N points.
//! - `sobol`: [`DimensionPair`], [`SobolSequence`] and [`SobolPoints`].
//! - `pcg`: the PCG32 generator ([`Pcg32`]), and a lane's worth of them
//!   ([`Pcg32Lanes`]).
//! - `streams`: [`pixel_rng`], [`uniform`] and [`PixelSample`], which names a
//!   camera sample's stream and its Sobol points.
//! - `mix`: [`mix64`], the hash that `streams`, `pcg` and `sobol` seed with.
//! - `sobol_tests`: the published points, elementary intervals, convergence and
//!   correlation of the Sobol sequences.

mod mix;
mod pattern;
mod pcg;
mod points;
mod sobol;
#[cfg(test)]
mod sobol_tests;
mod streams;

pub use mix::mix64;
pub use pattern::SamplePattern;
pub use pcg::{Pcg32, Pcg32Lanes, STREAM};
pub use points::{PointChunk, PointLanes, SamplePoints};
pub use sobol::{DimensionPair, RunLanes, SequenceCache, SobolPoints, SobolSequence, MAX_JOINT};
pub use streams::{
    pixel_key, pixel_rng, stream_seed, uniform, LaneSamples, PixelSample, PIXEL_STREAM,
};
