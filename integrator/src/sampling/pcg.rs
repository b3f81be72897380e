//! PCG32 (O'Neill, "PCG: A Family of Simple Fast Space-Efficient Statistically
//! Good Algorithms for Random Number Generation", 2014): the 64-bit LCG
//! `s ← a·s + c` with the XSH-RR output permutation, on Glint's one stream
//! [`STREAM`]. One generator ([`Pcg32`]) or [`LANES`] stepping in lanes
//! ([`Pcg32Lanes`]), each lane the scalar generator's numbers bit for bit.
//!
//! The numbers are those of `rand_pcg::Pcg32` (`Lcg64Xsh32`) seeded with
//! `Pcg32::new(state, STREAM)` (the tests compare), Glint's generator before
//! it had lanes; having the state at hand lets a stream jump ahead by any
//! number of draws in one multiply-add (Brown, "Random Number Generation with
//! Arbitrary Strides", 1994), which is how the lanes take consecutive draws
//! of one stream.

use glint_geometry::lanes::{self, F32Lanes, LANES};

/// The LCG's multiplier (Knuth's MMIX constant, PCG's default).
const MULTIPLIER: u64 = 6_364_136_223_846_793_005;

/// The stream every Glint generator runs on.
pub const STREAM: u64 = 0x0a02_bdbf_7bb3_c0a7;

/// The LCG's increment for [`STREAM`] (odd, as the full period needs).
const INCREMENT: u64 = (STREAM << 1) | 1;

/// `(A, C)` with `A·s + C` the state `delta` steps after `s`: the square-and-
/// multiply composition of the affine map `s ↦ a·s + c` with itself (Brown 1994).
const fn jump(delta: u64) -> (u64, u64) {
    let (mut acc_mult, mut acc_plus) = (1u64, 0u64);
    let (mut mult, mut plus) = (MULTIPLIER, INCREMENT);
    let mut d = delta;
    while d > 0 {
        if d & 1 == 1 {
            acc_mult = acc_mult.wrapping_mul(mult);
            acc_plus = acc_plus.wrapping_mul(mult).wrapping_add(plus);
        }
        plus = mult.wrapping_add(1).wrapping_mul(plus);
        mult = mult.wrapping_mul(mult);
        d /= 2;
    }
    (acc_mult, acc_plus)
}

/// `f` of every lane's state, in a loop the compiler vectorizes (`map` over
/// sixteen lanes is called out of line).
#[inline(always)]
fn each(mut states: [u64; LANES], f: impl Fn(u64) -> u64) -> [u64; LANES] {
    for state in &mut states {
        *state = f(*state);
    }
    states
}

/// XSH-RR: the top bits xor-shifted down, rotated by the top five bits.
#[inline(always)]
fn output(state: u64) -> u32 {
    let rot = (state >> 59) as u32;
    let xsh = (((state >> 18) ^ state) >> 27) as u32;
    xsh.rotate_right(rot)
}

/// The state `jump` (from [`jump`]) steps after `state`.
#[inline(always)]
fn jumped((a, c): (u64, u64), state: u64) -> u64 {
    a.wrapping_mul(state).wrapping_add(c)
}

/// The first state of the generator seeded with `seed` (as `rand_pcg` seeds).
#[inline(always)]
fn seeded(seed: u64) -> u64 {
    step(seed.wrapping_add(INCREMENT))
}

#[inline(always)]
fn step(state: u64) -> u64 {
    state.wrapping_mul(MULTIPLIER).wrapping_add(INCREMENT)
}

