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

use crate::lanes::Float;
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
        let (kx, ky, kz) = (self.kx.index(), self.ky.index(), self.kz.index());
        let permuted = |p: Vec3| {
            let a = (p - self.origin).to_array();
            [a[kx], a[ky], a[kz]]
        };
        let shear = [self.sx, self.sy, self.sz];
        let triangle = ShearedTriangle::new([p0, p1, p2].map(permuted), shear);
        let mut uvw = triangle.edge_functions();
        if uvw.contains(&0.0) {
            uvw = triangle.edge_functions_f64();
        }
        let verdict = triangle.verdict(uvw, t_max);
        if !verdict.hits {
            return None;
        }
        let inv = 1.0 / verdict.det;
        Some((verdict.t_scaled * inv, uvw.map(|e| e * inv)))
    }
}

/// A triangle in a ray's frame, the core of the watertight test written once
/// for one ray and one triangle (`F = f32`), for one ray and several triangles
/// ([`crate::triangle_packet`]) and for several rays and one triangle
/// ([`crate::triangle_lanes`]): the corners' x and y sheared so that the ray
/// runs along +z from the origin, and their z scaled by `1/d_z`.
///
/// Each lane performs the scalar test's IEEE operations in its order, so
/// every caller's verdict and distance are bit for bit one another's.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ShearedTriangle<F> {
    ax: F,
    ay: F,
    bx: F,
    by: F,
    cx: F,
    cy: F,
    az: F,
    bz: F,
    cz: F,
}

/// What [`ShearedTriangle::verdict`] finds.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Verdict<F: Float> {
    /// Hit in (0, t_max): the edge functions share a sign, their sum `det` is
    /// finite and nonzero, and `t_scaled / det` is in range.
    pub hits: F::Mask,
    /// `u·az + v·bz + w·cz`: the distance times `det`.
    pub t_scaled: F,
    pub det: F,
}

impl<F: Float> ShearedTriangle<F> {
    /// The triangle with corners `corners` (each translated to the ray's
    /// origin and permuted so that the ray's dominant axis is z: `[x, y, z]`),
    /// sheared by the ray's `[sx, sy, sz]`.
    #[inline(always)]
    pub(crate) fn new([a, b, c]: [[F; 3]; 3], [sx, sy, sz]: [F; 3]) -> Self {
        Self {
            ax: a[0] - sx * a[2],
            ay: a[1] - sy * a[2],
            bx: b[0] - sx * b[2],
            by: b[1] - sy * b[2],
            cx: c[0] - sx * c[2],
            cy: c[1] - sy * c[2],
            az: sz * a[2],
            bz: sz * b[2],
            cz: sz * c[2],
        }
    }

    /// The 2D edge functions at the origin: `u` for the edge opposite the
    /// first corner, `v` opposite the second, `w` opposite the third.
    #[inline(always)]
    pub(crate) fn edge_functions(&self) -> [F; 3] {
        let Self {
            ax,
            ay,
            bx,
            by,
            cx,
            cy,
            ..
        } = *self;
        [cx * by - cy * bx, ax * cy - ay * cx, bx * ay - by * ax]
    }

    /// The lanes whose edge functions `uvw` hold an exact zero: the ray
    /// passes through an edge or a corner, and the functions are to be
    /// recomputed in double precision, for a consistent sign.
    #[inline(always)]
    pub(crate) fn on_edge([u, v, w]: [F; 3]) -> F::Mask {
        u.eq(F::ZERO) | v.eq(F::ZERO) | w.eq(F::ZERO)
    }

    /// The hit test of Woop et al. from the edge functions `[u, v, w]`: the
    /// ray hits iff they share a sign and `det = u + v + w` is finite and
    /// nonzero, and then `t = (u·az + v·bz + w·cz) / det` must lie in
    /// `(0, t_max)`, tested before dividing, on the scaled distance (the
    /// inequality flips with the sign of `det`: the triangle seen from
    /// behind).
    #[inline(always)]
    pub(crate) fn verdict(&self, [u, v, w]: [F; 3], t_max: F) -> Verdict<F> {
        let zero = F::ZERO;
        let det = u + v + w;
        // Mixed signs are rejected. Where `det` is finite none of u, v, w is
        // NaN (NaN would propagate into the sum), and there "no operand below
        // zero" is "all at least zero": one mask for either sign.
        let same_sign =
            (u.ge(zero) & v.ge(zero) & w.ge(zero)) | (u.le(zero) & v.le(zero) & w.le(zero));
        // det == 0 (degenerate triangle, or a ray in its plane) and overflow never hit.
        let det_ok = !det.eq(zero) & det.is_finite();
        let t_scaled = u * self.az + v * self.bz + w * self.cz;
        let bound = t_max * det;
        let front = det.gt(zero) & t_scaled.gt(zero) & t_scaled.lt(bound);
        let back = det.lt(zero) & t_scaled.lt(zero) & t_scaled.gt(bound);
        Verdict {
            hits: same_sign & det_ok & (front | back),
            t_scaled,
            det,
        }
    }
}

impl ShearedTriangle<f32> {
    /// [`Self::edge_functions`] in double precision, rounded to `f32`.
    #[cold]
    pub(crate) fn edge_functions_f64(&self) -> [f32; 3] {
        let edge = |px: f32, py: f32, qx: f32, qy: f32| {
            (px as f64 * qy as f64 - py as f64 * qx as f64) as f32
        };
        let (a, b, c) = ((self.ax, self.ay), (self.bx, self.by), (self.cx, self.cy));
        [
            edge(c.0, c.1, b.0, b.1),
            edge(a.0, a.1, c.0, c.1),
            edge(b.0, b.1, a.0, a.1),
        ]
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
