//! [`Float`]: the numbers a kernel is written over, one `f32` or lanes of
//! them, and [`Mask`]: the per-lane truth values its comparisons give.
//!
//! A kernel written once over `F: Float` runs for one ray as `F = f32` (its
//! masks plain `bool`s, its early exits real branches) and for many as
//! `F = f32x4 | f32x8 | f32x16` (masks of lanes, an exit taken only when it
//! holds in every lane), as Mitsuba 3 writes its code once over its `Float`.
//! Each lane performs the IEEE operation the scalar type performs, so a lane's
//! result is bit for bit the scalar one; `min` and `max` keep each type's own
//! NaN rule ([`f32::min`] returns the non-NaN operand; `wide`'s `min` leaves
//! it to the instruction, `minps` returning the second operand), which matters
//! only where an input is already NaN.

use std::fmt::Debug;
use std::ops::{Add, BitAnd, BitOr, BitOrAssign, Div, Mul, Neg, Not, Sub};

/// The truth values of one comparison: a `bool`, or one per lane.
pub trait Mask:
    Copy + Debug + BitAnd<Output = Self> + BitOr<Output = Self> + BitOrAssign + Not<Output = Self>
{
    /// True in every lane.
    const TRUE: Self;
    /// False in every lane.
    const FALSE: Self;
    /// Whether any lane is true.
    fn any(self) -> bool;
    /// Whether every lane is true.
    fn all(self) -> bool;
    /// The lanes as bits, lane k as bit k.
    fn bits(self) -> u32;
}

/// One `f32`, or lanes of them, with the operations kernels need.
pub trait Float:
    Copy
    + Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    type Mask: Mask;
    /// Lanes in one value.
    const WIDTH: usize;
    const ZERO: Self;
    const ONE: Self;
    /// `v` in every lane.
    fn splat(v: f32) -> Self;
    fn sqrt(self) -> Self;
    fn abs(self) -> Self;
    fn min(self, other: Self) -> Self;
    fn max(self, other: Self) -> Self;
    /// `1` for `+0` and positive numbers, `−1` for `−0` and negative ones.
    fn signum(self) -> Self;
    fn is_finite(self) -> Self::Mask;
    fn lt(self, other: Self) -> Self::Mask;
    fn le(self, other: Self) -> Self::Mask;
    fn gt(self, other: Self) -> Self::Mask;
    fn ge(self, other: Self) -> Self::Mask;
    fn eq(self, other: Self) -> Self::Mask;
    /// Per lane, `if_true` where `mask` holds, else `if_false`.
    fn select(mask: Self::Mask, if_true: Self, if_false: Self) -> Self;
    /// [`Self::select`] of two values computed only if some lane takes them:
    /// for one `f32` a branch, for lanes both sides only where the mask is
    /// mixed.
    #[inline(always)]
    fn select_with(
        mask: Self::Mask,
        if_true: impl FnOnce() -> Self,
        if_false: impl FnOnce() -> Self,
    ) -> Self {
        if mask.all() {
            if_true()
        } else if !mask.any() {
            if_false()
        } else {
            Self::select(mask, if_true(), if_false())
        }
    }
    /// [`f32::next_up`]: the least float greater than `self` (∞ and NaN kept,
    /// −0 and +0 both to the least positive float), without a branch.
    fn next_up(self) -> Self;
    /// [`f32::next_down`]: `−next_up(−self)`.
    #[inline(always)]
    fn next_down(self) -> Self {
        -(-self).next_up()
    }
    /// `self` times the sign of `sign`, as Dr.Jit's `mulsign`: `self` with
    /// its sign bit flipped where `sign`'s is set (so `−0` and `−NaN` count
    /// as negative), exact for every value.
    fn mulsign(self, sign: Self) -> Self;
    /// `(m, e)` with `self = m·2^e`, `m` in [1, 2) and `e` a whole number, for
    /// a positive normal float (its exponent field read off the bits).
    fn frexp(self) -> (Self, Self);
    /// `2^self` for a whole `self` in [−126, 127], exactly (made as bits).
    fn exp2i(self) -> Self;
    /// The next float from `self` the way `direction` points: `next_up`
    /// where it is positive, `next_down` where negative, `self` where it is
    /// zero or NaN. One step up between two sign flips, since
    /// `next_down(x) = −next_up(−x)`.
    #[inline(always)]
    fn next_away(self, direction: Self) -> Self {
        let away = self.mulsign(direction).next_up().mulsign(direction);
        Self::select(direction.abs().gt(Self::ZERO), away, self)
    }
    /// `self` in `(0, t_max)`, the open range of a ray's valid distances.
    #[inline(always)]
    fn in_ray_range(self, t_max: Self) -> Self::Mask {
        self.gt(Self::ZERO) & self.lt(t_max)
    }
}

