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

use super::{BvhNode, EXIT_SCALE};
use crate::Ray;
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
    const UNUSED: Link = Link(u32::MAX);
    /// The root node.
    pub(super) const ROOT: Link = Link(0);

    fn interior(node: usize) -> Link {
        let node = super::index_u32(node);
        assert!(node < LEAF_BIT, "BVH node index exceeds 2³¹");
        Link(node)
    }

    fn leaf(first: usize, count: usize) -> Link {
        debug_assert!(first % LEAF_WIDTH == 0 && (1..=LEAF_WIDTH).contains(&count));
        let first = super::index_u32(first);
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
    planes: [Vec4; 6],
    links: [Link; WIDTH],
}

const _: () = assert!(std::mem::size_of::<WideNode>() == 128);

impl WideNode {
    const EMPTY: WideNode = WideNode {
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
    pub(super) fn child_bounds(&self, lane: usize) -> super::Bounds3 {
        super::Bounds3 {
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
        super::Bounds3 {
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

/// Entries in the traversal stack. A visit pushes at most three children (the
/// fourth is visited next), and a node at depth `d` is visited with at most `3d`
/// entries on the stack; the depth of the wide tree is at most the binary tree's,
/// at most [`super::MAX_DEPTH`]. One more slot takes the write above the top that
/// [`TraversalStack::order`] does not keep.
const STACK_SIZE: usize = 3 * super::MAX_DEPTH + 1;

/// Children still to visit with their entry distances, in a fixed array.
pub(super) struct TraversalStack {
    links: [Link; STACK_SIZE],
    enter: [f32; STACK_SIZE],
    len: usize,
}

impl TraversalStack {
    pub(super) fn new() -> Self {
        Self {
            links: [Link::UNUSED; STACK_SIZE],
            enter: [0.0; STACK_SIZE],
            len: 0,
        }
    }

    /// Empties the stack for a new ray.
    #[inline]
    pub(super) fn clear(&mut self) {
        self.len = 0;
    }

    #[inline]
    fn push(&mut self, link: Link, t_enter: f32) {
        self.links[self.len] = link;
        self.enter[self.len] = t_enter;
        self.len += 1;
    }

    /// Pops children until one the ray enters before `t_max`, skipping those a
    /// closer hit found since they were pushed has ruled out.
    #[inline]
    pub(super) fn pop_before(&mut self, t_max: f32) -> Option<Link> {
        while self.len > 0 {
            self.len -= 1;
            if self.enter[self.len] < t_max {
                return Some(self.links[self.len]);
            }
        }
        None
    }

    /// Of the children of `node` whose bits are set in `hits` (at least one),
    /// returns the one entered first and pushes the others, farthest first, so that
    /// they are popped front to back. (Which of two equally near children goes
    /// first changes no query's answer; see [`super::Bvh::closest_hit`].)
    ///
    /// One or two children (95% of the nodes an incoherent ray enters) take the
    /// same path, without a branch on which: the far child is written just above
    /// the top of the stack and kept only if it is not the near one. Measured (A/B
    /// in one process, incoherent streams, one core): 6–10% more rays per second on
    /// 10k, 1M and 4M triangles than branching on the count.
    #[inline(always)]
    pub(super) fn order(&mut self, node: &WideNode, hits: u32, enter: Vec4) -> Link {
        debug_assert!(hits != 0);
        let rest = hits & (hits - 1);
        if rest & rest.wrapping_sub(1) != 0 {
            return self.order_many(node, hits, enter);
        }
        let first = hits.trailing_zeros() as usize;
        let last = (31 - hits.leading_zeros()) as usize;
        let enter = enter.to_array();
        // On a tie the later lane goes first, as in `order_many`.
        let (near, far) = if enter[last] <= enter[first] {
            (last, first)
        } else {
            (first, last)
        };
        self.links[self.len] = node.links[far];
        self.enter[self.len] = enter[far];
        self.len += usize::from(rest != 0);
        node.links[near]
    }

    /// [`TraversalStack::order`] for three or four children: an insertion sort.
    #[inline(never)]
    fn order_many(&mut self, node: &WideNode, hits: u32, enter: Vec4) -> Link {
        let enter = enter.to_array();
        let mut lanes = [0usize; WIDTH];
        let mut n = 0;
        let mut bits = hits;
        while bits != 0 {
            let lane = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            // Farthest first.
            let mut j = n;
            while j > 0 && enter[lanes[j - 1]] < enter[lane] {
                lanes[j] = lanes[j - 1];
                j -= 1;
            }
            lanes[j] = lane;
            n += 1;
        }
        for &lane in &lanes[..n - 1] {
            self.push(node.links[lane], enter[lane]);
        }
        node.links[lanes[n - 1]]
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// A node over up to four boxes, as leaves of one primitive each.
    pub(in crate::bvh) fn node_of(boxes: &[super::super::Bounds3]) -> WideNode {
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

    /// The children `order` hands back for `hits` with entry distances `enter`:
    /// the one to visit now, then the stack's, as popped (with no pruning).
    fn visit_order(hits: u32, enter: [f32; 4], stacked: &[(Link, f32)]) -> Vec<usize> {
        let mut node = WideNode::EMPTY;
        for lane in 0..WIDTH {
            node.links[lane] = Link::interior(100 + lane);
        }
        let mut stack = TraversalStack::new();
        for &(link, t) in stacked {
            stack.push(link, t);
        }
        let first = stack.order(&node, hits, Vec4::from_array(enter));
        let mut order = vec![first.node() - 100];
        while let Some(link) = stack.pop_before(f32::INFINITY) {
            if link.node() < 100 {
                break;
            }
            order.push(link.node() - 100);
        }
        order
    }

    #[test]
    fn order_visits_the_hit_children_front_to_back_whatever_their_count() {
        let enter = [3.0, 1.0, 4.0, 2.0];
        // One child: nothing pushed, although the far slot is written above the top.
        let below = [(Link::interior(7), 9.0)];
        assert_eq!(visit_order(0b0100, enter, &below), [2]);
        let mut stack = TraversalStack::new();
        stack.push(Link::interior(7), 9.0);
        let node = WideNode::EMPTY;
        stack.order(&node, 0b0100, Vec4::from_array(enter));
        assert_eq!(stack.len, 1, "a lone child leaves the stack as it was");
        // Two children, in either lane order.
        assert_eq!(visit_order(0b0011, enter, &below), [1, 0]);
        assert_eq!(visit_order(0b0101, enter, &below), [0, 2]);
        assert_eq!(visit_order(0b1100, enter, &below), [3, 2]);
        // Three and four: sorted.
        assert_eq!(visit_order(0b0111, enter, &below), [1, 0, 2]);
        assert_eq!(visit_order(0b1111, enter, &below), [1, 3, 0, 2]);
        // Ties: the later lane first, with two children as with more.
        let tied = [2.0, 2.0, 2.0, 2.0];
        assert_eq!(visit_order(0b0011, tied, &[]), [1, 0]);
        assert_eq!(visit_order(0b1010, tied, &[]), [3, 1]);
        assert_eq!(visit_order(0b1011, tied, &[]), [3, 1, 0]);
    }
}
