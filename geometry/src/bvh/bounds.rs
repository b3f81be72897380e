//! Axis-aligned bounding boxes and the ray–box slab test, conservative under
//! rounding (pbrt-v4 §6.1.2, §6.8.2).

use glam::Vec3;

/// `1 + 2γ₃`, with `γₙ = nε/(1 − nε)` and `ε = 2⁻²⁴`: scaling a slab test's exit
/// distance by it makes the test conservative under rounding (pbrt-v4 §6.8.2,
/// used in `Bounds3::IntersectP`, §6.1.2).
pub(super) const EXIT_SCALE: f32 = 1.0 + 2.0 * (3.0 * HALF_ULP / (1.0 - 3.0 * HALF_ULP));
/// The unit roundoff `ε = 2⁻²⁴` of `f32`.
const HALF_ULP: f32 = f32::EPSILON * 0.5;

/// Axis-aligned bounding box.
///
/// `[min, max]` per axis; empty when `min > max` on some axis. Flat boxes
/// (`min = max` on one axis), segments and points are not empty.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds3 {
    pub min: Vec3,
    pub max: Vec3,
}

impl Bounds3 {
    /// The empty box, identity of [`Bounds3::union`]: `min = +∞`, `max = −∞`.
    pub const EMPTY: Bounds3 = Bounds3 {
        min: Vec3::INFINITY,
        max: Vec3::NEG_INFINITY,
    };

    /// The smallest box containing the points `a` and `b`: componentwise min and max.
    pub fn new(a: Vec3, b: Vec3) -> Self {
        Self {
            min: a.min(b),
            max: a.max(b),
        }
    }

