use crate::bvh::{Bounds3, Bvh, BvhStats, RayStream, LEAF_WIDTH};
use crate::prefetch::prefetch;
use crate::triangle::WatertightRay;
use crate::{Hit, Ray, Shape, TriangleMesh, TrianglePacket};
use glam::{Vec3, Vec4};
use std::ops::ControlFlow;

/// Below this many primitives [`ShapeList::build_acceleration`] builds no BVH.
pub const LINEAR_LIMIT: usize = 32;

/// What an object index names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Object {
    Shape(u32),
    Mesh(u32),
}

/// One object of a [`ShapeList`].
#[derive(Clone, Copy, Debug)]
pub enum ObjectRef<'a> {
    Shape(&'a Shape),
    Mesh(&'a TriangleMesh),
}

/// A primitive the BVH holds: an analytic shape, or one triangle of a mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Primitive {
    object: u32,
    triangle: u32,
}

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

impl Primitive {
    /// The order of the tie rule: object, then triangle.
    fn key(self) -> (u32, u32) {
        (self.object, self.triangle)
    }

    /// What fills the BVH's leaf order where a leaf is padded.
    const PADDING: Primitive = Primitive {
        object: u32::MAX,
        triangle: u32::MAX,
    };
}

/// Every object of a scene — analytic shapes and triangle meshes — and the two
/// queries the integrator asks of them: [`ShapeList::closest_hit`] and
/// [`ShapeList::any_hit`].
///
/// Objects are numbered in the order they are added (shapes and meshes share one
/// numbering); a hit reports its object in [`Hit::shape`] and, for meshes, the
/// triangle in [`Hit::primitive`]. After [`ShapeList::build_bvh`], bounded
/// primitives (each shape, each triangle) are found through a BVH and only
/// unbounded planes are tested one by one; before it, every object is tested in
/// turn (the course's linear loop), with the same answers. Batches of rays can be
/// handed over at once ([`ShapeList::closest_primitives`], [`ShapeList::any_hits`]),
/// to be traced several at a time.
#[derive(Clone, Debug, Default)]
pub struct ShapeList {
    shapes: Vec<Shape>,
    meshes: Vec<TriangleMesh>,
    objects: Vec<Object>,
    bvh: Option<Bvh>,
    /// The BVH's primitives in its padded leaf order (a leaf's adjacent, each
    /// leaf's run [`LEAF_WIDTH`] long, [`Primitive::PADDING`] in the gaps)…
    primitives: Vec<Primitive>,
    /// …one packet per leaf with its triangles' corners (NaN in lanes holding an
    /// analytic shape or padding): a leaf's triangles are one contiguous read and
    /// one four-wide test…
    packets: Vec<TrianglePacket>,
    /// …and per leaf, the lanes holding analytic shapes, tested one by one.
    shape_lanes: Vec<u8>,
    unbounded: Vec<u32>,
}

impl PartialEq for ShapeList {
    fn eq(&self, other: &Self) -> bool {
        self.shapes == other.shapes && self.meshes == other.meshes && self.objects == other.objects
    }
}

impl ShapeList {
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a shape and returns its object index. Invalidates the BVH.
    pub fn push(&mut self, shape: impl Into<Shape>) -> u32 {
        self.shapes.push(shape.into());
        self.add(Object::Shape(self.shapes.len() as u32 - 1))
    }

    /// Adds a triangle mesh and returns its object index. Invalidates the BVH.
    pub fn push_mesh(&mut self, mesh: TriangleMesh) -> u32 {
        self.meshes.push(mesh);
        self.add(Object::Mesh(self.meshes.len() as u32 - 1))
    }

    fn add(&mut self, object: Object) -> u32 {
        self.bvh = None;
        self.objects.push(object);
        self.objects.len() as u32 - 1
    }

