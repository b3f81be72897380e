//! The 4-wide BVH that traversal reads: the binary SAH tree collapsed so that
//! every node holds the boxes of up to four children, tested against a ray in one
//! run of four-wide SIMD operations.
//!
//! Collapsing follows Wald, Benthin and Boulos, "Getting Rid of Packets: Efficient
//! SIMD Single-Ray Traversal using Multi-branching BVHs" (IEEE Symposium on
//! Interactive Ray Tracing, 2008) and Embree's BVH4 (Wald et al., "Embree: A
//! Kernel Framework for Efficient CPU Ray Tracing", SIGGRAPH 2014): starting from
//! a binary node's two children, the interior child of largest surface area is
//! replaced by its own two children until there are four, or only leaves. A
//! traversal step then does the work of about two binary levels for the price of
//! one node fetch and one SIMD box test, and the tree has roughly a third as many
//! nodes as the binary one.
//!
//! Leaves hold at most [`LEAF_WIDTH`] primitives, and each leaf's run in leaf order
//! starts at a multiple of [`LEAF_WIDTH`] (the runs are padded), so that a caller
//! can store a leaf's primitives as one four-lane packet and test them together.

use super::binary_node::BvhNode;
use super::bounds::Bounds3;
use super::index_u32;
use glam::{Vec3, Vec4};

/// Children per node, and the lanes of the box test.
pub(super) const WIDTH: usize = 4;
/// The most primitives a leaf holds, and the alignment of leaf runs in leaf order.
pub const LEAF_WIDTH: usize = 4;
/// Marks a leaf in a [`Link`]; the rest of an interior link is a node index.
const LEAF_BIT: u32 = 1 << 31;
/// Where a leaf's primitive count (minus one) sits in its [`Link`]: the low bits,
/// free because a leaf's first position is a multiple of [`LEAF_WIDTH`].
const COUNT_MASK: u32 = LEAF_WIDTH as u32 - 1;

/// A child as traversal keeps it: an interior node's index in [`WideBvh::nodes`],
/// or a leaf as `LEAF_BIT | first | (count − 1)` with `first` its first position
/// in the padded leaf order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Link(u32);

impl Link {
    /// A link that is never followed: the child slot of an empty box.
    pub(super) const UNUSED: Link = Link(u32::MAX);
    /// The root node.
    pub(super) const ROOT: Link = Link(0);

    pub(super) fn interior(node: usize) -> Link {
        let node = index_u32(node);
        assert!(node < LEAF_BIT, "BVH node index exceeds 2³¹");
        Link(node)
    }

    pub(super) fn leaf(first: usize, count: usize) -> Link {
        debug_assert!(first.is_multiple_of(LEAF_WIDTH) && (1..=LEAF_WIDTH).contains(&count));
        let first = index_u32(first);
        assert!(first < LEAF_BIT, "BVH leaf position exceeds 2³¹");
        Link(LEAF_BIT | first | (count as u32 - 1))
    }

    #[inline]
    pub(super) fn is_leaf(self) -> bool {
        self.0 & LEAF_BIT != 0
    }

    /// An interior node's index.
    #[inline]
    pub(super) fn node(self) -> usize {
        self.0 as usize
    }

    /// A leaf's first position in leaf order and its primitive count.
    #[inline]
    pub(super) fn leaf_range(self) -> (u32, u32) {
        (
            (self.0 & !LEAF_BIT) & !COUNT_MASK,
            (self.0 & COUNT_MASK) + 1,
        )
    }
}

/// One node: the boxes of up to four children, axis by axis across the children
/// (`planes[i]` is the minima on axis `i`, `planes[3 + i]` the maxima), and their
/// links. An unused child has the empty box (`+∞` minima, `−∞` maxima), which no
/// ray enters. 112 bytes, padded to two 64-byte cache lines and aligned to them.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub(super) struct WideNode {
    pub(super) planes: [Vec4; 6],
    pub(super) links: [Link; WIDTH],
}

const _: () = assert!(std::mem::size_of::<WideNode>() == 128);

impl WideNode {
    pub(super) const EMPTY: WideNode = WideNode {
        planes: [
            Vec4::INFINITY,
            Vec4::INFINITY,
            Vec4::INFINITY,
            Vec4::NEG_INFINITY,
            Vec4::NEG_INFINITY,
            Vec4::NEG_INFINITY,
        ],
        links: [Link::UNUSED; WIDTH],
    };

    fn set_child(&mut self, lane: usize, min: Vec3, max: Vec3, link: Link) {
        for axis in 0..3 {
            self.planes[axis][lane] = min[axis];
            self.planes[3 + axis][lane] = max[axis];
        }
        self.links[lane] = link;
    }

    /// The box of the child in `lane` (empty for an unused one).
    pub(super) fn child_bounds(&self, lane: usize) -> Bounds3 {
        Bounds3 {
            min: Vec3::new(
                self.planes[0][lane],
                self.planes[1][lane],
                self.planes[2][lane],
            ),
            max: Vec3::new(
                self.planes[3][lane],
                self.planes[4][lane],
                self.planes[5][lane],
            ),
        }
    }

    #[inline(always)]
    pub(super) fn link(&self, lane: usize) -> Link {
        self.links[lane]
    }

