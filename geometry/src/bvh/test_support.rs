//! Helpers shared by the BVH's tests: a seeded generator, scenes of boxes, the
//! reference slab test, and a walk that checks a built tree's invariants.

use super::build::MAX_DEPTH;
use super::sah::MAX_LEAF_PRIMITIVES;
use super::wide::{self, Link};
use super::{Bounds3, Bvh, LEAF_WIDTH};
use crate::Ray;
use glam::Vec3;

/// Marsaglia's xorshift64 ("Xorshift RNGs", 2003): tiny, seeded, deterministic.
pub(crate) struct XorShift(pub(crate) u64);

impl XorShift {
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// Uniform in [0, 1), from the top 24 bits.
    pub(crate) fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u32 << 24) as f32
    }

    pub(crate) fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }

    pub(crate) fn vec3(&mut self, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
    }
}

/// `n³` small boxes, one per unit cell, centres jittered by up to ±0.3 and
/// half-extents 0.05–0.25 per axis.
pub(super) fn jittered_grid(n: usize, seed: u64) -> Vec<Bounds3> {
    let mut rng = XorShift(seed);
    let mut boxes = Vec::with_capacity(n * n * n);
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let cell = Vec3::new(i as f32, j as f32, k as f32);
                let centre = cell + rng.vec3(-0.3, 0.3);
                let half = rng.vec3(0.05, 0.25);
                boxes.push(Bounds3::new(centre - half, centre + half));
            }
        }
    }
    boxes
}

/// `count` boxes with sides of `min_size`–`max_size`, corners scattered
/// uniformly over `[0, extent]³`.
pub(super) fn random_boxes(
    count: usize,
    extent: f32,
    min_size: f32,
    max_size: f32,
    seed: u64,
) -> Vec<Bounds3> {
    let mut rng = XorShift(seed);
    (0..count)
        .map(|_| {
            let lo = rng.vec3(0.0, extent);
            Bounds3::new(lo, lo + rng.vec3(min_size, max_size))
        })
        .collect()
}

/// Four boxes for one node's children: corners in [-4, 4]³, sides up to 3.
pub(super) fn node_boxes(rng: &mut XorShift) -> [Bounds3; 4] {
    [0, 1, 2, 3].map(|_| {
        let lo = rng.vec3(-4.0, 4.0);
        Bounds3::new(lo, lo + rng.vec3(0.0, 3.0))
    })
}

/// A ray for testing node tests against `boxes`: from anywhere, with a +0 or −0
/// direction component, or starting on a box face and running along it (so
/// lying in the face's plane); with `through_corners`, also aimed at a box's
/// corner, where entry and exit distances agree up to rounding.
pub(super) fn awkward_ray(rng: &mut XorShift, boxes: &[Bounds3; 4], through_corners: bool) -> Ray {
    let mut origin = rng.vec3(-6.0, 6.0);
    let mut direction = rng.vec3(-1.0, 1.0);
    let axis = (rng.next_u64() % 3) as usize;
    let b = &boxes[(rng.next_u64() % 4) as usize];
    match rng.next_u64() % if through_corners { 5 } else { 4 } {
        0 => {}
        1 => direction[axis] = 0.0,
        2 => direction[axis] = -0.0,
        3 => {
            origin = b.min + rng.vec3(0.0, 1.0) * (b.max - b.min);
            origin[axis] = if rng.unit() < 0.5 {
                b.min[axis]
            } else {
                b.max[axis]
            };
            direction[axis] = if rng.unit() < 0.5 { 0.0 } else { -0.0 };
        }
        _ => {
            let corner = Vec3::select(
                glam::BVec3::new(rng.unit() < 0.5, rng.unit() < 0.5, rng.unit() < 0.5),
                b.min,
                b.max,
            );
            direction = corner - origin;
        }
    }
    Ray::new(origin, direction)
}

/// Infinite half the time, else uniform in [0, 8).
pub(super) fn some_t_max(rng: &mut XorShift) -> f32 {
    if rng.unit() < 0.5 {
        f32::INFINITY
    } else {
        rng.range(0.0, 8.0)
    }
}

pub(super) fn contains(outer: &Bounds3, inner: &Bounds3) -> bool {
    outer.min.cmple(inner.min).all() && inner.max.cmple(outer.max).all()
}

