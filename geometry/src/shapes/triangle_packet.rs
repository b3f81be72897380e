//! Four triangles against one ray at once: the watertight test of
//! [`crate::triangle`] (Woop, Benthin and Wald, "Watertight Ray/Triangle
//! Intersection", JCGT 2(1), 2013) evaluated lane-wise on `Vec4`s, for BVH leaves
//! that store their triangles in structure-of-arrays form ([`TrianglePacket`]).
//!
//! Every lane performs exactly the IEEE operations of the scalar
//! [`WatertightRay::intersect`], in the same order: the same translation, axis
//! permutation and shear, the same edge functions, sums and products grouped the
//! same way, and a true division for `1 / det`. Rust never contracts `a * b + c`
//! into a fused multiply-add and glam's `Vec4` operators are plain SSE adds,
//! multiplies and divides, so each lane's verdict and distance are bit for bit
//! those of the scalar test. A BVH may therefore mix the two paths freely, and the
//! watertightness argument of the scalar test (a shared edge's function is
//! computed from the same two vertices in the same way) carries over unchanged.
//!
//! The one step that does not vectorise is the double-precision recomputation of
//! an edge function that came out exactly zero. It only happens when the ray
//! passes exactly through an edge or a vertex, so lanes that need it are simply
//! handed to the scalar test, off the common path.

use crate::lanes::Mask;
use crate::triangle::{ShearedTriangle, WatertightRay};
use glam::{Vec3, Vec4};
use wide::f32x4;

/// Four triangles, structure of arrays: `corners[v][axis]` holds coordinate `axis`
/// (0 = x, 1 = y, 2 = z) of vertex `v` (0, 1, 2) of the four triangles, one per lane.
/// Unused lanes hold NaN and are never hit.
///
/// This layout lets [`WatertightRay::intersect4`] load each coordinate of each
/// vertex of all four triangles with one aligned 16-byte read. Note that, because
/// of the NaN lanes, the derived `PartialEq` finds a packet with an unused lane
/// unequal to itself; compare [`TrianglePacket::triangle`]s' bits if needed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrianglePacket {
    pub corners: [[Vec4; 3]; 3],
}

impl TrianglePacket {
    /// A packet with every lane unused (NaN): never hit by any ray.
    pub const EMPTY: TrianglePacket = TrianglePacket {
        corners: [[Vec4::NAN; 3]; 3],
    };

    /// Up to four triangles (`[p0, p1, p2]` each) in lanes 0.., the rest NaN.
    ///
    /// # Panics
    /// If given more than four triangles.
    pub fn new(triangles: &[[Vec3; 3]]) -> Self {
        assert!(
            triangles.len() <= 4,
            "a TrianglePacket holds at most 4 triangles, got {}",
            triangles.len()
        );
        let mut packet = Self::EMPTY;
        for (lane, triangle) in triangles.iter().enumerate() {
            packet.set_lane(lane, triangle);
        }
        packet
    }

    /// Puts `triangle` (`[p0, p1, p2]`) in `lane`.
    ///
    /// # Panics
    /// If `lane >= 4`.
    pub fn set_lane(&mut self, lane: usize, triangle: &[Vec3; 3]) {
        for (vertex, p) in self.corners.iter_mut().zip(triangle) {
            for (axis, lanes) in vertex.iter_mut().enumerate() {
                lanes[lane] = p[axis];
            }
        }
    }

    /// The triangle in `lane`, as given (NaN corners for an unused lane).
    ///
    /// # Panics
    /// If `lane >= 4`.
    pub fn triangle(&self, lane: usize) -> [Vec3; 3] {
        self.corners
            .map(|c| Vec3::new(c[0][lane], c[1][lane], c[2][lane]))
    }
}

/// What the vectorised part of [`WatertightRay::intersect4`] found: the hit mask
/// and distances of the lanes whose edge functions were all nonzero, and the
/// lanes that need the scalar test because one of them was exactly zero.
#[derive(Clone, Copy, Debug)]
struct SimdResult {
    hits: u32,
    t: Vec4,
    on_edge: u32,
}