/// A uniform f32 in [0, 1) from the top 24 bits of a 32-bit draw.
#[inline(always)]
fn unit(draw: u32) -> f32 {
    (draw >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// One PCG32 generator on [`STREAM`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pcg32 {
    state: u64,
}

impl Pcg32 {
    /// The generator seeded with `seed`, as `rand_pcg::Pcg32::new(seed, STREAM)`.
    #[inline]
    pub fn new(seed: u64) -> Self {
        Self {
            state: seeded(seed),
        }
    }

    /// The next 32 random bits.
    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let state = self.state;
        self.state = step(state);
        output(state)
    }

    /// A uniform f32 in [0, 1) from the top 24 bits of the next draw.
    #[inline]
    pub fn uniform(&mut self) -> f32 {
        unit(self.next_u32())
    }

    /// A point uniform in [0, 1)²: x from the next draw, then y.
    #[inline]
    pub fn uniform2(&mut self) -> glam::Vec2 {
        let x = self.uniform();
        glam::Vec2::new(x, self.uniform())
    }

    /// Skips the next `delta` draws.
    #[inline]
    pub fn advance(&mut self, delta: u64) {
        self.state = jumped(jump(delta), self.state);
    }
}

/// The jumps by 0, 2, 4, … 14 draws: lane k of a stream's pairs of draws.
const PAIR_LANES: [(u64, u64); LANES] = {
    let mut jumps = [(0, 0); LANES];
    let mut k = 0;
    while k < LANES {
        jumps[k] = jump(2 * k as u64);
        k += 1;
    }
    jumps
};

/// From a lane's state after its two draws of a chunk to its first draw of the
/// next: the lanes take `2·LANES` draws a chunk.
const NEXT_PAIRS: (u64, u64) = jump(2 * LANES as u64 - 2);

/// [`LANES`] PCG32 generators on [`STREAM`], stepped together.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pcg32Lanes {
    state: [u64; LANES],
}

impl Pcg32Lanes {
    /// Lane k seeded with `seeds[k]`, as [`Pcg32::new`].
    #[inline(always)]
    pub fn new(seeds: [u64; LANES]) -> Self {
        Self {
            state: each(seeds, seeded),
        }
    }

    /// Each lane's next 32 random bits.
    #[inline(always)]
    pub fn next_u32(&mut self) -> [u32; LANES] {
        let mut out = [0; LANES];
        for (out, &state) in out.iter_mut().zip(&self.state) {
            *out = output(state);
        }
        self.state = each(self.state, step);
        out
    }

    /// Each lane's next uniform f32 in [0, 1), as [`Pcg32::uniform`].
    #[inline(always)]
    pub fn uniform(&mut self) -> F32Lanes {
        let state = self.state;
        self.state = each(state, step);
        lanes::from_fn(|k| unit(output(state[k])))
    }

    /// Each lane's next two uniforms, as [`Pcg32::uniform2`]: the second
    /// draw's state and the state after both are each one multiply-add from
    /// the current state (the second by a jump of two), not two in a row.
    #[inline(always)]
    pub fn uniform2(&mut self) -> (F32Lanes, F32Lanes) {
        let first = self.state;
        let second = each(first, step);
        self.state = each(first, |s| jumped(TWO_DRAWS, s));
        let uniforms = |states: [u64; LANES]| lanes::from_fn(|k| unit(output(states[k])));
        (uniforms(first), uniforms(second))
    }

    /// Lane k's generator, where it is now.
    #[inline]
    pub fn lane(&self, k: usize) -> Pcg32 {
        Pcg32 {
            state: self.state[k],
        }
    }

    /// Puts `rng` in lane k.
    #[inline]
    pub fn set_lane(&mut self, k: usize, rng: Pcg32) {
        self.state[k] = rng.state;
    }

    /// Lane k from `if_set` where bit k of `lanes` is set, else from
    /// `if_clear`: the streams of the lanes that drew, the others as they were.
    #[inline(always)]
    pub fn select(lanes: u32, if_set: &Self, if_clear: &Self) -> Self {
        // Without branches, so that it compiles to a blend.
        let mut state = if_clear.state;
        for (k, state) in state.iter_mut().enumerate() {
            let set = 0u64.wrapping_sub(u64::from(lanes >> k & 1));
            *state ^= (*state ^ if_set.state[k]) & set;
        }
        Self { state }
    }
}

