//! The shapes rays can hit, one file per primitive, each with its ray–shape test
//! (`hit_distance`) beside its surface record and uv mapping (`surface_at`):
//! [`Sphere`], [`Parallelogram`], [`Plane`], [`AaBox`], and triangle meshes
//! ([`TriangleMesh`], intersected with the watertight test of [`triangle`], four
//! at a time in BVH leaves by [`triangle_packet`]).
//!
//! [`Shape`] gathers the analytic shapes in one enum, so that intersection
//! dispatch is a `match`, not a virtual call, and shapes sit in one flat array.

mod aabox;
mod mesh;
mod parallelogram;
mod plane;
mod ray_lanes;
mod shape_packets;
mod sphere;
pub mod triangle;
pub(crate) mod triangle_lanes;
pub mod triangle_packet;

pub use aabox::AaBox;
pub use mesh::{MeshError, TriangleMesh};
pub use parallelogram::Parallelogram;
pub use plane::Plane;
pub use ray_lanes::{SurfaceLanes, SPHERE_UV_APPROX_ERROR};
pub use shape_packets::{ParallelogramPacket, SpherePacket};
pub use sphere::Sphere;
pub use triangle_packet::TrianglePacket;

use crate::bvh::Bounds3;
use crate::counters::count;
use crate::{Hit, Ray};

/// Every kind of shape, as one enum so intersection dispatch is a `match`,
/// not a virtual call, and shapes sit in one flat array.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    Sphere(Sphere),
    Parallelogram(Parallelogram),
    Plane(Plane),
    Box(AaBox),
}

impl Shape {
    /// The ray parameter of the nearest hit in (0, t_max), without building a [`Hit`].
    #[inline]
    pub fn hit_distance(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        count(|c| match self {
            Shape::Sphere(_) => c.sphere_tests += 1,
            Shape::Parallelogram(_) => c.parallelogram_tests += 1,
            Shape::Plane(_) => c.plane_tests += 1,
            Shape::Box(_) => c.box_tests += 1,
        });
        match self {
            Shape::Sphere(s) => s.hit_distance(ray, t_max),
            Shape::Parallelogram(p) => p.hit_distance(ray, t_max),
            Shape::Plane(p) => p.hit_distance(ray, t_max),
            Shape::Box(b) => b.hit_distance(ray, t_max),
        }
    }

    /// [`Self::hit_distance`] for each of the [`LANES`](crate::lanes::LANES)
    /// rays of `rays`: the lanes with a hit in (0, `t_max`), and their
    /// distances, bit for bit the scalar ones. Counted as `tested` tests.
    #[inline]
    pub fn hit_distance_lanes(
        &self,
        rays: &crate::RayLanes,
        t_max: f32,
        tested: u64,
    ) -> (u32, crate::lanes::F32Lanes) {
        count(|c| match self {
            Shape::Sphere(_) => c.sphere_tests += tested,
            Shape::Parallelogram(_) => c.parallelogram_tests += tested,
            Shape::Plane(_) => c.plane_tests += tested,
            Shape::Box(_) => c.box_tests += tested,
        });
        match self {
            Shape::Sphere(s) => s.hit_distance_lanes(rays, t_max),
            Shape::Parallelogram(p) => p.hit_distance_lanes(rays, t_max),
            Shape::Plane(p) => p.hit_distance_lanes(rays, t_max),
            Shape::Box(b) => b.hit_distance_lanes(rays, t_max),
        }
    }

    /// The surface record at a distance returned by [`Self::hit_distance`].
    pub fn surface_at(&self, ray: &Ray, t: f32) -> Hit {
        match self {
            Shape::Sphere(s) => s.surface_at(ray, t),
            Shape::Parallelogram(p) => p.surface_at(ray, t),
            Shape::Plane(p) => p.surface_at(ray, t),
            Shape::Box(b) => b.surface_at(ray, t),
        }
    }

    /// Bounds of the shape, or `None` for the unbounded plane.
    pub fn bounds(&self) -> Option<Bounds3> {
        match self {
            Shape::Sphere(s) => Some(Bounds3::new(
                s.center() - s.radius(),
                s.center() + s.radius(),
            )),
            Shape::Parallelogram(p) => {
                let (e1, e2) = p.edges();
                let o = p.origin();
                Some(Bounds3::new(o, o + e1).include(o + e2).include(o + e1 + e2))
            }
            Shape::Plane(_) => None,
            Shape::Box(b) => Some(Bounds3::new(b.min(), b.max())),
        }
    }

