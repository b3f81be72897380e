//! Rounding-error bounds of computed points, and the `γₙ` they are written with.
//!
//! IEEE-754 `f32` arithmetic rounds each operation to nearest:
//! `fl(a ∘ b) = (a ∘ b)(1 + δ)` with `|δ| ≤ u = 2⁻²⁴`. A value computed with `n`
//! roundings in a chain is within `γₙ = n·u / (1 − n·u)` (relative) of the exact
//! value of the same formula, taken of the sum of the magnitudes of its terms
//! (Higham, *Accuracy and Stability of Numerical Algorithms*, 2002, §3.1; Pharr,
//! Jakob and Humphreys, *pbrt-v4*, §6.8). Every [`Hit`](crate::Hit) carries such a
//! bound, per axis, for its `point` ([`Hit::error`](crate::Hit::error)), and new
//! rays start that far off the surface ([`offset_ray_origin`](crate::offset_ray_origin)):
//!
//! | shape | point as computed | bound per axis (`|·|` per component) |
//! |---|---|---|
//! | parallelogram | `o + α·e₁ + β·e₂` | `γ₇(|o| + |e₁| + |e₂|)`: 3 roundings of the sum, and up to 4 for the tilt of the unit normal its ray test uses, across the extent |
//! | sphere | `c + r·n̂`, `n̂ = normalize(o + t·d − c)` | `γ₂|c| + γ₆·r·|n̂|`: the sum's 2 roundings; `|n̂|` within `γ₄` of 1 |
//! | plane | `q − ((q − p)·n)·n`, `q = o + t·d` | `γ₅(|x| + |p|)` of the point `x` and the plane's point `p` |
//! | box | the face coordinate exactly, the others rounded once | `γ₁|x|`: zero along the face's axis in fact; kept so the origin still moves |
//! | triangle | `b₀·a + b₁·b + b₂·c` | `γ₇(|b₀·a| + |b₁·b| + |b₂·c|)` (pbrt-v4 §6.8.4) |
//!
//! Points of a bounded flat shape are also kept inside its edges by at least
//! their error ([`Parallelogram`](crate::Parallelogram) and
//! [`AaBox`](crate::AaBox) hits): a point computed on an edge lies, within
//! rounding, on the neighbouring wall of a closed box as well, and a ray leaving
//! it could slip out through that wall at `t ≈ 0`.
//!
//! Shadow rays aim at a light's sample point moved off the light by that point's
//! own bound, so that the segment `0 < t < 1` ends before the light's surface
//! ([`spawn_ray_to`](crate::spawn_ray_to)): no ray starts or ends at a fixed
//! epsilon, and no hit is accepted or refused by one. The only fixed relative
//! tolerances left in the geometry stage are the margins of conservative culls
//! (the box around a batch of rays, the pyramid from a point to a light, a
//! pixel's frustum: 10⁻⁶ to 10⁻³ of the coordinates' size). They decide no hit:
//! they only keep shapes in the set a ray is tested against, so a wide margin
//! costs a few tests and never a wrong answer. They are kept hundreds of times
//! above the bounds above; a margin derived from them would also have to cover
//! every shape's acceptance margin (a parallelogram's edge margin, say).
//! The stress tool (`glint stress`) counts, at scales from 1e-4 to 1e6 and far
//! from the origin, what these bounds must keep at zero, and checks the culled
//! shadow rays of the shipped scenes against the unculled ones.

/// The unit roundoff of `f32`, `u = 2⁻²⁴` (half of `f32::EPSILON`).
pub const UNIT_ROUNDOFF: f32 = f32::EPSILON * 0.5;

/// `γₙ = n·u / (1 − n·u)`: the relative error bound of `n` chained roundings.
pub const fn gamma(n: u32) -> f32 {
    let nu = n as f32 * UNIT_ROUNDOFF;
    nu / (1.0 - nu)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gamma_grows_with_the_number_of_roundings_from_the_unit_roundoff() {
        assert_eq!(UNIT_ROUNDOFF, 2f32.powi(-24));
        assert!(gamma(1) > UNIT_ROUNDOFF && gamma(1) < 1.000001 * UNIT_ROUNDOFF);
        assert!(gamma(7) > 7.0 * UNIT_ROUNDOFF && gamma(7) < 7.00001 * UNIT_ROUNDOFF);
        assert!((1..10).all(|n| gamma(n) < gamma(n + 1)));
    }

    /// The bound holds for a sum of three products, the parallelogram's point,
    /// against the same sum in f64, on many random inputs.
    #[test]
    fn a_rounded_sum_of_products_is_within_its_gamma() {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        for _ in 0..100_000 {
            let (o, e1, e2) = (
                (next() - 0.5) * 1e6,
                (next() - 0.5) * 1e3,
                (next() - 0.5) * 1e3,
            );
            let (a, b) = (next(), next());
            let rounded = o + a * e1 + b * e2;
            let exact = o as f64 + a as f64 * e1 as f64 + b as f64 * e2 as f64;
            let bound = gamma(3) as f64 * (o.abs() + e1.abs() + e2.abs()) as f64;
            assert!((rounded as f64 - exact).abs() <= bound);
        }
    }
}
