//! Statistics of a built tree: node and leaf counts, depth, and its SAH cost.

use super::sah::{INTERSECTION_COST, TRAVERSAL_COST};
use super::wide;
use super::{Bounds3, Bvh};

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

impl Bvh {
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
}