    /// Object `i`: a shape or a mesh.
    pub fn object(&self, i: u32) -> ObjectRef<'_> {
        match self.objects[i as usize] {
            Object::Shape(s) => ObjectRef::Shape(&self.shapes[s as usize]),
            Object::Mesh(m) => ObjectRef::Mesh(&self.meshes[m as usize]),
        }
    }

    /// The analytic shapes, in the order they were added.
    pub fn shapes(&self) -> &[Shape] {
        &self.shapes
    }

    pub fn meshes(&self) -> &[TriangleMesh] {
        &self.meshes
    }

    /// Number of objects (shapes and meshes).
    pub fn len(&self) -> usize {
        self.objects.len()
    }

    pub fn is_empty(&self) -> bool {
        self.objects.is_empty()
    }

    /// Builds the BVH if the scene is large enough for it to pay: below
    /// 32 primitives (`LINEAR_LIMIT`) the linear loop is faster (and gives the same
    /// answers), so none is built.
    pub fn build_acceleration(&mut self) {
        let primitives: usize = self
            .objects
            .iter()
            .map(|o| match *o {
                Object::Shape(_) => 1,
                Object::Mesh(m) => self.meshes[m as usize].triangle_count(),
            })
            .sum();
        if primitives >= LINEAR_LIMIT {
            self.build_bvh();
        } else {
            self.bvh = None;
        }
    }

    /// Builds the BVH over every bounded primitive (binned SAH; see [`Bvh`]).
    pub fn build_bvh(&mut self) {
        let mut primitives = Vec::new();
        let mut bounds = Vec::new();
        self.unbounded.clear();
        for (object, kind) in self.objects.iter().enumerate() {
            let object = object as u32;
            match *kind {
                Object::Shape(s) => match self.shapes[s as usize].bounds() {
                    Some(b) => {
                        primitives.push(Primitive {
                            object,
                            triangle: 0,
                        });
                        bounds.push(b);
                    }
                    None => self.unbounded.push(object),
                },
                Object::Mesh(m) => {
                    let mesh = &self.meshes[m as usize];
                    for triangle in 0..mesh.triangle_count() as u32 {
                        let (lo, hi) = mesh.triangle_bounds(triangle);
                        primitives.push(Primitive { object, triangle });
                        bounds.push(Bounds3::new(lo, hi));
                    }
                }
            }
        }
        let mut bvh = Bvh::build(&bounds);
        let order = bvh.take_primitive_order();
        self.primitives = order
            .iter()
            .map(|&i| {
                primitives
                    .get(i as usize)
                    .copied()
                    .unwrap_or(Primitive::PADDING)
            })
            .collect();
        let leaves = self.primitives.chunks_exact(LEAF_WIDTH);
        self.packets = leaves.clone().map(|leaf| self.packet_of(leaf)).collect();
        self.shape_lanes = leaves
            .map(|leaf| {
                leaf.iter().enumerate().fold(0u8, |lanes, (lane, p)| {
                    match self.objects.get(p.object as usize) {
                        Some(Object::Shape(_)) => lanes | 1 << lane,
                        _ => lanes,
                    }
                })
            })
            .collect();
        self.bvh = Some(bvh);
    }

    /// The triangles of one leaf as a packet; other lanes NaN.
    fn packet_of(&self, leaf: &[Primitive]) -> TrianglePacket {
        let mut packet = TrianglePacket::EMPTY;
        for (lane, p) in leaf.iter().enumerate() {
            if let Some(Object::Mesh(m)) = self.objects.get(p.object as usize) {
                packet.set_lane(lane, &self.meshes[*m as usize].corners(p.triangle));
            }
        }
        packet
    }

    /// The hits of the leaf at `first` (a multiple of [`LEAF_WIDTH`]) in
    /// (0, t_max): bit `k` of the mask for the primitive at `first + k`, lane `k`
    /// its distance. Triangles are tested four at a time, shapes one by one.
    #[inline]
    fn leaf_hits(
        &self,
        first: u32,
        ray: &Ray,
        watertight: &WatertightRay,
        t_max: f32,
    ) -> (u32, Vec4) {
        let leaf = first as usize / LEAF_WIDTH;
        let (mut hits, mut t) = watertight.intersect4(&self.packets[leaf], t_max);
        let mut shapes = self.shape_lanes[leaf];
        while shapes != 0 {
            let lane = shapes.trailing_zeros() as usize;
            shapes &= shapes - 1;
            let p = self.primitives[first as usize + lane];
            if let Object::Shape(s) = self.objects[p.object as usize] {
                if let Some(d) = self.shapes[s as usize].hit_distance(ray, t_max) {
                    hits |= 1 << lane;
                    t[lane] = d;
                }
            }
        }
        (hits, t)
    }

    /// Statistics of the BVH, once built.
    pub fn bvh_stats(&self) -> Option<BvhStats> {
        self.bvh.as_ref().map(Bvh::stats)
    }

    /// The nearest hit with `0 < t < t_max`, if any, with its surface record.
    /// Hits at exactly the same distance (a ray through an edge where two surfaces
    /// meet) go to the lowest object index, then the lowest triangle: the same
    /// answer with or without the BVH, whatever its layout.
    pub fn closest_hit(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let found = self.closest_primitive(ray, t_max)?;
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

    /// The nearest hit with `0 < t < t_max` as [`ShapeList::closest_hit`] finds
    /// it, without its surface record: which primitive, and where along the ray.
    pub fn closest_primitive(&self, ray: &Ray, t_max: f32) -> Option<PrimitiveHit> {
        let mut search = ClosestSearch::new(ray, t_max);
        match &self.bvh {
            Some(bvh) => {
                search.test_unbounded(self);
                let _ = bvh.traverse_leaves(ray, search.limit(), |first, _, _| {
                    ControlFlow::Continue(search.visit_leaf(self, first))
                });
            }
            None => self.all_primitives().for_each(|p| search.test(self, p)),
        }
        search.finish(self)
    }

    /// [`ShapeList::closest_primitive`] for each of `rays`, with its own
    /// `t_max`, into `hits`: the same answers, found
    /// [`STREAM_LANES`](crate::bvh::STREAM_LANES) rays at a time with their
    /// traversals interleaved ([`Bvh::traverse_stream`]), which overlaps their
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

    /// Where the packet of the leaf at `first` is, for prefetching: only an
    /// address (see [`RayStream::leaf_address`]).
    #[inline(always)]
    fn leaf_address(&self, first: u32) -> *const u8 {
        let packets = self.packets.as_ptr();
        packets.wrapping_add(first as usize / LEAF_WIDTH).cast()
    }

    /// The primitive a candidate names.
    #[inline]
    fn resolve(&self, found: Found) -> Primitive {
        match found {
            Found::Primitive(p) => p,
            Found::Slot(k) => self.primitives[k as usize],
        }
    }

    /// Whether anything lies on the ray with `0 < t < t_max` (shadow query).
    pub fn any_hit(&self, ray: &Ray, t_max: f32) -> bool {
        match &self.bvh {
            Some(bvh) => {
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

    /// Whether an unbounded plane (which the BVH leaves out) lies on the ray in
    /// (0, t_max).
    fn unbounded_hit(&self, ray: &Ray, watertight: &WatertightRay, t_max: f32) -> bool {
        self.unbounded_primitives()
            .any(|p| self.primitive_distance(p, ray, watertight, t_max).is_some())
    }

    /// The primitives the BVH leaves out: unbounded planes.
    fn unbounded_primitives(&self) -> impl Iterator<Item = Primitive> + '_ {
        self.unbounded.iter().map(|&object| Primitive {
            object,
            triangle: 0,
        })
    }

    /// Whether the leaf at `first` holds a primitive on the ray in (0, t_max).
    #[inline]
    fn leaf_occludes(&self, first: u32, ray: &Ray, watertight: &WatertightRay, t_max: f32) -> bool {
        self.leaf_hits(first, ray, watertight, t_max).0 != 0
    }

    /// Every primitive, object by object (the linear loop's order).
    fn all_primitives(&self) -> impl Iterator<Item = Primitive> + '_ {
        self.objects
            .iter()
            .enumerate()
            .flat_map(move |(object, kind)| {
                let triangles = match *kind {
                    Object::Shape(_) => 1,
                    Object::Mesh(m) => self.meshes[m as usize].triangle_count() as u32,
                };
                (0..triangles).map(move |triangle| Primitive {
                    object: object as u32,
                    triangle,
                })
            })
    }

    #[inline]
    fn primitive_distance(
        &self,
        p: Primitive,
        ray: &Ray,
        watertight: &WatertightRay,
        t_max: f32,
    ) -> Option<f32> {
        match self.objects[p.object as usize] {
            Object::Shape(s) => self.shapes[s as usize].hit_distance(ray, t_max),
            Object::Mesh(m) => self.meshes[m as usize].hit_distance(p.triangle, watertight, t_max),
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

    /// Tests the primitives the BVH leaves out: unbounded planes.
    fn test_unbounded(&mut self, list: &ShapeList) {
        for p in list.unbounded_primitives() {
            self.test(list, p);
        }
    }

    /// Tests the leaf at `first`; returns the new limit.
    #[inline]
    fn visit_leaf(&mut self, list: &ShapeList, first: u32) -> f32 {
        let (ray, limit) = (self.ray, self.limit());
        let watertight = self
            .watertight
            .get_or_insert_with(|| WatertightRay::new(&ray));
        let (mut hits, t) = list.leaf_hits(first, &ray, watertight, limit);
        if hits != 0 {
            // What the slot holds is read at the end of the query.
            if let Some(slot) = list.primitives.get(first as usize) {
                prefetch(slot);
            }
        }
        while hits != 0 {
            let lane = hits.trailing_zeros();
            hits &= hits - 1;
            self.consider(list, Found::Slot(first + lane), t[lane as usize]);
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
        search.test_unbounded(self.list);
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
        search.occluded = self.list.unbounded_hit(&ray, &search.watertight, t_max);
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

impl FromIterator<Shape> for ShapeList {
    fn from_iter<I: IntoIterator<Item = Shape>>(iter: I) -> Self {
        let mut list = Self::new();
        for shape in iter {
            list.push(shape);
        }
        list
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Plane, Sphere};
    use glam::Vec3;

    fn scene() -> ShapeList {
        let mut list = ShapeList::new();
        list.push(Sphere::new(Vec3::new(0.0, 0.0, -10.0), 1.0).unwrap());
        list.push(Sphere::new(Vec3::new(0.0, 0.0, -5.0), 1.0).unwrap());
        list.push(Plane::new(Vec3::new(0.0, 0.0, -20.0), Vec3::Z, false).unwrap());
        list
    }

    #[test]
    fn closest_hit_picks_the_nearest_shape_whatever_the_order() {
        for with_bvh in [false, true] {
            let ray = Ray::new(Vec3::ZERO, -Vec3::Z);
            let mut list = scene();
            if with_bvh {
                list.build_bvh();
            }
            let hit = list.closest_hit(&ray, f32::INFINITY).unwrap();
            assert_eq!(hit.shape, 1);
            assert!((hit.t - 4.0).abs() < 1e-6);
            let mut reversed: ShapeList = scene().shapes().iter().rev().copied().collect();
            if with_bvh {
                reversed.build_bvh();
            }
            assert_eq!(reversed.closest_hit(&ray, f32::INFINITY).unwrap().shape, 1);
            // The plane, outside the BVH, is still found.
            let sideways = Ray::new(Vec3::new(5.0, 0.0, 0.0), -Vec3::Z);
            assert_eq!(list.closest_hit(&sideways, f32::INFINITY).unwrap().shape, 2);
        }
    }

    #[test]
    fn any_hit_respects_t_max() {
        for with_bvh in [false, true] {
            let mut list = scene();
            if with_bvh {
                list.build_bvh();
            }
            let ray = Ray::new(Vec3::ZERO, -Vec3::Z);
            assert!(list.any_hit(&ray, 4.5));
            assert!(!list.any_hit(&ray, 3.5));
            assert!(!list.any_hit(&Ray::new(Vec3::ZERO, Vec3::Z), f32::INFINITY));
        }
    }
}

#[cfg(test)]
mod bvh_agreement {
    use super::*;
    use crate::{AaBox, Parallelogram, Plane, Sphere, TriangleMesh};
    use glam::{Vec2, Vec3};

    /// xorshift64*: a tiny deterministic generator for test scenes.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f32 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            ((self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32) / (1u64 << 24) as f32
        }
        fn in_cube(&mut self, r: f32) -> Vec3 {
            Vec3::new(self.next(), self.next(), self.next()) * 2.0 * r - r
        }
    }

    /// A UV sphere of `n × 2n` quads (two triangles each).
    fn tessellated_sphere(centre: Vec3, radius: f32, n: u32) -> TriangleMesh {
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..=2 * n {
                let (theta, phi) = (
                    j as f32 / n as f32 * std::f32::consts::PI,
                    i as f32 / n as f32 * std::f32::consts::PI,
                );
                positions.push(
                    centre
                        + radius
                            * Vec3::new(
                                theta.sin() * phi.cos(),
                                theta.cos(),
                                theta.sin() * phi.sin(),
                            ),
                );
            }
        }
        let indices = TriangleMesh::grid_indices(2 * n, n);
        TriangleMesh::new(positions, indices, vec![], vec![]).unwrap()
    }

    fn random_scene(rng: &mut Rng) -> ShapeList {
        let mut list = ShapeList::new();
        for _ in 0..20 {
            let c = rng.in_cube(5.0);
            match (rng.next() * 4.0) as u32 {
                0 => {
                    list.push(Sphere::new(c, 0.2 + rng.next()).unwrap());
                }
                1 => {
                    list.push(
                        AaBox::new(c, c + Vec3::splat(0.3) + rng.in_cube(0.5).abs()).unwrap(),
                    );
                }
                2 => {
                    if let Some(p) = Parallelogram::new(c, rng.in_cube(1.0), rng.in_cube(1.0), true)
                    {
                        list.push(p);
                    }
                }
                _ => {
                    list.push_mesh(tessellated_sphere(c, 0.3 + rng.next(), 6));
                }
            }
        }
        // A few degenerate triangles: zero area, collinear, repeated vertices.
        let p = rng.in_cube(3.0);
        list.push_mesh(
            TriangleMesh::new(
                vec![p, p, p + Vec3::X, p + 2.0 * Vec3::X],
                vec![[0, 1, 2], [0, 2, 3], [1, 1, 1]],
                vec![],
                vec![Vec2::ZERO; 4],
            )
            .unwrap(),
        );
        list
    }

    #[test]
    fn bvh_and_brute_force_agree_on_random_rays_over_random_scenes() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        for _ in 0..20 {
            let linear = random_scene(&mut rng);
            let mut accelerated = linear.clone();
            accelerated.build_bvh();
            for _ in 0..500 {
                let origin = rng.in_cube(8.0);
                let toward = rng.in_cube(5.0);
                let ray = Ray::new(origin, toward - origin);
                let (a, b) = (
                    linear.closest_hit(&ray, f32::INFINITY),
                    accelerated.closest_hit(&ray, f32::INFINITY),
                );
                // The query without a surface record finds the same hit.
                for (list, hit) in [(&linear, a), (&accelerated, b)] {
                    let found = list.closest_primitive(&ray, f32::INFINITY);
                    assert_eq!(
                        found.map(|f| (f.t, f.object, f.primitive)),
                        hit.map(|h| (h.t, h.shape, h.primitive))
                    );
                }
                match (a, b) {
                    (None, None) => {}
                    (Some(a), Some(b)) => {
                        assert!(
                            (a.t - b.t).abs() <= 1e-5 * a.t.max(1.0),
                            "t {} vs {}",
                            a.t,
                            b.t
                        );
                        assert!(a.point.is_finite() && a.geometric_normal.is_finite());
                        // Ties go to the lowest index either way: the same primitive.
                        assert_eq!((a.shape, a.primitive), (b.shape, b.primitive));
                    }
                    (a, b) => panic!("linear {:?} vs bvh {:?}", a.map(|h| h.t), b.map(|h| h.t)),
                }
                let t_max = 0.5 + rng.next() * 20.0;
                assert_eq!(
                    linear.any_hit(&ray, t_max),
                    accelerated.any_hit(&ray, t_max)
                );
            }
        }
    }

    #[test]
    fn streams_of_rays_get_the_answers_of_rays_traced_alone() {
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        for scene in 0..10 {
            let mut linear = random_scene(&mut rng);
            if scene % 2 == 0 {
                linear
                    .push(Plane::new(rng.in_cube(4.0), rng.in_cube(1.0), scene % 4 == 0).unwrap());
            }
            let mut accelerated = linear.clone();
            accelerated.build_bvh();
            let mut rays: Vec<Ray> = (0..300)
                .map(|_| {
                    let origin = rng.in_cube(8.0);
                    Ray::new(origin, rng.in_cube(5.0) - origin)
                })
                .collect();
            rays[7] = Ray::new(Vec3::NAN, Vec3::X);
            let t_max: Vec<f32> = (0..rays.len())
                .map(|i| match i % 3 {
                    0 => f32::INFINITY,
                    _ => 0.5 + rng.next() * 20.0,
                })
                .collect();
            for list in [&linear, &accelerated] {
                let mut hits = vec![None; rays.len()];
                list.closest_primitives(&rays, &t_max, &mut hits);
                let mut occluded = vec![false; rays.len()];
                list.any_hits(&rays, &t_max, &mut occluded);
                for (i, ray) in rays.iter().enumerate() {
                    assert_eq!(hits[i], list.closest_primitive(ray, t_max[i]), "ray {i}");
                    assert_eq!(occluded[i], list.any_hit(ray, t_max[i]), "ray {i}");
                }
                assert!(hits.iter().filter(|h| h.is_some()).count() > 30);
                assert!(occluded.iter().filter(|&&o| o).count() > 30);
            }
        }
    }
}

#[cfg(test)]
mod found_hits_stay_found {
    use super::*;
    use crate::TriangleMesh;
    use glam::Vec3;

    #[test]
    fn every_triangle_hit_found_yields_a_surface_record() {
        // Many rays at a fine fan of triangles: whenever a distance is found, the
        // surface record must exist too (rounding once turned such hits into misses).
        let mut positions = vec![Vec3::new(0.0, 0.0, -3.0)];
        for i in 0..64 {
            let a = i as f32 / 64.0 * std::f32::consts::TAU;
            positions.push(Vec3::new(a.cos(), a.sin(), -3.0));
        }
        let indices = (0..64u32).map(|i| [0, 1 + i, 1 + (i + 1) % 64]).collect();
        let mut list = ShapeList::new();
        list.push_mesh(TriangleMesh::new(positions, indices, vec![], vec![]).unwrap());
        list.build_bvh();
        let mut found = 0;
        for j in 0..300 {
            for i in 0..300 {
                let d = Vec3::new(i as f32 / 300.0 - 0.5, j as f32 / 300.0 - 0.5, -1.0);
                let ray = Ray::new(Vec3::new(0.013, -0.007, 0.0), d);
                let hit = list.closest_hit(&ray, f32::INFINITY);
                // The fan lies in z = −3 and covers the disk of radius cos(π/64).
                let p = ray.at(3.0);
                let inside = p.x * p.x + p.y * p.y < 0.99;
                if inside {
                    assert!(hit.is_some(), "ray {d} slipped through");
                    found += 1;
                }
            }
        }
        assert!(found > 10_000);
    }
}
