//! Culling for a pixel's camera rays: the objects its frustum may meet.
//!
//! The rays through one pixel leave one apex between the four corner rays;
//! each corner ray and the next span a plane through the apex, and the rays
//! lie on the inner side of all four. An object wholly on the outer side of
//! one plane cannot be hit: its bounding sphere (centre beyond the plane by
//! more than the radius) or its box (even the corner furthest inward lies
//! beyond the plane) tells. The box is what culls a large flat wall, whose
//! bounding sphere meets nearly every pixel's frustum (Assarsson and Möller,
//! "Optimized View Frustum Culling Algorithms for Bounding Boxes", 2000: the
//! "p-vertex" test).

use super::ShapeList;
use glam::Vec3;

impl ShapeList {
    /// The objects a ray from `apex` between the four `corners` directions
    /// (in order around the pixel, either way round) may hit, as bits
    /// (object k as bit k; objects from 64 on always count): those whose
    /// bounding sphere and box both reach the inner side of all four planes,
    /// each plane widened well past rounding error (a thousandth of the
    /// distance from the apex, and 10⁻⁴ of the coordinates' size), so that no
    /// hit a ray's exact test would find is left out. For
    /// [`ShapeList::closest_lanes_among`], with the corner rays of one pixel.
    /// All objects without the linear layout; every object where the corners
    /// span no frustum (a plane's normal is not finite).
    pub fn objects_in_frustum(&self, apex: Vec3, corners: [Vec3; 4]) -> u64 {
        let Some(linear) = self.linear.as_ref() else {
            return u64::MAX;
        };
        let inside = corners.iter().sum::<Vec3>();
        let planes: [Vec3; 4] = std::array::from_fn(|i| {
            let n = corners[i].cross(corners[(i + 1) % 4]).normalize();
            if n.dot(inside) < 0.0 {
                -n
            } else {
                n
            }
        });
        if !planes.iter().all(|n| n.is_finite()) {
            return u64::MAX;
        }
        let apex_size = apex.abs().max_element();
        // How far beyond a plane a point `p` can lie and still be counted in.
        let margin =
            |p: Vec3| 1e-3 * p.distance(apex) + 1e-4 * p.abs().max_element().max(apex_size);
        let mut bits = 0;
        for (object, &(bounds, center, radius)) in linear.object_bounds.iter().enumerate().take(64)
        {
            if bounds.is_empty() {
                continue;
            }
            let outside = planes.iter().any(|&n| {
                let sphere_beyond = n.dot(center - apex) < -(radius * 1.001 + margin(center));
                // The box's corner furthest along the inward normal.
                let inmost = Vec3::select(n.cmpge(Vec3::ZERO), bounds.max, bounds.min);
                let box_beyond = n.dot(inmost - apex) < -margin(inmost);
                sphere_beyond || box_beyond
            });
            bits |= u64::from(!outside) << object;
        }
        bits
    }
}
