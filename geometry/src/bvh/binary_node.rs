//! The binary tree's node: what the build (module `build`) produces and the
//! collapse into the 4-wide tree (module `wide`) reads.

use super::bounds::Bounds3;
use super::index_u32;
use glam::Vec3;

/// One node of the binary tree as the build produces it, 32 bytes. A subtree built
/// on one thread is an array of these in depth-first order, with links relative to
/// its start; the build joins the subtrees into one array, which the collapse
/// turns into the wide tree.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub(super) struct BvhNode {
    pub(super) min: Vec3,
    /// Leaf: position of its first primitive in the build's primitive order.
    /// Interior: index of its second child (the first child is the next node).
    pub(super) offset: u32,
    pub(super) max: Vec3,
    /// Number of primitives of a leaf (≥ 1); 0 marks an interior node.
    pub(super) count: u32,
}

const _: () = assert!(std::mem::size_of::<BvhNode>() == 32);

impl BvhNode {
    pub(super) fn leaf(bounds: &Bounds3, first: usize, count: usize) -> Self {
        Self {
            min: bounds.min,
            offset: index_u32(first),
            max: bounds.max,
            count: index_u32(count),
        }
    }

    pub(super) fn interior(bounds: &Bounds3, second_child: usize) -> Self {
        Self {
            min: bounds.min,
            offset: index_u32(second_child),
            max: bounds.max,
            count: 0,
        }
    }

    pub(super) fn is_leaf(&self) -> bool {
        self.count > 0
    }
}
