//! The second stage of Glint: rays, the shapes they can hit (spheres,
//! parallelograms, planes, boxes, triangle meshes), and the closest-hit and
//! any-hit (shadow) queries over a collection of them, answered through a BVH.
//!
//! # Conventions
//! - World space is right-handed with y up; `f32` throughout, glam vectors.
//! - A [`Ray`] is `origin + t · direction` for `t > 0`; the direction need not be
//!   unit length, and `t` is measured in multiples of it.
//! - A [`Hit`] reports the shape's *geometric* normal as the shape defines it
//!   (outward for spheres and boxes, the front side for flat shapes) together with
//!   `front_face`, whether the ray arrived on that side. Shading code flips it as needed.
//! - Flat shapes (parallelogram, plane) are one-sided unless built two-sided:
//!   a one-sided shape is invisible from behind, for every kind of ray.
//! - uv coordinates lie in [0, 1]² on bounded shapes, with v increasing "upwards"
//!   (towards +y on spheres and box sides), as in pbrt; `dpdu` and `dpdv` are the
//!   partial derivatives of the surface point with respect to them (world units per
//!   unit of uv), the Jacobian later stages use for texture filtering.
//! - Every [`Hit`] carries an error bound of its point ([`Hit::error`], derived
//!   shape by shape in [`error_bounds`]); new rays leaving a surface start just
//!   outside it ([`offset_ray_origin`]), and shadow rays end just short of the
//!   light's surface ([`RayTarget`]). No distance is a fixed epsilon.
//! - Triangles are intersected watertightly ([`triangle`]): rays through shared
//!   edges and vertices of a closed mesh never slip through. Hits at exactly equal
//!   distances go to the lowest object index, with or without the BVH, and a
//!   ray's closest hit never depends on the order primitives are met in (every
//!   one is tested up to the query's limit; the nearest so far only prunes
//!   boxes), so it is the same alone or in lanes.
//! - The BVH ([`bvh`]) is 4-wide; meshes' triangles sit in its leaves as
//!   [`TrianglePacket`]s of four, tested together ([`triangle_packet`]).
//! - Batches of rays ([`ShapeList::closest_primitives`], [`ShapeList::any_hits`])
//!   are traced several at a time, interleaved so that their waits on memory
//!   overlap; each answer is the one the ray would get alone.
//!
//! # Entry points
//! - Shapes: [`Sphere`], [`Parallelogram`], [`Plane`], [`AaBox`] (gathered in the
//!   [`Shape`] enum) and [`TriangleMesh`]; each shape's `hit_distance` and
//!   `surface_at` answer for one ray.
//! - [`ShapeList`]: a scene's objects; [`ShapeList::build_acceleration`], then
//!   [`ShapeList::closest_hit`] (a [`Hit`]), [`ShapeList::closest_primitive`] (a
//!   [`PrimitiveHit`]) and [`ShapeList::any_hit`], or their batch forms; for
//!   shadow rays to an area light, [`ShapeList::occluders_towards`] culls the
//!   shapes that cannot block them once per point and
//!   [`ShapeList::any_hit_among`] tests the rest. Small scenes' spheres and
//!   parallelograms are tested four at a time ([`SpherePacket`],
//!   [`ParallelogramPacket`]).
//! - [`CountingGuard`] and [`take_counters`]: counts of BVH visits and tests by
//!   shape ([`QueryCounters`]) for `--stats`.
//! - [`spawn_ray`] and [`spawn_ray_to`] start secondary rays off a [`Hit`], the
//!   latter towards a [`RayTarget`].
//! - [`Hit::differentials`] turns a [`RayDifferential`] into the pixel's footprint
//!   on the surface ([`SurfaceDifferentials`]); [`reflect_differential`] follows it
//!   through a mirror.
//! - [`lanes::Vec3Lanes`]: [`lanes::LANES`] (16) 3-vectors in SIMD lanes, each lane bit for bit the
//!   scalar arithmetic, for shading a chunk's samples together; their rays as
//!   [`RayLanes`]: closest hits by [`ShapeList::closest_lanes`], shadow rays by
//!   [`ShapeList::any_hits_among`], each shape and triangle tested against all
//!   the lanes at once and the BVH walked by all of them together.
//! - [`bvh::Bvh`] on its own: a BVH over any primitives given by their bounds.

pub mod bvh;
mod counters;
mod differentials;
pub mod error_bounds;
mod hit;
pub use glint_lanes as lanes;
mod offset;
mod prefetch;
pub use prefetch::prefetch;
mod ray;
mod shape_list;
mod shapes;

pub use counters::{take_counters, CountingGuard, QueryCounters};
pub use differentials::{reflect, reflect_differential, RayDifferential, SurfaceDifferentials};
pub use hit::Hit;
pub use offset::{offset_ray_origin, offset_ray_origins, spawn_ray, spawn_ray_to, RayTarget};
pub use ray::{Ray, RayLanes};
pub use shape_list::{
    BvhRef, BvhVisit, ChildVisit, ClosestExplained, ClosestLanes, LeafPrimitive, ObjectRef,
    ObjectTest, Occluders, PrimitiveHit, ShapeList, PRUNE_SCALE,
};
pub(crate) use shapes::triangle_lanes;
pub use shapes::{triangle, triangle_packet};
pub use shapes::{
    AaBox, MeshError, Parallelogram, ParallelogramPacket, Plane, Shape, Sphere, SpherePacket,
    SurfaceLanes, TriangleMesh, TrianglePacket, SPHERE_UV_APPROX_ERROR,
};

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
