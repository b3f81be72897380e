//! Polynomial `acos`, `atan2` and `sin_cos` over [`Float`], for lanes where libm would
//! take one lane at a time.
//!
//! They round differently from libm, by a few units in the last place. A
//! caller that must decide what libm's value decides (a checkerboard's edge)
//! compares against its boundaries with a margin of [`ACOS_ERROR`] or
//! [`ATAN2_ERROR`] and takes libm's value inside it; one that reads a map at
//! the angles (the environment's lat-long coordinates) takes them as they are,
//! in its scalar path as in its lanes, so both give the same bits.

use crate::Float;
use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, LN_2, LOG2_E, PI, SQRT_2};

/// A bound on `|acos_approx(x) − acos(x)|` in radians over [−1, 1]: the
/// polynomial's own 2·10⁻⁸ (Abramowitz and Stegun 4.4.46) plus the rounding
/// of its f32 evaluation, with room (the tests measure under 10⁻⁶).
pub const ACOS_ERROR: f32 = 4e-6;

/// A bound on `|atan2_approx(y, x) − atan2(y, x)|` in radians for finite
/// `(y, x)`: the polynomial's relative 2·10⁻⁷ (Cephes' `atanf`) plus the
/// rounding of its f32 evaluation and of the octant's offset, with room (the
/// tests measure 4.8·10⁻⁷, two units in the last place of π).
pub const ATAN2_ERROR: f32 = 1e-6;

/// `acos(x)` for `x` in [−1, 1]: `√(1 − |x|)·P(|x|)`, reflected as
/// `π − acos(|x|)` for negative `x` (Abramowitz and Stegun 4.4.46).
#[inline(always)]
pub fn acos_approx<F: Float>(x: F) -> F {
    const A: [f32; 8] = [
        FRAC_PI_2,
        -0.214_598_8,
        0.088_978_99,
        -0.050_174_303,
        0.030_891_88,
        -0.017_088_126,
        0.006_670_09,
        -0.001_262_491_1,
    ];
    let a = x.abs().min(F::ONE);
    let mut p = F::splat(A[7]);
    for &c in A[..7].iter().rev() {
        p = p * a + F::splat(c);
    }
    let r = (F::ONE - a).sqrt() * p;
    F::select(x.lt(F::ZERO), F::splat(PI) - r, r)
}

/// `atan2(y, x)` in [−π, π]: `atan t` of the smaller of `|x|, |y|` over the
/// larger, `t` in [0, 1], then moved to its octant. Past `tan(π/8)`, `t` is
/// reduced to `(t − 1)/(t + 1)` and `π/4` added back; on [−tan(π/8), tan(π/8)]
/// `atan` is Cephes' odd polynomial of degree 9 (Moshier, *Methods and
/// Programs for Mathematical Functions*, 1989; `atanf.c`). Both 0 give 0.
#[inline(always)]
pub fn atan2_approx<F: Float>(y: F, x: F) -> F {
    const TAN_PI_8: f32 = 0.414_213_57;
    const C: [f32; 4] = [-0.333_329_5, 0.199_777_1, -0.138_776_86, 0.080_537_446];
    let (ax, ay) = (x.abs(), y.abs());
    let (small, large) = (ax.min(ay), ax.max(ay));
    let t = F::select(large.eq(F::ZERO), F::ZERO, small / large);
    let reduced = t.gt(F::splat(TAN_PI_8));
    let t = F::select(reduced, (t - F::ONE) / (t + F::ONE), t);
    let z = t * t;
    let mut p = F::splat(C[3]);
    for &c in C[..3].iter().rev() {
        p = p * z + F::splat(c);
    }
    let r = p * z * t + t;
    let r = F::select(reduced, F::splat(FRAC_PI_4) + r, r);
    let r = F::select(ay.gt(ax), F::splat(FRAC_PI_2) - r, r);
    let r = F::select(x.lt(F::ZERO), F::splat(PI) - r, r);
    F::select(y.lt(F::ZERO), -r, r)
}

