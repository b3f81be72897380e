//! Closest-hit queries: the nearest hit with its surface record, the nearest
//! primitive alone, and batches of rays traced as an interleaved stream. Ties at
//! exactly equal distances go to the lowest (object, triangle), with or without
//! the BVH.

use super::{LinearShapes, Object, ObjectRef, Primitive, ShapeList};
use crate::bvh::RayStream;
use crate::counters::count;
use crate::lanes::I32Lanes;
use crate::lanes::{self, F32Lanes, LANES};
use crate::prefetch::prefetch;
use crate::triangle::WatertightRay;
use crate::{Hit, Ray};
use crate::{RayLanes, Shape};
use glam::{Vec3, Vec4};
use std::ops::ControlFlow;

/// A candidate for the closest hit: a primitive, or a position in the BVH's leaf
/// order, looked up only when needed.
#[derive(Clone, Copy, Debug)]
enum Found {
    Primitive(Primitive),
    Slot(u32),
}

/// The closest hit as [`ShapeList::closest_primitive`] reports it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrimitiveHit {
    /// Distance along the ray, in multiples of its direction.
    pub t: f32,
    /// The object hit, as [`crate::Hit::shape`].
    pub object: u32,
    /// The triangle of a mesh hit (0 for a shape), as [`crate::Hit::primitive`].
    pub primitive: u32,
}

/// The closest hits of [`LANES`] rays, in lanes ([`ShapeList::closest_lanes`]).
#[derive(Clone, Copy, Debug)]
pub struct ClosestLanes {
    /// The lanes whose ray hits something (bit k for lane k).
    pub hits: u32,
    /// Each hit lane's distance, as [`PrimitiveHit::t`].
    pub t: F32Lanes,
    /// Each hit lane's object, as [`PrimitiveHit::object`] (shapes only: the
    /// primitive is 0).
    pub object: [u32; LANES],
}

impl ClosestLanes {
    /// The answer of lane `lane`.
    #[inline]
    pub fn hit(&self, lane: usize) -> Option<PrimitiveHit> {
        (self.hits >> lane & 1 == 1).then(|| PrimitiveHit {
            t: self.t.as_array()[lane],
            object: self.object[lane],
            primitive: 0,
        })
    }

    /// The one object every lane of `lanes` hits, if they all hit the same.
    #[inline]
    pub fn common_object(&self, lanes: u32) -> Option<u32> {
        if lanes == 0 {
            return None;
        }
        let first = self.object[lanes.trailing_zeros() as usize];
        let same = (0..LANES).all(|k| lanes >> k & 1 == 0 || self.object[k] == first);
        (same && lanes & !self.hits == 0).then_some(first)
    }
}

impl ShapeList {
    /// The nearest hit with `0 < t < t_max`, if any, with its surface record.
    /// Hits at exactly the same distance (a ray through an edge where two surfaces
    /// meet) go to the lowest object index, then the lowest triangle: the same
    /// answer with or without the BVH, whatever its layout.
    pub fn closest_hit(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        self.surface_record(ray, self.closest_primitive(ray, t_max)?)
    }

    /// The surface record of the hit `found` along `ray`, as
    /// [`ShapeList::closest_hit`] reports it.
    pub fn surface_record(&self, ray: &Ray, found: PrimitiveHit) -> Option<Hit> {
        let hit = match self.objects[found.object as usize] {
            Object::Shape(s) => Some(self.shapes[s as usize].surface_at(ray, found.t)),
            // Re-run the (same, deterministic) test for the barycentrics. Without an
            // upper limit: the test compares T < t_max·det before dividing, and
            // t = T/det rounded can make t_max·det fall just below T, turning a
            // found hit into a miss.
            Object::Mesh(m) => {
                self.meshes[m as usize].surface_at(found.primitive, ray, f32::INFINITY)
            }
        }?;
        Some(Hit {
            shape: found.object,
            primitive: found.primitive,
            ..hit
        })
    }