impl WatertightRay {
    /// The watertight test against the four triangles of `packet` at once: bit k of
    /// the mask is set iff `self.intersect(triangle k, t_max)` is `Some((t, _))`, and
    /// lane k of the `Vec4` is then that very `t`, bit for bit. Lanes not hit hold
    /// unspecified values. Unused (NaN) lanes and degenerate triangles are never hit.
    ///
    /// The math, per lane, is that of [`WatertightRay::intersect`] (Woop et al.
    /// 2013): with the vertices translated to the ray origin, permuted so that the
    /// ray's dominant axis is z and sheared so that the ray runs along +z,
    /// `u = cx·by − cy·bx`, `v = ax·cy − ay·cx`, `w = bx·ay − by·ax`; the ray hits
    /// iff `u, v, w` share a sign and `det = u + v + w` is finite and nonzero, and
    /// then `t = (u·az + v·bz + w·cz) / det` must lie in `(0, t_max)`, which is
    /// tested before dividing, on the scaled distance.
    #[inline]
    pub fn intersect4(&self, packet: &TrianglePacket, t_max: f32) -> (u32, Vec4) {
        let SimdResult { hits, t, on_edge } = self.intersect4_simd(packet, t_max);
        if on_edge == 0 {
            (hits, t)
        } else {
            self.intersect4_on_edges(packet, t_max, hits, t, on_edge)
        }
    }

    /// The vectorised test: exactly the operations of the scalar `intersect`
    /// ([`ShearedTriangle`], the same code), minus its double-precision
    /// fallback. Lanes with an edge function of exactly zero are reported in
    /// `on_edge`; their `hits` bits are meaningless.
    #[inline]
    fn intersect4_simd(&self, packet: &TrianglePacket, t_max: f32) -> SimdResult {
        let (kx, ky, kz) = (self.kx.index(), self.ky.index(), self.kz.index());
        let o = self.origin.to_array();
        // Translated to the ray origin (as `p - origin` in the scalar code),
        // keeping only the permuted axes: the axis arrays indexed with kx, ky, kz.
        let permuted =
            |p: &[Vec4; 3]| [kx, ky, kz].map(|k| f32x4::from(p[k].to_array()) - f32x4::splat(o[k]));
        let shear = [self.sx, self.sy, self.sz].map(f32x4::splat);
        let triangles = ShearedTriangle::new(packet.corners.each_ref().map(permuted), shear);
        let uvw = triangles.edge_functions();
        // NaN == 0 is false: unused lanes never leave the SIMD path.
        let on_edge = ShearedTriangle::on_edge(uvw).bits();
        let verdict = triangles.verdict(uvw, f32x4::splat(t_max));
        // A true division, as in the scalar code: never an approximate reciprocal.
        let t = verdict.t_scaled * (f32x4::ONE / verdict.det);
        SimdResult {
            hits: verdict.hits.bits(),
            t: Vec4::from_array(t.to_array()),
            on_edge,
        }
    }

