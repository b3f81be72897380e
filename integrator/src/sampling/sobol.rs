//! Owen-scrambled Sobol points, one independent 2D sequence per pixel and
//! dimension pair ("padding", Burley 2020 §4; pbrt-v4 §8.7).
//!
//! Every [`DimensionPair`] of every pixel gets its own 32-bit seed, a hash of the
//! render seed, the pixel index and the pair. The points are Sobol dimensions 0
//! and 1 of [`sobol_burley::sample`] with that seed, which both Owen-scrambles the
//! two dimensions and shuffles the index: each pair's sequence is a (0, 2)-sequence
//! in base 2, and sequences of different seeds are statistically independent.
//!
//! `sobol_burley`'s sequences have 2^16 points. Point `i` of a longer sequence is
//! point `i mod 2^16` of a fresh sequence whose seed is re-hashed with `i / 2^16`:
//! each block of 2^16 points is a (0, 16, 2)-net of its own, independent of the
//! other blocks (so the first `N` points stay stratified only for `N ≤ 2^16`).
//!
//! # Evaluation
//! `sobol_burley::sample` hashes its seed three times and walks the index's bits
//! for every coordinate. A fill hashes once per block instead ([`Scrambles`]).
//! Dimensions 0 and 1 need no generator matrix in memory: dimension 0 (van der
//! Corput) is the index's bits reversed, and dimension 1, whose matrix is
//! Pascal's triangle mod 2, is a superset transform of them (four shifts and
//! XORs, [`sobol_dimension_1`]), so sixteen points are computed in SIMD lanes
//! without a lookup. The joint pairs' dimensions look the points up in tables,
//! one per byte of the (shuffled) index ([`JOINT_TABLES`]). The scrambles are
//! `sobol_burley::parts`'s own, with the constants of `sobol_burley::sample`
//! (version 0.5). The points are bit for bit those of
//! `sobol_burley::sample(index, dimension, seed)`, which the tests check for every
//! index of several sequences; a point costs about a quarter of the two calls.

use super::mix::mix64;
use super::points::{PointLanes, SamplePoints};
use glam::Vec2;
use glint_geometry::lanes::U32Lanes;
use glint_geometry::lanes::{F32Lanes, LANES};
use sobol_burley::parts::{hash, owen_scramble_rev, u32_to_f32_norm};
use std::ops::{BitAnd, BitXor, Shr};
use wide::bytemuck::cast;

/// Which 2D sample dimensions of a pixel a set of points is for; each has its own
/// Sobol sequence, so that no two of them correlate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DimensionPair {
    /// The position in the pixel: camera sample `s` is point `s`.
    Pixel,
    /// Points on the light at index `light` of [`crate::Scene::lights`], for
    /// shading points `depth` mirror reflections deep (0: the camera ray's hit).
    /// Camera sample `s` with `m` light samples takes points `s·m` to `s·m + m − 1`.
    Light { light: u32, depth: u32 },
    /// Directions drawn from the BRDF towards the light at index `light`, for
    /// shading points `depth` mirror reflections deep (physical shading's
    /// multiple importance sampling); taken as [`Self::Light`]'s points are.
    Brdf { light: u32, depth: u32 },
    /// Environment directions for shading points `depth` mirror reflections deep;
    /// camera sample `s` with `m` environment samples takes points `s·m` to
    /// `s·m + m − 1`.
    Environment { depth: u32 },
    /// Sobol dimensions `2k` and `2k + 1` (`k` up to [`MAX_JOINT`]) of the
    /// pixel's own sequence, whose dimensions 0 and 1 place the camera samples:
    /// camera sample `s` takes point `s`. The integrator gives dimensions 2 and 3
    /// to the first area light (or the environment) at the camera ray's hit when
    /// it takes one sample per camera sample, so that the pixel position and the
    /// light sample are stratified together in 4D, not only each on its own.
    Joint { k: u32 },
}

