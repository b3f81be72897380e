//! The lane width the renderer's wavefronts use, [`LANES`], its types, and
//! helpers for masks held as lanes of all-ones or all-zeros bits.
//!
//! Sixteen lanes by default: one AVX-512 register of f32 (`wide` uses two AVX
//! halves, or four SSE quarters, where the build lacks it); eight with the
//! `lanes8` feature. The code depends on the width only through [`LANES`] and
//! these aliases, and every lane is bit for bit the scalar result, so the
//! image is the same at either width (docs/speed.md measures which is faster).

use crate::vector::Vector3;
use glam::Vec3;

/// [`LANES`] f32 lanes.
#[cfg(not(feature = "lanes8"))]
pub type F32Lanes = wide::f32x16;
/// [`LANES`] i32 lanes.
#[cfg(not(feature = "lanes8"))]
pub type I32Lanes = wide::i32x16;
/// [`LANES`] u32 lanes.
#[cfg(not(feature = "lanes8"))]
pub type U32Lanes = wide::u32x16;
/// The number of lanes (at most 32: sets of lanes are `u32` bits).
#[cfg(not(feature = "lanes8"))]
pub const LANES: usize = 16;

/// [`LANES`] f32 lanes.
#[cfg(feature = "lanes8")]
pub type F32Lanes = wide::f32x8;
/// [`LANES`] i32 lanes.
#[cfg(feature = "lanes8")]
pub type I32Lanes = wide::i32x8;
/// [`LANES`] u32 lanes.
#[cfg(feature = "lanes8")]
pub type U32Lanes = wide::u32x8;
/// The number of lanes (at most 32: sets of lanes are `u32` bits).
#[cfg(feature = "lanes8")]
pub const LANES: usize = 8;

/// [`LANES`] 3-vectors, one per lane.
pub type Vec3Lanes = Vector3<F32Lanes>;

impl Vector3<F32Lanes> {
    /// The vectors `v`, lane k holding `v[k]`.
    #[inline]
    pub fn from_lanes(v: [Vec3; LANES]) -> Self {
        Self {
            x: from_fn(|k| v[k].x),
            y: from_fn(|k| v[k].y),
            z: from_fn(|k| v[k].z),
        }
    }

    /// Lane `lane` as a scalar vector.
    #[inline]
    pub fn lane(&self, lane: usize) -> Vec3 {
        Vec3::new(
            self.x.as_array()[lane],
            self.y.as_array()[lane],
            self.z.as_array()[lane],
        )
    }

    /// Sets lane `lane` to `v`.
    #[inline]
    pub fn set_lane(&mut self, lane: usize, v: Vec3) {
        self.x.as_mut_array()[lane] = v.x;
        self.y.as_mut_array()[lane] = v.y;
        self.z.as_mut_array()[lane] = v.z;
    }
}

/// `a > b` per lane.
#[inline]
pub fn gt(a: F32Lanes, b: F32Lanes) -> F32Lanes {
    a.simd_gt(b)
}

/// `a < b` per lane.
#[inline]
pub fn lt(a: F32Lanes, b: F32Lanes) -> F32Lanes {
    a.simd_lt(b)
}

/// `a <= b` per lane.
#[inline]
pub fn le(a: F32Lanes, b: F32Lanes) -> F32Lanes {
    a.simd_le(b)
}

/// The lanes of `mask` as bits, lane k as bit k.
#[inline]
pub fn bits(mask: F32Lanes) -> u32 {
    mask.to_bitmask()
}

/// Lane k set to `f(k)`. A plain loop: the compiler inlines and vectorizes
/// it, where `std::array::from_fn` and `map` over sixteen lanes are called out
/// of line and fill the array through memory.
#[inline(always)]
pub fn from_fn(mut f: impl FnMut(usize) -> f32) -> F32Lanes {
    let mut lanes = [0.0; LANES];
    for (k, lane) in lanes.iter_mut().enumerate() {
        *lane = f(k);
    }
    F32Lanes::new(lanes)
}

/// `[f(0), …, f(LANES − 1)]` by a loop, for the reason [`from_fn`] gives.
#[inline(always)]
pub fn array_from_fn<T: Copy>(mut f: impl FnMut(usize) -> T) -> [T; LANES] {
    let mut out = [f(0); LANES];
    for (k, lane) in out.iter_mut().enumerate().skip(1) {
        *lane = f(k);
    }
    out
}

