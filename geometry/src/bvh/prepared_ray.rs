//! The ray–node test: a ray prepared once per query, tested against the four
//! child boxes of a wide node with one run of four-wide SIMD operations.

use super::bounds::EXIT_SCALE;
use super::wide::WideNode;
use crate::Ray;
use glam::Vec4;

/// A ray prepared once per query for [`WideNode`]s: per axis, the origin and the
/// reciprocal direction in all four lanes, and which of the node's planes the ray
/// meets first on that axis (the minima for a direction ≥ +0, else the maxima).
pub(super) struct PreparedRay {
    origin: [Vec4; 3],
    inv_dir: [Vec4; 3],
    /// Per axis: the ray meets the minima first (`1/dᵢ ≥ 0`).
    min_first: [bool; 3],
}

impl PreparedRay {
    #[inline]
    pub(super) fn new(ray: &Ray) -> Self {
        // Spelt out axis by axis: `[0, 1, 2].map` is not always inlined.
        let (o, inv) = (ray.origin, ray.direction.recip());
        Self {
            origin: [Vec4::splat(o.x), Vec4::splat(o.y), Vec4::splat(o.z)],
            inv_dir: [Vec4::splat(inv.x), Vec4::splat(inv.y), Vec4::splat(inv.z)],
            // The sign of 1/d, not of d: d = −0 gives −∞, for which the maxima are near.
            min_first: [inv.x >= 0.0, inv.y >= 0.0, inv.z >= 0.0],
        }
    }

    /// The indices into [`WideNode::planes`] of the near and the far plane on `axis`.
    #[inline(always)]
    fn planes(&self, axis: usize) -> (usize, usize) {
        let min_first = self.min_first[axis] as usize;
        (axis + 3 * (1 - min_first), axis + 3 * min_first)
    }

    /// The slab test of [`super::Bounds3::hit`] for the four children of a node:
    /// bit `k` of the mask is set if the ray enters child `k` before `t_max`, and
    /// lane `k` of the vector is then its entry distance, bit for bit as
    /// [`super::Bounds3::hit`] computes it.
    ///
    /// On axis `i` the near plane's distance `(near − oᵢ)/dᵢ` is `min(t₁, t₂)` of
    /// [`super::Bounds3::hit`] and the far plane's is `max(t₁, t₂)`, as the sign of
    /// `1/dᵢ` orders them; so `t_enter = max(0, maxᵢ nearᵢ)` and
    /// `t_exit = min(t_max, minᵢ farᵢ)` (Williams et al., "An Efficient and Robust
    /// Ray–Box Intersection Algorithm", JGT 10(1), 2005). A NaN distance (`0·∞`:
    /// origin on a plane the ray runs along) is only ever the first operand of
    /// `max`/`min`, whose SSE forms then return the second: neutral, as in
    /// [`super::Bounds3::hit`]. The exit is scaled by `1 + 2γ₃` as there.
    #[inline]
    pub(super) fn enters(&self, node: &WideNode, t_max: f32) -> (u32, Vec4) {
        let mut enter = Vec4::ZERO;
        let mut exit = Vec4::splat(t_max);
        for axis in 0..3 {
            let (near, far) = self.planes(axis);
            let near = (node.planes[near] - self.origin[axis]) * self.inv_dir[axis];
            let far = (node.planes[far] - self.origin[axis]) * self.inv_dir[axis];
            enter = max_or_second(near, enter);
            exit = min_or_second(far, exit);
        }
        let hit = enter.cmple(exit * EXIT_SCALE) & enter.cmplt(Vec4::splat(t_max));
        (hit.bitmask(), enter)
    }
}

/// `max(a, b)` lane-wise where `a` may be NaN and `b` is not, returning `b` for a
/// NaN `a`. On x86 glam's `max` is `maxps`, which is exactly `a > b ? a : b`;
/// elsewhere (NEON's `fmax` propagates NaN) it is spelt out.
#[inline(always)]
fn max_or_second(a: Vec4, b: Vec4) -> Vec4 {
    #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
    {
        a.max(b)
    }
    #[cfg(not(any(target_arch = "x86", target_arch = "x86_64")))]
    {
        Vec4::select(a.cmpgt(b), a, b)
    }
}

/// `min(a, b)` lane-wise, `b` for a NaN `a`: `minps` is `a < b ? a : b`.
#[inline(always)]
fn min_or_second(a: Vec4, b: Vec4) -> Vec4 {
    #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
    {
        a.min(b)
    }
    #[cfg(not(any(target_arch = "x86", target_arch = "x86_64")))]
    {
        Vec4::select(a.cmplt(b), a, b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::test_support::{awkward_ray, box_hit, node_boxes, some_t_max, XorShift};
    use crate::bvh::wide::tests::node_of;
    use crate::bvh::Bounds3;
    use glam::Vec3;

    /// The wide node test against four children, as `Bounds3::hit` results.
    fn node_hits(boxes: &[Bounds3; 4], ray: &Ray, t_max: f32) -> [Option<f32>; 4] {
        let node = node_of(boxes);
        let (hits, enter) = PreparedRay::new(ray).enters(&node, t_max);
        [0, 1, 2, 3].map(|k| (hits & (1 << k) != 0).then_some(enter[k]))
    }

    #[test]
    fn node_test_agrees_with_the_slab_test_of_each_child() {
        let mut rng = XorShift(0x5EED);
        let mut checked = 0;
        for _ in 0..20_000 {
            let boxes = node_boxes(&mut rng);
            let ray = awkward_ray(&mut rng, &boxes, false);
            let t_max = some_t_max(&mut rng);
            let want = boxes.map(|b| box_hit(&b, &ray, t_max));
            assert_eq!(node_hits(&boxes, &ray, t_max), want, "{ray:?} {boxes:?}");
            checked += want.iter().flatten().count();
        }
        assert!(checked > 4_000, "{checked} hits");
        // The parallel-ray cases of the slab test above, box against copies of itself.
        let b = Bounds3::new(Vec3::new(-1.0, -2.0, -3.0), Vec3::new(1.0, 2.0, 3.0));
        for (origin, direction) in [
            (Vec3::new(-10.0, -1.0, 0.0), Vec3::new(1.0, 0.0, -0.0)),
            (Vec3::new(-10.0, 1.0, -3.0), Vec3::X),
            (Vec3::new(1.5, -10.0, 0.0), Vec3::new(0.0, 1.0, 0.0)),
            (Vec3::new(5.0, 0.0, 0.0), Vec3::Z),
        ] {
            let ray = Ray::new(origin, direction);
            let want = box_hit(&b, &ray, f32::INFINITY);
            assert_eq!(
                node_hits(&[b; 4], &ray, f32::INFINITY),
                [want; 4],
                "{ray:?}"
            );
        }
        // Unused lanes (empty boxes) are never entered.
        let empty = [Bounds3::EMPTY; 4];
        let ray = Ray::new(Vec3::ZERO, Vec3::ONE);
        assert_eq!(node_hits(&empty, &ray, f32::INFINITY), [None; 4]);
    }
}
