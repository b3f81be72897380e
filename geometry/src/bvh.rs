//! A bounding volume hierarchy (BVH) over primitives known only by their bounds.
//!
//! The tree is built top-down with the binned surface area heuristic (SAH) of
//! Wald, "On fast Construction of SAH-based Bounding Volume Hierarchies" (IEEE
//! Symposium on Interactive Ray Tracing, 2007), as in pbrt-v4 §7.3.2, as a binary
//! tree of 32-byte nodes in depth-first order (pbrt-v4 §7.3.4), with leaves of at
//! most four primitives priced as one four-wide intersection test. The binary
//! tree is then collapsed into a 4-wide BVH (module `wide`; Wald, Benthin and Boulos
//! 2008, Embree's BVH4): each node holds the boxes of up to four children axis by
//! axis, so that one run of four-wide SIMD operations tests them all, and leaf
//! runs are padded to multiples of four so that a caller can test a leaf's
//! primitives as one packet.
//!
//! Traversal (pbrt-v4 §7.3.5, for four children) tests a node's children against
//! the ray, descends into the nearest and keeps the others on a fixed-size stack,
//! farthest first, with their entry distances, so that they are dropped once a
//! closer hit is known. Nothing is allocated per ray.
//!
//! The primitives themselves stay with the caller: [`Bvh::closest_hit`] and
//! [`Bvh::any_hit`] take the primitive intersection test as a closure, and report
//! primitives by their index in the slice given to [`Bvh::build`] (or by their
//! position in leaf order, after [`Bvh::take_primitive_order`]);
//! [`Bvh::traverse_leaves`] hands over whole leaves.
//!
//! [`Bvh::traverse_stream`] traverses a batch of rays several at a time,
//! interleaved, with each next node prefetched (module `stream`): the same
//! answers, with the waits on memory of large trees overlapped.

mod stream;
mod wide;

use crate::prefetch::prefetch;
use crate::Ray;
use glam::{Vec3, Vec3A};
use std::ops::ControlFlow;
pub use stream::{RayStream, STREAM_LANES};
pub use wide::LEAF_WIDTH;
use wide::{Link, PreparedRay, TraversalStack, WideBvh};

/// `C_trav`: the SAH cost of visiting an interior node, relative to [`INTERSECTION_COST`].
const TRAVERSAL_COST: f32 = 1.0;
/// `C_isect`: the SAH cost of one leaf's four-wide primitive test.
const INTERSECTION_COST: f32 = 1.0;
/// Centroid bins per axis in the binned SAH (Wald 2007 uses 16 or 32, pbrt-v4 12).
const BIN_COUNT: usize = 12;
/// The most primitives a leaf may hold: one four-wide packet.
const MAX_LEAF_PRIMITIVES: usize = LEAF_WIDTH;
/// The deepest a leaf of the binary tree may sit below the root, in edges; it
/// bounds the wide tree's depth, and so the traversal stack.
const MAX_DEPTH: usize = 64;
/// Nodes of at most this many primitives are split by an exact SAH sweep rather
/// than by binning.
const SWEEP_MAX_PRIMITIVES: usize = 2 * MAX_LEAF_PRIMITIVES;
/// Subtrees over more primitives than this are built on two rayon tasks.
const PARALLEL_THRESHOLD: usize = 4096;
/// `1 + 2γ₃`, with `γₙ = nε/(1 − nε)` and `ε = 2⁻²⁴`: scaling a slab test's exit
/// distance by it makes the test conservative under rounding (pbrt-v4 §6.8.2,
/// used in `Bounds3::IntersectP`, §6.1.2).
const EXIT_SCALE: f32 = 1.0 + 2.0 * (3.0 * HALF_ULP / (1.0 - 3.0 * HALF_ULP));
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

    fn is_finite(&self) -> bool {
        self.min.is_finite() && self.max.is_finite()
    }
}

/// Statistics of a built BVH, as traversal sees it: the 4-wide tree.
///
/// `nodes` counts interior (wide) nodes, each with up to four children; `leaves`
/// counts leaves, of at most four primitives. `max_depth` counts edges from the
/// root node to a leaf (a lone leaf, under a root of one child, has depth 1).
/// `sah_cost` is pbrt's measure of the tree's expected cost for a random ray
/// through the root: `Σ (A_node / A_root) · (C_trav for interior nodes | C_isect
/// for leaves)` with surface areas `A` and `C_trav = C_isect = 1` (a leaf is one
/// four-wide test). A root of zero area weighs every node 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhStats {
    pub nodes: usize,
    pub leaves: usize,
    pub max_depth: usize,
    pub max_leaf_size: usize,
    pub sah_cost: f32,
}

/// A BVH over primitives given only by their bounds; the primitives themselves
/// stay with the caller, who supplies the intersection test to the queries.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    /// The 4-wide tree, and the primitive indices (into the slice given to
    /// [`Bvh::build`]) in padded leaf order: each leaf owns a run starting at a
    /// multiple of [`LEAF_WIDTH`], padded with `u32::MAX`.
    tree: WideBvh,
    /// Set by [`Bvh::take_primitive_order`]: the queries then report leaf
    /// positions without reading the indices.
    in_leaf_order: bool,
}

/// One node of the binary tree as the build produces it, 32 bytes. A subtree built
/// on one thread is an array of these in depth-first order, with links relative to
/// its start; [`Subtree::flatten_into`] joins the subtrees into one array, which
/// [`WideBvh::collapse`] turns into the wide tree.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
struct BvhNode {
    min: Vec3,
    /// Leaf: position of its first primitive in the build's primitive order.
    /// Interior: index of its second child (the first child is the next node).
    offset: u32,
    max: Vec3,
    /// Number of primitives of a leaf (≥ 1); 0 marks an interior node.
    count: u32,
}

const _: () = assert!(std::mem::size_of::<BvhNode>() == 32);

impl BvhNode {
    fn leaf(bounds: &Bounds3, first: usize, count: usize) -> Self {
        Self {
            min: bounds.min,
            offset: index_u32(first),
            max: bounds.max,
            count: index_u32(count),
        }
    }

    fn interior(bounds: &Bounds3, second_child: usize) -> Self {
        Self {
            min: bounds.min,
            offset: index_u32(second_child),
            max: bounds.max,
            count: 0,
        }
    }

    fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

fn index_u32(i: usize) -> u32 {
    u32::try_from(i).expect("BVH index exceeds u32")
}

impl Bvh {
    /// Builds with binned SAH (Wald 2007; pbrt-v4 §7.3.2), then collapses the
    /// binary tree into a 4-wide one (module `wide`).
    ///
    /// At each node the primitive centroids are sorted into 12 equal bins along
    /// each of the three axes of the centroid bounds, and every plane between bins
    /// is scored with `cost = C_trav + C_isect · (A_L·⌈N_L/4⌉ + A_R·⌈N_R/4⌉) / A`
    /// (child surface areas `A_L`, `A_R`, primitive counts `N_L`, `N_R`, node area
    /// `A`; `C_trav = C_isect = 1`): a leaf's primitives are tested four at a time,
    /// so it costs one test per four (Embree prices leaves by blocks the same way).
    /// Nodes of at most 8 primitives are scored exactly instead, at the split
    /// between every two neighbours in centroid order along each axis (the full
    /// sweep that binning approximates). Nodes of at most 4 primitives become
    /// leaves (one test, which no split can beat); larger nodes are always split:
    /// at the cheapest plane, or at the object median of the longest centroid axis
    /// when no plane separates them (equal centroids, zero-area nodes).
    ///
    /// Depth is bounded by 64 levels: when the levels left are just enough for
    /// halving down to leaves of 4, the build switches to median splits.
    ///
    /// Primitives with empty or non-finite bounds are left out of the tree entirely
    /// (they can never be hit). Subtrees over 4096 primitives build their two
    /// halves with `rayon::join`; each half is built on its own slice by the same
    /// sequential decisions and the halves are joined parent, first, second, so
    /// the layout is identical whatever the thread count.
    ///
    /// Panics past 2³¹ primitives (node indices are `u32`).
    pub fn build(bounds: &[Bounds3]) -> Bvh {
        Self::build_with(bounds, BuildOptions::DEFAULT)
    }

