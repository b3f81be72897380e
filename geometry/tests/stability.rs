//! Numerical stability as properties (proptest, fixed seeds): spheres and
//! parallelograms at every scale from 1e-4 to 1e6, moved up to 1e6 from the
//! origin (as far as f32 can still tell the shape from its position: the shape
//! spans at least a thousandth of its distance from the origin).
//!
//! - A ray aimed at a sphere's centre from outside always hits it.
//! - A hit point lies within its error bound of the exact surface (measured in
//!   f64), and the offset origin of a spawned ray is on the side of the surface
//!   it was moved to, for either side.
//! - A ray spawned from a hit towards a point on the outgoing side (a light)
//!   never hits that surface again.

use glam::Vec3;
use glint_geometry::{offset_ray_origin, spawn_ray_to, Hit, Parallelogram, Ray, RayTarget, Sphere};
use proptest::prelude::*;

/// A scale from the list the stability work names, and a translation of up to
/// 1e6 that f32 can still resolve the shape at (at most 1000 scales).
fn placement() -> impl Strategy<Value = (f32, Vec3)> {
    (
        prop::sample::select(vec![1e-4f32, 1e-2, 1.0, 1e2, 1e4, 1e6]),
        prop::array::uniform3(-1.0f32..1.0),
        0.0f32..1.0,
    )
        .prop_map(|(scale, dir, reach)| {
            let far = (1000.0 * scale).min(1e6);
            (scale, Vec3::from(dir) * far * reach)
        })
}

fn unit() -> impl Strategy<Value = Vec3> {
    prop::array::uniform3(-1.0f32..1.0)
        .prop_filter("not too short", |v| Vec3::from(*v).length() > 0.1)
        .prop_map(|v| Vec3::from(v).normalize())
}

/// A sphere and a ray from outside it towards a point of it, at one placement.
fn sphere_and_ray() -> impl Strategy<Value = (Sphere, Ray)> {
    (
        placement(),
        0.1f32..10.0,
        unit(),
        1.01f32..100.0,
        unit(),
        0.0f32..0.95,
    )
        .prop_map(|((scale, at), radius, from, distance, aim, spread)| {
            let (center, radius) = (at, radius * scale);
            let origin = center + from * radius * distance;
            // Towards the centre, tilted by up to `spread` of the sphere's apparent radius.
            let to_center = center - origin;
            let side = aim - aim.dot(to_center.normalize()) * to_center.normalize();
            let target = center + side * radius * spread;
            (
                Sphere::new(center, radius).unwrap(),
                Ray::new(origin, target - origin),
            )
        })
}

/// A parallelogram and a ray from one side of it towards its inside.
fn wall_and_ray() -> impl Strategy<Value = (Parallelogram, Ray)> {
    (
        placement(),
        unit(),
        unit(),
        0.1f32..10.0,
        0.01f32..0.99,
        0.01f32..0.99,
        unit(),
        0.01f32..100.0,
    )
        .prop_filter_map(
            "edges not parallel",
            |((scale, at), e1, e2, size, a, b, from, distance)| {
                if e1.cross(e2).length() < 0.2 {
                    return None;
                }
                let (e1, e2) = (e1 * size * scale, e2 * size * scale);
                let wall = Parallelogram::new(at, e1, e2, true)?;
                let inside = at + a * e1 + b * e2;
                let origin = inside + from * size * scale * distance;
                Some((wall, Ray::new(origin, inside - origin)))
            },
        )
}

/// How far the offset origin of `hit` (moved along `normal`) lies from it,
/// along `normal`.
fn offset_distance(hit: &Hit, normal: Vec3) -> f32 {
    (offset_ray_origin(hit.point, hit.error, normal) - hit.point).dot(normal)
}