impl DimensionPair {
    /// A distinct 64-bit number per pair: the kind in bits 0–1, the depth in bits
    /// 2–31 (a render follows at most 64 reflections), the light in bits 32–63.
    #[inline]
    fn id(self) -> u64 {
        let depth = |d: u32| {
            debug_assert!(d < 1 << 30, "reflection depth {d} out of range");
            ((d & 0x3fff_ffff) as u64) << 2
        };
        match self {
            Self::Pixel => 0,
            Self::Light { light, depth: d } => 1 | depth(d) | (light as u64) << 32,
            Self::Environment { depth: d } => 2 | depth(d),
            Self::Brdf { light, depth: d } => 3 | depth(d) | (light as u64) << 32,
            // The pixel's own sequence (other dimensions of it).
            Self::Joint { .. } => Self::Pixel.id(),
        }
    }

    /// Which Sobol dimensions the pair reads: `2k` and `2k + 1`.
    #[inline]
    fn dimension_pair(self) -> u32 {
        match self {
            Self::Joint { k } => {
                debug_assert!((1..=MAX_JOINT).contains(&k), "joint pair {k}");
                k.min(MAX_JOINT)
            }
            _ => 0,
        }
    }
}

/// The most joint pairs beyond the pixel's: Sobol dimensions 2 and 3 (the 2D
/// projection of dimensions 4 and 5 is a (3, 2)-net at 256 points, too weak).
pub const MAX_JOINT: u32 = 1;

/// Sets the Sobol keys apart from the PCG stream states (also hashes of the seed
/// and the pixel).
const SOBOL_SALT: u64 = 0x5b0b_01ee_d5ea_2b1c;

/// The points per `sobol_burley` sequence.
const BLOCK_BITS: u32 = 16;

/// One pixel's Owen-scrambled Sobol sequence for one [`DimensionPair`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SobolSequence {
    /// The 64-bit hash of (render seed, pixel, pair); blocks of 2^16 points after
    /// the first re-hash it.
    key: u64,
    /// Which two Sobol dimensions: `2·dimensions` and `2·dimensions + 1`.
    dimensions: u32,
    /// The scrambles of the first 2^16 points.
    first_block: Scrambles,
}

impl SobolSequence {
    pub fn new(seed: u64, pixel: u64, pair: DimensionPair) -> Self {
        let key = mix64(mix64(mix64(seed ^ SOBOL_SALT) ^ pixel) ^ pair.id());
        let dimensions = pair.dimension_pair();
        Self {
            key,
            dimensions,
            first_block: Scrambles::new(fold(key), dimensions),
        }
    }

    /// The `sobol_burley` seed of the block of 2^16 points that holds point `index`.
    #[inline]
    pub fn block_seed(self, index: u64) -> u32 {
        match index >> BLOCK_BITS {
            0 => fold(self.key),
            block => fold(mix64(self.key ^ block)),
        }
    }

    #[inline]
    fn scrambles(self, index: u64) -> Scrambles {
        match index >> BLOCK_BITS {
            0 => self.first_block,
            _ => Scrambles::new(self.block_seed(index), self.dimensions),
        }
    }

    /// Point `index` of the sequence, in [0, 1)²: Sobol dimensions `2k` and
    /// `2k + 1` (0 and 1 but for [`DimensionPair::Joint`]) of
    /// `sobol_burley::sample(index mod 2^16, dimension, self.block_seed(index))`.
    #[inline]
    pub fn point(self, index: u64) -> Vec2 {
        self.scrambles(index).point(index as u32 & BLOCK_MASK)
    }

    /// Points `first..first + out.len()`, [`LANES`] at a time
    /// (hashed in SIMD lanes) where that many consecutive ones share a block.
    #[inline]
    pub fn fill(self, first: u64, out: &mut [Vec2]) {
        for (chunk, start) in out.chunks_mut(LANES).zip((first..).step_by(LANES)) {
            let lanes = self.lanes_at(start);
            for (k, p) in chunk.iter_mut().enumerate() {
                *p = lanes.lane(k);
            }
        }
    }

