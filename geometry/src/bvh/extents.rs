//! The build's view of primitives and of sets of them, shared by the build
//! (module `build`) and the split decisions (module `sah`): boxes in glam's SIMD
//! `Vec3A`, primitives with their centroid bins, and [`Extents`].

use super::bounds::Bounds3;
use glam::Vec3A;

/// A box during the build, in glam's SIMD `Vec3A`: a union is two instructions.
#[derive(Clone, Copy, Debug)]
pub(super) struct Aabb {
    pub(super) min: Vec3A,
    pub(super) max: Vec3A,
}

impl Aabb {
    pub(super) const EMPTY: Aabb = Aabb {
        min: Vec3A::INFINITY,
        max: Vec3A::NEG_INFINITY,
    };

    pub(super) fn union(self, other: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    pub(super) fn include(self, p: Vec3A) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    pub(super) fn bounds3(&self) -> Bounds3 {
        Bounds3 {
            min: self.min.into(),
            max: self.max.into(),
        }
    }

    pub(super) fn surface_area(&self) -> f32 {
        self.bounds3().surface_area()
    }
}

/// A primitive during the build: its bounds, its input index, and its centroid's
/// bins on the three axes in the current node's binning (set by `sah::fill_bins`,
/// read by the partition that follows; they fit in what would be padding).
#[derive(Clone, Copy, Debug)]
pub(super) struct BuildPrimitive {
    pub(super) bounds: Aabb,
    pub(super) index: u32,
    pub(super) bins: [u8; 3],
}

impl BuildPrimitive {
    /// `min/2 + max/2`, as [`Bounds3::centroid`].
    #[inline]
    pub(super) fn centroid(&self) -> Vec3A {
        0.5 * self.bounds.min + 0.5 * self.bounds.max
    }
}

/// A set of primitives as the build sees it: joint bounds, bounds of the
/// centroids, and count. Nodes and SAH bins both have one.
#[derive(Clone, Copy, Debug)]
pub(super) struct Extents {
    pub(super) bounds: Aabb,
    pub(super) centroids: Aabb,
    pub(super) count: u32,
}

impl Extents {
    pub(super) const EMPTY: Extents = Extents {
        bounds: Aabb::EMPTY,
        centroids: Aabb::EMPTY,
        count: 0,
    };

    pub(super) fn of(prims: &[BuildPrimitive]) -> Extents {
        let mut extents = Extents::EMPTY;
        for prim in prims {
            extents.add(prim, prim.centroid());
        }
        extents
    }

    #[inline]
    pub(super) fn add(&mut self, prim: &BuildPrimitive, centroid: Vec3A) {
        self.bounds = self.bounds.union(prim.bounds);
        self.centroids = self.centroids.include(centroid);
        self.count += 1;
    }

    pub(super) fn merge(self, other: Extents) -> Extents {
        Extents {
            bounds: self.bounds.union(other.bounds),
            centroids: self.centroids.union(other.centroids),
            count: self.count + other.count,
        }
    }
}