/// `(sin x, cos x)` for `x` in [−π, π], within 10⁻⁷ of libm's (the tests
/// measure 6·10⁻⁸, a unit in the last place of 1): `x` less
/// its nearest multiple `q·π/2` (taken by comparisons, as `|q| ≤ 2`), in
/// three parts so the difference is exact, then Cephes' polynomials on
/// [−π/4, π/4] (Moshier, `sinf.c`), swapped and negated by `q`.
#[inline(always)]
pub fn sin_cos_approx<F: Float>(x: F) -> (F, F) {
    const HALF_PI_PARTS: [f32; 3] = [1.570_312_5, 4.837_513e-4, 7.549_79e-8];
    const SIN: [f32; 3] = [-1.666_665_5e-1, 8.332_161e-3, -1.951_529_6e-4];
    const COS: [f32; 3] = [4.166_664_6e-2, -1.388_731_6e-3, 2.443_315_7e-5];
    let one_if = |m: F::Mask| F::select(m, F::ONE, F::ZERO);
    let past = |a: f32| one_if(x.gt(F::splat(a))) - one_if(x.lt(F::splat(-a)));
    let q = past(FRAC_PI_4) + past(3.0 * FRAC_PI_4);
    let [p0, p1, p2] = HALF_PI_PARTS.map(F::splat);
    let r = ((x - q * p0) - q * p1) - q * p2;
    let z = r * r;
    let s = ((F::splat(SIN[2]) * z + F::splat(SIN[1])) * z + F::splat(SIN[0])) * z * r + r;
    let c = ((F::splat(COS[2]) * z + F::splat(COS[1])) * z + F::splat(COS[0])) * z * z
        - F::splat(0.5) * z
        + F::ONE;
    let half_turn = q.abs().gt(F::splat(1.5));
    let (s, c) = (F::select(half_turn, -s, s), F::select(half_turn, -c, c));
    let (plus, minus) = (q.eq(F::ONE), q.eq(-F::ONE));
    let sin = F::select(plus, c, F::select(minus, -c, s));
    let cos = F::select(plus, -s, F::select(minus, s, c));
    (sin, cos)
}

/// `log2(x)` for a positive normal `x`: its exponent plus the logarithm of
/// its mantissa `m` in [√2/2, √2) as the series `ln m = 2·atanh t`,
/// `t = (m − 1)/(m + 1)`, `|t| ≤ 0.172`, to `t⁹` (the next term is 2·10⁻⁹
/// of it), so relative to the result near `x = 1` as elsewhere.
#[inline(always)]
pub fn log2_approx<F: Float>(x: F) -> F {
    const SERIES: [f32; 4] = [1.0 / 3.0, 1.0 / 5.0, 1.0 / 7.0, 1.0 / 9.0];
    let (m, e) = x.frexp();
    let big = m.gt(F::splat(SQRT_2));
    let (m, e) = (
        F::select(big, m * F::splat(0.5), m),
        F::select(big, e + F::ONE, e),
    );
    let t = (m - F::ONE) / (m + F::ONE);
    let t2 = t * t;
    let mut p = F::splat(SERIES[3]);
    for &c in SERIES[..3].iter().rev() {
        p = p * t2 + F::splat(c);
    }
    let half_ln = p * t2 * t + t;
    e + half_ln * F::splat(2.0 * LOG2_E)
}

/// `2^z`, exactly 1 at 0 and 0 below −126: `z = n + f` with `n` the nearest
/// whole number (by adding and taking away 1.5·2²³, ties to even) and `f` in
/// [−½, ½]; `2^f = e^(f·ln 2)` by its Taylor series to the seventh power
/// (the next term is 6·10⁻⁹), times `2^n` made as bits. `z` above 127 is
/// taken as 127.
#[inline(always)]
pub fn exp2_approx<F: Float>(z: F) -> F {
    const MAGIC: f32 = 12_582_912.0;
    const TAYLOR: [f32; 7] = [
        1.0,
        1.0 / 2.0,
        1.0 / 6.0,
        1.0 / 24.0,
        1.0 / 120.0,
        1.0 / 720.0,
        1.0 / 5040.0,
    ];
    let below = z.lt(F::splat(-126.0));
    let clamped = z.max(F::splat(-126.0)).min(F::splat(127.0));
    let n = (clamped + F::splat(MAGIC)) - F::splat(MAGIC);
    let g = (clamped - n) * F::splat(LN_2);
    let mut p = F::splat(TAYLOR[6]);
    for &c in TAYLOR[..6].iter().rev() {
        p = p * g + F::splat(c);
    }
    let power = (p * g + F::ONE) * n.exp2i();
    F::select(below, F::ZERO, power)
}