    /// Points `first..first + out.len()`, as lanes.
    #[inline]
    pub fn fill_lanes(self, first: u64, out: &mut SamplePoints) {
        for (lanes, start) in out.chunks_mut().iter_mut().zip((first..).step_by(LANES)) {
            *lanes = self.lanes_at(start);
        }
    }

    /// Points `first..first + LANES` in lanes.
    #[inline]
    pub fn lanes_at(self, first: u64) -> PointLanes {
        self.lanes_strided(first, 1)
    }

    /// Points `first + k·stride`, lane k: hashed together where they share a
    /// block, else point by point.
    #[inline]
    pub fn lanes_strided(self, first: u64, stride: u64) -> PointLanes {
        self.lanes_strided_from(first, stride, 0)
    }

    /// Points `first + (k − lane)·stride` in the lanes k from `lane` on (the
    /// lanes before it repeat point `first`): a run of a pixel's samples that
    /// starts at lane `lane` of a chunk holding several pixels.
    #[inline]
    pub fn lanes_strided_from(self, first: u64, stride: u64, lane: usize) -> PointLanes {
        let last = first + (LANES - 1).saturating_sub(lane) as u64 * stride;
        let step = |k: usize| k.saturating_sub(lane) as u64;
        if first >> BLOCK_BITS == last >> BLOCK_BITS {
            let i = first as u32 & BLOCK_MASK;
            let steps = U32Lanes::new(std::array::from_fn(|k| step(k) as u32));
            let index = U32Lanes::splat(i) + steps * U32Lanes::splat(stride as u32);
            self.scrambles(first).points(index)
        } else {
            let points: [Vec2; LANES] =
                std::array::from_fn(|k| self.point(first + step(k) * stride));
            PointLanes::from_points(&points)
        }
    }
}

const BLOCK_MASK: u32 = (1 << BLOCK_BITS) - 1;

/// The hashed seeds `sobol_burley::sample` derives from its `seed` (version
/// 0.5): one shuffles the index, one Owen-scrambles each of the two dimensions;
/// and which two dimensions they are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Scrambles {
    index: u32,
    x: u32,
    y: u32,
    dimensions: u32,
}

/// `sobol_burley::sample`'s per-dimension constants, by dimension mod 4.
const DIMENSION_CONSTANTS: [u32; 4] = [0x912f_69ba, 0x174f_18ab, 0x691e_72ca, 0xb40c_c1b8];

impl Scrambles {
    #[inline]
    fn new(seed: u32, dimensions: u32) -> Self {
        // As in `sobol_burley::sample`: the dimension's scramble seed is the
        // seed's product, its dimension set (dimension / 4) and a constant.
        let dimension_seed = seed.wrapping_mul(0x9c8f_2d3b);
        let scramble =
            |d: u32| hash(dimension_seed ^ (d >> 2) ^ DIMENSION_CONSTANTS[d as usize & 3]);
        Self {
            index: hash(seed ^ 0x79c6_8e4a),
            x: scramble(2 * dimensions),
            y: scramble(2 * dimensions + 1),
            dimensions,
        }
    }

    /// The points of the indices `index` (all below 2^16), as [`Self::point`]
    /// computes each, bit for bit ([`points_of`]).
    #[inline]
    fn points(self, index: U32Lanes) -> PointLanes {
        let splat = U32Lanes::splat;
        points_of(
            index,
            [splat(self.index), splat(self.x), splat(self.y)],
            self.joint_tables(),
        )
    }

    /// The tables of this sequence's two dimensions where it reads a joint
    /// pair; `None` for dimensions 0 and 1, which need none.
    #[inline]
    fn joint_tables(self) -> Option<&'static PairTables> {
        match self.dimensions {
            0 => None,
            k => Some(&JOINT_TABLES[k as usize - 1]),
        }
    }

    /// Point `i < 2^16`: the index shuffled (an Owen scramble of its reversed
    /// bits), the Sobol point of the shuffled index, each coordinate Owen-scrambled.
    #[inline]
    fn point(self, i: u32) -> Vec2 {
        let shuffled = owen_scramble_rev(i.reverse_bits(), self.index);
        let (x, y) = match self.joint_tables() {
            None => {
                let x = shuffled.reverse_bits() & BLOCK_MASK;
                (x, sobol_dimension_1(x, |m| m))
            }
            Some(tables) => lookup(tables, shuffled),
        };
        let unit =
            |v: u32, scramble: u32| u32_to_f32_norm(owen_scramble_rev(v, scramble).reverse_bits());
        Vec2::new(unit(x, self.x), unit(y, self.y))
    }
}

