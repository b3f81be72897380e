//! Any-hit (shadow) queries: whether anything lies on a ray before `t_max`, for
//! one ray or a batch traced as an interleaved stream.

use super::{LinearShapes, Object, ShapeList};
use crate::bvh::{Bvh, RayStream};
use crate::triangle::WatertightRay;
use crate::{Occluders, Ray};
use glam::Vec3;
use std::ops::ControlFlow;

impl ShapeList {
    /// Whether anything lies on the ray with `0 < t < t_max` (shadow query).
    pub fn any_hit(&self, ray: &Ray, t_max: f32) -> bool {
        match &self.bvh {
            Some(bvh) => {
                self.linear
                    .as_ref()
                    .is_some_and(|linear| self.packets_hit(linear, ray, t_max))
                    || self.bvh_hit(bvh, ray, t_max)
            }
            None if self.linear.is_some() => self.linear_any_hit(ray, t_max),
            // Without meshes the objects are the shapes, in order: the course's loop.
            None if self.meshes.is_empty() => self
                .shapes
                .iter()
                .any(|s| s.hit_distance(ray, t_max).is_some()),
            None => {
                let watertight = WatertightRay::new(ray);
                self.objects.iter().any(|object| match *object {
                    Object::Shape(s) => self.shapes[s as usize].hit_distance(ray, t_max).is_some(),
                    Object::Mesh(m) => {
                        let mesh = &self.meshes[m as usize];
                        (0..mesh.triangle_count() as u32)
                            .any(|t| mesh.hit_distance(t, &watertight, t_max).is_some())
                    }
                })
            }
        }
    }

    /// [`ShapeList::any_hit`] for each of `rays`, with its own `t_max`, into
    /// `occluded`: the same answers, found as [`ShapeList::closest_primitives`]
    /// finds its own (shadow rays of many shading points, say).
    ///
    /// Panics unless `t_max` and `occluded` are as long as `rays`.
    pub fn any_hits(&self, rays: &[Ray], t_max: &[f32], occluded: &mut [bool]) {
        assert!(
            t_max.len() == rays.len() && occluded.len() == rays.len(),
            "one t_max and one answer per ray"
        );
        match &self.bvh {
            Some(bvh) => bvh.traverse_stream(
                rays.len(),
                &mut AnyHitStream {
                    list: self,
                    rays,
                    t_max,
                    occluded,
                },
            ),
            None => {
                for ((ray, &t_max), occluded) in rays.iter().zip(t_max).zip(occluded) {
                    *occluded = self.any_hit(ray, t_max);
                }
            }
        }
    }

    /// [`ShapeList::any_hit`] through the linear loop's packets.
    fn linear_any_hit(&self, ray: &Ray, t_max: f32) -> bool {
        let Some(linear) = &self.linear else {
            return false;
        };
        self.packets_hit(linear, ray, t_max) || self.others_hit(linear, &Occluders::ALL, ray, t_max)
    }

    /// Whether a shape of the linear layout's packets lies on the ray.
    fn packets_hit(&self, linear: &LinearShapes, ray: &Ray, t_max: f32) -> bool {
        linear
            .spheres
            .iter()
            .any(|(packet, _)| packet.hit4(ray, t_max).0 != 0)
            || linear
                .parallelograms
                .iter()
                .any(|(packet, _)| packet.hit4(ray, t_max).0 != 0)
    }

    /// Whether a primitive the BVH holds, or an unbounded plane, lies on the ray.
    pub(super) fn bvh_hit(&self, bvh: &Bvh, ray: &Ray, t_max: f32) -> bool {
        let watertight = WatertightRay::new(ray);
        self.unbounded_hit(ray, &watertight, t_max)
            || bvh
                .traverse_leaves(ray, t_max, |first, _, t_max| {
                    if self.leaf_occludes(first, ray, &watertight, t_max) {
                        ControlFlow::Break(())
                    } else {
                        ControlFlow::Continue(t_max)
                    }
                })
                .is_break()
    }