    fn build_with(bounds: &[Bounds3], options: BuildOptions) -> Bvh {
        let mut prims = buildable_primitives(bounds);
        if prims.is_empty() {
            return Bvh::default();
        }
        debug_assert!(halvings_to_leaf(prims.len()) <= options.max_depth);
        let binary = build_binary(&mut prims, &options);
        let indices: Vec<u32> = prims.iter().map(|p| p.index).collect();
        Bvh {
            tree: WideBvh::collapse(&binary, &indices),
            in_leaf_order: false,
        }
    }

    /// Whether the tree holds no primitive (none given, or none with valid bounds).
    pub fn is_empty(&self) -> bool {
        self.tree.nodes.is_empty()
    }

    /// Node counts, depth and SAH cost of the 4-wide tree; see [`BvhStats`].
    pub fn stats(&self) -> BvhStats {
        let mut stats = BvhStats {
            nodes: self.tree.nodes.len(),
            leaves: 0,
            max_depth: 0,
            max_leaf_size: 0,
            sah_cost: 0.0,
        };
        if let Some(root) = self.tree.nodes.first() {
            let root_area = (0..wide::WIDTH)
                .fold(Bounds3::EMPTY, |b, lane| b.union(root.child_bounds(lane)))
                .surface_area();
            self.accumulate_stats(0, 0, root_area, &mut stats);
        }
        stats
    }

    /// Adds the subtree of wide node `node`, at `depth`, to `stats`.
    fn accumulate_stats(&self, node: usize, depth: usize, root_area: f32, stats: &mut BvhStats) {
        let weight = |b: Bounds3| {
            if root_area > 0.0 {
                b.surface_area() / root_area
            } else {
                1.0
            }
        };
        let wide_node = &self.tree.nodes[node];
        if node == 0 {
            let root = (0..wide::WIDTH).fold(Bounds3::EMPTY, |b, lane| {
                b.union(wide_node.child_bounds(lane))
            });
            stats.sah_cost += weight(root) * TRAVERSAL_COST;
        }
        for (lane, link) in wide_node.children() {
            let area_weight = weight(wide_node.child_bounds(lane));
            if link.is_leaf() {
                let (_, count) = link.leaf_range();
                stats.leaves += 1;
                stats.max_depth = stats.max_depth.max(depth + 1);
                stats.max_leaf_size = stats.max_leaf_size.max(count as usize);
                stats.sah_cost += area_weight * INTERSECTION_COST;
            } else {
                stats.sah_cost += area_weight * TRAVERSAL_COST;
                self.accumulate_stats(link.node(), depth + 1, root_area, stats);
            }
        }
    }

    /// Closest hit: visits nodes front to back (nearest child first, by entry
    /// distance), pruning by the closest t found so far. `intersect(prim, ray, t_max)`
    /// returns the hit distance of primitive `prim` in (0, t_max) if any. Returns
    /// (prim, t) of the nearest.
    ///
    /// The caller's bounds must contain every point `intersect` can report.
    /// A ray with a NaN component hits nothing. Which of two primitives at the same
    /// distance is reported depends on the tree; a caller that needs a rule for
    /// ties reports hits just past their distance (`t.next_up()`), so that every
    /// node entered at that distance is still visited.
    pub fn closest_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        mut intersect: impl FnMut(u32, &Ray, f32) -> Option<f32>,
    ) -> Option<(u32, f32)> {
        let mut closest = None;
        let _ = self.traverse(ray, t_max, |leaf, mut t_max| {
            for prim in self.leaf_primitives(leaf) {
                if let Some(t) = intersect(prim, ray, t_max) {
                    t_max = t;
                    closest = Some((prim, t));
                }
            }
            ControlFlow::Continue(t_max)
        });
        closest
    }

    /// Any hit in (0, t_max) (shadow rays): returns at the first primitive that reports one.
    pub fn any_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        mut hit: impl FnMut(u32, &Ray, f32) -> bool,
    ) -> bool {
        let found = self.traverse(ray, t_max, |leaf, t_max| {
            if self.leaf_primitives(leaf).any(|prim| hit(prim, ray, t_max)) {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(t_max)
            }
        });
        found.is_break()
    }

    /// Visits the leaves the ray enters before `t_max`, nearest entry first:
    /// `visit(first, count, t_max)` gets a leaf's run of positions in leaf order
    /// (`first` a multiple of [`LEAF_WIDTH`], `count` ≤ [`LEAF_WIDTH`]) and returns
    /// the new `t_max` (leaves entered at or beyond it are skipped), or breaks to
    /// end the traversal. For callers that store primitives in leaf order
    /// ([`Bvh::take_primitive_order`]) and test a leaf's primitives together.
    #[inline]
    pub fn traverse_leaves(
        &self,
        ray: &Ray,
        t_max: f32,
        mut visit: impl FnMut(u32, u32, f32) -> ControlFlow<(), f32>,
    ) -> ControlFlow<()> {
        self.traverse(ray, t_max, |leaf, t_max| {
            let (first, count) = leaf.leaf_range();
            visit(first, count, t_max)
        })
    }

    /// Depth-first traversal shared by the queries: `visit_leaf(leaf, t_max)`
    /// sees each leaf the ray reaches before `t_max` and returns the new `t_max`,
    /// or breaks to end the traversal.
    #[inline]
    fn traverse(
        &self,
        ray: &Ray,
        t_max: f32,
        mut visit_leaf: impl FnMut(Link, f32) -> ControlFlow<(), f32>,
    ) -> ControlFlow<()> {
        if ray.origin.is_nan() || ray.direction.is_nan() || self.is_empty() {
            return ControlFlow::Continue(());
        }
        let ray = PreparedRay::new(ray);
        let mut t_max = t_max;
        let mut stack = TraversalStack::new();
        let mut next = Some(Link::ROOT);
        while let Some(link) = next {
            next = self.step(
                &ray,
                &mut stack,
                link,
                &mut t_max,
                &mut visit_leaf,
                |node, hits| {
                    if hits & (hits - 1) != 0 {
                        self.prefetch_children(node, hits);
                    }
                },
            )?;
        }
        ControlFlow::Continue(())
    }

    /// One step of a ray's traversal: visits leaf `link`, or tests the children of
    /// node `link` (and hands the node and the mask of children hit to
    /// `read_ahead`). Returns the link to take next, `None` once the stack is
    /// empty, or the leaf visit's break.
    #[inline(always)]
    fn step(
        &self,
        ray: &PreparedRay,
        stack: &mut TraversalStack,
        link: Link,
        t_max: &mut f32,
        visit_leaf: impl FnOnce(Link, f32) -> ControlFlow<(), f32>,
        read_ahead: impl FnOnce(&wide::WideNode, u32),
    ) -> ControlFlow<(), Option<Link>> {
        if link.is_leaf() {
            *t_max = visit_leaf(link, *t_max)?;
            return ControlFlow::Continue(stack.pop_before(*t_max));
        }
        let node = &self.tree.nodes[link.node()];
        ControlFlow::Continue(match ray.enters(node, *t_max) {
            (0, _) => stack.pop_before(*t_max),
            (hits, enter) => {
                read_ahead(node, hits);
                Some(stack.order(node, hits, enter))
            }
        })
    }

    /// Prefetches each interior child in `hits`: the cache lines are then on their
    /// way while the nearest child is traversed, and usually cached when the
    /// others' turn comes. Measured (A/B in one process, one ray at a time): +4–7%
    /// incoherent rays per second on 1M and 4M triangles over reading one word of
    /// each child through `black_box`, which had itself gained 6% over nothing.
    #[inline(always)]
    fn prefetch_children(&self, node: &wide::WideNode, hits: u32) {
        let mut bits = hits;
        while bits != 0 {
            let lane = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let link = node.link(lane);
            if !link.is_leaf() {
                if let Some(child) = self.tree.nodes.get(link.node()) {
                    prefetch(child);
                }
            }
        }
    }

    /// Makes the queries report primitives by their position in leaf order, and
    /// returns that order: `order[k]` is the primitive (an index into the slice
    /// given to [`Bvh::build`]) at position `k`, or `u32::MAX` where a leaf's run
    /// is padded to a multiple of [`LEAF_WIDTH`]. A caller that stores its
    /// primitive data in this order reads a leaf's primitives from adjacent memory,
    /// and the queries no longer read the order at all. Primitives left out of the
    /// tree (empty or non-finite bounds) are not listed. A second call returns the
    /// identity.
    pub fn take_primitive_order(&mut self) -> Vec<u32> {
        let identity = (0..self.tree.indices.len() as u32).collect();
        self.in_leaf_order = true;
        std::mem::replace(&mut self.tree.indices, identity)
    }

    /// The primitives of a leaf as the queries report them.
    #[inline]
    fn leaf_primitives(&self, leaf: Link) -> LeafPrimitives<'_> {
        let (first, count) = leaf.leaf_range();
        if self.in_leaf_order {
            LeafPrimitives::Positions(first..first + count)
        } else {
            let first = first as usize;
            LeafPrimitives::Indices(self.tree.indices[first..first + count as usize].iter())
        }
    }
}