impl Mask for bool {
    const TRUE: Self = true;
    const FALSE: Self = false;
    #[inline(always)]
    fn any(self) -> bool {
        self
    }
    #[inline(always)]
    fn all(self) -> bool {
        self
    }
    #[inline(always)]
    fn bits(self) -> u32 {
        self as u32
    }
}

impl Float for f32 {
    type Mask = bool;
    const WIDTH: usize = 1;
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    #[inline(always)]
    fn splat(v: f32) -> Self {
        v
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f32::abs(self)
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        f32::min(self, other)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        f32::max(self, other)
    }
    #[inline(always)]
    fn signum(self) -> Self {
        f32::signum(self)
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
    #[inline(always)]
    fn lt(self, other: Self) -> bool {
        self < other
    }
    #[inline(always)]
    fn le(self, other: Self) -> bool {
        self <= other
    }
    #[inline(always)]
    fn gt(self, other: Self) -> bool {
        self > other
    }
    #[inline(always)]
    fn ge(self, other: Self) -> bool {
        self >= other
    }
    #[inline(always)]
    fn eq(self, other: Self) -> bool {
        self == other
    }
    #[inline(always)]
    fn select(mask: bool, if_true: Self, if_false: Self) -> Self {
        if mask {
            if_true
        } else {
            if_false
        }
    }
    #[inline(always)]
    fn next_up(self) -> Self {
        // Adding +0 turns −0 into +0, whose bits stepped up are the least
        // positive float; the step is a select, not the library's branches.
        let zeroed = self + 0.0;
        let bits = zeroed.to_bits();
        let step = if zeroed >= 0.0 { 1 } else { u32::MAX };
        let stepped = f32::from_bits(bits.wrapping_add(step));
        if self < f32::INFINITY {
            stepped
        } else {
            self
        }
    }
    #[inline(always)]
    fn mulsign(self, sign: Self) -> Self {
        f32::from_bits(self.to_bits() ^ (sign.to_bits() & SIGN_BIT))
    }
    #[inline(always)]
    fn frexp(self) -> (Self, Self) {
        let bits = self.to_bits();
        let e = ((bits >> 23) & 0xff) as i32 - 127;
        (f32::from_bits((bits & MANTISSA) | ONE_BITS), e as f32)
    }
    #[inline(always)]
    fn exp2i(self) -> Self {
        f32::from_bits(((self as i32 + 127) as u32) << 23)
    }
}

/// The mantissa bits of an `f32`, and the bits of 1.0.
const MANTISSA: u32 = 0x007f_ffff;
const ONE_BITS: u32 = 0x3f80_0000;

/// The sign bit of an `f32`.
const SIGN_BIT: u32 = 1 << 31;

/// [`Float`] and [`Mask`] for a `wide` vector of f32: its masks are the same
/// register type, each lane all ones (true) or all zeros (false).
macro_rules! lanes_of_f32 {
    ($t:ty, $i:ty, $width:expr) => {
        impl Mask for $t {
            const TRUE: Self = <$t>::new([f32::from_bits(u32::MAX); $width]);
            const FALSE: Self = <$t>::ZERO;
            #[inline(always)]
            fn any(self) -> bool {
                <$t>::any(self)
            }
            #[inline(always)]
            fn all(self) -> bool {
                <$t>::all(self)
            }
            #[inline(always)]
            fn bits(self) -> u32 {
                self.to_bitmask() as u32
            }
        }

        impl Float for $t {
            type Mask = $t;
            const WIDTH: usize = $width;
            const ZERO: Self = <$t>::ZERO;
            const ONE: Self = <$t>::ONE;
            #[inline(always)]
            fn splat(v: f32) -> Self {
                <$t>::splat(v)
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                <$t>::sqrt(self)
            }
            #[inline(always)]
            fn abs(self) -> Self {
                <$t>::abs(self)
            }
            #[inline(always)]
            fn min(self, other: Self) -> Self {
                <$t>::min(self, other)
            }
            #[inline(always)]
            fn max(self, other: Self) -> Self {
                <$t>::max(self, other)
            }
            #[inline(always)]
            fn signum(self) -> Self {
                <$t>::signum(self)
            }
            #[inline(always)]
            fn is_finite(self) -> Self {
                <$t>::is_finite(self)
            }
            #[inline(always)]
            fn lt(self, other: Self) -> Self {
                self.simd_lt(other)
            }
            #[inline(always)]
            fn le(self, other: Self) -> Self {
                self.simd_le(other)
            }
            #[inline(always)]
            fn gt(self, other: Self) -> Self {
                self.simd_gt(other)
            }
            #[inline(always)]
            fn ge(self, other: Self) -> Self {
                self.simd_ge(other)
            }
            #[inline(always)]
            fn eq(self, other: Self) -> Self {
                self.simd_eq(other)
            }
            #[inline(always)]
            fn select(mask: Self, if_true: Self, if_false: Self) -> Self {
                mask.select(if_true, if_false)
            }
            #[inline(always)]
            fn next_up(self) -> Self {
                // As for `f32`, lane by lane; the step, +1 or −1 as the sign
                // bit is clear or set, is the bits shifted arithmetically
                // (0 or −1), or'ed with 1.
                let zeroed = self + <$t>::ZERO;
                let bits: $i = bytemuck::cast(zeroed);
                let stepped: $t = bytemuck::cast(bits + ((bits >> 31) | <$i>::splat(1)));
                self.simd_lt(<$t>::splat(f32::INFINITY))
                    .select(stepped, self)
            }
            #[inline(always)]
            fn mulsign(self, sign: Self) -> Self {
                let sign_bit = <$i>::splat(SIGN_BIT as i32);
                let bits: $i = bytemuck::cast(self);
                bytemuck::cast(bits ^ (bytemuck::cast::<_, $i>(sign) & sign_bit))
            }
            #[inline(always)]
            fn frexp(self) -> (Self, Self) {
                let bits: $i = bytemuck::cast(self);
                let e: $i = ((bits >> 23) & <$i>::splat(0xff)) - <$i>::splat(127);
                let mantissa: $i =
                    (bits & <$i>::splat(MANTISSA as i32)) | <$i>::splat(ONE_BITS as i32);
                (bytemuck::cast(mantissa), e.round_float())
            }
            #[inline(always)]
            fn exp2i(self) -> Self {
                bytemuck::cast((self.trunc_int() + <$i>::splat(127)) << 23)
            }
        }
    };
}

lanes_of_f32!(wide::f32x4, wide::i32x4, 4);
lanes_of_f32!(wide::f32x8, wide::i32x8, 8);
lanes_of_f32!(wide::f32x16, wide::i32x16, 16);

#[cfg(test)]
mod tests {
    use super::*;