/// Walks the tree from the root and checks its structure against the input:
/// nodes in depth-first order (children after their parent, in lane order),
/// used lanes first (one or more at the root, two or more elsewhere), unused
/// lanes with empty boxes, every child's box the union of its children's (a
/// leaf's, of its primitives') and inside its parent's, leaves of 1–4
/// primitives starting at multiples of 4 in the leaf order with the rest of
/// their run padded, every valid primitive in exactly one leaf and no invalid
/// one in any, every node reachable, and the depth within the limit.
pub(super) fn check_invariants(bvh: &Bvh, bounds: &[Bounds3]) {
    let valid: Vec<bool> = bounds
        .iter()
        .map(|b| b.is_finite() && !b.is_empty())
        .collect();
    let mut seen = vec![0u32; bounds.len()];
    let mut next_node = 1;
    if let Some(root) = bvh.tree.nodes.first() {
        let root_bounds =
            (0..wide::WIDTH).fold(Bounds3::EMPTY, |b, lane| b.union(root.child_bounds(lane)));
        let mut walk = Walk {
            bvh,
            bounds,
            seen: &mut seen,
            next_node: &mut next_node,
        };
        walk.check_node(0, &root_bounds, 0);
    }
    assert_eq!(next_node.min(bvh.tree.nodes.len()), bvh.tree.nodes.len());
    assert_eq!(next_node, bvh.tree.nodes.len().max(1), "unreachable nodes");
    let stats = bvh.stats();
    assert_eq!(
        bvh.tree.indices.len(),
        LEAF_WIDTH * stats.leaves,
        "padded runs"
    );
    for (i, (&count, &valid)) in seen.iter().zip(&valid).enumerate() {
        assert_eq!(count, u32::from(valid), "primitive {i} in {count} leaves");
    }
    assert!(stats.max_depth <= MAX_DEPTH, "depth {}", stats.max_depth);
    assert!(stats.max_leaf_size <= MAX_LEAF_PRIMITIVES);
}

struct Walk<'a> {
    bvh: &'a Bvh,
    bounds: &'a [Bounds3],
    seen: &'a mut [u32],
    /// The node that depth-first order puts next.
    next_node: &'a mut usize,
}

impl Walk<'_> {
    /// Checks node `index`, whose box (the union of its children's) is `own`.
    fn check_node(&mut self, index: usize, own: &Bounds3, depth: usize) {
        assert!(depth <= MAX_DEPTH);
        let node = &self.bvh.tree.nodes[index];
        let used: Vec<(usize, Link)> = node.children().collect();
        let lanes: Vec<usize> = used.iter().map(|(lane, _)| *lane).collect();
        assert_eq!(lanes, (0..used.len()).collect::<Vec<_>>(), "lanes in use");
        assert!(used.len() >= if index == 0 { 1 } else { 2 }, "node {index}");
        for lane in used.len()..wide::WIDTH {
            assert!(node.child_bounds(lane).is_empty(), "unused lane {lane}");
        }
        let mut union = Bounds3::EMPTY;
        for (lane, link) in used {
            let child_bounds = node.child_bounds(lane);
            union = union.union(child_bounds);
            assert!(contains(own, &child_bounds), "node {index}.{lane} outside");
            if link.is_leaf() {
                let (first, count) = link.leaf_range();
                assert!((1..=MAX_LEAF_PRIMITIVES as u32).contains(&count));
                assert_eq!(first as usize % LEAF_WIDTH, 0);
                let run = &self.bvh.tree.indices[first as usize..first as usize + LEAF_WIDTH];
                if !self.bvh.in_leaf_order {
                    assert!(run[count as usize..].iter().all(|&i| i == u32::MAX));
                }
                let mut prims = Bounds3::EMPTY;
                for prim in self.bvh.leaf_primitives(link) {
                    prims = prims.union(self.bounds[prim as usize]);
                    self.seen[prim as usize] += 1;
                }
                assert_eq!(prims, child_bounds, "leaf {index}.{lane} not tight");
            } else {
                let child = link.node();
                assert_eq!(
                    child, *self.next_node,
                    "node {index}.{lane}: child at {child}"
                );
                *self.next_node += 1;
                let grandchildren = &self.bvh.tree.nodes[child];
                let tight = (0..wide::WIDTH).fold(Bounds3::EMPTY, |b, lane| {
                    b.union(grandchildren.child_bounds(lane))
                });
                assert_eq!(tight, child_bounds, "node {index}.{lane} not tight");
                self.check_node(child, &child_bounds, depth + 1);
            }
        }
        assert_eq!(union, *own);
    }
}

pub(super) fn box_hit(b: &Bounds3, ray: &Ray, t_max: f32) -> Option<f32> {
    b.hit(ray.origin, ray.direction.recip(), t_max)
}