/// The lanes whose bit is set in `bits` (lane k as bit k), in order: one
/// step per set bit, where a filter over every lane takes a branch per lane
/// that a random mask mispredicts.
#[inline(always)]
pub fn each_set(bits: u32) -> impl Iterator<Item = usize> {
    let mut rest = bits;
    std::iter::from_fn(move || {
        (rest != 0).then(|| {
            let k = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            k
        })
    })
}

/// The lanes where `values` holds `value`, as bits (lane k as bit k): one
/// comparison of all the lanes.
#[inline(always)]
pub fn bits_eq(values: &[u32; LANES], value: u32) -> u32 {
    let equal = U32Lanes::new(*values).simd_eq(U32Lanes::splat(value));
    bits(bytemuck::cast(equal))
}

/// The mask of the lanes whose bit is set in `bits` (lane k as bit k): the
/// inverse of [`bits`].
#[inline]
pub fn from_bits(bits: u32) -> F32Lanes {
    let bit = U32Lanes::new(std::array::from_fn(|k| 1 << k));
    let set = (U32Lanes::splat(bits) & bit).simd_eq(bit);
    bytemuck::cast(set)
}

/// The least of the lanes of `v` in `mask` that are not NaN (+∞ if none),
/// compared in a tree of pairs rather than one after another.
#[inline]
pub fn min_lane(v: F32Lanes, mask: F32Lanes) -> f32 {
    let v = (mask & !v.is_nan()).select(v, F32Lanes::splat(f32::INFINITY));
    reduce_pairs(v.to_array(), |a, b| if b < a { b } else { a })
}

/// The greatest of the lanes of `v` in `mask` that are not NaN (−∞ if none),
/// as [`min_lane`].
#[inline]
pub fn max_lane(v: F32Lanes, mask: F32Lanes) -> f32 {
    let v = (mask & !v.is_nan()).select(v, F32Lanes::splat(f32::NEG_INFINITY));
    reduce_pairs(v.to_array(), |a, b| if b > a { b } else { a })
}

/// `pick` folded over the lanes in halves: lane i with lane i + n/2, and so on.
#[inline]
fn reduce_pairs(mut lanes: [f32; LANES], pick: impl Fn(f32, f32) -> f32) -> f32 {
    let mut n = LANES;
    while n > 1 {
        n /= 2;
        for i in 0..n {
            lanes[i] = pick(lanes[i], lanes[i + n]);
        }
    }
    lanes[0]
}

/// Every lane as bits: the low [`LANES`] bits set.
#[inline]
pub const fn all_bits() -> u32 {
    u32::MAX >> (32 - LANES)
}

/// The mask of the first `n` lanes.
#[inline]
pub fn first_lanes(n: usize) -> F32Lanes {
    let index = F32Lanes::new(std::array::from_fn(|k| k as f32));
    index.simd_lt(F32Lanes::splat(n as f32))
}

/// Lane j of the result is lane `index[j]` of `values` (each index below
/// [`LANES`]): one `vpermd` on AVX-512 ([`permute_avx512`]); on AVX2 a
/// `vpermps` per 8-lane half of the result and source, blended by which half
/// each index names ([`permute_avx2`]); a lane-by-lane copy elsewhere
/// ([`permute_lanes`]).
#[inline(always)]
pub fn permute(values: F32Lanes, index: U32Lanes) -> F32Lanes {
    #[cfg(all(
        target_arch = "x86_64",
        target_feature = "avx512f",
        not(feature = "lanes8")
    ))]
    let implementation = permute_avx512;
    #[cfg(all(
        target_arch = "x86_64",
        target_feature = "avx2",
        any(feature = "lanes8", not(target_feature = "avx512f"))
    ))]
    let implementation = permute_avx2;
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
    let implementation = permute_lanes;
    implementation(values, index)
}

/// [`permute`] on AVX-512: one `vpermd`.
#[cfg(all(
    target_arch = "x86_64",
    target_feature = "avx512f",
    not(feature = "lanes8")
))]
#[inline(always)]
fn permute_avx512(values: F32Lanes, index: U32Lanes) -> F32Lanes {
    use safe_arch::{m512i, permute_i32_m512i};
    let index = bytemuck::cast::<U32Lanes, m512i>(index);
    bytemuck::cast(permute_i32_m512i(index, bytemuck::cast(values)))
}