    /// [`ShapeList::surface_record`] without the derivatives of the point and
    /// normal where they cost extra (a sphere's: left zero, see
    /// [`Sphere::surface_point`](crate::Sphere::surface_point)), for shading
    /// that reads no texture footprint. Every other field is the same.
    #[inline(always)]
    pub fn surface_point(&self, ray: &Ray, found: PrimitiveHit) -> Option<Hit> {
        // Inlined, with the two common shapes spelled out: the record then stays
        // in registers instead of being stored and reloaded (a stall on every
        // hit when the stores and the loads differ in width).
        let hit = match self.objects[found.object as usize] {
            Object::Shape(s) => match &self.shapes[s as usize] {
                Shape::Sphere(sphere) => sphere.surface_point(ray, found.t),
                Shape::Parallelogram(p) => p.surface_at(ray, found.t),
                _ => return self.surface_record(ray, found),
            },
            Object::Mesh(_) => return self.surface_record(ray, found),
        };
        Some(Hit {
            shape: found.object,
            primitive: found.primitive,
            ..hit
        })
    }

    /// The nearest hit with `0 < t < t_max` as [`ShapeList::closest_hit`] finds
    /// it, without its surface record: which primitive, and where along the ray.
    pub fn closest_primitive(&self, ray: &Ray, t_max: f32) -> Option<PrimitiveHit> {
        let mut search = ClosestSearch::new(ray, t_max);
        match &self.bvh {
            Some(bvh) => {
                search.test_outside_bvh(self);
                let _ = bvh.traverse_leaves(ray, search.limit(), |first, _, _| {
                    ControlFlow::Continue(search.visit_leaf(self, first))
                });
            }
            None => match &self.linear {
                Some(linear) => search.test_linear(self, linear),
                None => self.all_primitives().for_each(|p| search.test(self, p)),
            },
        }
        search.finish(self)
    }

    /// [`ShapeList::closest_primitive`] without an upper limit for each of the
    /// `LANES` rays of `rays`, one shape against all the rays at a time: the same
    /// answers. The first `used` lanes hold real rays (the others are counted
    /// by no `--stats` test, and their answers are to be ignored). `None` unless
    /// the list is the linear loop with every object in its packets (spheres and
    /// parallelograms: the course's scenes), where this pays; ask the rays one
    /// by one then.
    pub fn closest_primitives_lanes(
        &self,
        rays: &RayLanes,
        used: usize,
    ) -> Option<[Option<PrimitiveHit>; LANES]> {
        let closest = self.closest_lanes(rays, used)?;
        Some(std::array::from_fn(|lane| closest.hit(lane)))
    }

    /// Whether [`ShapeList::closest_lanes`] answers (the linear loop holds every
    /// object in its packets, but for planes and boxes).
    pub fn has_closest_lanes(&self) -> bool {
        self.lanes_layout().is_some()
    }

    pub(super) fn lanes_layout(&self) -> Option<&LinearShapes> {
        self.linear.as_ref().filter(|linear| {
            self.bvh.is_none()
                && (linear.others.iter()).all(|&o| {
                    matches!(
                        self.object(o),
                        ObjectRef::Shape(Shape::Plane(_) | Shape::Box(_))
                    )
                })
        })
    }

    /// [`ShapeList::closest_primitives_lanes`] with the answers left in lanes.
    pub fn closest_lanes(&self, rays: &RayLanes, used: usize) -> Option<ClosestLanes> {
        self.closest_lanes_among(rays, used, u64::MAX)
    }

