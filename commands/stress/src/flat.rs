//! Flat configurations: a floor under a grazing light, and planes seen edge-on.

use crate::{finite, lit_and_mirrored, off_surface, plane_distance, Counts, Truth};
use glam::{DVec3, Vec3};
use glint_geometry::{Parallelogram, Plane, Ray, ShapeList};

/// Where a floor is seen from: one eye above it, or along rays that arrive
/// this many degrees above its horizon.
#[derive(Clone, Copy)]
pub(crate) enum View {
    Above,
    Grazing(f32),
}

/// The floor's normal: tilted off every axis, so that its points round off
/// its plane (an axis-aligned floor's points lie on it exactly, and would test
/// nothing).
const FLOOR_NORMAL: Vec3 = Vec3::new(0.3, 1.0, 0.2);

/// A two-sided floor of 20 × 20 scale units, tilted, alone under a point light
/// `degrees` above its horizon, seen from `view` at a grid of points: every
/// point is lit, and a mirror ray off it meets nothing.
pub(crate) fn floor(at: Vec3, scale: f32, degrees: f32, view: View, steps: &[f32]) -> Counts {
    let mut list = ShapeList::new();
    let n = FLOOR_NORMAL.normalize();
    let (t1, t2) = n.any_orthonormal_pair();
    let half = 10.0 * scale;
    let corner = at - half * t1 - half * t2;
    let (e1, e2) = (2.0 * half * t1, 2.0 * half * t2);
    // Two-sided: a one-sided floor ignores the rays that leave its front from
    // just under it, and would count nothing with any offset or none.
    let wall = Parallelogram::new(corner, e1, e2, true).expect("a floor");
    list.push(wall.facing(n));
    list.build_acceleration();
    let along = |x: f32, up: f32, side: f32| x * t1 + up * n + side * t2;
    let elevation = degrees.to_radians();
    let light = at + along(elevation.cos(), elevation.sin(), 0.3).normalize() * 100.0 * scale;
    let eye_for = |target: Vec3| match view {
        View::Above => at + along(-3.0, 8.0, 5.0) * scale,
        View::Grazing(degrees) => {
            let e = degrees.to_radians();
            target + along(-e.cos(), e.sin(), 0.2) * 30.0 * scale
        }
    };
    // The plane of the floor as built (its rounded corner and edges), in f64.
    let exact_normal = e1.as_dvec3().cross(e2.as_dvec3());
    let truth = Truth {
        distance: |hit: &glint_geometry::Hit| {
            plane_distance(hit.point, corner.as_dvec3(), exact_normal)
        },
        judged: |_: &glint_geometry::Hit| true,
        mirror_escapes: true,
    };
    let mut counts = Counts::default();
    for &u in steps {
        for &v in steps {
            let target = at + along(-0.9 + 1.8 * u, 0.0, -0.9 + 1.8 * v) * half;
            let eye = eye_for(target);
            let ray = Ray::new(eye, target - eye);
            lit_and_mirrored(&list, &ray, light, &truth, &mut counts);
        }
    }
    counts
}

/// A two-sided plane and a two-sided parallelogram in the plane y = at.y,
/// seen from eyes in that plane and just above and below it (by 1e-7 to 1e-2
/// of the scale), looking along it: rays exactly in the plane miss, or hit
/// nothing non-finite; every hit lies on the surface within its bound.
pub(crate) fn edge_on(at: Vec3, scale: f32, steps: &[f32]) -> Counts {
    let mut list = ShapeList::new();
    list.push(Plane::new(at, Vec3::Y, true).expect("a plane"));
    let half = 10.0 * scale;
    let corner = at + Vec3::new(-half, 0.0, -half);
    list.push(
        Parallelogram::new(corner, Vec3::X * 2.0 * half, Vec3::Z * 2.0 * half, true)
            .expect("a floor"),
    );
    list.build_acceleration();
    let mut counts = Counts::default();
    for &u in steps {
        for &v in steps {
            // Heights from −1e-2 to 1e-2 of the scale, 0 exactly in the middle.
            let signed = 2.0 * v - 1.0;
            let height = signed * 10f32.powf(-2.0 - 5.0 * (1.0 - signed.abs()));
            let eye = at + Vec3::new(-30.0 * scale, height * scale, (2.0 * u - 1.0) * half);
            let aim = at + Vec3::new(30.0 * scale, -height * scale, (1.0 - 2.0 * u) * half);
            counts.rays += 1;
            let Some(hit) = list.closest_hit(&Ray::new(eye, aim - eye), f32::INFINITY) else {
                continue;
            };
            if !finite(&hit) {
                counts.non_finite += 1;
                continue;
            }
            let distance = plane_distance(hit.point, at.as_dvec3(), DVec3::Y);
            counts.off_surface += u64::from(off_surface(&hit, distance));
        }
    }
    counts
}