/// The extent of `hit`'s error bound along its normal: how far off the exact
/// surface its point may be.
fn error_along_normal(hit: &Hit) -> f64 {
    hit.geometric_normal.abs().dot(hit.error) as f64
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 2000,
        failure_persistence: None,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x0057_ab1e),
        ..ProptestConfig::default()
    })]

    #[test]
    fn a_ray_aimed_at_a_spheres_centre_from_outside_hits((sphere, ray) in sphere_and_ray()) {
        let aimed = Ray::new(ray.origin, sphere.center() - ray.origin);
        prop_assert!(sphere.hit_distance(&aimed, f32::INFINITY).is_some());
        prop_assert!(sphere.hit_distance(&ray, f32::INFINITY).is_some());
    }

    #[test]
    fn sphere_hits_lie_closer_to_the_surface_than_the_offset((sphere, ray) in sphere_and_ray()) {
        let t = sphere.hit_distance(&ray, f32::INFINITY).unwrap();
        let hit = sphere.surface_at(&ray, t);
        let n = hit.geometric_normal;
        let outside = offset_ray_origin(hit.point, hit.error, n);
        let inside = offset_ray_origin(hit.point, hit.error, -n);
        let c = sphere.center();
        prop_assert!(outside.distance(c) > sphere.radius(), "outside {} at {}", outside.distance(c), sphere.radius());
        prop_assert!(inside.distance(c) < sphere.radius(), "inside {} at {}", inside.distance(c), sphere.radius());
        prop_assert!(offset_distance(&hit, n) > 0.0);
        let off = (hit.point.as_dvec3() - c.as_dvec3()).length() - sphere.radius() as f64;
        prop_assert!(off.abs() <= error_along_normal(&hit), "{off} off, bound {}", error_along_normal(&hit));
    }

    #[test]
    fn parallelogram_offsets_land_on_the_side_they_were_moved_to((wall, ray) in wall_and_ray()) {
        let t = wall.hit_distance(&ray, f32::INFINITY).unwrap();
        let hit = wall.surface_at(&ray, t);
        let n = hit.geometric_normal;
        let height = |p: Vec3| (p - wall.center()).dot(n);
        prop_assert!(height(offset_ray_origin(hit.point, hit.error, n)) > 0.0);
        prop_assert!(height(offset_ray_origin(hit.point, hit.error, -n)) < 0.0);
        // The exact plane through the wall's corner, in f64.
        let (e1, e2) = wall.edges();
        let exact_normal = e1.as_dvec3().cross(e2.as_dvec3()).normalize();
        let off = (hit.point.as_dvec3() - wall.origin().as_dvec3()).dot(exact_normal);
        prop_assert!(off.abs() <= error_along_normal(&hit), "{off} off, bound {}", error_along_normal(&hit));
    }

    #[test]
    fn shadow_rays_never_hit_the_sphere_they_leave((sphere, ray) in sphere_and_ray(), light in unit(), far in 0.01f32..100.0) {
        let t = sphere.hit_distance(&ray, f32::INFINITY).unwrap();
        let hit = sphere.surface_at(&ray, t);
        // A light anywhere on the outer side of the tangent plane.
        let n = hit.geometric_normal;
        let towards = if light.dot(n) > 0.05 { light } else { (light + n * (0.05 - light.dot(n) + 0.01)).normalize() };
        let target = hit.point + towards * sphere.radius() * far;
        let shadow = spawn_ray_to(&hit, &RayTarget::exact(target));
        prop_assert_eq!(sphere.hit_distance(&shadow, 1.0), None);
    }

    #[test]
    fn shadow_rays_never_hit_the_wall_they_leave((wall, ray) in wall_and_ray(), light in unit(), far in 0.01f32..100.0) {
        let t = wall.hit_distance(&ray, f32::INFINITY).unwrap();
        let hit = wall.surface_at(&ray, t);
        let n = hit.geometric_normal;
        // Either side: a two-sided wall is lit from both.
        let towards = if light.dot(n).abs() > 0.01 { light } else { (light + n * 0.02).normalize() };
        let target = hit.point + towards * wall.edges().0.length() * far;
        let shadow = spawn_ray_to(&hit, &RayTarget::exact(target));
        prop_assert_eq!(wall.hit_distance(&shadow, 1.0), None);
    }
}