    /// Whether an object outside the linear layout's packets lies on the ray:
    /// one tested one by one, or one in the BVH beside the packets.
    #[inline]
    pub(super) fn rest_hit(
        &self,
        linear: &LinearShapes,
        occluders: &Occluders,
        ray: &Ray,
        t_max: f32,
    ) -> bool {
        self.others_hit(linear, occluders, ray, t_max)
            || self
                .bvh
                .as_ref()
                .is_some_and(|bvh| self.bvh_hit(bvh, ray, t_max))
    }

    /// Whether an object of the linear loop outside its packets, and kept by
    /// `occluders`, lies on the ray.
    #[inline]
    pub(super) fn others_hit(
        &self,
        linear: &LinearShapes,
        occluders: &Occluders,
        ray: &Ray,
        t_max: f32,
    ) -> bool {
        let mut kept = (linear.others.iter().enumerate())
            .filter(|&(i, _)| occluders.keeps_other(i))
            .peekable();
        if kept.peek().is_none() {
            return false;
        }
        let watertight = WatertightRay::new(ray);
        kept.any(|(_, &object)| {
            self.primitives_of(object).any(|p| {
                self.primitive_distance(p, ray, &watertight, t_max)
                    .is_some()
            })
        })
    }

    /// Whether an unbounded plane (which the BVH leaves out) lies on the ray in
    /// (0, t_max).
    pub(super) fn unbounded_hit(&self, ray: &Ray, watertight: &WatertightRay, t_max: f32) -> bool {
        self.unbounded_primitives()
            .any(|p| self.primitive_distance(p, ray, watertight, t_max).is_some())
    }

    /// Whether the leaf at `first` holds a primitive on the ray in (0, t_max).
    #[inline]
    pub(super) fn leaf_occludes(
        &self,
        first: u32,
        ray: &Ray,
        watertight: &WatertightRay,
        t_max: f32,
    ) -> bool {
        self.leaf_hits(first, ray, watertight, t_max).0 != 0
    }
}

/// One shadow ray in flight in [`ShapeList::any_hits`].
struct AnyHitSearch {
    ray: Ray,
    watertight: WatertightRay,
    occluded: bool,
}

/// An empty slot of a stream's lane.
impl Default for AnyHitSearch {
    fn default() -> Self {
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        Self {
            ray,
            watertight: WatertightRay::new(&ray),
            occluded: false,
        }
    }
}

/// [`ShapeList::any_hits`] as a [`RayStream`].
struct AnyHitStream<'a> {
    list: &'a ShapeList,
    rays: &'a [Ray],
    t_max: &'a [f32],
    occluded: &'a mut [bool],
}

impl RayStream for AnyHitStream<'_> {
    type State = AnyHitSearch;

    fn begin(&self, index: usize, search: &mut AnyHitSearch) -> Option<(Ray, f32)> {
        let (ray, t_max) = (self.rays[index], self.t_max[index]);
        search.ray = ray;
        search.watertight = WatertightRay::new(&ray);
        search.occluded = self.list.unbounded_hit(&ray, &search.watertight, t_max)
            || self
                .list
                .linear
                .as_ref()
                .is_some_and(|linear| self.list.packets_hit(linear, &ray, t_max));
        (!search.occluded).then_some((ray, t_max))
    }

    #[inline(always)]
    fn leaf_address(&self, first: u32) -> *const u8 {
        self.list.leaf_address(first)
    }

    #[inline(always)]
    fn visit_leaf(
        &self,
        search: &mut AnyHitSearch,
        first: u32,
        _: u32,
        t_max: f32,
    ) -> ControlFlow<(), f32> {
        if self
            .list
            .leaf_occludes(first, &search.ray, &search.watertight, t_max)
        {
            search.occluded = true;
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(t_max)
        }
    }

    fn end(&mut self, index: usize, search: &AnyHitSearch) {
        self.occluded[index] = search.occluded;
    }
}
