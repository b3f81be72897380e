//! Spheres: one alone, and a tiny one resting on a huge one.

use crate::{lit_and_mirrored, Counts, Truth};
use glam::Vec3;
use glint_geometry::{Hit, Ray, ShapeList, Sphere};

/// The exact signed distance of `hit`'s point from `sphere`.
fn sphere_distance(sphere: &Sphere, hit: &Hit) -> f64 {
    (hit.point.as_dvec3() - sphere.center().as_dvec3()).length() - sphere.radius() as f64
}

/// A sphere alone, lit from one side: no point with n·l > 0 is shadowed, and no
/// mirror ray off it hits it again.
pub(crate) fn lone(at: Vec3, scale: f32, steps: &[f32]) -> Counts {
    let mut list = ShapeList::new();
    let sphere = Sphere::new(at, scale).expect("a sphere");
    list.push(sphere);
    list.build_acceleration();
    let light = at + Vec3::new(3.0, 4.0, 2.0) * 10.0 * scale;
    let eye = at + Vec3::new(0.5, 1.0, 6.0) * scale;
    let truth = Truth {
        distance: |hit: &Hit| sphere_distance(&sphere, hit),
        judged: |_: &Hit| true,
        mirror_escapes: true,
    };
    let mut counts = Counts::default();
    for &u in steps {
        for &v in steps {
            // Across the disc the sphere covers, out to its silhouette.
            let target = at + Vec3::new(-1.0 + 2.0 * u, -1.0 + 2.0 * v, 0.0) * scale;
            let ray = Ray::new(eye, target - eye);
            lit_and_mirrored(&list, &ray, light, &truth, &mut counts);
        }
    }
    counts
}

/// A sphere of radius 1e-3 resting on top of one of radius 1e5 (times the
/// scale), under a light high above. No point of the small sphere that faces
/// the light is shadowed (the large sphere lies below their common tangent
/// plane, and the shadow rays rise), nor any point of the large sphere from 20
/// to 200 small radii away from the contact (the small sphere's shadow falls
/// within a few radii of it). Rays are aimed at the small sphere's disc and at
/// a ring of the large sphere around the contact.
pub(crate) fn tiny_on_huge(at: Vec3, scale: f32, steps: &[f32]) -> Counts {
    let (r, big) = (1e-3 * scale, 1e5 * scale);
    let tiny = Sphere::new(at + Vec3::Y * r, r).expect("a tiny sphere");
    let huge = Sphere::new(at - Vec3::Y * big, big).expect("a huge sphere");
    let mut list = ShapeList::new();
    list.push(tiny);
    list.push(huge);
    list.build_acceleration();
    let light = at + Vec3::new(0.2, 1.0, 0.1) * 1000.0 * r;
    let eye = at + Vec3::new(0.0, 3.0, 6.0) * r;
    // Off the small sphere a mirror ray can rightly meet the large one.
    let truth = Truth {
        distance: |hit: &Hit| match hit.shape {
            0 => sphere_distance(&tiny, hit),
            _ => sphere_distance(&huge, hit),
        },
        judged: |hit: &Hit| {
            let across = hit.point - at;
            hit.shape == 0 || Vec3::new(across.x, 0.0, across.z).length() >= 19.0 * r
        },
        mirror_escapes: false,
    };
    let mut counts = Counts::default();
    for &u in steps {
        for &v in steps {
            let on_tiny = at + Vec3::new(-1.0 + 2.0 * u, 1.0 + (-1.0 + 2.0 * v) * 0.99, 0.0) * r;
            let angle = std::f32::consts::TAU * u;
            let reach = (20.0 + 180.0 * v) * r;
            let on_huge = at + Vec3::new(angle.cos(), 0.0, angle.sin()) * reach;
            for target in [on_tiny, on_huge] {
                let ray = Ray::new(eye, target - eye);
                lit_and_mirrored(&list, &ray, light, &truth, &mut counts);
            }
        }
    }
    counts
}
