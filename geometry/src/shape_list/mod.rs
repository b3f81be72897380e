//! The scene's objects as the integrator queries them. A [`ShapeList`] holds the
//! analytic shapes and the triangle meshes, numbered in the order they are added,
//! and answers closest-hit and any-hit queries: through a BVH over every bounded
//! primitive, or by the course's linear loop, with the same answers either way.
//!
//! - `acceleration`: the BVH over the primitives, and its leaves' triangle packets.
//! - `closest`: closest-hit queries (with the surface record, without, and batches).
//! - `frustum`: the objects a pixel's camera rays may hit, for culling.
//! - `any_hit`: shadow queries, one ray or a batch.
//! - `linear`: the linear loop's layout, spheres and parallelograms in packets of four.
//! - `occluders`: shadow rays towards an area light, testing only the shapes that may block them.

mod acceleration;
mod any_hit;
mod closest;
mod explain;
mod frustum;
mod linear;
mod occluders;

pub use closest::{ClosestLanes, PrimitiveHit, PRUNE_SCALE};
pub use explain::{BvhRef, BvhVisit, ChildVisit, ClosestExplained, LeafPrimitive, ObjectTest};
pub use occluders::Occluders;

use crate::bvh::Bvh;
use crate::counters::count;
use crate::triangle::WatertightRay;
use crate::{Ray, Shape, TriangleMesh, TrianglePacket};
use linear::LinearShapes;

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

impl ObjectRef<'_> {
    /// `sphere`, `parallelogram`, `plane`, `box` or `mesh`.
    pub fn kind(self) -> &'static str {
        match self {
            ObjectRef::Shape(Shape::Sphere(_)) => "sphere",
            ObjectRef::Shape(Shape::Parallelogram(_)) => "parallelogram",
            ObjectRef::Shape(Shape::Plane(_)) => "plane",
            ObjectRef::Shape(Shape::Box(_)) => "box",
            ObjectRef::Mesh(_) => "mesh",
        }
    }
}

/// A primitive the BVH holds: an analytic shape, or one triangle of a mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Primitive {
    object: u32,
    triangle: u32,
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
/// numbering); a hit reports its object in [`Hit::shape`](crate::Hit::shape) and, for meshes, the
/// triangle in [`Hit::primitive`](crate::Hit::primitive). After [`ShapeList::build_bvh`], bounded
/// primitives (each shape, each triangle) are found through a BVH and only
/// unbounded planes are tested one by one; before it, every object is tested in
/// turn (the course's linear loop), with the same answers.
/// [`ShapeList::build_acceleration`] chooses between them, and for a mesh in a
/// room of a few walls and spheres, keeps those in packets beside a BVH over the
/// mesh. Batches of rays can be
/// handed over at once ([`ShapeList::closest_primitives`], [`ShapeList::any_hits`]),
/// to be traced several at a time.
#[derive(Clone, Debug, Default)]
pub struct ShapeList {
    shapes: Vec<Shape>,
    meshes: Vec<TriangleMesh>,
    objects: Vec<Object>,
    bvh: Option<Bvh>,
    /// The BVH's primitives in its padded leaf order (a leaf's adjacent, each
    /// leaf's run [`LEAF_WIDTH`](crate::bvh::LEAF_WIDTH) long, [`Primitive::PADDING`] in the gaps)…
    primitives: Vec<Primitive>,
    /// …one packet per leaf with its triangles' corners (NaN in lanes holding an
    /// analytic shape or padding): a leaf's triangles are one contiguous read and
    /// one four-wide test…
    packets: Vec<TrianglePacket>,
    /// …and per leaf, the lanes holding analytic shapes, tested one by one.
    shape_lanes: Vec<u8>,
    unbounded: Vec<u32>,
    /// The linear loop's packets, when [`ShapeList::build_acceleration`] chose
    /// it (alone, or beside a BVH over the objects not in packets).
    linear: Option<LinearShapes>,
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
        self.linear = None;
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

    /// The primitives the BVH leaves out: unbounded planes.
    fn unbounded_primitives(&self) -> impl Iterator<Item = Primitive> + '_ {
        self.unbounded.iter().map(|&object| Primitive {
            object,
            triangle: 0,
        })
    }

    /// Every primitive, object by object (the linear loop's order).
    fn all_primitives(&self) -> impl Iterator<Item = Primitive> + '_ {
        (0..self.objects.len() as u32).flat_map(move |object| self.primitives_of(object))
    }

    /// The primitives of object `object`: the shape, or each triangle of the mesh.
    fn primitives_of(&self, object: u32) -> impl Iterator<Item = Primitive> {
        let triangles = match self.objects[object as usize] {
            Object::Shape(_) => 1,
            Object::Mesh(m) => self.meshes[m as usize].triangle_count() as u32,
        };
        (0..triangles).map(move |triangle| Primitive { object, triangle })
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
            Object::Mesh(m) => {
                count(|c| c.triangle_tests += 1);
                self.meshes[m as usize].hit_distance(p.triangle, watertight, t_max)
            }
        }
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
mod tests;