    /// The used children: (lane, link).
    pub(super) fn children(&self) -> impl Iterator<Item = (usize, Link)> + '_ {
        self.links
            .iter()
            .enumerate()
            .filter(|(_, l)| **l != Link::UNUSED)
            .map(|(lane, l)| (lane, *l))
    }
}

/// The collapsed tree: nodes in depth-first order (root first), and the
/// primitive indices in padded leaf order (`u32::MAX` in padding).
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct WideBvh {
    pub(super) nodes: Vec<WideNode>,
    pub(super) indices: Vec<u32>,
}

impl WideBvh {
    /// Collapses a binary tree, given as nodes in depth-first order (an interior
    /// node's first child follows it, its `offset` is its second child's index;
    /// a leaf's `offset` and `count` are its run in `indices`). A lone leaf gets a
    /// root of one child.
    pub(super) fn collapse(binary: &[BvhNode], indices: &[u32]) -> WideBvh {
        let mut wide = WideBvh {
            nodes: Vec::with_capacity(binary.len() / 3 + 1),
            indices: Vec::with_capacity(indices.len() + indices.len() / 2),
        };
        if binary.is_empty() {
            return wide;
        }
        if binary[0].is_leaf() {
            let mut root = WideNode::EMPTY;
            let link = wide.place_leaf(&binary[0], indices);
            root.set_child(0, binary[0].min, binary[0].max, link);
            wide.nodes.push(root);
        } else {
            wide.emit(binary, 0, indices);
        }
        wide
    }

    /// Appends the wide node replacing binary interior node `index`, then its
    /// children's subtrees in order; returns its index.
    fn emit(&mut self, binary: &[BvhNode], index: usize, indices: &[u32]) -> usize {
        let at = self.nodes.len();
        self.nodes.push(WideNode::EMPTY);
        let mut node = WideNode::EMPTY;
        for (lane, child) in open_children(binary, index)
            .into_iter()
            .flatten()
            .enumerate()
        {
            let c = &binary[child];
            let link = if c.is_leaf() {
                self.place_leaf(c, indices)
            } else {
                Link::interior(self.emit(binary, child, indices))
            };
            node.set_child(lane, c.min, c.max, link);
        }
        self.nodes[at] = node;
        at
    }

    /// Appends a leaf's primitives to the padded leaf order, then padding up to the
    /// next multiple of [`LEAF_WIDTH`].
    fn place_leaf(&mut self, leaf: &BvhNode, indices: &[u32]) -> Link {
        let first = self.indices.len();
        let (start, count) = (leaf.offset as usize, leaf.count as usize);
        self.indices
            .extend_from_slice(&indices[start..start + count]);
        self.indices.resize(first + LEAF_WIDTH, u32::MAX);
        Link::leaf(first, count)
    }
}

/// The (up to four) binary nodes that become the children of the wide node
/// replacing interior node `index`: its two children, then repeatedly the interior
/// one of largest surface area replaced in place by its two children, so that the
/// children stay in the binary tree's order. On equal areas the shallowest is
/// opened (then the first), so that a balanced binary tree gives a balanced wide
/// one.
fn open_children(binary: &[BvhNode], index: usize) -> [Option<usize>; WIDTH] {
    let children_of = |i: usize| [i + 1, binary[i].offset as usize];
    let area = |i: usize| {
        let n = &binary[i];
        Bounds3 {
            min: n.min,
            max: n.max,
        }
        .surface_area()
    };
    // (binary node, levels below `index`)
    let mut open = [(0usize, 0usize); WIDTH];
    let [first, second] = children_of(index);
    open[0] = (first, 1);
    open[1] = (second, 1);
    let mut len = 2;
    while len < WIDTH {
        let mut widest: Option<(usize, f32, usize)> = None;
        for (k, &(node, depth)) in open[..len].iter().enumerate() {
            if binary[node].is_leaf() {
                continue;
            }
            let a = area(node);
            let better = match widest {
                None => true,
                Some((_, best, best_depth)) => a > best || (a == best && depth < best_depth),
            };
            if better {
                widest = Some((k, a, depth));
            }
        }
        let Some((k, _, depth)) = widest else { break };
        let [a, b] = children_of(open[k].0);
        open.copy_within(k + 1..len, k + 2);
        open[k] = (a, depth + 1);
        open[k + 1] = (b, depth + 1);
        len += 1;
    }
    let mut children = [None; WIDTH];
    for (child, &(node, _)) in children.iter_mut().zip(&open[..len]) {
        *child = Some(node);
    }
    children
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// A node over up to four boxes, as leaves of one primitive each.
    pub(in crate::bvh) fn node_of(boxes: &[Bounds3]) -> WideNode {
        let mut node = WideNode::EMPTY;
        for (lane, b) in boxes.iter().enumerate() {
            node.set_child(lane, b.min, b.max, Link::leaf(LEAF_WIDTH * lane, 1));
        }
        node
    }

    #[test]
    fn links_round_trip() {
        let leaf = Link::leaf(4 * 12345, 3);
        assert!(leaf.is_leaf());
        assert_eq!(leaf.leaf_range(), (4 * 12345, 3));
        let interior = Link::interior(777);
        assert!(!interior.is_leaf());
        assert_eq!(interior.node(), 777);
        assert_eq!(Link::ROOT.node(), 0);
    }
}