    /// [`ShapeList::closest_lanes`] where the rays can only hit the objects of
    /// `candidates` (object k as bit k; objects from 64 on always tested), as
    /// [`ShapeList::objects_in_frustum`] finds them: the same answers.
    pub fn closest_lanes_among(
        &self,
        rays: &RayLanes,
        used: usize,
        candidates: u64,
    ) -> Option<ClosestLanes> {
        let tested = used.min(LANES) as u64;
        let linear = self.lanes_layout()?;
        // The nearest so far per lane, and its object (i32::MAX: none yet).
        let mut best_t = F32Lanes::splat(f32::INFINITY);
        let mut best_object = I32Lanes::splat(i32::MAX);
        let spheres = linear.spheres.iter().map(|(_, objects)| objects);
        let parallelograms = linear.parallelograms.iter().map(|(_, objects)| objects);
        let used = spheres
            .chain(parallelograms)
            .flatten()
            .filter(|&&o| o != u32::MAX && (o >= 64 || candidates >> o & 1 == 1));
        // Planes, unbounded, are in every pixel's view, and boxes are few:
        // always tested.
        for &object in used.chain(&linear.others) {
            let (hits, t) = match self.object(object) {
                ObjectRef::Shape(Shape::Sphere(s)) => {
                    count(|c| c.sphere_tests += tested);
                    s.hit_distance_lanes(rays, f32::INFINITY)
                }
                ObjectRef::Shape(Shape::Parallelogram(p)) => {
                    count(|c| c.parallelogram_tests += tested);
                    p.hit_distance_lanes(rays, f32::INFINITY)
                }
                ObjectRef::Shape(Shape::Plane(p)) => {
                    count(|c| c.plane_tests += tested);
                    p.hit_distance_lanes(rays, f32::INFINITY)
                }
                ObjectRef::Shape(Shape::Box(b)) => {
                    count(|c| c.box_tests += tested);
                    b.hit_distance_lanes(rays, f32::INFINITY)
                }
                _ => {
                    unreachable!("the lanes layout holds spheres, parallelograms, planes and boxes")
                }
            };
            if hits == 0 {
                continue;
            }
            // The rule of `ClosestSearch::consider`: nearer, or as near and lower.
            let o = I32Lanes::splat(object as i32);
            let lower: F32Lanes = bytemuck::cast(o.simd_lt(best_object));
            let nearer = lanes::lt(t, best_t) | (t.simd_eq(best_t) & lower);
            let take = lanes::from_bits(hits) & nearer;
            best_t = take.select(t, best_t);
            best_object = bytemuck::cast::<F32Lanes, I32Lanes>(take).select(o, best_object);
        }
        let none: F32Lanes = bytemuck::cast(best_object.simd_eq(I32Lanes::splat(i32::MAX)));
        Some(ClosestLanes {
            hits: !lanes::bits(none) & lanes::all_bits(),
            t: best_t,
            object: bytemuck::cast(best_object),
        })
    }

    /// [`ShapeList::closest_primitive`] for each of `rays`, with its own
    /// `t_max`, into `hits`: the same answers, found
    /// [`STREAM_LANES`](crate::bvh::STREAM_LANES) rays at a time with their
    /// traversals interleaved ([`Bvh::traverse_stream`](crate::bvh::Bvh::traverse_stream)), which overlaps their
    /// waits on memory. It pays for batches of incoherent rays (hundreds or more)
    /// on scenes that outgrow the caches.
    ///
    /// Panics unless `t_max` and `hits` are as long as `rays`.
    pub fn closest_primitives(
        &self,
        rays: &[Ray],
        t_max: &[f32],
        hits: &mut [Option<PrimitiveHit>],
    ) {
        assert!(
            t_max.len() == rays.len() && hits.len() == rays.len(),
            "one t_max and one answer per ray"
        );
        match &self.bvh {
            Some(bvh) => bvh.traverse_stream(
                rays.len(),
                &mut ClosestStream {
                    list: self,
                    rays,
                    t_max,
                    hits,
                },
            ),
            None => {
                for ((ray, &t_max), hit) in rays.iter().zip(t_max).zip(hits) {
                    *hit = self.closest_primitive(ray, t_max);
                }
            }
        }
    }

    /// The primitive a candidate names.
    #[inline]
    fn resolve(&self, found: Found) -> Primitive {
        match found {
            Found::Primitive(p) => p,
            Found::Slot(k) => self.primitives[k as usize],
        }
    }
}

/// One closest-hit query in progress: the ray, and the best hit so far.
///
/// A candidate at distance t (found below the best's t, or equal to it) becomes
/// the best if nearer, or as near with a lower (object, triangle). Only ties read
/// which primitive a BVH slot holds.
struct ClosestSearch {
    ray: Ray,
    /// The ray prepared for triangle tests, made on first use: a third of
    /// incoherent rays meet no leaf, and it costs three divisions.
    watertight: Option<WatertightRay>,
    /// How far a hit may still be: the query's `t_max`, or just past the best
    /// hit, so that the BVH still visits nodes entered exactly at its distance
    /// (which may hold a lower-index primitive at the same distance).
    limit: f32,
    best: Option<(f32, Found)>,
}

/// An empty slot of a stream's lane.
impl Default for ClosestSearch {
    fn default() -> Self {
        Self::new(&Ray::new(Vec3::ZERO, Vec3::Z), 0.0)
    }
}

impl ClosestSearch {
    fn new(ray: &Ray, t_max: f32) -> Self {
        Self {
            ray: *ray,
            watertight: None,
            limit: t_max,
            best: None,
        }
    }

    #[inline]
    fn limit(&self) -> f32 {
        self.limit
    }