/// The points of the indices `index` (all below 2^16), each lane's of its
/// own scrambles `[index, x, y]` ([`Scrambles`]), as [`Scrambles::point`]
/// computes each, bit for bit: the integer hashing of them all in SIMD lanes
/// (wrapping products, exact), a joint pair's table lookups lane by lane.
#[inline]
fn points_of(
    index: U32Lanes,
    [index_scramble, x_scramble, y_scramble]: [U32Lanes; 3],
    tables: Option<&PairTables>,
) -> PointLanes {
    let shuffled = owen_scramble_lanes(reverse_bits_lanes(index), index_scramble);
    let (xs, ys) = match tables {
        None => {
            let x = reverse_bits_lanes(shuffled) & U32Lanes::splat(BLOCK_MASK);
            (x, sobol_dimension_1(x, U32Lanes::splat))
        }
        Some(tables) => {
            let (mut xs, mut ys) = ([0u32; LANES], [0u32; LANES]);
            for (k, &shuffled) in shuffled.to_array().iter().enumerate() {
                (xs[k], ys[k]) = lookup(tables, shuffled);
            }
            (U32Lanes::new(xs), U32Lanes::new(ys))
        }
    };
    PointLanes {
        x: unit_lanes(xs, x_scramble),
        y: unit_lanes(ys, y_scramble),
    }
}

/// The points of a chunk's runs of camera samples for one pair, every run's
/// lanes from its own pixel's sequence, hashed together in one set of
/// lanes: lane k takes point `first + (k − lane)·stride + j` of the sequence
/// of its run `(sequence, first, lane)`, the last run whose first lane is
/// at most k.
#[derive(Clone, Copy, Debug)]
pub struct RunLanes {
    /// Each lane's point index at `j = 0`.
    index: U32Lanes,
    /// Each lane's sequence's scrambles `[index, x, y]`.
    scrambles: [U32Lanes; 3],
    tables: Option<&'static PairTables>,
}

impl RunLanes {
    /// The runs' lanes for the points `j < points`; `None` where a lane's
    /// points leave the first 2^16 of its sequence, or the runs read
    /// different dimensions. The first run starts at lane 0.
    pub fn new(runs: &[(SobolSequence, u64, usize)], stride: u64, points: u64) -> Option<Self> {
        let (first_run, _, _) = *runs.first()?;
        let dimensions = first_run.dimensions;
        let mut index = [0u32; LANES];
        let mut scrambles = [[0u32; LANES]; 3];
        let mut run = 0;
        for k in 0..LANES {
            while runs.get(run + 1).is_some_and(|&(_, _, lane)| lane <= k) {
                run += 1;
            }
            let (sequence, first, lane) = runs[run];
            let i = first + k.checked_sub(lane)? as u64 * stride;
            if (i + points.max(1) - 1) >> BLOCK_BITS != 0 || sequence.dimensions != dimensions {
                return None;
            }
            let hashed = sequence.first_block;
            index[k] = i as u32;
            [scrambles[0][k], scrambles[1][k], scrambles[2][k]] =
                [hashed.index, hashed.x, hashed.y];
        }
        Some(Self {
            index: U32Lanes::new(index),
            scrambles: scrambles.map(U32Lanes::new),
            tables: first_run.first_block.joint_tables(),
        })
    }

    /// Every lane's point `j`.
    #[inline]
    pub fn points(&self, j: u32) -> PointLanes {
        points_of(self.index + U32Lanes::splat(j), self.scrambles, self.tables)
    }
}