    /// The smallest box containing both boxes.
    pub fn union(self, other: Bounds3) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// The smallest box containing this box and the point `p`.
    pub fn include(self, p: Vec3) -> Self {
        Self {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// `(min + max)/2`, evaluated as `min/2 + max/2` so that it cannot overflow.
    /// NaN for [`Bounds3::EMPTY`].
    /// Whether the two boxes share a point (NaN bounds count as sharing).
    #[inline]
    pub fn overlaps(&self, other: &Bounds3) -> bool {
        !(self.min.cmpgt(other.max).any() || other.min.cmpgt(self.max).any())
    }

    pub fn centroid(&self) -> Vec3 {
        0.5 * self.min + 0.5 * self.max
    }

    /// `2·(dx·dy + dy·dz + dz·dx)` for the extent `d = max − min`; 0 for an
    /// empty box, and for segments and points. A flat box counts both sides.
    pub fn surface_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.max - self.min;
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// Whether `min > max` on some axis.
    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    /// Slab test: the entry distance if the ray meets the box within (0, t_max)
    /// (entry may be ≤ 0 if the origin is inside), using a precomputed inverse direction.
    ///
    /// The ray `o + t·d` is inside the slab of axis `i` for `t` between
    /// `t₁ = (minᵢ − oᵢ)/dᵢ` and `t₂ = (maxᵢ − oᵢ)/dᵢ`; the box interval is the
    /// intersection `[t_enter, t_exit]` of the three slab intervals and `[0, t_max]`:
    /// `t_enter = maxᵢ min(max(t₁, 0), max(t₂, 0))` and
    /// `t_exit = minᵢ max(min(t₁, t_max), min(t₂, t_max))`, which for numbers equal
    /// `max(0, maxᵢ min(t₁, t₂))` and `min(t_max, minᵢ max(t₁, t₂))`. So the entry
    /// returned is clamped to 0 when the origin is inside. Boundaries count as
    /// inside: a ray grazing a face, edge or corner meets the box.
    ///
    /// For `dᵢ = ±0` the reciprocal is `±∞` and `t₁, t₂` are `±∞` (the ray is in
    /// the slab for every `t`, or for none), or NaN (`0·∞`) when the origin lies
    /// on the slab's plane. A NaN only ever stands as the first operand of the
    /// inner `max(·, 0)` and `min(·, t_max)`, which then return the second, neutral
    /// one (both for `f32::max`, which glam documents, and for the `maxps` it
    /// compiles to): a ray lying in a face's plane, parallel to it, is inside that
    /// slab (Tavian Barnes, "Fast, Branchless Ray/Bounding Box Intersections,
    /// Part 3: Boundaries", 2022). The exit distance is scaled by `1 + 2γ₃` so
    /// that rounding never loses a hit (pbrt-v4 §6.1.2).
    #[inline]
    pub fn hit(&self, origin: Vec3, inv_dir: Vec3, t_max: f32) -> Option<f32> {
        let t_lo = (self.min - origin) * inv_dir;
        let t_hi = (self.max - origin) * inv_dir;
        let t_max3 = Vec3::splat(t_max);
        let near = t_lo.max(Vec3::ZERO).min(t_hi.max(Vec3::ZERO));
        let far = t_lo.min(t_max3).max(t_hi.min(t_max3));
        let (t_enter, t_exit) = (near.max_element(), far.min_element());
        (t_enter <= t_exit * EXIT_SCALE && t_enter < t_max).then_some(t_enter)
    }

    pub(super) fn is_finite(&self) -> bool {
        self.min.is_finite() && self.max.is_finite()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::test_support::box_hit;
    use crate::Ray;

    #[test]
    fn bounds_construction_union_area_and_emptiness() {
        let b = Bounds3::new(Vec3::new(1.0, -1.0, 2.0), Vec3::new(-1.0, 3.0, 0.0));
        assert_eq!(b.min, Vec3::new(-1.0, -1.0, 0.0));
        assert_eq!(b.max, Vec3::new(1.0, 3.0, 2.0));
        assert_eq!(b.centroid(), Vec3::new(0.0, 1.0, 1.0));
        // 2·(2·4 + 4·2 + 2·2) = 40.
        assert_eq!(b.surface_area(), 40.0);
        assert_eq!(Bounds3::EMPTY.union(b), b);
        assert_eq!(b.union(Bounds3::EMPTY), b);
        assert!(Bounds3::EMPTY.is_empty());
        assert_eq!(Bounds3::EMPTY.surface_area(), 0.0);
        let p = Bounds3::EMPTY.include(Vec3::ONE);
        assert!(!p.is_empty());
        assert_eq!(p.surface_area(), 0.0);
        assert_eq!(p.include(Vec3::ZERO), Bounds3::new(Vec3::ZERO, Vec3::ONE));
        let flat = Bounds3::new(Vec3::ZERO, Vec3::new(2.0, 3.0, 0.0));
        assert_eq!(flat.surface_area(), 12.0);
        let inverted = Bounds3 {
            min: Vec3::ONE,
            max: Vec3::new(2.0, 0.0, 2.0),
        };
        assert!(inverted.is_empty());
        assert_eq!(inverted.surface_area(), 0.0);
        let huge = Bounds3::new(Vec3::splat(3e38), Vec3::splat(3.2e38));
        assert!(huge.centroid().is_finite());
    }

    #[test]
    fn slab_test_entry_exit_and_t_max() {
        let b = Bounds3::new(-Vec3::ONE, Vec3::ONE);
        let toward = Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z);
        assert_eq!(box_hit(&b, &toward, f32::INFINITY), Some(4.0));
        assert_eq!(box_hit(&b, &toward, 4.5), Some(4.0));
        assert_eq!(box_hit(&b, &toward, 4.0), None, "entry must be below t_max");
        assert_eq!(box_hit(&b, &toward, 3.9), None);
        let away = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::Z);
        assert_eq!(box_hit(&b, &away, f32::INFINITY), None);
        let inside = Ray::new(Vec3::new(0.2, 0.1, 0.0), Vec3::new(1.0, 2.0, -0.5));
        assert_eq!(box_hit(&b, &inside, f32::INFINITY), Some(0.0));
        assert_eq!(box_hit(&b, &inside, 1e-3), Some(0.0));
        // Through a corner exactly: entry = exit = 4 on all three axes.
        let corner = Ray::new(Vec3::splat(5.0), -Vec3::ONE);
        assert_eq!(box_hit(&b, &corner, f32::INFINITY), Some(4.0));
        // Parallel to the face x = 1, just outside it.
        let past = Ray::new(Vec3::new(1.01, 5.0, 0.0), Vec3::new(0.0, -1.0, 0.0));
        assert_eq!(box_hit(&b, &past, f32::INFINITY), None);
        // Direction not unit: t in multiples of it.
        let short = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0 / 1024.0));
        assert_eq!(box_hit(&b, &short, f32::INFINITY), Some(4096.0));
    }

    #[test]
    fn slab_test_rays_parallel_to_faces_including_rays_lying_on_them() {
        let b = Bounds3::new(Vec3::new(-1.0, -2.0, -3.0), Vec3::new(1.0, 2.0, 3.0));
        for axis in 0..3 {
            let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
            for sign in [1.0f32, -1.0] {
                // Direction along `axis`; the other components are +0 or −0, whose
                // reciprocals are +∞ or −∞.
                let mut dir = Vec3::splat(if sign > 0.0 { 0.0 } else { -0.0 });
                dir[axis] = sign;
                let mut start = Vec3::ZERO;
                start[axis] = -sign * 10.0;
                let entry = 10.0 - b.max[axis];
                for (du, dw, hits) in [
                    (0.0, 0.0, true),
                    (b.min[u], 0.0, true),      // lying on the face at min u
                    (b.max[u], 0.0, true),      // lying on the face at max u
                    (b.max[u], b.min[w], true), // along an edge
                    (1.5 * b.max[u], 0.0, false),
                    (0.0, 1.01 * b.min[w], false),
                ] {
                    let mut origin = start;
                    origin[u] = du;
                    origin[w] = dw;
                    let ray = Ray::new(origin, dir);
                    let want = hits.then_some(entry);
                    assert_eq!(box_hit(&b, &ray, f32::INFINITY), want, "{origin} {dir}");
                    assert_eq!(box_hit(&b, &ray, 100.0), want, "{origin} {dir}");
                }
            }
        }
        // Parallel and outside, with t_max = ∞: no "hit at infinity".
        let outside = Ray::new(Vec3::new(5.0, 0.0, 0.0), Vec3::Z);
        assert_eq!(box_hit(&b, &outside, f32::INFINITY), None);
        // A flat box (zero thickness in y), hit across and along its plane.
        let flat = Bounds3::new(Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, 1.0));
        let across = Ray::new(Vec3::new(0.5, 3.0, 0.5), -Vec3::Y);
        assert_eq!(box_hit(&flat, &across, f32::INFINITY), Some(3.0));
        let along = Ray::new(Vec3::new(-3.0, 0.0, 0.5), Vec3::X);
        assert_eq!(box_hit(&flat, &along, f32::INFINITY), Some(2.0));
        let above = Ray::new(Vec3::new(-3.0, 1e-6, 0.5), Vec3::X);
        assert_eq!(box_hit(&flat, &above, f32::INFINITY), None);
    }
}