    const VALUES: [f32; 16] = [
        0.0,
        -0.0,
        1.0,
        -1.0,
        f32::MIN_POSITIVE,
        -f32::MIN_POSITIVE,
        f32::from_bits(1),
        -f32::from_bits(1),
        f32::MAX,
        -f32::MAX,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
        123.456,
        -1e-30,
        3e38,
    ];

    /// `F`'s `next_up`, `next_down`, and `next_away` and `mulsign` against
    /// every value as the direction or sign, lane by lane, as `f32`s.
    fn stepped<F: Float>(
        values: &[f32],
        lanes: impl Fn(&[f32]) -> F,
        array: impl Fn(F) -> Vec<f32>,
    ) {
        let bits = |v: Vec<f32>| v.into_iter().map(f32::to_bits).collect::<Vec<_>>();
        for chunk in values.chunks(F::WIDTH) {
            let mut v = chunk.to_vec();
            v.resize(F::WIDTH, 0.0);
            let x = lanes(&v);
            let up: Vec<f32> = chunk.iter().map(|x| x.next_up()).collect();
            let down: Vec<f32> = chunk.iter().map(|x| x.next_down()).collect();
            let n = chunk.len();
            assert_eq!(
                bits(array(x.next_up()))[..n],
                bits(up),
                "up, {} lanes",
                F::WIDTH
            );
            let got = bits(array(x.next_down()));
            assert_eq!(got[..n], bits(down), "down, {} lanes", F::WIDTH);
            for turn in 0..values.len() {
                let d: Vec<f32> = (0..F::WIDTH)
                    .map(|k| values[(k + turn) % values.len()])
                    .collect();
                let (away, signed) = (x.next_away(lanes(&d)), x.mulsign(lanes(&d)));
                let away_of = |(x, d): (&f32, &f32)| match () {
                    _ if *d > 0.0 => x.next_up(),
                    _ if *d < 0.0 => x.next_down(),
                    _ => *x,
                };
                let signed_of = |(x, d): (&f32, &f32)| if d.is_sign_negative() { -x } else { *x };
                let want = chunk.iter().zip(&d).map(away_of).collect();
                assert_eq!(
                    bits(array(away))[..n],
                    bits(want),
                    "away {d:?}, {} lanes",
                    F::WIDTH
                );
                let want = chunk.iter().zip(&d).map(signed_of).collect();
                assert_eq!(
                    bits(array(signed))[..n],
                    bits(want),
                    "mulsign {d:?}, {} lanes",
                    F::WIDTH
                );
            }
        }
    }