    /// The nearest hit in (0, t_max).
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        self.hit_distance(ray, t_max)
            .map(|t| self.surface_at(ray, t))
    }
}

impl From<Sphere> for Shape {
    fn from(s: Sphere) -> Self {
        Shape::Sphere(s)
    }
}
impl From<Parallelogram> for Shape {
    fn from(p: Parallelogram) -> Self {
        Shape::Parallelogram(p)
    }
}
impl From<Plane> for Shape {
    fn from(p: Plane) -> Self {
        Shape::Plane(p)
    }
}
impl From<AaBox> for Shape {
    fn from(b: AaBox) -> Self {
        Shape::Box(b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use glint_snapfmt::{sig5, vec2, vec3};
    use std::fmt::Write;

    fn shapes() -> Vec<(&'static str, Shape)> {
        vec![
            (
                "sphere",
                Sphere::new(Vec3::new(0.0, 0.0, -5.0), 1.5).unwrap().into(),
            ),
            (
                "parallelogram",
                Parallelogram::new(
                    Vec3::new(-1.0, -1.0, -4.0),
                    Vec3::new(2.0, 0.0, 0.0),
                    Vec3::new(0.0, 2.0, 0.0),
                    false,
                )
                .unwrap()
                .into(),
            ),
            (
                "plane",
                Plane::new(Vec3::new(0.0, -1.0, 0.0), Vec3::Y, false)
                    .unwrap()
                    .into(),
            ),
            (
                "box",
                AaBox::new(Vec3::new(-1.0, -1.0, -6.0), Vec3::new(1.0, 1.0, -4.0))
                    .unwrap()
                    .into(),
            ),
        ]
    }

    fn rays() -> Vec<(&'static str, Ray)> {
        let o = Vec3::ZERO;
        vec![
            ("straight", Ray::new(o, -Vec3::Z)),
            ("oblique", Ray::new(o, Vec3::new(0.2, -0.1, -1.0))),
            (
                "downward",
                Ray::new(o, Vec3::new(0.1, -0.5, -1.0).normalize()),
            ),
            ("away", Ray::new(o, Vec3::Z)),
            (
                "inside-sphere",
                Ray::new(Vec3::new(0.0, 0.5, -5.0), Vec3::X),
            ),
            (
                "tangent-sphere",
                Ray::new(Vec3::new(0.0, 1.5, 0.0), -Vec3::Z),
            ),
            (
                "inside-box",
                Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::new(0.3, 1.0, 0.2)),
            ),
            (
                "behind-flat",
                Ray::new(Vec3::new(0.0, -2.0, -3.0), Vec3::new(0.0, 1.0, -0.2)),
            ),
            ("grazing", Ray::new(Vec3::new(0.0, -1.0, 1.0), -Vec3::Z)),
        ]
    }

    #[test]
    fn fixed_rays_against_each_shape() {
        let mut s = String::new();
        for (shape_name, shape) in shapes() {
            writeln!(s, "## {shape_name}").unwrap();
            for (ray_name, ray) in rays() {
                match shape.intersect(&ray, f32::INFINITY) {
                    None => writeln!(s, "{ray_name:<15} miss").unwrap(),
                    Some(h) => writeln!(
                        s,
                        "{ray_name:<15} t={} p={} n={} uv={} front={}",
                        sig5(h.t),
                        vec3(h.point),
                        vec3(h.geometric_normal),
                        vec2(h.uv),
                        h.front_face
                    )
                    .unwrap(),
                }
            }
        }
        insta::assert_snapshot!(s);
    }

    #[test]
    fn hit_points_lie_on_the_surface_and_t_matches() {
        let sphere = Sphere::new(Vec3::new(0.3, -0.2, -7.0), 2.0).unwrap();
        for i in 0..200 {
            let a = i as f32 * 0.37;
            let d = Vec3::new(0.3 + 0.2 * a.sin(), -0.2 + 0.2 * a.cos(), -7.0);
            let ray = Ray::new(Vec3::ZERO, d);
            let h = Shape::from(sphere).intersect(&ray, f32::INFINITY).unwrap();
            let dist = (h.point - sphere.center()).length();
            assert!((dist - 2.0).abs() < 2e-6, "off surface by {}", dist - 2.0);
            assert!((ray.at(h.t) - h.point).length() < 1e-4);
            assert!(h.front_face);
        }
    }

    /// Parallelogram hits against Cramer's rule in f64 (glam's `DMat3`), apart from
    /// the shape's own test: `o + t d = p + a e₁ + b e₂`, a hit where `t > 0`
    /// and `a, b ∈ [0, 1]`. Rays within 1e-4 of an edge are left out (either
    /// answer is right there); the rest must agree, `t` to 1e-5.
    #[test]
    fn parallelogram_hits_match_cramers_rule_in_f64() {
        use glam::{DMat3, DVec3};
        let (p, e1, e2) = (
            Vec3::new(-1.0, -0.5, -4.0),
            Vec3::new(2.0, 0.3, -0.4),
            Vec3::new(-0.2, 1.5, 0.3),
        );
        let shape = Parallelogram::new(p, e1, e2, true).unwrap();
        let det3 = |c0: DVec3, c1: DVec3, c2: DVec3| DMat3::from_cols(c0, c1, c2).determinant();
        let (e1, e2) = (e1.as_dvec3(), e2.as_dvec3());
        let (mut hits, mut compared) = (0, 0);
        for i in 0..4000 {
            let k = i as f32;
            let origin = Vec3::new(0.1 * (k * 0.37).sin(), 0.1 * (k * 0.11).cos(), 0.5);
            let target = Vec3::new(
                -1.6 + (k * 0.618).fract() * 3.4,
                -0.9 + (k * 0.382).fract() * 2.6,
                -4.0,
            );
            let ray = Ray::new(origin, target - origin);
            // o − p = −t d + a e₁ + b e₂.
            let (minus_d, rhs) = (-ray.direction.as_dvec3(), (ray.origin - p).as_dvec3());
            let det = det3(minus_d, e1, e2);
            let t = det3(rhs, e1, e2) / det;
            let a = det3(minus_d, rhs, e2) / det;
            let b = det3(minus_d, e1, rhs) / det;
            let near_edge = [a, 1.0 - a, b, 1.0 - b].iter().any(|x| x.abs() < 1e-4);
            if near_edge {
                continue;
            }
            let expected =
                (t > 0.0 && (0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b)).then_some(t);
            let got = Shape::from(shape)
                .intersect(&ray, f32::INFINITY)
                .map(|h| h.t as f64);
            compared += 1;
            match (expected, got) {
                (Some(t), Some(got)) => {
                    hits += 1;
                    assert!((got - t).abs() <= 1e-5 * t, "ray {i}: t {got} against {t}");
                }
                (None, None) => {}
                _ => panic!("ray {i} (a {a}, b {b}): {got:?} against {expected:?}"),
            }
        }
        assert!(
            hits > 1000 && compared - hits > 1000,
            "{hits} hits of {compared}"
        );
    }

    #[test]
    fn sphere_far_from_origin_keeps_precision() {
        // A small sphere 10^4 units away: the naive b² − 4ac loses the hit entirely
        // or misplaces it by far more than the radius' ULP budget.
        let sphere = Sphere::new(Vec3::new(0.0, 0.0, -1.0e4), 0.01).unwrap();
        let ray = Ray::new(Vec3::ZERO, Vec3::new(0.0, 0.0099 / 1.0e4, -1.0));
        let h = Shape::from(sphere).intersect(&ray, f32::INFINITY).unwrap();
        let dist = (h.point - sphere.center()).length();
        assert!((dist - 0.01).abs() < 1e-6, "radius error {}", dist - 0.01);
    }

    #[test]
    fn one_sided_shapes_are_invisible_from_behind_and_two_sided_are_not() {
        let from_behind = Ray::new(Vec3::new(0.2, 0.3, -10.0), Vec3::Z);
        let (e1, e2) = (Vec3::X, Vec3::Y);
        let one = Parallelogram::new(Vec3::new(0.0, 0.0, -4.0), e1, e2, false).unwrap();
        let two = Parallelogram::new(Vec3::new(0.0, 0.0, -4.0), e1, e2, true).unwrap();
        assert!(one.hit_distance(&from_behind, f32::INFINITY).is_none());
        let h = Shape::from(two)
            .intersect(&from_behind, f32::INFINITY)
            .unwrap();
        assert!(!h.front_face);
        assert!((h.uv - glam::Vec2::new(0.2, 0.3)).length() < 1e-6);
        let flipped = one.facing(-Vec3::Z);
        assert!(flipped.hit_distance(&from_behind, f32::INFINITY).is_some());
    }

    #[test]
    fn parallel_edges_are_judged_by_their_angle_whatever_their_length() {
        for scale in [1e-6f32, 1.0, 1e10] {
            let (e1, e2) = (Vec3::new(scale, 0.0, 0.0), Vec3::new(0.0, 0.0, scale));
            let p = Parallelogram::new(Vec3::ZERO, e1, e2, false).expect("a square");
            assert_eq!(p.normal(), -Vec3::Y, "scale {scale}");
            assert!(
                (p.area() / (scale * scale) - 1.0).abs() < 1e-6,
                "scale {scale}"
            );
            // Hit from above at its centre, at the right distance.
            let ray = Ray::new(Vec3::new(0.5 * scale, -2.0 * scale, 0.5 * scale), Vec3::Y);
            let two = Parallelogram::new(Vec3::ZERO, e1, e2, true).unwrap();
            let t = two.hit_distance(&ray, f32::INFINITY).expect("hit");
            assert!(
                (t / (2.0 * scale) - 1.0).abs() < 1e-5,
                "scale {scale}: t {t}"
            );
            // Edges 1e-7 radians apart are parallel at any scale.
            let nearly = Vec3::new(scale, scale * 1e-7, 0.0);
            assert!(Parallelogram::new(Vec3::ZERO, e1, nearly, false).is_none());
        }
    }

    #[test]
    fn uv_derivatives_match_finite_differences() {
        // Move along dpdu by a small step in u, re-intersect from the camera, and
        // check the uv advanced by that step.
        let h = 1e-3;
        for (name, shape) in shapes() {
            let ray = Ray::new(Vec3::ZERO, Vec3::new(0.11, -0.13, -1.0));
            let Some(hit) = shape.intersect(&ray, f32::INFINITY) else {
                continue;
            };
            for (deriv, axis) in [(hit.dpdu, 0), (hit.dpdv, 1)] {
                let target = hit.point + h * deriv;
                let r2 = Ray::new(Vec3::ZERO, target);
                let hit2 = shape.intersect(&r2, f32::INFINITY).unwrap();
                let du = (hit2.uv - hit.uv)[axis] / h;
                assert!((du - 1.0).abs() < 2e-2, "{name}: d{axis} gave {du}");
            }
        }
    }

    #[test]
    fn axis_parallel_rays_hit_or_miss_a_box_consistently() {
        let b = Shape::from(AaBox::new(-Vec3::ONE, Vec3::ONE).unwrap());
        for axis in 0..3 {
            for sign in [-1.0f32, 1.0] {
                let mut dir = Vec3::ZERO;
                dir[axis] = -sign;
                let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
                for (ou, ow, hits) in [
                    (0.0, 0.0, true),
                    (1.0, 0.0, true),  // grazing the face at +1
                    (-1.0, 0.0, true), // grazing the face at −1
                    (1.0, -1.0, true), // along an edge
                    (1.5, 0.0, false),
                    (0.0, -1.01, false),
                ] {
                    let mut origin = Vec3::ZERO;
                    origin[axis] = 5.0 * sign;
                    origin[u] = ou;
                    origin[w] = ow;
                    let got = b.hit_distance(&Ray::new(origin, dir), f32::INFINITY);
                    assert_eq!(
                        got,
                        hits.then_some(4.0),
                        "axis {axis} sign {sign} at {origin}"
                    );
                }
            }
        }
    }

    #[test]
    fn uv_derivatives_match_on_every_box_face_and_a_tiled_plane() {
        // Step along dpdu (dpdv) from a hit, re-intersect towards that point, and
        // check uv advanced by the step in u (v) only.
        let aabox =
            Shape::from(AaBox::new(Vec3::new(-1.0, -2.0, -3.0), Vec3::new(2.0, 1.0, 0.5)).unwrap());
        let plane = Shape::from(
            Plane::new(Vec3::new(0.0, -1.0, 0.0), Vec3::new(0.2, 1.0, 0.1), false)
                .unwrap()
                .with_tile_size(4.0)
                .unwrap(),
        );
        let centre = Vec3::new(0.5, -0.5, -1.25);
        let mut cases: Vec<(Shape, Vec3)> =
            [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z]
                .into_iter()
                .map(|axis| (aabox, centre + 10.0 * axis + Vec3::new(0.13, 0.07, -0.11)))
                .collect();
        cases.push((plane, Vec3::new(0.3, 5.0, 0.2)));
        let mut normals = Vec::new();
        for (shape, origin) in cases {
            let target = if shape == plane {
                Vec3::new(1.0, -1.0, -2.0)
            } else {
                centre
            };
            let hit = shape
                .intersect(&Ray::new(origin, target - origin), f32::INFINITY)
                .unwrap();
            normals.push(hit.geometric_normal);
            let h = 1e-3;
            for (deriv, axis) in [(hit.dpdu, 0), (hit.dpdv, 1)] {
                let moved = hit.point + h * deriv;
                let again = shape
                    .intersect(&Ray::new(origin, moved - origin), f32::INFINITY)
                    .unwrap();
                let duv = (again.uv - hit.uv) / h;
                assert!(
                    (duv[axis] - 1.0).abs() < 1e-2,
                    "{:?} axis {axis}: {duv}",
                    hit.geometric_normal
                );
                assert!(
                    duv[1 - axis].abs() < 1e-2,
                    "{:?} axis {axis}: {duv}",
                    hit.geometric_normal
                );
            }
            // The frame is right-handed seen from outside: dpdu × dpdv along n.
            assert!(
                hit.dpdu.cross(hit.dpdv).dot(hit.geometric_normal) > 0.0,
                "{:?}",
                hit.geometric_normal
            );
        }
        assert_eq!(normals.len(), 7);
    }

    #[test]
    fn box_faces_as_parallelograms_match_the_box() {
        let b = AaBox::new(Vec3::new(-1.0, -2.0, -3.0), Vec3::new(2.0, 1.0, 0.5)).unwrap();
        let faces = b.face_parallelograms();
        let centre = Vec3::new(0.5, -0.5, -1.25);
        for (i, axis) in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z]
            .into_iter()
            .enumerate()
        {
            let origin = centre + 10.0 * axis + Vec3::new(0.3, -0.2, 0.1);
            let ray = Ray::new(origin, centre + Vec3::new(0.1, 0.2, -0.15) - origin);
            let from_box = Shape::from(b).intersect(&ray, f32::INFINITY).unwrap();
            let from_face = Shape::from(faces[i])
                .intersect(&ray, f32::INFINITY)
                .unwrap();
            assert_eq!(from_face.geometric_normal, axis);
            assert!((from_box.uv - from_face.uv).length() < 1e-5, "face {i}");
            assert!((from_box.point - from_face.point).length() < 1e-5);
        }
    }

    #[test]
    fn t_max_limits_hits() {
        for (name, shape) in shapes() {
            let ray = Ray::new(Vec3::ZERO, Vec3::new(0.0, -0.1, -1.0));
            if let Some(t) = shape.hit_distance(&ray, f32::INFINITY) {
                assert!(shape.hit_distance(&ray, t * 0.999).is_none(), "{name}");
            }
        }
    }

    #[test]
    fn degenerate_inputs_are_refused() {
        assert!(Parallelogram::new(Vec3::ZERO, Vec3::X, 2.0 * Vec3::X, false).is_none());
        assert!(Parallelogram::new(Vec3::ZERO, Vec3::ZERO, Vec3::Y, false).is_none());
        assert!(Plane::new(Vec3::ZERO, Vec3::ZERO, false).is_none());
        assert!(AaBox::new(Vec3::ONE, Vec3::ONE).is_none());
    }
}