/// The unscrambled points of a pair of dimensions, bits reversed (as
/// `sobol_burley::parts::sobol_rev` gives them), of the index whose reversed
/// bits are `index_rev`, from the pair's `tables`.
#[inline]
fn lookup(tables: &PairTables, index_rev: u32) -> (u32, u32) {
    // The index's bits 0–7 and 8–15, still reversed.
    let (low, high) = (
        (index_rev >> 24) as usize,
        (index_rev >> 16 & 0xff) as usize,
    );
    let both = tables[0][low] ^ tables[1][high];
    (both as u32, (both >> 32) as u32)
}

/// Sobol dimension 1 of an index below 2^16 whose bits are `index`, bits
/// reversed (as `sobol_burley::parts::sobol_rev` gives it): no table needed.
/// Its direction numbers `v_1 = 1/2`, `v_j = v_{j−1} ⊕ v_{j−1}/2` make the
/// generator matrix Pascal's triangle mod 2: `v_j` has the bit of `2^−(m+1)`
/// where `C(j, m)` is odd, which by Lucas's theorem is where the bits of `m`
/// are a subset of those of `j`. Reversed, bit `m` of the point is then the
/// XOR of the index bits `j ⊇ m`: a superset transform over the four bits of
/// the bit positions, one shift-and-XOR per bit. Dimension 0 (van der Corput)
/// is the index itself. For one `u32` or for lanes of them (`splat` makes a
/// constant of the type).
#[inline(always)]
fn sobol_dimension_1<T>(index: T, splat: impl Fn(u32) -> T) -> T
where
    T: Copy + Shr<u32, Output = T> + BitAnd<Output = T> + BitXor<Output = T>,
{
    let mut x = index;
    for (shift, positions) in [(1, 0x5555), (2, 0x3333), (4, 0x0f0f), (8, 0x00ff)] {
        x = x ^ ((x >> shift) & splat(positions));
    }
    x
}

/// `sobol_burley::parts::owen_scramble_rev` on [`LANES`] integers, each
/// with its lane's `scramble` (wrapping products and sums, so the same bits).
#[inline]
fn owen_scramble_lanes(mut n_rev: U32Lanes, scramble: U32Lanes) -> U32Lanes {
    n_rev ^= n_rev * U32Lanes::splat(0x3d20_adea);
    n_rev += scramble;
    n_rev *= (scramble >> 16) | U32Lanes::splat(1);
    n_rev ^= n_rev * U32Lanes::splat(0x0552_6c56);
    n_rev ^= n_rev * U32Lanes::splat(0x53a2_2864);
    n_rev
}

/// `u32::reverse_bits` on [`LANES`] integers. Written lane by lane, the
/// compiler makes it one vector bit reversal: on a CPU with GFNI a byte shuffle
/// and one affine transform over GF(2), two instructions where swapping ever
/// larger bit groups takes twenty.
#[inline]
fn reverse_bits_lanes(v: U32Lanes) -> U32Lanes {
    U32Lanes::new(v.to_array().map(u32::reverse_bits))
}

/// The coordinates in [0, 1) of [`LANES`] scrambled Sobol values, as
/// `u32_to_f32_norm(owen_scramble_rev(v, scramble).reverse_bits())`: the top 23
/// bits as the mantissa of a float in [1, 2), minus 1.
#[inline]
fn unit_lanes(v: U32Lanes, scramble: U32Lanes) -> F32Lanes {
    let bits =
        (reverse_bits_lanes(owen_scramble_lanes(v, scramble)) >> 9) | U32Lanes::splat(0x3f80_0000);
    cast::<U32Lanes, F32Lanes>(bits) - F32Lanes::ONE
}

/// A pair of dimensions' tables by index byte, `[byte][b]`, each entry the
/// first dimension's value in its low 32 bits and the second's in its high.
type PairTables = [[u64; 256]; 2];

