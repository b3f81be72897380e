//! Watertight ray–triangle intersection: Woop, Benthin and Wald, "Watertight
//! Ray/Triangle Intersection", JCGT 2(1), 2013.
//!
//! The ray is turned into a coordinate system where it runs along +z from the
//! origin (a permutation of axes and a shear); the three 2D edge functions of the
//! sheared triangle are then evaluated at the origin. Because the edge function of
//! an edge shared by two triangles is computed from the same two vertices in the
//! same way, a ray through a shared edge or vertex can never miss both triangles:
//! no cracks. When an edge function is exactly zero it is recomputed in double
//! precision, so that a ray exactly on an edge gets a consistent sign.

use crate::Ray;
use glam::Vec3;

/// The per-ray part of the watertight test, computed once and reused for every
/// triangle the ray is tested against.
///
/// The fields are visible to the crate so that the four-wide test of
/// [`crate::triangle_packet`] can repeat exactly the same operations lane-wise.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay {
    pub(crate) origin: Vec3,
    /// Axis permutation: the ray's dominant axis becomes z.
    pub(crate) kx: Axis,
    pub(crate) ky: Axis,
    pub(crate) kz: Axis,
    /// Shear that makes the ray direction (0, 0, 1).
    pub(crate) sx: f32,
    pub(crate) sy: f32,
    pub(crate) sz: f32,
}

/// A coordinate axis. An index that is known to be below 3, so that indexing a
/// three-element array with it needs no bounds check (the permutation is applied
/// for every triangle tested).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub(crate) enum Axis {
    X = 0,
    Y = 1,
    Z = 2,
}

impl Axis {
    const ALL: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

    /// The axis after this one, cyclically.
    fn next(self) -> Axis {
        Axis::ALL[(self as usize + 1) % 3]
    }

    #[inline(always)]
    pub(crate) fn index(self) -> usize {
        self as usize
    }
}

impl WatertightRay {
    #[inline]
    pub fn new(ray: &Ray) -> Self {
        let d = ray.direction.to_array();
        let kz = Axis::ALL[ray.direction.abs().max_position()];
        let mut kx = kz.next();
        let mut ky = kx.next();
        let dz = d[kz.index()];
        // Keep the winding: swapping x and y when the ray points down z.
        if dz < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        Self {
            origin: ray.origin,
            kx,
            ky,
            kz,
            sx: d[kx.index()] / dz,
            sy: d[ky.index()] / dz,
            sz: 1.0 / dz,
        }
    }

