//! A bounding volume hierarchy (BVH) over primitives known only by their bounds.
//!
//! The tree is built top-down with the binned surface area heuristic (SAH) of
//! Wald, "On fast Construction of SAH-based Bounding Volume Hierarchies" (IEEE
//! Symposium on Interactive Ray Tracing, 2007), as in pbrt-v4 §7.3.2, as a binary
//! tree of 32-byte nodes in depth-first order (pbrt-v4 §7.3.4), with leaves of at
//! most four primitives priced as one four-wide intersection test. The binary
//! tree is then collapsed into a 4-wide BVH (Wald, Benthin and Boulos
//! 2008, Embree's BVH4): each node holds the boxes of up to four children axis by
//! axis, so that one run of four-wide SIMD operations tests them all, and leaf
//! runs are padded to multiples of four so that a caller can test a leaf's
//! primitives as one packet.
//!
//! Traversal (pbrt-v4 §7.3.5, for four children) tests a node's children against
//! the ray, descends into the nearest and keeps the others on a fixed-size stack,
//! farthest first, with their entry distances, so that they are dropped once a
//! closer hit is known. Nothing is allocated per ray (except while
//! [`record_steps`] records a query's path).
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
//!
//! # Files, one concept each
//! - `bounds`: [`Bounds3`] and the ray–box slab test.
//! - `binary_node`: the binary tree's 32-byte node, which the build produces and
//!   the collapse reads.
//! - `extents`: the boxes, primitives and sets of primitives the build and the
//!   SAH work on.
//! - `build`: the binary tree, built in parallel, flattened, then collapsed.
//! - `sah`: where a node is split (binned SAH, and an exact sweep for small nodes),
//!   and how many primitives a leaf may hold.
//! - `wide`: the 4-wide node layout (two cache lines per node) and the collapse.
//! - `prepared_ray`: the ray–node test, four child boxes at once.
//! - `traversal_stack`: the children still to visit, front to back.
//! - `traversal`: the single-ray queries.
//! - `traversal_lanes`: several rays walking the tree at once, one ray per
//!   SIMD lane: any hit ([`Bvh::any_hit_lanes`]) and the leaves for closest
//!   hits ([`Bvh::traverse_leaves_lanes`]), each lane pruning by its own limit.
//! - `stream`: traversal of a batch of rays, interleaved.
//! - `trail`: the steps of one query, recorded for `glint explain`.
//! - `stats`: [`BvhStats`].
//! - `tests` and `test_support`: tests of the tree as built (the queries' tests
//!   sit beside them, in `traversal`, `traversal_lanes` and `stream`).

mod binary_node;
mod bounds;
mod build;
mod extents;
mod prepared_ray;
mod sah;
mod stats;
mod stream;
#[cfg(test)]
pub(crate) mod test_support;
#[cfg(test)]
mod tests;
mod trail;
mod traversal;
mod traversal_lanes;
mod traversal_stack;
mod wide;

pub use bounds::Bounds3;
pub use stats::BvhStats;
pub use stream::{RayStream, LEAF_PREFETCH_LINES, STREAM_LANES};
pub use trail::{record_steps, BvhChild, BvhStep, ChildTest};
pub use traversal_lanes::LeavesLanes;
use wide::WideBvh;
pub use wide::LEAF_WIDTH;

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

fn index_u32(i: usize) -> u32 {
    u32::try_from(i).expect("BVH index exceeds u32")
}

impl Bvh {
    /// Whether the tree holds no primitive (none given, or none with valid bounds).
    pub fn is_empty(&self) -> bool {
        self.tree.nodes.is_empty()
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
}