/// `x^y` for a positive normal `x` and a finite `y`, as
/// `exp2(y·log2 x)` ([`log2_approx`], [`exp2_approx`]): within a relative
/// 2·10⁻⁷·(1 + |y·log2 x|) of the exact power (the tests measure it), 0
/// where that is below 2⁻¹²⁶. One kernel for one `f32` and for lanes, where
/// libm's `powf` would take one lane at a time.
#[inline(always)]
pub fn powf_approx<F: Float>(x: F, y: F) -> F {
    exp2_approx(y * log2_approx(x))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::F32Lanes;

    #[test]
    fn acos_is_within_its_bound_of_libm() {
        let mut worst = 0.0f32;
        for i in 0..=200_000 {
            let x = -1.0 + 2.0 * i as f32 / 200_000.0;
            worst = worst.max((acos_approx(x) - x.acos()).abs());
        }
        assert!(worst < 1e-6, "{worst}");
        assert!(worst < ACOS_ERROR);
    }

    #[test]
    fn atan2_is_within_its_bound_of_libm_in_every_octant() {
        let mut worst = 0.0f32;
        for i in 0..100_000 {
            let a = -PI + 2.0 * PI * (i as f32 + 0.5) / 100_000.0;
            for r in [1e-3f32, 0.7, 1.0, 250.0] {
                let (y, x) = (r * a.sin(), r * a.cos());
                worst = worst.max((atan2_approx(y, x) - y.atan2(x)).abs());
            }
        }
        for (y, x) in [
            (0.0f32, 1.0f32),
            (1.0, 0.0),
            (0.0, -1.0),
            (-1.0, 0.0),
            (1.0, 1.0),
        ] {
            worst = worst.max((atan2_approx(y, x) - y.atan2(x)).abs());
        }
        assert!(worst < 5e-7, "{worst}");
        assert!(worst < ATAN2_ERROR);
        assert_eq!(atan2_approx(0.0f32, 0.0), 0.0);
    }

    #[test]
    fn sin_cos_is_within_its_bound_of_libm() {
        let mut worst = 0.0f32;
        let mut check = |x: f32| {
            let (s, c) = sin_cos_approx(x);
            worst = worst.max((s - x.sin()).abs()).max((c - x.cos()).abs());
        };
        for i in 0..=400_000 {
            check(-PI + 2.0 * PI * i as f32 / 400_000.0);
        }
        for x in [0.0, FRAC_PI_4, 3.0 * FRAC_PI_4, FRAC_PI_2, PI, -PI, 1e-30] {
            check(x.next_down());
            check(x);
            check(x.next_up());
        }
        assert!(worst < 1e-7, "{worst}");
        assert_eq!(sin_cos_approx(0.0f32), (0.0, 1.0));
    }

    #[test]
    fn powers_are_within_their_bound_of_the_exact_power() {
        let mut worst = 0.0f64;
        for i in 0..=20_000 {
            // x from 1 down to 1e-30, densest near 1 where lobes peak.
            let x = if i < 10_000 {
                1.0 - i as f32 / 20_000.0
            } else {
                10f32.powf(-30.0 * (i - 10_000) as f32 / 10_000.0)
            };
            for y in [
                0.0f32,
                0.001,
                1.0 / 1001.0,
                1.0 / 17.0,
                0.5,
                1.0,
                16.0,
                120.0,
                1000.0,
            ] {
                let exact = f64::from(x).powf(f64::from(y));
                let z = f64::from(y) * f64::from(x).log2();
                let got = f64::from(powf_approx(x, y));
                if z < -125.0 {
                    assert!(got <= 2f64.powi(-125), "{x}^{y} = {got}");
                    continue;
                }
                let rel = (got - exact).abs() / exact / (1.0 + z.abs());
                worst = worst.max(rel);
            }
        }
        assert!(worst < 2e-7, "{worst}");
        assert_eq!(powf_approx(0.37f32, 0.0), 1.0);
        assert_eq!(powf_approx(1.0f32, 120.0), 1.0);
        assert_eq!(exp2_approx(f32::NEG_INFINITY), 0.0);
    }

    #[test]
    fn exponents_split_and_made_exactly() {
        for x in [1.0f32, 1.5, 0.75, 3e-38, 1.9999999, 6.5e37, 0.1] {
            let (m, e) = x.frexp();
            assert!((1.0..2.0).contains(&m), "{x}: {m}");
            assert_eq!(m * e.exp2i(), x, "{x}");
        }
        for e in [-126.0f32, -1.0, 0.0, 1.0, 127.0] {
            assert_eq!(e.exp2i(), 2f32.powi(e as i32));
        }
    }

    #[test]
    fn lanes_give_each_lanes_scalar_value() {
        let x: [f32; crate::LANES] = std::array::from_fn(|k| -0.97 + 0.13 * k as f32);
        let y: [f32; crate::LANES] = std::array::from_fn(|k| 0.31 - 0.07 * k as f32);
        let acos = acos_approx(F32Lanes::new(x)).to_array();
        let atan2 = atan2_approx(F32Lanes::new(y), F32Lanes::new(x)).to_array();
        let base = x.map(|x| x.abs() + 1e-3);
        let pow = powf_approx(
            F32Lanes::new(base),
            F32Lanes::new(y) * F32Lanes::splat(40.0),
        );
        let pow = pow.to_array();
        let (sin, cos) = sin_cos_approx(F32Lanes::new(x) * F32Lanes::splat(PI));
        let (sin, cos) = (sin.to_array(), cos.to_array());
        for k in 0..crate::LANES {
            let (s, c) = sin_cos_approx(x[k] * PI);
            assert_eq!(
                (sin[k].to_bits(), cos[k].to_bits()),
                (s.to_bits(), c.to_bits())
            );
            assert_eq!(acos[k].to_bits(), acos_approx(x[k]).to_bits());
            assert_eq!(atan2[k].to_bits(), atan2_approx(y[k], x[k]).to_bits());
            let alone = powf_approx(base[k], y[k] * 40.0);
            assert_eq!(
                pow[k].to_bits(),
                alone.to_bits(),
                "{}^{}",
                base[k],
                y[k] * 40.0
            );
        }
    }
}