    /// `(t, [b0, b1, b2])`: the hit distance in (0, t_max) and the barycentric
    /// weights of `p0, p1, p2`, or `None`. Both faces are hit; degenerate
    /// (zero-area) triangles never are.
    #[inline]
    pub fn intersect(&self, p0: Vec3, p1: Vec3, p2: Vec3, t_max: f32) -> Option<(f32, [f32; 3])> {
        let (a, b, c) = (p0 - self.origin, p1 - self.origin, p2 - self.origin);
        let (a, b, c) = (a.to_array(), b.to_array(), c.to_array());
        let (kx, ky, kz) = (self.kx.index(), self.ky.index(), self.kz.index());
        let ax = a[kx] - self.sx * a[kz];
        let ay = a[ky] - self.sy * a[kz];
        let bx = b[kx] - self.sx * b[kz];
        let by = b[ky] - self.sy * b[kz];
        let cx = c[kx] - self.sx * c[kz];
        let cy = c[ky] - self.sy * c[kz];
        // Edge functions: u for the edge opposite p0, v opposite p1, w opposite p2.
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            let edge = |px: f32, py: f32, qx: f32, qy: f32| {
                (px as f64 * qy as f64 - py as f64 * qx as f64) as f32
            };
            u = edge(cx, cy, bx, by);
            v = edge(ax, ay, cx, cy);
            w = edge(bx, by, ax, ay);
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let (az, bz, cz) = (self.sz * a[kz], self.sz * b[kz], self.sz * c[kz]);
        let t_scaled = u * az + v * bz + w * cz;
        // t = t_scaled / det must lie in (0, t_max), without dividing first.
        let inside = if det > 0.0 {
            t_scaled > 0.0 && t_scaled < t_max * det
        } else {
            t_scaled < 0.0 && t_scaled > t_max * det
        };
        if !inside {
            return None;
        }
        let inv = 1.0 / det;
        Some((t_scaled * inv, [u * inv, v * inv, w * inv]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hit(origin: Vec3, dir: Vec3, tri: [Vec3; 3]) -> Option<(f32, [f32; 3])> {
        WatertightRay::new(&Ray::new(origin, dir)).intersect(tri[0], tri[1], tri[2], f32::INFINITY)
    }

    #[test]
    fn hits_with_correct_distance_and_barycentrics() {
        let tri = [
            Vec3::new(0.0, 0.0, -2.0),
            Vec3::new(1.0, 0.0, -2.0),
            Vec3::new(0.0, 1.0, -2.0),
        ];
        let (t, b) = hit(Vec3::new(0.25, 0.25, 0.0), -Vec3::Z, tri).unwrap();
        assert!((t - 2.0).abs() < 1e-6);
        assert!(
            (b[0] - 0.5).abs() < 1e-6 && (b[1] - 0.25).abs() < 1e-6 && (b[2] - 0.25).abs() < 1e-6
        );
        // Both faces, and t_max respected.
        assert!(hit(Vec3::new(0.25, 0.25, -4.0), Vec3::Z, tri).is_some());
        let r = WatertightRay::new(&Ray::new(Vec3::new(0.25, 0.25, 0.0), -Vec3::Z));
        assert!(r.intersect(tri[0], tri[1], tri[2], 1.9).is_none());
        // Behind the origin, outside, parallel: misses.
        assert!(hit(Vec3::new(0.25, 0.25, 0.0), Vec3::Z, tri).is_none());
        assert!(hit(Vec3::new(0.8, 0.8, 0.0), -Vec3::Z, tri).is_none());
        assert!(hit(Vec3::new(0.25, 0.25, -2.0), Vec3::X, tri).is_none());
    }

    #[test]
    fn degenerate_triangles_are_never_hit_and_give_no_nan() {
        let o = Vec3::new(0.2, 0.1, 1.0);
        for tri in [
            [Vec3::ZERO, Vec3::ZERO, Vec3::ZERO],
            [Vec3::ZERO, Vec3::X, 2.0 * Vec3::X],
            [Vec3::ZERO, Vec3::X, Vec3::X],
        ] {
            assert!(hit(o, -Vec3::Z, tri).is_none());
            assert!(hit(Vec3::new(0.5, 0.0, 1.0), -Vec3::Z, tri).is_none());
        }
    }

    #[test]
    fn a_ray_through_a_shared_edge_or_vertex_hits_exactly_one_side_or_both() {
        // A fan of triangles around the origin in z = −1, sharing edges and the
        // central vertex; rays aimed exactly at the shared vertex and at points on
        // shared edges must hit at least one triangle of the fan.
        let n = 7;
        let rim: Vec<Vec3> = (0..n)
            .map(|i| {
                let a = i as f32 / n as f32 * std::f32::consts::TAU;
                Vec3::new(a.cos(), a.sin(), -1.0)
            })
            .collect();
        let centre = Vec3::new(0.0, 0.0, -1.0);
        let fan: Vec<[Vec3; 3]> = (0..n).map(|i| [centre, rim[i], rim[(i + 1) % n]]).collect();
        let origins = [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.3, -0.7, 2.0),
            Vec3::new(-1.1, 0.4, 0.5),
        ];
        for origin in origins {
            let mut targets = vec![centre];
            for r in &rim {
                for f in [0.1f32, 0.37, 0.5, 0.83] {
                    targets.push(centre + (*r - centre) * f);
                }
            }
            for target in targets {
                let hits = fan
                    .iter()
                    .filter(|t| hit(origin, target - origin, **t).is_some())
                    .count();
                assert!(hits >= 1, "ray from {origin} to {target} slipped through");
            }
        }
    }
}