/// The primitives of a leaf: their positions in leaf order, which need no memory
/// read, or their indices into the slice given to [`Bvh::build`].
enum LeafPrimitives<'a> {
    Positions(std::ops::Range<u32>),
    Indices(std::slice::Iter<'a, u32>),
}

impl Iterator for LeafPrimitives<'_> {
    type Item = u32;

    #[inline]
    fn next(&mut self) -> Option<u32> {
        match self {
            LeafPrimitives::Positions(positions) => positions.next(),
            LeafPrimitives::Indices(indices) => indices.next().copied(),
        }
    }
}

/// Build parameters; tests vary them to reach the depth limit and serial builds.
#[derive(Clone, Copy, Debug)]
struct BuildOptions {
    max_depth: usize,
    parallel_threshold: usize,
}

impl BuildOptions {
    const DEFAULT: BuildOptions = BuildOptions {
        max_depth: MAX_DEPTH,
        parallel_threshold: PARALLEL_THRESHOLD,
    };
}

/// A box during the build, in glam's SIMD `Vec3A`: a union is two instructions.
#[derive(Clone, Copy, Debug)]
struct Aabb {
    min: Vec3A,
    max: Vec3A,
}

impl Aabb {
    const EMPTY: Aabb = Aabb {
        min: Vec3A::INFINITY,
        max: Vec3A::NEG_INFINITY,
    };

    fn union(self, other: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    fn include(self, p: Vec3A) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    fn bounds3(&self) -> Bounds3 {
        Bounds3 {
            min: self.min.into(),
            max: self.max.into(),
        }
    }

    fn surface_area(&self) -> f32 {
        self.bounds3().surface_area()
    }
}

/// A primitive during the build: its bounds, its input index, and its centroid's
/// bins on the three axes in the current node's binning (set by [`fill_bins`],
/// read by the partition that follows; they fit in what would be padding).
#[derive(Clone, Copy, Debug)]
struct BuildPrimitive {
    bounds: Aabb,
    index: u32,
    bins: [u8; 3],
}

impl BuildPrimitive {
    /// `min/2 + max/2`, as [`Bounds3::centroid`].
    #[inline]
    fn centroid(&self) -> Vec3A {
        0.5 * self.bounds.min + 0.5 * self.bounds.max
    }
}

/// The primitives with finite, non-empty bounds, in input order.
fn buildable_primitives(bounds: &[Bounds3]) -> Vec<BuildPrimitive> {
    bounds
        .iter()
        .enumerate()
        .filter(|(_, b)| b.is_finite() && !b.is_empty())
        .map(|(i, b)| BuildPrimitive {
            bounds: Aabb {
                min: b.min.into(),
                max: b.max.into(),
            },
            index: index_u32(i),
            bins: [0; 3],
        })
        .collect()
}

/// A set of primitives as the build sees it: joint bounds, bounds of the
/// centroids, and count. Nodes and SAH bins both have one.
#[derive(Clone, Copy, Debug)]
struct Extents {
    bounds: Aabb,
    centroids: Aabb,
    count: u32,
}

impl Extents {
    const EMPTY: Extents = Extents {
        bounds: Aabb::EMPTY,
        centroids: Aabb::EMPTY,
        count: 0,
    };

    fn of(prims: &[BuildPrimitive]) -> Extents {
        let mut extents = Extents::EMPTY;
        for prim in prims {
            extents.add(prim, prim.centroid());
        }
        extents
    }

    #[inline]
    fn add(&mut self, prim: &BuildPrimitive, centroid: Vec3A) {
        self.bounds = self.bounds.union(prim.bounds);
        self.centroids = self.centroids.include(centroid);
        self.count += 1;
    }

    fn merge(self, other: Extents) -> Extents {
        Extents {
            bounds: self.bounds.union(other.bounds),
            centroids: self.centroids.union(other.centroids),
            count: self.count + other.count,
        }
    }
}

/// A subtree under construction: built sequentially into one node array (child
/// indices relative to its start), or two halves built in parallel under a parent.
enum Subtree {
    Serial(Vec<BvhNode>),
    Split {
        bounds: Aabb,
        children: Box<(Subtree, Subtree)>,
    },
}

impl Subtree {
    fn len(&self) -> usize {
        match self {
            Subtree::Serial(nodes) => nodes.len(),
            Subtree::Split { children, .. } => 1 + children.0.len() + children.1.len(),
        }
    }