/// [`permute`] on AVX2. Compiled wherever the CPU has AVX2, AVX-512 ones
/// included, so that its test runs there too.
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
#[cfg_attr(
    all(target_feature = "avx512f", not(feature = "lanes8"), not(test)),
    allow(dead_code)
)]
#[inline(always)]
fn permute_avx2(values: F32Lanes, index: U32Lanes) -> F32Lanes {
    use safe_arch::shuffle_av_f32_all_m256 as permute_half;
    use safe_arch::{blend_varying_m256, cmp_gt_mask_i32_m256i, m256, m256i};
    let halves: [m256; LANES / 8] = bytemuck::cast(values);
    let indices: [m256i; LANES / 8] = bytemuck::cast(index);
    // `vpermps` reads an index's low three bits: its lane within a half.
    let permuted = indices.map(|index| {
        let mut lanes = permute_half(halves[0], index);
        for (half, source) in halves.iter().enumerate().skip(1) {
            let below = m256i::from([8 * half as i32 - 1; 8]);
            let from_this_half = bytemuck::cast(cmp_gt_mask_i32_m256i(index, below));
            lanes = blend_varying_m256(lanes, permute_half(*source, index), from_this_half);
        }
        lanes
    });
    bytemuck::cast(permuted)
}

/// [`permute`] lane by lane, on any CPU (and the others' test).
#[cfg_attr(
    all(target_arch = "x86_64", target_feature = "avx2", not(test)),
    allow(dead_code)
)]
#[inline(always)]
fn permute_lanes(values: F32Lanes, index: U32Lanes) -> F32Lanes {
    let (values, index) = (values.as_array(), index.as_array());
    from_fn(|j| values[index[j] as usize % LANES])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_set_names_the_set_lanes_in_order() {
        assert_eq!(each_set(0).count(), 0);
        assert_eq!(each_set(0b1010_0001).collect::<Vec<_>>(), [0, 5, 7]);
        let all = (1u32 << LANES) - 1;
        assert!(each_set(all).eq(0..LANES));
        for bits in [0x8000_0001u32, 0x1234_5678] {
            let filtered = (0..32).filter(|k| bits >> k & 1 == 1);
            assert!(each_set(bits).eq(filtered), "{bits:#x}");
        }
    }

    #[test]
    fn bits_eq_names_the_lanes_holding_a_value() {
        let values: [u32; LANES] = std::array::from_fn(|k| [7, u32::MAX, 7, 0][k % 4]);
        for value in [7, u32::MAX, 0, 5] {
            let expected = (0..LANES).filter(|&k| values[k] == value);
            assert!(each_set(bits_eq(&values, value)).eq(expected), "{value}");
        }
    }

    fn lanes(f: impl Fn(usize) -> Vec3) -> Vec3Lanes {
        Vec3Lanes::from_lanes(std::array::from_fn(f))
    }

    #[test]
    fn lane_extremes_skip_nan_and_masked_lanes() {
        let first = [3.0, f32::NAN, -2.0, 7.0, -0.5, 9.0, f32::NAN, 1.0];
        let v = F32Lanes::new(std::array::from_fn(|k| {
            first.get(k).copied().unwrap_or(f32::NAN)
        }));
        let all = first_lanes(LANES);
        assert_eq!((min_lane(v, all), max_lane(v, all)), (-2.0, 9.0));
        let some = from_bits(0b1001_0011);
        assert_eq!((min_lane(v, some), max_lane(v, some)), (-0.5, 3.0));
        let nan = from_bits(0b0100_0010);
        assert_eq!(
            (min_lane(v, nan), max_lane(v, nan)),
            (f32::INFINITY, f32::NEG_INFINITY)
        );
    }

    #[test]
    fn masks_from_bits_give_back_their_bits() {
        for bits in 0..=255u32 {
            let mask = from_bits(bits);
            assert_eq!(super::bits(mask), bits);
            let picked = mask.select(F32Lanes::ONE, F32Lanes::ZERO).to_array();
            for (k, &p) in picked.iter().enumerate() {
                assert_eq!(p, (bits >> k & 1) as f32, "bits {bits:#b}, lane {k}");
            }
        }
    }

    /// Awkward values: tiny, huge, negative zero, zero vectors and NaN.
    fn sample(k: usize, salt: f32) -> Vec3 {
        let t = k as f32 + salt;
        match k {
            0 => Vec3::ZERO,
            1 => Vec3::new(-0.0, 1e-30, 1e30),
            2 => Vec3::new(f32::NAN, 1.0, 2.0),
            _ => Vec3::new(t.sin() * 3.7, (t * 1.3).cos() / 7.0, t.sqrt() - 1.1),
        }
    }

    #[test]
    fn every_lane_is_the_scalar_result_bit_for_bit() {
        let a = lanes(|k| sample(k, 0.25));
        let b = lanes(|k| sample(k, 0.75));
        let s = F32Lanes::new(std::array::from_fn(|k| sample(k, 0.5).z));
        let (unit, ok) = a.try_normalize();
        let zero = (a - a).is_zero();
        for k in 0..LANES {
            // The lanes' own values: `sample` again could round otherwise where
            // the optimiser folds its `sin` and `cos` at compile time.
            let (sa, sb) = (a.lane(k), b.lane(k));
            let same = |x: f32, y: f32| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan());
            assert!(same(a.dot(&b).as_array()[k], sa.dot(sb)), "dot, lane {k}");
            assert!(same(a.dot_splat(sb).as_array()[k], sa.dot(sb)));
            let scaled = a.scale(s).lane(k);
            let expected = sa * s.as_array()[k];
            for axis in 0..3 {
                assert!(same(scaled[axis], expected[axis]), "scale, lane {k}");
                assert!(same((a - b).lane(k)[axis], (sa - sb)[axis]));
                assert!(same((a + b).lane(k)[axis], (sa + sb)[axis]));
                assert!(same(a.cross_splat(sb).lane(k)[axis], sa.cross(sb)[axis]));
                assert!(same(
                    Vec3Lanes::splat_cross(sb, &a).lane(k)[axis],
                    sb.cross(sa)[axis]
                ));
            }
            match sa.try_normalize() {
                Some(n) => {
                    assert!(ok.as_array()[k] != 0.0, "normalize ok, lane {k}");
                    assert_eq!(unit.lane(k), n);
                }
                None => assert!(ok.as_array()[k] == 0.0, "normalize fails, lane {k}"),
            }
            if sa.length_squared() > 0.0 && sa.is_finite() {
                assert_eq!(a.normalize().lane(k), sa.normalize(), "normalize, lane {k}");
            }
            let mut set = Vec3Lanes::default();
            set.set_lane(k, sb);
            assert_eq!(
                set.lane(k).to_array().map(f32::to_bits),
                sb.to_array().map(f32::to_bits)
            );
            for axis in 0..3 {
                assert!(same(
                    Vec3Lanes::splat_add(sb, &a).lane(k)[axis],
                    (sb + sa)[axis]
                ));
            }
            assert_eq!(bits(zero) >> k & 1 == 1, (sa - sa) == Vec3::ZERO);
        }
        assert_eq!(bits(first_lanes(3)), 0b111);
        assert_eq!(bits(first_lanes(LANES)), all_bits());
        assert_eq!(all_bits().count_ones() as usize, LANES);
    }

    /// Each lane of a permute is the indexed lane, repeats included, in
    /// every implementation this CPU can run: the one [`permute`] uses and
    /// the narrower ones (on AVX-512, the AVX2 blend of halves too).
    #[test]
    fn permute_takes_each_lane_from_its_index() {
        type Permute = fn(F32Lanes, U32Lanes) -> F32Lanes;
        #[allow(unused_mut)] // Only a CPU with AVX2 has more.
        let mut implementations: Vec<(&str, Permute)> =
            vec![("permute", permute), ("lane by lane", permute_lanes)];
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        implementations.push(("AVX2", permute_avx2));
        #[cfg(all(
            target_arch = "x86_64",
            target_feature = "avx512f",
            not(feature = "lanes8")
        ))]
        implementations.push(("AVX-512", permute_avx512));
        let values = F32Lanes::new(std::array::from_fn(|k| 10.0 + k as f32));
        // Lanes from both halves, and the last one again and again.
        let index: [u32; LANES] = std::array::from_fn(|j| match j % 3 {
            0 => LANES as u32 - 1,
            _ => (5 * j as u32 + 3) % LANES as u32,
        });
        for (name, implementation) in implementations {
            let permuted = implementation(values, U32Lanes::new(index));
            for (j, (lane, from)) in permuted.as_array().iter().zip(index).enumerate() {
                assert_eq!(*lane, 10.0 + from as f32, "{name}: lane {j}");
            }
        }
    }
}
