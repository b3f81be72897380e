//! Construction: the binary tree over the primitives' bounds, built top-down in
//! parallel (rayon) and flattened into 32-byte nodes in depth-first order
//! (pbrt-v4 §7.3.4), then collapsed into the 4-wide tree of module `wide`.
//! Where each node is split is decided by the surface area heuristic (module
//! `sah`), or by object medians where the depth limit or the geometry leaves no
//! choice.

use super::binary_node::BvhNode;
use super::bounds::Bounds3;
use super::extents::{Aabb, BuildPrimitive, Extents};
use super::sah::{best_binned_split, sweep_split, MAX_LEAF_PRIMITIVES, SWEEP_MAX_PRIMITIVES};
use super::wide::WideBvh;
use super::{index_u32, Bvh};

/// The deepest a leaf of the binary tree may sit below the root, in edges; it
/// bounds the wide tree's depth, and so the traversal stack.
pub(super) const MAX_DEPTH: usize = 64;
/// Subtrees over more primitives than this are built on two rayon tasks.
const PARALLEL_THRESHOLD: usize = 4096;
/// Nodes over this many primitives (those near the root, whose passes would
/// otherwise run on one thread while the others wait) are binned in chunks
/// of it on every thread.
const BINNING_CHUNK: usize = 1 << 15;

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

    /// [`Self::build`] taking the bounds, which are freed before the tree is
    /// built: on a large mesh they are a sixth of the build's memory.
    pub fn build_owned(bounds: Vec<Bounds3>) -> Bvh {
        let prims = buildable_primitives(&bounds);
        drop(bounds);
        Self::build_from(prims, BuildOptions::DEFAULT)
    }

    pub(super) fn build_with(bounds: &[Bounds3], options: BuildOptions) -> Bvh {
        Self::build_from(buildable_primitives(bounds), options)
    }

    fn build_from(mut prims: Vec<BuildPrimitive>, options: BuildOptions) -> Bvh {
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
}

/// Build parameters; tests vary them to reach the depth limit and serial builds.
#[derive(Clone, Copy, Debug)]
pub(super) struct BuildOptions {
    pub(super) max_depth: usize,
    pub(super) parallel_threshold: usize,
    /// Nodes over this many primitives are binned in chunks of it, on every
    /// thread (the same bins as in one pass).
    pub(super) binning_chunk: usize,
}

impl BuildOptions {
    pub(super) const DEFAULT: BuildOptions = BuildOptions {
        max_depth: MAX_DEPTH,
        parallel_threshold: PARALLEL_THRESHOLD,
        binning_chunk: BINNING_CHUNK,
    };
}

/// The primitives with finite, non-empty bounds, in input order (in a list
/// sized for all of them: grown by doubling, it would briefly hold half again).
pub(super) fn buildable_primitives(bounds: &[Bounds3]) -> Vec<BuildPrimitive> {
    let mut prims = Vec::with_capacity(bounds.len());
    prims.extend(
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
            }),
    );
    prims
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
    pub(super) fn len(&self) -> usize {
        match self {
            Subtree::Serial(nodes) => nodes.len(),
            Subtree::Split { children, .. } => 1 + children.0.len() + children.1.len(),
        }
    }

    /// Appends the subtree's nodes to `nodes` in depth-first order, links made
    /// absolute: the same array whatever the threads that built the subtree.
    pub(super) fn flatten_into(self, nodes: &mut Vec<BvhNode>) {
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
pub(super) fn build_binary(prims: &mut [BuildPrimitive], options: &BuildOptions) -> Vec<BvhNode> {
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
    let chunk = options.binning_chunk;
    let Some((mid, left_extents, right_extents)) = split(prims, extents, depth_budget, chunk)
    else {
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
    let Some((mid, left_extents, right_extents)) = split(prims, extents, depth_budget, usize::MAX)
    else {
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
/// extents, else `None` for a leaf. Nodes over `binning_chunk` primitives
/// are binned in chunks of it on every thread. A node of at most [`MAX_LEAF_PRIMITIVES`] is a
/// leaf: its one packet test costs `C_isect`, and a split at least `C_trav` more.
fn split(
    prims: &mut [BuildPrimitive],
    extents: &Extents,
    depth_budget: usize,
    binning_chunk: usize,
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
        best_binned_split(prims, extents, binning_chunk).map(|plane| {
            let mid = partition(prims, |p| plane.goes_left(p));
            debug_assert_eq!(mid, plane.left.count as usize);
            (mid, plane.left, plane.right)
        })
    };
    Some(cheapest.unwrap_or_else(|| median_split(prims, &extents.centroids)))
}

/// How many halvings `n ↦ ⌈n/2⌉` bring `n` primitives down to a leaf's worth:
/// the depth a subtree of median splits over them needs.
pub(super) fn halvings_to_leaf(n: usize) -> usize {
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