/// Two dimensions' tables `[d][byte][b]` as [`PairTables`].
const fn pack(t: [[[u32; 256]; 2]; 2]) -> PairTables {
    let mut packed = [[0u64; 256]; 2];
    let mut k = 0;
    while k < 2 {
        let mut b = 0;
        while b < 256 {
            packed[k][b] = t[0][k][b] as u64 | (t[1][k][b] as u64) << 32;
            b += 1;
        }
        k += 1;
    }
    packed
}

/// The generator tables of Sobol dimensions 2 to 5 (the joint pairs) by bytes
/// of the index, bits reversed, made once from
/// `sobol_burley::parts::sobol_rev`: a point is linear in its index's bits, so a
/// byte's entry is the point of that byte alone.
static JOINT_TABLES: std::sync::LazyLock<[PairTables; MAX_JOINT as usize]> =
    std::sync::LazyLock::new(|| {
        let mut tables = [[[[0u32; 256]; 2]; 2]; MAX_JOINT as usize];
        for (k, pair) in tables.iter_mut().enumerate() {
            for (d, dimension) in pair.iter_mut().enumerate() {
                let sobol_dimension = 2 * (k as u32 + 1) + d as u32;
                for (byte, table) in dimension.iter_mut().enumerate() {
                    for (b, entry) in table.iter_mut().enumerate() {
                        // The reversed index holds index byte `byte` in its bits
                        // 24 − 8·byte upwards.
                        let index_rev = (b as u32) << (24 - 8 * byte);
                        *entry = sobol_burley::parts::sobol_rev(index_rev, sobol_dimension);
                    }
                }
            }
        }
        tables.map(pack)
    });

/// Consecutive points of one pixel's sequence for one pair, named but not yet
/// hashed: [`crate::SamplePattern::fill`] makes the [`SobolSequence`] only for the
/// Sobol pattern, so the other patterns pay nothing for it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SobolPoints {
    /// The render's seed.
    pub seed: u64,
    /// The pixel's index, `y · width + x`.
    pub pixel: u64,
    pub pair: DimensionPair,
    /// The index of the first point.
    pub first: u64,
}

impl SobolPoints {
    /// The positions in the pixel, points `0..spp` of the [`DimensionPair::Pixel`]
    /// sequence.
    pub fn pixel_positions(seed: u64, pixel: u64) -> Self {
        Self {
            seed,
            pixel,
            pair: DimensionPair::Pixel,
            first: 0,
        }
    }

    /// The sequence these points come from.
    pub fn sequence(self) -> SobolSequence {
        SobolSequence::new(self.seed, self.pixel, self.pair)
    }

    /// Points `first..first + out.len()` of the sequence.
    #[inline]
    pub fn fill(self, out: &mut [Vec2]) {
        self.sequence().fill(self.first, out);
    }
}

/// The last few [`SobolSequence`]s a thread made, by the points that named them:
/// a pixel's camera samples take their points of a pair from one sequence, so
/// the sequence is hashed once per pixel and pair rather than once per sample.
#[derive(Clone, Debug, Default)]
pub struct SequenceCache {
    entries: [Option<(SobolPoints, SobolSequence)>; CACHED_SEQUENCES],
    /// The entry the next new sequence replaces.
    next: usize,
}

/// Enough for a few lights, their BRDF pairs and the environment.
const CACHED_SEQUENCES: usize = 4;

impl SequenceCache {
    /// The sequence `points` come from ([`SobolPoints::sequence`]).
    #[inline]
    pub fn sequence(&mut self, points: SobolPoints) -> SobolSequence {
        let same = |named: &SobolPoints| {
            (named.seed, named.pixel, named.pair) == (points.seed, points.pixel, points.pair)
        };
        if let Some((_, sequence)) = self.entries.iter().flatten().find(|(n, _)| same(n)) {
            return *sequence;
        }
        let sequence = points.sequence();
        self.entries[self.next] = Some((points, sequence));
        self.next = (self.next + 1) % CACHED_SEQUENCES;
        sequence
    }
}

/// 64 bits to 32, both halves mixed in.
#[inline]
fn fold(h: u64) -> u32 {
    (h ^ (h >> 32)) as u32
}