    #[test]
    fn next_up_down_and_away_are_the_library_functions_bit_for_bit_at_every_width() {
        stepped::<f32>(&VALUES, |v| v[0], |f| vec![f]);
        stepped::<wide::f32x4>(
            &VALUES,
            |v| wide::f32x4::new(v.try_into().unwrap()),
            |f| f.to_array().to_vec(),
        );
        stepped::<wide::f32x8>(
            &VALUES,
            |v| wide::f32x8::new(v.try_into().unwrap()),
            |f| f.to_array().to_vec(),
        );
        stepped::<wide::f32x16>(
            &VALUES,
            |v| wide::f32x16::new(v.try_into().unwrap()),
            |f| f.to_array().to_vec(),
        );
    }
    #[test]
    fn select_with_computes_only_the_sides_some_lane_takes() {
        let calls = std::cell::Cell::new((0, 0));
        let pick = |mask| {
            <wide::f32x4 as Float>::select_with(
                mask,
                || {
                    calls.set((calls.get().0 + 1, calls.get().1));
                    wide::f32x4::ONE
                },
                || {
                    calls.set((calls.get().0, calls.get().1 + 1));
                    wide::f32x4::ZERO
                },
            )
        };
        let on = f32::from_bits(u32::MAX);
        assert_eq!(pick(wide::f32x4::TRUE), wide::f32x4::ONE);
        assert_eq!(calls.get(), (1, 0));
        assert_eq!(pick(wide::f32x4::FALSE), wide::f32x4::ZERO);
        assert_eq!(calls.get(), (1, 1));
        let mixed = wide::f32x4::new([on, 0.0, on, 0.0]);
        assert_eq!(pick(mixed).to_array(), [1.0, 0.0, 1.0, 0.0]);
        assert_eq!(calls.get(), (2, 2));
        assert_eq!(f32::select_with(false, || 1.0, || 2.0), 2.0);
    }
}