    /// Appends the subtree's nodes to `nodes` in depth-first order, links made
    /// absolute: the same array whatever the threads that built the subtree.
    fn flatten_into(self, nodes: &mut Vec<BvhNode>) {
        match self {
            Subtree::Serial(serial) => {
                let base = index_u32(nodes.len());
                nodes.extend(serial.into_iter().map(|mut node| {
                    if !node.is_leaf() {
                        node.offset += base;
                    }
                    node
                }));
            }
            Subtree::Split { bounds, children } => {
                let parent = nodes.len();
                nodes.push(BvhNode::interior(&bounds.bounds3(), 0));
                let (first, second) = *children;
                first.flatten_into(nodes);
                nodes[parent].offset = index_u32(nodes.len());
                second.flatten_into(nodes);
            }
        }
    }
}

/// The binary tree over `prims`, as one array in depth-first order.
fn build_binary(prims: &mut [BuildPrimitive], options: &BuildOptions) -> Vec<BvhNode> {
    let extents = Extents::of(prims);
    let tree = build_subtree(prims, &extents, 0, options.max_depth, options);
    let mut nodes = Vec::with_capacity(tree.len());
    tree.flatten_into(&mut nodes);
    nodes
}

/// Builds the subtree over `prims`, which start at position `first` of the final
/// primitive order. Over `parallel_threshold` primitives the two halves are built
/// by `rayon::join`; below it, sequentially.
fn build_subtree(
    prims: &mut [BuildPrimitive],
    extents: &Extents,
    first: usize,
    depth_budget: usize,
    options: &BuildOptions,
) -> Subtree {
    if prims.len() <= options.parallel_threshold {
        let mut nodes = Vec::with_capacity(2 * prims.len() - 1);
        build_serial(prims, extents, first, depth_budget, &mut nodes);
        return Subtree::Serial(nodes);
    }
    let Some((mid, left_extents, right_extents)) = split(prims, extents, depth_budget) else {
        let leaf = BvhNode::leaf(&extents.bounds.bounds3(), first, prims.len());
        return Subtree::Serial(vec![leaf]);
    };
    let (left, right) = prims.split_at_mut(mid);
    let children = rayon::join(
        || build_subtree(left, &left_extents, first, depth_budget - 1, options),
        || {
            build_subtree(
                right,
                &right_extents,
                first + mid,
                depth_budget - 1,
                options,
            )
        },
    );
    Subtree::Split {
        bounds: extents.bounds,
        children: Box::new(children),
    }
}

/// Appends the subtree over `prims` to `nodes` in depth-first order.
fn build_serial(
    prims: &mut [BuildPrimitive],
    extents: &Extents,
    first: usize,
    depth_budget: usize,
    nodes: &mut Vec<BvhNode>,
) {
    let bounds = extents.bounds.bounds3();
    let Some((mid, left_extents, right_extents)) = split(prims, extents, depth_budget) else {
        nodes.push(BvhNode::leaf(&bounds, first, prims.len()));
        return;
    };
    let parent = nodes.len();
    nodes.push(BvhNode::interior(&bounds, 0));
    let (left, right) = prims.split_at_mut(mid);
    build_serial(left, &left_extents, first, depth_budget - 1, nodes);
    nodes[parent].offset = index_u32(nodes.len());
    build_serial(right, &right_extents, first + mid, depth_budget - 1, nodes);
}

/// Decides whether the node over `prims` is split; if so partitions `prims` in
/// place and returns the number going to the first child and both children's
/// extents, else `None` for a leaf. A node of at most [`MAX_LEAF_PRIMITIVES`] is a
/// leaf: its one packet test costs `C_isect`, and a split at least `C_trav` more.
fn split(
    prims: &mut [BuildPrimitive],
    extents: &Extents,
    depth_budget: usize,
) -> Option<(usize, Extents, Extents)> {
    let n = prims.len();
    if n <= MAX_LEAF_PRIMITIVES || depth_budget == 0 {
        return None;
    }
    if depth_budget <= halvings_to_leaf(n) {
        return Some(median_split(prims, &extents.centroids));
    }
    let cheapest = if n <= SWEEP_MAX_PRIMITIVES {
        sweep_split(prims, extents)
    } else {
        best_binned_split(prims, extents).map(|plane| {
            let mid = partition(prims, |p| plane.goes_left(p));
            debug_assert_eq!(mid, plane.left.count as usize);
            (mid, plane.left, plane.right)
        })
    };
    Some(cheapest.unwrap_or_else(|| median_split(prims, &extents.centroids)))
}

/// Splits a small node by the exact SAH: along each axis, sorts the centroids and
/// scores the plane between every two neighbours (the full sweep that binning
/// approximates; Wald 2007 §2, pbrt-v4 §7.3.2). For a handful of primitives it
/// is cheaper than filling 3 × 12 bins, and exact. `None` if the node has no
/// positive finite area.
fn sweep_split(
    prims: &mut [BuildPrimitive],
    extents: &Extents,
) -> Option<(usize, Extents, Extents)> {
    let area = extents.bounds.surface_area();
    if !(area > 0.0 && area.is_finite()) {
        return None;
    }
    let mut best = cheapest_sweep(prims, 0, area);
    for axis in 1..3 {
        let sweep = cheapest_sweep(prims, axis, area);
        if sweep.cost < best.cost {
            best = sweep;
        }
    }
    if best.mid == 0 {
        return None;
    }
    reorder(prims, &best.order);
    let (left, right) = prims.split_at(best.mid);
    Some((best.mid, Extents::of(left), Extents::of(right)))
}

/// A split of a small node: its primitives in centroid order along an axis, the
/// first `mid` going left, and the SAH cost (∞ if none was scored).
#[derive(Clone, Copy, Debug)]
struct Sweep {
    order: [u8; SWEEP_MAX_PRIMITIVES],
    mid: usize,
    cost: f32,
}

/// The cheapest split of a small node between consecutive centroids along `axis`:
/// suffix areas from the right, then prefixes from the left, as in [`cheapest_plane`].
fn cheapest_sweep(prims: &[BuildPrimitive], axis: usize, node_area: f32) -> Sweep {
    let n = prims.len();
    let order = order_along(prims, axis);
    let bounds = |k: usize| prims[order[k] as usize].bounds;
    let mut right_areas = [0.0f32; SWEEP_MAX_PRIMITIVES];
    let mut right = Aabb::EMPTY;
    for k in (1..n).rev() {
        right = right.union(bounds(k));
        right_areas[k] = right.surface_area();
    }
    let mut best = Sweep {
        order,
        mid: 0,
        cost: f32::INFINITY,
    };
    let mut left = Aabb::EMPTY;
    for (mid, right_area) in right_areas.into_iter().enumerate().take(n).skip(1) {
        left = left.union(bounds(mid - 1));
        let weighted = left.surface_area() * packets(mid) + right_area * packets(n - mid);
        let cost = TRAVERSAL_COST + INTERSECTION_COST * weighted / node_area;
        if cost < best.cost {
            best.mid = mid;
            best.cost = cost;
        }
    }
    best
}

/// The positions of at most [`SWEEP_MAX_PRIMITIVES`] primitives sorted by centroid
/// along `axis`, equal centroids in position order (insertion sort).
fn order_along(prims: &[BuildPrimitive], axis: usize) -> [u8; SWEEP_MAX_PRIMITIVES] {
    let mut keys = [0.0f32; SWEEP_MAX_PRIMITIVES];
    let mut order = [0u8; SWEEP_MAX_PRIMITIVES];
    for (i, prim) in prims.iter().enumerate() {
        let key = prim.centroid()[axis];
        let mut j = i;
        while j > 0 && keys[j - 1] > key {
            keys[j] = keys[j - 1];
            order[j] = order[j - 1];
            j -= 1;
        }
        keys[j] = key;
        order[j] = i as u8;
    }
    order
}

/// Rearranges `prims` so that position `k` holds the primitive that was at `order[k]`.
fn reorder(prims: &mut [BuildPrimitive], order: &[u8; SWEEP_MAX_PRIMITIVES]) {
    let mut original = [prims[0]; SWEEP_MAX_PRIMITIVES];
    original[..prims.len()].copy_from_slice(prims);
    for (prim, &from) in prims.iter_mut().zip(order) {
        *prim = original[from as usize];
    }
}

/// The four-wide tests `⌈n/4⌉` that `n` primitives in leaves cost at best: the
/// SAH's weight for a side of a split.
fn packets(n: usize) -> f32 {
    n.div_ceil(MAX_LEAF_PRIMITIVES) as f32
}

/// How many halvings `n ↦ ⌈n/2⌉` bring `n` primitives down to a leaf's worth:
/// the depth a subtree of median splits over them needs.
fn halvings_to_leaf(n: usize) -> usize {
    let (mut remaining, mut levels) = (n, 0);
    while remaining > MAX_LEAF_PRIMITIVES {
        remaining = remaining.div_ceil(2);
        levels += 1;
    }
    levels
}

/// Splits at the object median of the longest centroid axis (in input order if the
/// centroids coincide): both halves get at most `⌈n/2⌉` primitives.
fn median_split(prims: &mut [BuildPrimitive], centroids: &Aabb) -> (usize, Extents, Extents) {
    let mid = prims.len() / 2;
    let axis = (centroids.max - centroids.min).max_position();
    if centroids.max[axis] > centroids.min[axis] {
        prims.select_nth_unstable_by(mid, |a, b| {
            a.centroid()[axis].total_cmp(&b.centroid()[axis])
        });
    }
    let (left, right) = prims.split_at(mid);
    (mid, Extents::of(left), Extents::of(right))
}

/// Moves the primitives for which `goes_left` holds to the front, swapping pairs
/// from both ends inwards (Hoare), and returns how many there are.
fn partition(prims: &mut [BuildPrimitive], goes_left: impl Fn(&BuildPrimitive) -> bool) -> usize {
    let (mut left, mut right) = (0, prims.len());
    loop {
        while left < right && goes_left(&prims[left]) {
            left += 1;
        }
        while left < right && !goes_left(&prims[right - 1]) {
            right -= 1;
        }
        if left == right {
            return left;
        }
        prims.swap(left, right - 1);
        left += 1;
        right -= 1;
    }
}

/// The centroid bins along all three axes: on axis `i`,
/// `bin(c) = ⌊BINS·(cᵢ − c_min,i)/(c_max,i − c_min,i)⌋`, clamped to the last bin
/// (Wald 2007, §3.2). An axis the centroids do not spread along puts everything
/// in bin 0, so that no plane on it separates anything.
#[derive(Clone, Copy, Debug)]
struct Binning {
    min: Vec3A,
    scale: Vec3A,
}

impl Binning {
    fn new(centroids: &Aabb) -> Self {
        let extent = centroids.max - centroids.min;
        let spread = extent.cmpgt(Vec3A::ZERO);
        Self {
            min: centroids.min,
            scale: Vec3A::select(spread, BIN_COUNT as f32 / extent, Vec3A::ZERO),
        }
    }