    #[inline]
    fn consider(&mut self, list: &ShapeList, found: Found, t: f32) {
        let better = match self.best {
            None => true,
            Some((bt, bf)) => {
                t < bt || (t == bt && list.resolve(found).key() < list.resolve(bf).key())
            }
        };
        if better {
            self.best = Some((t, found));
            self.limit = t.next_up();
        }
    }

    /// Tests one primitive on its own.
    fn test(&mut self, list: &ShapeList, p: Primitive) {
        let ray = self.ray;
        let watertight = *self
            .watertight
            .get_or_insert_with(|| WatertightRay::new(&ray));
        if let Some(t) = list.primitive_distance(p, &self.ray, &watertight, self.limit()) {
            self.consider(list, Found::Primitive(p), t);
        }
    }

    /// Tests every object through the linear loop's packets.
    fn test_linear(&mut self, list: &ShapeList, linear: &LinearShapes) {
        for (packet, objects) in &linear.spheres {
            let (hits, t) = packet.hit4(&self.ray, self.limit);
            self.consider_lanes(list, hits, t, objects);
        }
        for (packet, objects) in &linear.parallelograms {
            let (hits, t) = packet.hit4(&self.ray, self.limit);
            self.consider_lanes(list, hits, t, objects);
        }
        for &object in &linear.others {
            for p in list.primitives_of(object) {
                self.test(list, p);
            }
        }
    }

    /// Considers the hit lanes of a packet of shapes, lane k being object `objects[k]`.
    #[inline]
    fn consider_lanes(&mut self, list: &ShapeList, hits: u32, t: Vec4, objects: &[u32; 4]) {
        for lane in crate::lanes::each_set(hits) {
            let p = Primitive {
                object: objects[lane],
                triangle: 0,
            };
            self.consider(list, Found::Primitive(p), t[lane]);
        }
    }

    /// Tests the primitives the BVH leaves out: unbounded planes, and the
    /// spheres and parallelograms of the linear layout's packets beside it.
    fn test_outside_bvh(&mut self, list: &ShapeList) {
        for p in list.unbounded_primitives() {
            self.test(list, p);
        }
        if let Some(linear) = &list.linear {
            self.test_linear(list, linear);
        }
    }

    /// Tests the leaf at `first`; returns the new limit.
    #[inline]
    fn visit_leaf(&mut self, list: &ShapeList, first: u32) -> f32 {
        let (ray, limit) = (self.ray, self.limit());
        let watertight = self
            .watertight
            .get_or_insert_with(|| WatertightRay::new(&ray));
        let (hits, t) = list.leaf_hits(first, &ray, watertight, limit);
        if hits != 0 {
            // What the slot holds is read at the end of the query.
            if let Some(slot) = list.primitives.get(first as usize) {
                prefetch(slot);
            }
        }
        for lane in crate::lanes::each_set(hits) {
            self.consider(list, Found::Slot(first + lane as u32), t[lane]);
        }
        self.limit()
    }

    fn finish(&self, list: &ShapeList) -> Option<PrimitiveHit> {
        let (t, found) = self.best?;
        let p = list.resolve(found);
        Some(PrimitiveHit {
            t,
            object: p.object,
            primitive: p.triangle,
        })
    }
}

/// [`ShapeList::closest_primitives`] as a [`RayStream`].
struct ClosestStream<'a> {
    list: &'a ShapeList,
    rays: &'a [Ray],
    t_max: &'a [f32],
    hits: &'a mut [Option<PrimitiveHit>],
}

impl RayStream for ClosestStream<'_> {
    type State = ClosestSearch;

    fn begin(&self, index: usize, search: &mut ClosestSearch) -> Option<(Ray, f32)> {
        let ray = &self.rays[index];
        *search = ClosestSearch::new(ray, self.t_max[index]);
        search.test_outside_bvh(self.list);
        Some((*ray, search.limit()))
    }

    #[inline(always)]
    fn leaf_address(&self, first: u32) -> *const u8 {
        self.list.leaf_address(first)
    }

    #[inline(always)]
    fn visit_leaf(
        &self,
        search: &mut ClosestSearch,
        first: u32,
        _: u32,
        _: f32,
    ) -> ControlFlow<(), f32> {
        ControlFlow::Continue(search.visit_leaf(self.list, first))
    }

    fn end(&mut self, index: usize, search: &ClosestSearch) {
        self.hits[index] = search.finish(self.list);
    }
}