/// Two draws' step: the state after `uniform2`.
const TWO_DRAWS: (u64, u64) = jump(2);

/// Fills `out` with uniform points of `rng`, point i from draws 2i and 2i + 1
/// (x, then y), and leaves `rng` past them: the same points and state as
/// drawing them one by one, [`LANES`] points at a time in lanes.
pub fn fill_uniform_pairs(rng: &mut Pcg32, out: &mut [glam::Vec2]) {
    let mut chunks = out.chunks_exact_mut(LANES);
    let mut lanes = Pcg32Lanes {
        state: PAIR_LANES.map(|jump| jumped(jump, rng.state)),
    };
    for chunk in &mut chunks {
        let (x, y) = lanes.uniform2();
        let (x, y) = (x.to_array(), y.to_array());
        for (k, p) in chunk.iter_mut().enumerate() {
            *p = glam::Vec2::new(x[k], y[k]);
        }
        lanes.state = lanes.state.map(|s| jumped(NEXT_PAIRS, s));
    }
    let done = out.len() / LANES * LANES;
    rng.advance(2 * done as u64);
    out[done..].iter_mut().for_each(|p| *p = rng.uniform2());
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_core::RngCore;

    #[test]
    fn draws_are_those_of_rand_pcg_on_the_same_stream() {
        for seed in [0, 1, 0xdead_beef, u64::MAX, 0x0123_4567_89ab_cdef] {
            let mut ours = Pcg32::new(seed);
            let mut theirs = rand_pcg::Pcg32::new(seed, STREAM);
            for _ in 0..1000 {
                assert_eq!(ours.next_u32(), theirs.next_u32(), "seed {seed:#x}");
            }
        }
    }

    #[test]
    fn advancing_skips_exactly_that_many_draws() {
        for delta in [0, 1, 2, 7, 15, 16, 1000, 123_456] {
            let mut jumped = Pcg32::new(42);
            jumped.advance(delta);
            let mut stepped = Pcg32::new(42);
            for _ in 0..delta {
                stepped.next_u32();
            }
            assert_eq!(jumped, stepped, "delta {delta}");
        }
    }

    #[test]
    fn lanes_are_the_scalar_generators() {
        let seeds: [u64; LANES] = std::array::from_fn(|k| 0x9e37_79b9 * k as u64 + 5);
        let mut lanes = Pcg32Lanes::new(seeds);
        let mut scalars = seeds.map(Pcg32::new);
        for round in 0..100 {
            // One draw, then two at once: the pairs start at odd and even draws.
            let u = if round % 3 == 0 {
                vec![lanes.uniform()]
            } else {
                let (x, y) = lanes.uniform2();
                vec![x, y]
            };
            for u in u {
                for (k, rng) in scalars.iter_mut().enumerate() {
                    assert_eq!(u.to_array()[k].to_bits(), rng.uniform().to_bits());
                }
            }
        }
    }

    /// Every length, including partial chunks, gives the one-by-one points and
    /// the one-by-one state after them.
    #[test]
    fn pairs_filled_in_lanes_are_the_pairs_drawn_one_by_one() {
        for n in [0, 1, 7, 8, 9, 16, 61, 64, 256] {
            let mut lanes_rng = Pcg32::new(n as u64 * 31 + 7);
            let mut scalar_rng = lanes_rng;
            let mut filled = vec![glam::Vec2::NAN; n];
            fill_uniform_pairs(&mut lanes_rng, &mut filled);
            for (i, p) in filled.iter().enumerate() {
                let x = scalar_rng.uniform();
                let expected = glam::Vec2::new(x, scalar_rng.uniform());
                assert_eq!(
                    p.to_array().map(f32::to_bits),
                    expected.to_array().map(f32::to_bits),
                    "n {n}, point {i}"
                );
            }
            assert_eq!(lanes_rng, scalar_rng, "n {n}: the state after");
        }
    }
}