    /// The bins of a centroid on the three axes. `(c − c_min)·scale` is ≥ 0, and
    /// `min` clamps it to the last bin, mapping NaN there too (`minps` returns its
    /// second operand for NaN): the casts need no further check.
    #[inline]
    fn bins(&self, centroid: Vec3A) -> [u8; 3] {
        let x = ((centroid - self.min) * self.scale).min(Vec3A::splat((BIN_COUNT - 1) as f32));
        [x.x as u8, x.y as u8, x.z as u8]
    }
}

/// A splitting plane between bins: on `axis`, primitives in bins below
/// `first_right` go left. With its SAH cost and the two sides' extents.
#[derive(Clone, Copy, Debug)]
struct SplitPlane {
    axis: usize,
    first_right: usize,
    cost: f32,
    left: Extents,
    right: Extents,
}

impl SplitPlane {
    /// Whether a primitive binned by [`fill_bins`] for this node goes left.
    #[inline]
    fn goes_left(&self, prim: &BuildPrimitive) -> bool {
        (prim.bins[self.axis] as usize) < self.first_right
    }
}

/// The cheapest plane between bins over all three axes, or `None` if the node has
/// no positive finite area or no plane puts primitives on both sides. Ties go to
/// the lower axis, then the lower plane.
fn best_binned_split(prims: &mut [BuildPrimitive], extents: &Extents) -> Option<SplitPlane> {
    let area = extents.bounds.surface_area();
    if !(area > 0.0 && area.is_finite()) {
        return None;
    }
    let binning = Binning::new(&extents.centroids);
    let bins = fill_bins(prims, &binning);
    (0..3)
        .filter_map(|axis| cheapest_plane(&bins[axis], area, axis))
        .reduce(|best, plane| if plane.cost < best.cost { plane } else { best })
}

/// Sorts the primitives into the bins of all three axes in one pass, noting
/// each one's bins in it.
fn fill_bins(prims: &mut [BuildPrimitive], binning: &Binning) -> [[Extents; BIN_COUNT]; 3] {
    let mut bins = [[Extents::EMPTY; BIN_COUNT]; 3];
    for prim in prims {
        let centroid = prim.centroid();
        prim.bins = binning.bins(centroid);
        for (axis_bins, bin) in bins.iter_mut().zip(prim.bins) {
            axis_bins[bin as usize].add(prim, centroid);
        }
    }
    bins
}

/// The cheapest plane between bins `i − 1` and `i` on one axis with primitives on
/// both sides, with its cost `C_trav + C_isect·(A_L·N_L + A_R·N_R)/A`: one sweep
/// from the right collects the right-hand sides, one from the left scores the
/// planes (Wald 2007, §3.1).
fn cheapest_plane(bins: &[Extents; BIN_COUNT], node_area: f32, axis: usize) -> Option<SplitPlane> {
    let mut right_sides = [Extents::EMPTY; BIN_COUNT];
    let mut right = Extents::EMPTY;
    for i in (1..BIN_COUNT).rev() {
        right = right.merge(bins[i]);
        right_sides[i] = right;
    }
    let (mut best, mut best_cost) = (None, f32::INFINITY);
    let mut left = Extents::EMPTY;
    for first_right in 1..BIN_COUNT {
        left = left.merge(bins[first_right - 1]);
        let right = right_sides[first_right];
        if left.count == 0 || right.count == 0 {
            continue;
        }
        let weighted = left.bounds.surface_area() * packets(left.count as usize)
            + right.bounds.surface_area() * packets(right.count as usize);
        let cost = TRAVERSAL_COST + INTERSECTION_COST * weighted / node_area;
        if cost < best_cost {
            best_cost = cost;
            best = Some(SplitPlane {
                axis,
                first_right,
                cost,
                left,
                right,
            });
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{AaBox, Shape, Sphere};
    use glint_snapfmt::sig5;
    use proptest::prelude::*;
    use std::fmt::Write;
    use std::time::Instant;

    /// Marsaglia's xorshift64 ("Xorshift RNGs", 2003): tiny, seeded, deterministic.
    pub(super) struct XorShift(pub(super) u64);

    impl XorShift {
        fn next_u64(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }

        /// Uniform in [0, 1), from the top 24 bits.
        pub(super) fn unit(&mut self) -> f32 {
            (self.next_u64() >> 40) as f32 / (1u32 << 24) as f32
        }

        fn range(&mut self, lo: f32, hi: f32) -> f32 {
            lo + (hi - lo) * self.unit()
        }

        pub(super) fn vec3(&mut self, lo: f32, hi: f32) -> Vec3 {
            Vec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
        }
    }

    /// `n³` small boxes, one per unit cell, centres jittered by up to ±0.3 and
    /// half-extents 0.05–0.25 per axis.
    fn jittered_grid(n: usize, seed: u64) -> Vec<Bounds3> {
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

    fn contains(outer: &Bounds3, inner: &Bounds3) -> bool {
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
    fn check_invariants(bvh: &Bvh, bounds: &[Bounds3]) {
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

    /// The depth (edges) of the binary tree the build makes before collapsing it.
    fn binary_depth(bounds: &[Bounds3], options: BuildOptions) -> usize {
        fn depth(nodes: &[BvhNode], i: usize) -> usize {
            if nodes[i].is_leaf() {
                0
            } else {
                1 + depth(nodes, i + 1).max(depth(nodes, nodes[i].offset as usize))
            }
        }
        let nodes = build_binary(&mut buildable_primitives(bounds), &options);
        depth(&nodes, 0)
    }

    pub(super) fn box_hit(b: &Bounds3, ray: &Ray, t_max: f32) -> Option<f32> {
        b.hit(ray.origin, ray.direction.recip(), t_max)
    }

    // ---- Bounds3 ----

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

    /// The wide node test against four children, as `Bounds3::hit` results.
    fn node_hits(boxes: &[Bounds3; 4], ray: &Ray, t_max: f32) -> [Option<f32>; 4] {
        let node = wide::tests::node_of(boxes);
        let (hits, enter) = wide::PreparedRay::new(ray).enters(&node, t_max);
        [0, 1, 2, 3].map(|k| (hits & (1 << k) != 0).then_some(enter[k]))
    }

    #[test]
    fn node_test_agrees_with_the_slab_test_of_each_child() {
        let mut rng = XorShift(0x5EED);
        let mut checked = 0;
        for _ in 0..20_000 {
            let boxes = [0, 1, 2, 3].map(|_| {
                let lo = rng.vec3(-4.0, 4.0);
                Bounds3::new(lo, lo + rng.vec3(0.0, 3.0))
            });
            // Origins anywhere, or on a face of a box (and so, with a zero
            // direction component across it, lying in the face's plane).
            let mut origin = rng.vec3(-6.0, 6.0);
            let mut direction = rng.vec3(-1.0, 1.0);
            let axis = (rng.next_u64() % 3) as usize;
            match rng.next_u64() % 4 {
                0 => {}
                1 => direction[axis] = 0.0,
                2 => direction[axis] = -0.0,
                _ => {
                    let b = &boxes[(rng.next_u64() % 4) as usize];
                    origin = b.min + rng.vec3(0.0, 1.0) * (b.max - b.min);
                    origin[axis] = if rng.unit() < 0.5 {
                        b.min[axis]
                    } else {
                        b.max[axis]
                    };
                    direction[axis] = if rng.unit() < 0.5 { 0.0 } else { -0.0 };
                }
            }
            let t_max = if rng.unit() < 0.5 {
                f32::INFINITY
            } else {
                rng.range(0.0, 8.0)
            };
            let ray = Ray::new(origin, direction);
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

    #[test]
    fn traverse_leaves_hands_over_padded_runs_and_finds_the_same_hits() {
        let bounds = random_boxes(3000, 20.0, 0.1, 2.0, 8);
        let bvh = Bvh::build(&bounds);
        let mut taken = bvh.clone();
        let order = taken.take_primitive_order();
        let mut rng = XorShift(21);
        let mut leaves = 0;
        for _ in 0..2000 {
            let origin = rng.vec3(-5.0, 25.0);
            let ray = Ray::new(origin, rng.vec3(0.0, 20.0) - origin);
            let mut nearest: Option<(u32, f32)> = None;
            let _ = taken.traverse_leaves(&ray, f32::INFINITY, |first, count, mut t_max| {
                leaves += 1;
                assert_eq!(first as usize % LEAF_WIDTH, 0);
                assert!((1..=LEAF_WIDTH as u32).contains(&count));
                let run = &order[first as usize..first as usize + LEAF_WIDTH];
                assert!(run[..count as usize].iter().all(|&i| i != u32::MAX));
                assert!(run[count as usize..].iter().all(|&i| i == u32::MAX));
                for &prim in &run[..count as usize] {
                    if let Some(t) = box_hit(&bounds[prim as usize], &ray, t_max) {
                        if t > 0.0 {
                            t_max = t;
                            nearest = Some((prim, t));
                        }
                    }
                }
                ControlFlow::Continue(t_max)
            });
            let want = bvh.closest_hit(&ray, f32::INFINITY, |i, r, t| {
                box_hit(&bounds[i as usize], r, t).filter(|&t| t > 0.0)
            });
            assert_eq!(nearest.map(|n| n.1), want.map(|w| w.1));
            // Breaking ends the traversal at the first leaf.
            let mut visits = 0;
            let broke = taken.traverse_leaves(&ray, f32::INFINITY, |_, _, _| {
                visits += 1;
                ControlFlow::Break(())
            });
            assert_eq!(broke.is_break(), visits == 1);
            assert!(visits <= 1);
        }
        assert!(leaves > 2000, "{leaves} leaves visited");
    }

    #[test]
    fn after_take_primitive_order_queries_report_leaf_positions() {
        let bounds = random_boxes(3000, 20.0, 0.1, 2.0, 5);
        let bvh = Bvh::build(&bounds);
        let mut taken = bvh.clone();
        let order = taken.take_primitive_order();
        assert_eq!(order, bvh.tree.indices);
        let identity: Vec<u32> = (0..order.len() as u32).collect();
        assert_eq!(taken.take_primitive_order(), identity, "a second call");
        // Padding (u32::MAX) gets an empty box, which no query reaches.
        let in_order: Vec<Bounds3> = order
            .iter()
            .map(|&i| bounds.get(i as usize).copied().unwrap_or(Bounds3::EMPTY))
            .collect();
        let mut rng = XorShift(11);
        let mut hits = 0;
        for _ in 0..2000 {
            let origin = rng.vec3(-5.0, 25.0);
            let ray = Ray::new(origin, rng.vec3(0.0, 20.0) - origin);
            let want = bvh.closest_hit(&ray, f32::INFINITY, |i, r, t| {
                box_hit(&bounds[i as usize], r, t).filter(|&t| t > 0.0)
            });
            let got = taken.closest_hit(&ray, f32::INFINITY, |k, r, t| {
                box_hit(&in_order[k as usize], r, t).filter(|&t| t > 0.0)
            });
            assert_eq!(got.map(|(k, t)| (order[k as usize], t)), want);
            let any = taken.any_hit(&ray, f32::INFINITY, |k, r, t| {
                box_hit(&in_order[k as usize], r, t).is_some_and(|t| t > 0.0)
            });
            assert_eq!(any, want.is_some());
            hits += usize::from(want.is_some());
        }
        assert!(hits > 100, "{hits} hits");
    }

    // ---- Agreement with brute force ----

    /// Bounds of a test shape. Sphere bounds are padded by 10⁻³·r, the caller's
    /// margin for the rounding of the quadratic's roots; box bounds are exact,
    /// so that rays lying on box faces also lie on node faces.
    fn shape_bounds(shape: &Shape) -> Bounds3 {
        match shape {
            Shape::Sphere(s) => {
                let r = Vec3::splat(s.radius() * 1.001);
                Bounds3::new(s.center() - r, s.center() + r)
            }
            Shape::Box(b) => Bounds3::new(b.min(), b.max()),
            _ => unreachable!("tests use spheres and boxes"),
        }
    }

    fn brute_closest(shapes: &[Shape], ray: &Ray, t_max: f32) -> Option<(u32, f32)> {
        let mut closest = None;
        let mut t_max = t_max;
        for (i, shape) in shapes.iter().enumerate() {
            if let Some(t) = shape.hit_distance(ray, t_max) {
                t_max = t;
                closest = Some((i as u32, t));
            }
        }
        closest
    }

    fn point() -> impl Strategy<Value = Vec3> {
        (-10.0f32..10.0, -10.0f32..10.0, -10.0f32..10.0).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    fn shape() -> impl Strategy<Value = Shape> {
        let sphere =
            (point(), 0.05f32..2.0).prop_map(|(c, r)| Shape::from(Sphere::new(c, r).unwrap()));
        let size = (0.01f32..3.0, 0.01f32..3.0, 0.01f32..3.0);
        let aabox = (point(), size).prop_map(|(lo, (x, y, z))| {
            Shape::from(AaBox::new(lo, lo + Vec3::new(x, y, z)).unwrap())
        });
        prop_oneof![sphere, aabox]
    }

    /// How a test ray is placed relative to the scene.
    #[derive(Clone, Copy, Debug)]
    enum RayKind {
        /// Random origin and direction.
        Free,
        /// Random origin, direction ±x, ±y or ±z (zero components ±0).
        AxisParallel,
        /// Starting inside the bounds of a chosen shape (inside it, for boxes).
        Inside,
        /// Starting on a face of a chosen shape's bounds, parallel to that face.
        OnFace,
    }

    #[derive(Clone, Copy, Debug)]
    struct RaySpec {
        kind: RayKind,
        target: prop::sample::Index,
        lerp: Vec3,
        origin: Vec3,
        direction: Vec3,
        axis: usize,
        negative: bool,
        t_max: f32,
    }

    fn ray_spec() -> impl Strategy<Value = RaySpec> {
        let kind = prop_oneof![
            Just(RayKind::Free),
            Just(RayKind::AxisParallel),
            Just(RayKind::Inside),
            Just(RayKind::OnFace),
        ];
        let lerp =
            (0.01f32..0.99, 0.01f32..0.99, 0.01f32..0.99).prop_map(|(x, y, z)| Vec3::new(x, y, z));
        let direction =
            (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0).prop_map(|(x, y, z)| Vec3::new(x, y, z));
        let t_max = prop_oneof![3 => Just(f32::INFINITY), 1 => 0.5f32..30.0];
        (
            kind,
            any::<prop::sample::Index>(),
            lerp,
            point(),
            direction,
            0..3usize,
            any::<bool>(),
            t_max,
        )
            .prop_map(
                |(kind, target, lerp, origin, direction, axis, negative, t_max)| RaySpec {
                    kind,
                    target,
                    lerp,
                    origin: 1.2 * origin,
                    direction,
                    axis,
                    negative,
                    t_max,
                },
            )
    }

    /// The ray a spec describes in a scene, and the shape it starts in or on.
    fn make_ray(spec: &RaySpec, shapes: &[Shape]) -> (Ray, Option<usize>) {
        let zero = if spec.negative { -0.0 } else { 0.0 };
        let sign = if spec.negative { -1.0 } else { 1.0 };
        let target = spec.target.index(shapes.len());
        let b = shape_bounds(&shapes[target]);
        let inside = b.min + spec.lerp * (b.max - b.min);
        match spec.kind {
            RayKind::Free => (Ray::new(spec.origin, spec.direction), None),
            RayKind::AxisParallel => {
                let mut dir = Vec3::splat(zero);
                dir[spec.axis] = sign;
                (Ray::new(spec.origin, dir), None)
            }
            RayKind::Inside => (Ray::new(inside, spec.direction), Some(target)),
            RayKind::OnFace => {
                let mut origin = inside;
                origin[spec.axis] = if spec.negative {
                    b.min[spec.axis]
                } else {
                    b.max[spec.axis]
                };
                let mut dir = spec.direction;
                dir[spec.axis] = zero;
                (Ray::new(origin, dir), Some(target))
            }
        }
    }

    fn agree_on_ray(bvh: &Bvh, shapes: &[Shape], spec: &RaySpec) -> Result<(), TestCaseError> {
        let (ray, start) = make_ray(spec, shapes);
        if ray.direction == Vec3::ZERO {
            return Ok(());
        }
        let t_max = spec.t_max;
        let want = brute_closest(shapes, &ray, t_max);
        let got = bvh.closest_hit(&ray, t_max, |i, r, t| shapes[i as usize].hit_distance(r, t));
        match (got, want) {
            (Some((gi, gt)), Some((wi, wt))) => {
                prop_assert_eq!(gt, wt, "t of {} vs {}", gi, wi);
                // Equal distances to two shapes: either index is right.
                let tie = shapes[gi as usize].hit_distance(&ray, f32::INFINITY);
                prop_assert!(gi == wi || tie == Some(wt), "{} vs {}", gi, wi);
            }
            (got, want) => prop_assert_eq!(got, want),
        }
        let any = bvh.any_hit(&ray, t_max, |i, r, t| {
            shapes[i as usize].hit_distance(r, t).is_some()
        });
        prop_assert_eq!(any, want.is_some());
        // A ray starting inside a box (or on a face, along it) always leaves it.
        let starts_in_box = start.is_some_and(|i| matches!(shapes[i], Shape::Box(_)));
        if starts_in_box && t_max.is_infinite() {
            prop_assert!(got.is_some(), "ray from inside box {:?} missed", start);
        }
        Ok(())
    }

    proptest! {
        // A fixed seed: the same 1024 cases on every run and in CI, so a failure
        // is reproducible (change the seed to explore new cases locally).
        #![proptest_config(ProptestConfig {
            cases: 1024,
            failure_persistence: None,
            rng_seed: proptest::test_runner::RngSeed::Fixed(0x5eed_b0b5),
            ..ProptestConfig::default()
        })]

        #[test]
        fn bvh_agrees_with_brute_force(
            shapes in prop::collection::vec(shape(), 1..150),
            rays in prop::collection::vec(ray_spec(), 1..48),
        ) {
            let bounds: Vec<Bounds3> = shapes.iter().map(shape_bounds).collect();
            let bvh = Bvh::build(&bounds);
            check_invariants(&bvh, &bounds);
            for spec in &rays {
                agree_on_ray(&bvh, &shapes, spec)?;
            }
        }
    }

    // ---- Structure and statistics ----

    #[test]
    fn stats_of_deterministic_scenes() {
        let scenes = [
            (
                "jittered grid, 1000 small boxes",
                jittered_grid(10, 0x9E37_79B9_7F4A_7C15),
            ),
            (
                "1000 overlapping boxes",
                random_boxes(1000, 10.0, 0.5, 4.0, 99),
            ),
        ];
        let mut report = String::new();
        for (name, bounds) in scenes {
            let bvh = Bvh::build(&bounds);
            check_invariants(&bvh, &bounds);
            let s = bvh.stats();
            // Leaves of at most 4 need at least 250 of them, so with at most four
            // children per node, depth ≥ 4.
            assert!((4..=24).contains(&s.max_depth), "{name}: {s:?}");
            // SAH must not lose to the same tree built by object medians alone (a
            // depth limit of 8 forces median splits all the way down). The build
            // minimises the binary tree's cost, and collapsing can shift it a
            // little: on heavily overlapping boxes the two come within a few percent.
            let median = Bvh::build_with(
                &bounds,
                BuildOptions {
                    max_depth: halvings_to_leaf(bounds.len()),
                    ..BuildOptions::DEFAULT
                },
            );
            check_invariants(&median, &bounds);
            let median_cost = median.stats().sah_cost;
            assert!(
                s.sah_cost < 1.05 * median_cost,
                "{name}: {s:?} vs {median_cost}"
            );
            writeln!(
                report,
                "{name}: nodes {}, leaves {}, max depth {}, max leaf size {}, SAH cost {} \
                 (object medians: {})",
                s.nodes,
                s.leaves,
                s.max_depth,
                s.max_leaf_size,
                sig5(s.sah_cost),
                sig5(median_cost)
            )
            .unwrap();
        }
        insta::assert_snapshot!(report);
    }

    #[test]
    fn sah_cost_of_a_two_leaf_tree_by_hand() {
        // Four unit cubes at the origin and four 9 apart along x: the root box is
        // 10×1×1 (area 2·(10+1+10) = 42), each leaf's area 6; one wide node over
        // two leaves. Cost = 1 (root) + 2 · (6/42) · 1.
        let near = Bounds3::new(Vec3::ZERO, Vec3::ONE);
        let far = Bounds3::new(Vec3::new(9.0, 0.0, 0.0), Vec3::new(10.0, 1.0, 1.0));
        let bounds = [near, far, near, far, near, far, near, far];
        let s = Bvh::build(&bounds).stats();
        assert_eq!(
            (s.nodes, s.leaves, s.max_depth, s.max_leaf_size),
            (1, 2, 1, 4)
        );
        let want = 1.0 + 2.0 * 6.0 / 42.0;
        assert!((s.sah_cost - want).abs() < 1e-6, "{s:?}");
    }

    #[test]
    fn closest_hit_prunes_by_distance_and_any_hit_stops_early() {
        // 1000 unit boxes in a row along −z; a ray down the row meets all of them.
        let bounds: Vec<Bounds3> = (0..1000)
            .map(|i| {
                let z = -2.0 * i as f32;
                Bounds3::new(Vec3::new(-0.5, -0.5, z - 1.0), Vec3::new(0.5, 0.5, z))
            })
            .collect();
        let bvh = Bvh::build(&bounds);
        let ray = Ray::new(Vec3::new(0.1, 0.2, 5.0), -Vec3::Z);
        let mut tests = 0;
        let hit = bvh.closest_hit(&ray, f32::INFINITY, |i, r, t| {
            tests += 1;
            box_hit(&bounds[i as usize], r, t).filter(|&t| t > 0.0)
        });
        assert_eq!(hit, Some((0, 5.0)));
        assert!(tests <= 2 * MAX_LEAF_PRIMITIVES, "{tests} primitive tests");
        let mut tests = 0;
        let any = bvh.any_hit(&ray, f32::INFINITY, |_, _, _| {
            tests += 1;
            true
        });
        assert!(any);
        assert_eq!(tests, 1);
        // The same ray backwards, from beyond the far end.
        let back = Ray::new(Vec3::new(0.1, 0.2, -2100.0), Vec3::Z);
        let hit = bvh.closest_hit(&back, f32::INFINITY, |i, r, t| {
            box_hit(&bounds[i as usize], r, t)
        });
        assert_eq!(hit, Some((999, 2100.0 - 1999.0)));
    }

    // ---- Degenerate inputs ----

    #[test]
    fn zero_primitives() {
        let bvh = Bvh::build(&[]);
        assert!(bvh.is_empty());
        let zero = BvhStats {
            nodes: 0,
            leaves: 0,
            max_depth: 0,
            max_leaf_size: 0,
            sah_cost: 0.0,
        };
        assert_eq!(bvh.stats(), zero);
        let ray = Ray::new(Vec3::ZERO, Vec3::X);
        assert_eq!(
            bvh.closest_hit(&ray, f32::INFINITY, |_, _, _| unreachable!()),
            None
        );
        assert!(!bvh.any_hit(&ray, f32::INFINITY, |_, _, _| unreachable!()));
        assert!(Bvh::default().is_empty());
    }

    #[test]
    fn one_primitive() {
        let bounds = [Bounds3::new(
            Vec3::new(2.0, -1.0, -1.0),
            Vec3::new(3.0, 1.0, 1.0),
        )];
        let bvh = Bvh::build(&bounds);
        check_invariants(&bvh, &bounds);
        let s = bvh.stats();
        assert_eq!(
            (s.nodes, s.leaves, s.max_depth, s.max_leaf_size),
            (1, 1, 1, 1)
        );
        // The root node (1) and its one leaf, of the same box (1).
        assert_eq!(s.sah_cost, 2.0);
        let hit = |i: u32, r: &Ray, t: f32| box_hit(&bounds[i as usize], r, t);
        let ray = Ray::new(Vec3::ZERO, Vec3::X);
        assert_eq!(bvh.closest_hit(&ray, f32::INFINITY, hit), Some((0, 2.0)));
        assert_eq!(bvh.closest_hit(&ray, 1.5, hit), None);
        assert!(bvh.any_hit(&ray, 2.5, |i, r, t| hit(i, r, t).is_some()));
        assert!(
            !bvh.any_hit(&Ray::new(Vec3::ZERO, -Vec3::X), f32::INFINITY, |_, _, _| {
                true
            })
        );
        let nan = Ray::new(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::X);
        assert_eq!(bvh.closest_hit(&nan, f32::INFINITY, hit), None);
    }

    #[test]
    fn identical_primitives_and_identical_centroids_terminate_in_small_leaves() {
        let same = vec![Bounds3::new(Vec3::ZERO, Vec3::ONE); 1000];
        let nested: Vec<Bounds3> = (1..=1000)
            .map(|i| Bounds3::new(Vec3::splat(-(i as f32)), Vec3::splat(i as f32)))
            .collect();
        for (bounds, identical) in [(same, true), (nested, false)] {
            let bvh = Bvh::build(&bounds);
            check_invariants(&bvh, &bounds);
            let s = bvh.stats();
            // No plane separates equal centroids, so median splits of 1000 go
            // 500, 250, 125, 63, 32, 16, 8, 4: 256 leaves at binary depth 8. The
            // collapse opens the largest boxes first: for identical boxes the
            // shallowest, giving four levels of four-wide nodes; for nested ones
            // the outermost, a lopsided wide tree of at most 8 levels.
            assert_eq!(s.leaves, 256, "{s:?}");
            if identical {
                assert_eq!(s.max_depth, 4, "{s:?}");
            } else {
                assert!((4..=8).contains(&s.max_depth), "{s:?}");
            }
            let ray = Ray::new(Vec3::new(0.5, 0.5, 5000.0), -Vec3::Z);
            let (prim, t) = bvh
                .closest_hit(&ray, f32::INFINITY, |i, r, t| {
                    box_hit(&bounds[i as usize], r, t)
                })
                .unwrap();
            assert_eq!(t, 5000.0 - bounds[prim as usize].max.z);
            assert_eq!(
                t,
                5000.0 - bounds.iter().map(|b| b.max.z).fold(0.0, f32::max)
            );
        }
    }

    #[test]
    fn zero_area_primitives_build_by_median() {
        // Points along a line: every node has zero surface area, so no SAH.
        let bounds: Vec<Bounds3> = (0..100)
            .map(|i| Bounds3::EMPTY.include(Vec3::new(i as f32, 1.0, 2.0)))
            .collect();
        let bvh = Bvh::build(&bounds);
        check_invariants(&bvh, &bounds);
        // A zero-area root weighs every node 1: interior nodes cost 1, leaves N.
        let s = bvh.stats();
        assert_eq!(s.sah_cost, (s.nodes + s.leaves) as f32);
        let ray = Ray::new(Vec3::new(-5.0, 1.0, 2.0), Vec3::X);
        let mut count = 0;
        bvh.closest_hit(&ray, f32::INFINITY, |_, _, _| {
            count += 1;
            None
        });
        assert_eq!(count, 100, "a ray along the line reaches every point");
    }

    #[test]
    fn nan_infinite_and_empty_bounds_are_left_out() {
        let unit = Bounds3::new(Vec3::ZERO, Vec3::ONE);
        let bounds = [
            unit,
            Bounds3 {
                min: Vec3::new(f32::NAN, 0.0, 0.0),
                max: Vec3::ONE,
            },
            Bounds3::new(Vec3::ZERO, Vec3::new(f32::INFINITY, 1.0, 1.0)),
            Bounds3::new(Vec3::splat(f32::NEG_INFINITY), Vec3::ONE),
            Bounds3::EMPTY,
            Bounds3 {
                min: Vec3::ONE,
                max: Vec3::ZERO,
            },
            Bounds3::new(Vec3::splat(3.0), Vec3::splat(4.0)),
        ];
        let bvh = Bvh::build(&bounds);
        check_invariants(&bvh, &bounds);
        let mut sorted: Vec<u32> = bvh
            .tree
            .indices
            .iter()
            .copied()
            .filter(|&i| i != u32::MAX)
            .collect();
        sorted.sort_unstable();
        assert_eq!(sorted, [0, 6]);
        // A ray through every box, valid or not, only ever tests the valid ones.
        let ray = Ray::new(Vec3::splat(-1.0), Vec3::ONE);
        let hit = bvh.closest_hit(&ray, f32::INFINITY, |i, r, t| {
            assert!(i == 0 || i == 6, "primitive {i} tested");
            box_hit(&bounds[i as usize], r, t)
        });
        assert_eq!(hit, Some((0, 1.0)));
        let all_invalid = [bounds[1], bounds[2], bounds[4]];
        assert!(Bvh::build(&all_invalid).is_empty());
    }

    #[test]
    fn depth_limit_switches_to_median_splits() {
        let bounds = jittered_grid(10, 7);
        // 1000 primitives need 8 halvings to reach leaves of 4; allow just that.
        let options = BuildOptions {
            max_depth: 8,
            ..BuildOptions::DEFAULT
        };
        let bvh = Bvh::build_with(&bounds, options);
        check_invariants(&bvh, &bounds);
        assert!(binary_depth(&bounds, options) <= 8);
        let unlimited = binary_depth(&bounds, BuildOptions::DEFAULT);
        assert!(unlimited > 8, "the limit should bind: {unlimited}");
    }

    #[test]
    fn a_skewed_tree_is_cut_to_the_depth_limit_and_still_answers_queries() {
        // Cubes of side x/10 at distance x = 2⁻⁶⁰ … 2⁶⁰ along each axis: the top
        // centroid bins hold only the farthest few cubes of an axis, so SAH peels
        // them off a few per level into a deep, lopsided tree.
        let bounds: Vec<Bounds3> = (0..3)
            .flat_map(|axis| {
                (-60..=60).map(move |i| {
                    let mut corner = Vec3::ZERO;
                    corner[axis] = 2f32.powi(i);
                    Bounds3::new(corner, corner + Vec3::splat(0.1 * 2f32.powi(i)))
                })
            })
            .collect();
        let unbounded = Bvh::build_with(
            &bounds,
            BuildOptions {
                max_depth: usize::MAX,
                ..BuildOptions::DEFAULT
            },
        );
        let depth = binary_depth(
            &bounds,
            BuildOptions {
                max_depth: usize::MAX,
                ..BuildOptions::DEFAULT
            },
        );
        assert!(depth > 24, "unbounded SAH depth {depth}");
        check_invariants(&unbounded, &bounds);
        let eye = Vec3::new(-1.0, -2.0, -3.0);
        let prim_hit = |i: u32, r: &Ray, t: f32| box_hit(&bounds[i as usize], r, t);
        for limit in [7, 12, 20] {
            let options = BuildOptions {
                max_depth: limit,
                ..BuildOptions::DEFAULT
            };
            let bvh = Bvh::build_with(&bounds, options);
            check_invariants(&bvh, &bounds);
            assert!(binary_depth(&bounds, options) <= limit);
            for b in &bounds {
                let ray = Ray::new(eye, b.centroid() - eye);
                let want = (0..bounds.len() as u32)
                    .filter_map(|i| prim_hit(i, &ray, f32::INFINITY).map(|t| (i, t)))
                    .min_by(|a, b| a.1.total_cmp(&b.1));
                let got = bvh.closest_hit(&ray, f32::INFINITY, prim_hit);
                assert_eq!(got.map(|g| g.1), want.map(|w| w.1), "limit {limit}");
            }
        }
    }

    // ---- Determinism ----

    fn layout(bvh: &Bvh) -> &WideBvh {
        &bvh.tree
    }

    fn build_in_pool(threads: usize, bounds: &[Bounds3]) -> Bvh {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| Bvh::build(bounds))
    }

    #[test]
    fn build_is_deterministic_across_runs_and_thread_counts() {
        // 27 000 primitives: several levels above PARALLEL_THRESHOLD.
        let bounds = jittered_grid(30, 12345);
        let first = Bvh::build(&bounds);
        check_invariants(&first, &bounds);
        let again = Bvh::build(&bounds);
        let one = build_in_pool(1, &bounds);
        let two = build_in_pool(2, &bounds);
        let serial = Bvh::build_with(
            &bounds,
            BuildOptions {
                parallel_threshold: usize::MAX,
                ..BuildOptions::DEFAULT
            },
        );
        assert_eq!(layout(&first), layout(&again));
        assert_eq!(layout(&first), layout(&one));
        assert_eq!(layout(&first), layout(&two));
        assert_eq!(
            layout(&first),
            layout(&serial),
            "parallel and serial layouts differ"
        );
    }

    // ---- Build time ----
    #[test]
    #[ignore = "timing: cargo test --release -p glint-geometry -- --ignored --nocapture"]
    fn build_time_for_a_million_boxes() {
        let bounds = random_boxes(1_000_000, 100.0, 0.01, 0.5, 2024);
        let start = Instant::now();
        let bvh = Bvh::build(&bounds);
        let elapsed = start.elapsed();
        println!(
            "built a BVH over {} boxes in {:.1} ms on {} rayon threads: {:?}",
            bounds.len(),
            elapsed.as_secs_f64() * 1e3,
            rayon::current_num_threads(),
            bvh.stats()
        );
        check_invariants(&bvh, &bounds);
        // Closest hits for rays from random points towards random points, on one
        // thread, against the boxes themselves.
        let mut rng = XorShift(77);
        let rays: Vec<Ray> = (0..100_000)
            .map(|_| {
                let origin = rng.vec3(0.0, 100.0);
                Ray::new(origin, rng.vec3(0.0, 100.0) - origin)
            })
            .collect();
        let start = Instant::now();
        let hits = rays
            .iter()
            .filter(|ray| {
                let hit = |i: u32, r: &Ray, t: f32| {
                    box_hit(&bounds[i as usize], r, t).filter(|&t| t > 0.0)
                };
                bvh.closest_hit(ray, f32::INFINITY, hit).is_some()
            })
            .count();
        let elapsed = start.elapsed().as_secs_f64();
        println!(
            "{} closest-hit rays ({hits} hits) in {:.1} ms: {:.2} Mrays/s on one thread",
            rays.len(),
            elapsed * 1e3,
            rays.len() as f64 / elapsed / 1e6
        );
        assert!(hits > 0);
    }
}
