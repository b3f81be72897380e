//! The surface area heuristic (SAH): where to split a node of the binary tree.
//!
//! A split of a node of area `A` into sides of areas `A_L`, `A_R` holding `N_L`,
//! `N_R` primitives is priced `C_trav + C_isect·(A_L·⌈N_L/4⌉ + A_R·⌈N_R/4⌉)/A`
//! (MacDonald and Booth 1990; pbrt-v4 §7.3.2), leaves counting one four-wide test
//! per four primitives. Large nodes bin their centroids and score the planes
//! between bins (Wald 2007); small ones sweep every split between neighbours.

use super::extents::{Aabb, BuildPrimitive, Extents};
use super::wide::LEAF_WIDTH;
use glam::Vec3A;

/// The most primitives a leaf may hold: one four-wide packet.
pub(super) const MAX_LEAF_PRIMITIVES: usize = LEAF_WIDTH;

/// `C_trav`: the SAH cost of visiting an interior node, relative to [`INTERSECTION_COST`].
pub(super) const TRAVERSAL_COST: f32 = 1.0;
/// `C_isect`: the SAH cost of one leaf's four-wide primitive test.
pub(super) const INTERSECTION_COST: f32 = 1.0;
/// Centroid bins per axis in the binned SAH (Wald 2007 uses 16 or 32, pbrt-v4 12).
const BIN_COUNT: usize = 12;
/// Nodes of at most this many primitives are split by an exact SAH sweep rather
/// than by binning.
pub(super) const SWEEP_MAX_PRIMITIVES: usize = 2 * MAX_LEAF_PRIMITIVES;

/// Splits a small node by the exact SAH: along each axis, sorts the centroids and
/// scores the plane between every two neighbours (the full sweep that binning
/// approximates; Wald 2007 §2, pbrt-v4 §7.3.2). For a handful of primitives it
/// is cheaper than filling 3 × 12 bins, and exact. `None` if the node has no
/// positive finite area.
pub(super) fn sweep_split(
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
pub(super) struct SplitPlane {
    axis: usize,
    first_right: usize,
    cost: f32,
    pub(super) left: Extents,
    pub(super) right: Extents,
}

impl SplitPlane {
    /// Whether a primitive binned by [`fill_bins`] for this node goes left.
    #[inline]
    pub(super) fn goes_left(&self, prim: &BuildPrimitive) -> bool {
        (prim.bins[self.axis] as usize) < self.first_right
    }
}

/// The cheapest plane between bins over all three axes, or `None` if the node has
/// no positive finite area or no plane puts primitives on both sides. Ties go to
/// the lower axis, then the lower plane.
pub(super) fn best_binned_split(
    prims: &mut [BuildPrimitive],
    extents: &Extents,
    binning_chunk: usize,
) -> Option<SplitPlane> {
    let area = extents.bounds.surface_area();
    if !(area > 0.0 && area.is_finite()) {
        return None;
    }
    let binning = Binning::new(&extents.centroids);
    let bins = fill_bins(prims, &binning, binning_chunk);
    (0..3)
        .filter_map(|axis| cheapest_plane(&bins[axis], area, axis))
        .reduce(|best, plane| if plane.cost < best.cost { plane } else { best })
}

/// Sorts the primitives into the bins of all three axes in one pass, noting
/// each one's bins in it; over `chunk` primitives, chunk by chunk on every
/// thread. The bins are the same either way: a bin's bounds are minima and
/// maxima, and its count a sum.
fn fill_bins(
    prims: &mut [BuildPrimitive],
    binning: &Binning,
    chunk: usize,
) -> [[Extents; BIN_COUNT]; 3] {
    if prims.len() <= chunk {
        return fill_bins_serial(prims, binning);
    }
    use rayon::prelude::*;
    prims
        .par_chunks_mut(chunk)
        .map(|chunk| fill_bins_serial(chunk, binning))
        .reduce(
            || [[Extents::EMPTY; BIN_COUNT]; 3],
            |a, b| {
                std::array::from_fn(|axis| {
                    std::array::from_fn(|bin| a[axis][bin].merge(b[axis][bin]))
                })
            },
        )
}

fn fill_bins_serial(prims: &mut [BuildPrimitive], binning: &Binning) -> [[Extents; BIN_COUNT]; 3] {
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