    /// The rare lanes whose ray passes exactly through an edge or vertex: their
    /// edge functions must be recomputed in double precision, so they get the
    /// scalar test outright, which does exactly that.
    #[cold]
    #[inline(never)]
    fn intersect4_on_edges(
        &self,
        packet: &TrianglePacket,
        t_max: f32,
        mut hits: u32,
        mut t: Vec4,
        on_edge: u32,
    ) -> (u32, Vec4) {
        hits &= !on_edge;
        for lane in crate::lanes::each_set(on_edge) {
            let [p0, p1, p2] = packet.triangle(lane);
            if let Some((t_hit, _)) = self.intersect(p0, p1, p2, t_max) {
                hits |= 1 << lane;
                t[lane] = t_hit;
            }
        }
        (hits, t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Ray;

    /// xorshift64: a tiny deterministic generator, enough to spread test cases.
    struct XorShift(u64);

    impl XorShift {
        fn next_u64(&mut self) -> u64 {
            let mut x = self.0;
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            self.0 = x;
            x
        }
        /// Uniform in [0, n).
        fn below(&mut self, n: u64) -> u64 {
            self.next_u64() % n
        }
        /// Uniform in [lo, hi).
        fn range(&mut self, lo: f32, hi: f32) -> f32 {
            let unit = (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32;
            lo + (hi - lo) * unit
        }
        fn vec3(&mut self, lo: f32, hi: f32) -> Vec3 {
            Vec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
        }
        /// A point on a coarse grid (multiples of 1/4): with axis-aligned rays,
        /// edge functions then come out exactly zero on edges and vertices.
        fn grid(&mut self, half_extent: i64) -> Vec3 {
            let mut c =
                || (self.below(8 * half_extent as u64 + 1) as i64 - 4 * half_extent) as f32 / 4.0;
            Vec3::new(c(), c(), c())
        }
    }

    /// A random triangle, often degenerate or on the grid, sometimes huge enough
    /// for the edge functions to overflow.
    fn random_triangle(rng: &mut XorShift) -> [Vec3; 3] {
        let p = rng.vec3(-2.0, 2.0);
        let q = rng.vec3(-2.0, 2.0);
        let r = rng.vec3(-2.0, 2.0);
        match rng.below(12) {
            0 => [p, p, p],
            1 => [p, q, p],
            2 => [p, q, q],
            3 => [q, p, p],
            // Collinear, up to rounding.
            4 => [p, q, p + (q - p) * rng.range(-1.0, 2.0)],
            5 | 6 => [rng.grid(2), rng.grid(2), rng.grid(2)],
            7 => [p * 1e19, q * 1e19, r * 1e19],
            _ => [p, q, r],
        }
    }

    /// The scalar verdict and the packet's for every lane, asserted equal bit for bit.
    fn assert_lanes_agree(
        ray: &WatertightRay,
        triangles: &[[Vec3; 3]],
        packet: &TrianglePacket,
        t_max: f32,
    ) -> u32 {
        let (mask, t) = ray.intersect4(packet, t_max);
        assert_eq!(mask & !0b1111, 0, "mask {mask:#b} has bits beyond lane 3");
        for lane in 0..4 {
            let scalar = match triangles.get(lane) {
                Some(&[p0, p1, p2]) => ray.intersect(p0, p1, p2, t_max),
                None => None,
            };
            let hit = mask & (1 << lane) != 0;
            assert_eq!(
                hit,
                scalar.is_some(),
                "lane {lane} of {triangles:?}, ray {ray:?}, t_max {t_max}: packet {hit}, scalar {scalar:?}"
            );
            if let Some((t_scalar, _)) = scalar {
                assert_eq!(
                    t[lane].to_bits(),
                    t_scalar.to_bits(),
                    "lane {lane} of {triangles:?}, ray {ray:?}: t {} vs scalar {t_scalar}",
                    t[lane]
                );
            }
        }
        mask
    }

    #[test]
    fn every_lane_matches_the_scalar_test_bit_for_bit() {
        let mut rng = XorShift(0x9E37_79B9_7F4A_7C15);
        let axes = [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z];
        let (mut front_hits, mut back_hits, mut misses) = (0, 0, 0);
        let (mut edge_lanes, mut simd_hits) = (0, 0);
        for _ in 0..200_000 {
            let count = rng.below(5) as usize;
            let triangles: Vec<[Vec3; 3]> = (0..count).map(|_| random_triangle(&mut rng)).collect();
            let packet = TrianglePacket::new(&triangles);
            let origin = if rng.below(3) == 0 {
                rng.grid(4)
            } else {
                rng.vec3(-4.0, 4.0)
            };
            let direction = match rng.below(7) {
                0 => axes[rng.below(6) as usize] * rng.range(0.25, 4.0),
                // Exactly at a vertex of one of the triangles.
                1 if count > 0 => {
                    triangles[rng.below(count as u64) as usize][rng.below(3) as usize] - origin
                }
                // At a point inside one of the triangles (up to rounding).
                2 | 3 if count > 0 => {
                    let [p0, p1, p2] = triangles[rng.below(count as u64) as usize];
                    let (b1, b2) = (rng.range(0.0, 1.0), rng.range(0.0, 1.0));
                    let (b1, b2) = if b1 + b2 > 1.0 {
                        (1.0 - b1, 1.0 - b2)
                    } else {
                        (b1, b2)
                    };
                    p0 + (p1 - p0) * b1 + (p2 - p0) * b2 - origin
                }
                4 => rng.vec3(-1.0, 1.0),
                _ => rng.vec3(-1.5, 1.5) - origin,
            };
            if direction == Vec3::ZERO || !direction.is_finite() {
                continue;
            }
            // Some rays point away, to be rejected by the range test.
            let direction = if rng.below(4) == 0 {
                -direction
            } else {
                direction
            };
            let t_max = match rng.below(4) {
                0 => f32::INFINITY,
                1 => f32::MAX,
                _ => rng.range(0.0, 3.0),
            };
            let ray = WatertightRay::new(&Ray::new(origin, direction));
            let on_edge = ray.intersect4_simd(&packet, t_max).on_edge;
            edge_lanes += on_edge.count_ones();
            let mask = assert_lanes_agree(&ray, &triangles, &packet, t_max);
            simd_hits += (mask & !on_edge).count_ones();
            for (lane, [p0, p1, p2]) in triangles.iter().enumerate() {
                if mask & (1 << lane) == 0 {
                    misses += 1;
                } else if (*p1 - *p0).cross(*p2 - *p0).dot(direction) < 0.0 {
                    front_hits += 1;
                } else {
                    back_hits += 1;
                }
            }
        }
        // The comparison above is only meaningful if all paths were exercised.
        assert!(front_hits > 10_000, "{front_hits} hits from the front");
        assert!(back_hits > 10_000, "{back_hits} hits from the back");
        assert!(simd_hits > 10_000, "{simd_hits} hits on the SIMD path");
        assert!(misses > 10_000, "{misses} misses");
        assert!(edge_lanes > 1_000, "{edge_lanes} lanes took the f64 path");
    }

    #[test]
    fn rays_through_shared_edges_and_vertices_of_a_fan_agree_and_never_slip_through() {
        // A fan around (0, 0, −1) on a grid, packed 3 + 3 + 2 (unused lanes NaN).
        // Axis-aligned rays aimed at its vertices and edge points get edge functions
        // of exactly zero, so the f64 path is taken; oblique rays at the same
        // targets test the usual path near edges.
        let centre = Vec3::new(0.0, 0.0, -1.0);
        let rim: Vec<Vec3> = [
            (1., 0.),
            (1., 1.),
            (0., 1.),
            (-1., 1.),
            (-1., 0.),
            (-1., -1.),
            (0., -1.),
            (1., -1.),
        ]
        .iter()
        .map(|&(x, y)| Vec3::new(x, y, -1.0))
        .collect();
        let n = rim.len();
        let fan: Vec<[Vec3; 3]> = (0..n).map(|i| [centre, rim[i], rim[(i + 1) % n]]).collect();
        let groups: Vec<&[[Vec3; 3]]> = vec![&fan[0..3], &fan[3..6], &fan[6..8]];
        let packets: Vec<TrianglePacket> = groups.iter().map(|g| TrianglePacket::new(g)).collect();

        // (target, whether it is inside the fan rather than on its outer boundary).
        // A boundary edge belongs to one triangle only, so an oblique ray that
        // rounds outwards may rightly miss it; interior edges and vertices are
        // shared, and there watertightness forbids a miss.
        let mut targets = vec![(centre, true)];
        for i in 0..n {
            targets.push((rim[i], false));
            targets.push(((rim[i] + rim[(i + 1) % n]) * 0.5, false));
            for f in [0.25f32, 0.5, 0.75] {
                targets.push((centre + (rim[i] - centre) * f, true));
            }
        }
        let mut edge_lanes = 0;
        for (target, interior) in targets {
            let rays = [
                (target + Vec3::Z * 2.0, -Vec3::Z, true),
                (target - Vec3::Z * 3.0, Vec3::Z, true),
                (
                    Vec3::new(0.3, -0.7, 2.0),
                    target - Vec3::new(0.3, -0.7, 2.0),
                    false,
                ),
                (
                    Vec3::new(-1.1, 0.4, -0.5),
                    target - Vec3::new(-1.1, 0.4, -0.5),
                    false,
                ),
            ];
            for (origin, direction, axis_aligned) in rays {
                let ray = WatertightRay::new(&Ray::new(origin, direction));
                for t_max in [f32::INFINITY, 100.0] {
                    let mut hits = 0;
                    let mut on_edge = 0;
                    for (group, packet) in groups.iter().zip(&packets) {
                        hits += assert_lanes_agree(&ray, group, packet, t_max).count_ones();
                        on_edge += ray.intersect4_simd(packet, t_max).on_edge.count_ones();
                    }
                    assert!(
                        hits >= 1 || !(interior || axis_aligned),
                        "ray from {origin} to {target} slipped through the fan"
                    );
                    if axis_aligned {
                        assert!(
                            on_edge >= 1,
                            "ray from {origin} to {target} hit no edge exactly"
                        );
                    }
                    edge_lanes += on_edge;
                }
            }
        }
        assert!(edge_lanes > 0);
    }

    #[test]
    fn the_empty_packet_is_never_hit() {
        let mut rng = XorShift(0x2545_F491_4F6C_DD1D);
        let empty = TrianglePacket::new(&[]);
        for (a, b) in empty
            .corners
            .iter()
            .flatten()
            .zip(TrianglePacket::EMPTY.corners.iter().flatten())
        {
            assert!(a.is_nan_mask().all() && b.is_nan_mask().all());
        }
        for _ in 0..10_000 {
            let origin = if rng.below(2) == 0 {
                rng.grid(2)
            } else {
                rng.vec3(-4.0, 4.0)
            };
            let direction = rng.vec3(-1.0, 1.0);
            if direction == Vec3::ZERO {
                continue;
            }
            let ray = WatertightRay::new(&Ray::new(origin, direction));
            for t_max in [f32::INFINITY, f32::MAX, 1.0] {
                assert_eq!(ray.intersect4(&TrianglePacket::EMPTY, t_max).0, 0);
                assert_eq!(ray.intersect4(&empty, t_max).0, 0);
                assert_eq!(
                    ray.intersect4_simd(&TrianglePacket::EMPTY, t_max).on_edge,
                    0
                );
            }
        }
    }

    #[test]
    fn packets_keep_their_triangles_and_hit_the_right_lane() {
        let tri = [
            Vec3::new(0.0, 0.0, -2.0),
            Vec3::new(1.0, 0.0, -2.0),
            Vec3::new(0.0, 1.0, -2.0),
        ];
        let far = tri.map(|p| p - Vec3::Z);
        let aside = tri.map(|p| p + Vec3::X * 5.0);
        let packet = TrianglePacket::new(&[aside, far, tri]);
        assert_eq!(packet.triangle(0), aside);
        assert_eq!(packet.triangle(1), far);
        assert_eq!(packet.triangle(2), tri);
        assert!(packet.triangle(3).iter().all(|p| p.is_nan()));

        let ray = WatertightRay::new(&Ray::new(Vec3::new(0.25, 0.25, 0.0), -Vec3::Z));
        let (mask, t) = ray.intersect4(&packet, f32::INFINITY);
        assert_eq!(mask, 0b110);
        assert!((t[1] - 3.0).abs() < 1e-6 && (t[2] - 2.0).abs() < 1e-6);
        assert_eq!(ray.intersect4(&packet, 2.5).0, 0b100);
    }

    #[test]
    #[should_panic(expected = "at most 4")]
    fn more_than_four_triangles_do_not_fit() {
        TrianglePacket::new(&[[Vec3::ZERO; 3]; 5]);
    }
}
