//! One triangle against [`LANES`] rays at once: the watertight test of
//! [`crate::triangle`] (Woop, Benthin and Wald, JCGT 2(1), 2013) with each
//! lane a ray of its own, for BVH leaves that several rays reach together.
//!
//! Each ray has its own frame: the axis its direction is largest along
//! becomes z, so the permutation differs from lane to lane. A corner's
//! coordinates are picked per lane by selects (or indexed once, where every
//! lane shares its permutation: the common case for a pixel's camera rays or
//! one point's shadow rays), and then [`ShearedTriangle`] runs the scalar
//! test's operations in every lane, so each lane's verdict and distance are
//! bit for bit those of [`WatertightRay::intersect`]. Lanes whose ray passes
//! exactly through an edge or a corner take the scalar test, whose
//! double-precision fallback gives the edge a consistent sign.
//!
//! A BVH leaf's four triangles (a [`TrianglePacket`]) are tested against the
//! rays that reach it as (ray, triangle) pairs, four rays per test
//! ([`WatertightLanes::packet_hits`]): the same operations, lanes filled by
//! pairs rather than by rays, since few of the rays reach any one leaf.

use crate::counters::count;
use crate::lanes::{self, F32Lanes, Mask, U32Lanes, LANES};
use crate::triangle::{ShearedTriangle, WatertightRay};
use crate::{RayLanes, TrianglePacket};

/// Triangles in a [`TrianglePacket`].
const PACKET_WIDTH: usize = 4;
/// Rays per test in [`WatertightLanes::packet_hits`]: one per four lanes.
const PAIR_RAYS: usize = LANES / PACKET_WIDTH;
use glam::Vec3;

/// Per lane, which coordinate an axis of the ray's frame takes: x where
/// `is_x`, else y where `is_y`, else z.
#[derive(Clone, Copy, Debug)]
struct AxisLanes {
    is_x: F32Lanes,
    is_y: F32Lanes,
}

impl AxisLanes {
    /// Each lane's coordinate of `(x, y, z)`.
    #[inline(always)]
    fn pick(&self, [x, y, z]: [F32Lanes; 3]) -> F32Lanes {
        self.is_x.select(x, self.is_y.select(y, z))
    }

    /// `a` in the lanes of `mask`, `b` in the others.
    #[inline(always)]
    fn select(mask: F32Lanes, a: Self, b: Self) -> Self {
        Self {
            is_x: mask.select(a.is_x, b.is_x),
            is_y: mask.select(a.is_y, b.is_y),
        }
    }

    /// The axis as an index, where the lanes `active` all take the same.
    fn uniform(&self, active: u32) -> Option<usize> {
        let (x, y) = (self.is_x.bits() & active, self.is_y.bits() & active);
        match (x, y & !x) {
            (x, 0) if x == active => Some(0),
            (0, y) if y == active => Some(1),
            (0, 0) => Some(2),
            _ => None,
        }
    }
}

/// [`LANES`] rays prepared for the watertight test: [`WatertightRay::new`]
/// in every lane.
pub(crate) struct WatertightLanes<'a> {
    rays: &'a RayLanes,
    /// The axes of each lane's frame: x, y, z (the dominant one).
    axes: [AxisLanes; 3],
    /// The axes as indices, where every active lane shares them.
    uniform: Option<[usize; 3]>,
    /// Each lane's origin, permuted into its frame.
    origin: [F32Lanes; 3],
    /// `[sx, sy, sz]`: the shear that makes each lane's direction (0, 0, 1).
    shear: [F32Lanes; 3],
}

impl<'a> WatertightLanes<'a> {
    /// The rays of `rays`, for the lanes `active` (the others' answers are
    /// to be ignored).
    #[inline]
    pub(crate) fn new(rays: &'a RayLanes, active: u32) -> Self {
        let (o, d) = (&rays.origin, &rays.direction);
        let (x, y, z) = (d.x.abs(), d.y.abs(), d.z.abs());
        // glam's `max_position`: y if above x, then z if above the larger.
        let y_above = y.simd_gt(x);
        let z_above = z.simd_gt(y_above.select(y, x));
        let no = F32Lanes::ZERO;
        let kz = AxisLanes {
            is_x: !(y_above | z_above),
            is_y: y_above & !z_above,
        };
        let kz_is_z = !(kz.is_x | kz.is_y);
        // The next axes cyclically: z → x → y for kz = z, and so on.
        let kx = AxisLanes {
            is_x: kz_is_z,
            is_y: kz.is_x,
        };
        let ky = AxisLanes {
            is_x: kz.is_y,
            is_y: kz_is_z,
        };
        let direction = [d.x, d.y, d.z];
        let dz = kz.pick(direction);
        // Keep the winding: x and y swapped where the ray points down z.
        let down = dz.simd_lt(no);
        let (kx, ky) = (
            AxisLanes::select(down, ky, kx),
            AxisLanes::select(down, kx, ky),
        );
        let axes = [kx, ky, kz];
        let uniform = match axes.map(|axis| axis.uniform(active)) {
            [Some(x), Some(y), Some(z)] => Some([x, y, z]),
            _ => None,
        };
        let origin = [o.x, o.y, o.z];
        Self {
            rays,
            axes,
            uniform,
            origin: axes.map(|axis| axis.pick(origin)),
            shear: [
                kx.pick(direction) / dz,
                ky.pick(direction) / dz,
                F32Lanes::ONE / dz,
            ],
        }
    }

    /// The lanes of `active` whose ray hits the triangle `corners` in
    /// (0, `t_max`), each lane with its own `t_max`, and in those lanes the
    /// distance: bit for bit [`WatertightRay::intersect`] of each lane's ray.
    #[inline]
    pub(crate) fn hits(
        &self,
        corners: &[Vec3; 3],
        t_max: F32Lanes,
        active: u32,
    ) -> (u32, F32Lanes) {
        self.hits_of(|vertex, axis| corners[vertex][axis], t_max, active)
    }

    /// [`Self::hits`] for the triangle whose corner `vertex`'s coordinate
    /// `axis` is `coordinate(vertex, axis)`: read straight from where the
    /// triangle is kept (a leaf's packet), with no copy of its corners.
    #[inline(always)]
    pub(crate) fn hits_of(
        &self,
        coordinate: impl Fn(usize, usize) -> f32,
        t_max: F32Lanes,
        active: u32,
    ) -> (u32, F32Lanes) {
        let permuted = |vertex: usize| -> [F32Lanes; 3] {
            let coordinates = match self.uniform {
                Some(axes) => axes.map(|k| F32Lanes::splat(coordinate(vertex, k))),
                None => {
                    let splat = [0, 1, 2].map(|k| F32Lanes::splat(coordinate(vertex, k)));
                    self.axes.map(|axis| axis.pick(splat))
                }
            };
            // `p − origin` in the ray's frame: the scalar test's subtraction.
            [0, 1, 2].map(|i| coordinates[i] - self.origin[i])
        };
        let triangle = ShearedTriangle::new([0, 1, 2].map(permuted), self.shear);
        let uvw = triangle.edge_functions();
        let verdict = triangle.verdict(uvw, t_max);
        let mut hits = verdict.hits.bits() & active;
        let on_edge = ShearedTriangle::on_edge(uvw).bits() & active;
        if hits | on_edge == 0 {
            // No lane's distance is read: the division (a sixteen-lane one
            // takes the divider 16 cycles) is skipped.
            return (0, verdict.t_scaled);
        }
        // A true division, as in the scalar test.
        let mut t = verdict.t_scaled * (F32Lanes::ONE / verdict.det);
        if on_edge != 0 {
            let corners =
                [0, 1, 2].map(|v| Vec3::new(coordinate(v, 0), coordinate(v, 1), coordinate(v, 2)));
            (hits, t) = self.on_edges(&corners, t_max, (hits, t), on_edge);
        }
        (hits, t)
    }

    /// The four triangles of `packet` against the rays of the lanes `reach`:
    /// `hit(lane, slot, t)` for each ray that hits the triangle in `slot` in
    /// (0, `t_max`), `t` bit for bit [`WatertightRay::intersect`]'s (NaN
    /// slots, a leaf's padding, are never hit).
    ///
    /// A leaf is mostly reached by a few of the rays (by 3.3 of a camera
    /// packet's 16 on average), so the (ray, triangle) pairs are what fill
    /// the lanes: [`PAIR_RAYS`] rays at a time, each in four lanes, one per
    /// triangle. Lane `j` tests ray `rays[j / 4]` against triangle `j % 4`,
    /// its ray's data moved there by a lane permute and the triangle's
    /// coordinates by a 4-lane broadcast; its operations are the scalar
    /// test's. Where the triangle-by-triangle test ([`Self::hits_of`]) takes
    /// four tests of all the lanes, this takes ⌈reach / [`PAIR_RAYS`]⌉.
    #[inline(always)]
    pub(crate) fn packet_hits(
        &self,
        packet: &TrianglePacket,
        t_max: f32,
        reach: u32,
        mut hit: impl FnMut(usize, usize, f32),
    ) {
        count(|c| c.triangle_tests += (PACKET_WIDTH as u32 * reach.count_ones()) as u64);
        let mut rest = reach;
        while rest != 0 {
            let (rays, pairs) = next_rays(&mut rest);
            let index = U32Lanes::new(lanes::array_from_fn(|j| rays[j / PACKET_WIDTH]));
            let of_rays = |v: F32Lanes| lanes::permute(v, index);
            let origin = self.origin.map(of_rays);
            let axes = self.uniform.ok_or_else(|| {
                self.axes.map(|axis| AxisLanes {
                    is_x: of_rays(axis.is_x),
                    is_y: of_rays(axis.is_y),
                })
            });
            let permuted = |vertex: usize| -> [F32Lanes; 3] {
                let corner = |axis: usize| each_triangle(packet.corners[vertex][axis]);
                let coordinates = match axes {
                    Ok(axes) => axes.map(corner),
                    Err(axes) => axes.map(|axis| axis.pick([0, 1, 2].map(corner))),
                };
                [0, 1, 2].map(|i| coordinates[i] - origin[i])
            };
            let shear = self.shear.map(of_rays);
            let triangle = ShearedTriangle::new([0, 1, 2].map(permuted), shear);
            let uvw = triangle.edge_functions();
            let verdict = triangle.verdict(uvw, F32Lanes::splat(t_max));
            let hits = verdict.hits.bits() & pairs;
            let on_edge = ShearedTriangle::on_edge(uvw).bits() & pairs;
            if hits | on_edge == 0 {
                continue;
            }
            let pair = |j: usize| (rays[j / PACKET_WIDTH] as usize, j % PACKET_WIDTH);
            let t = verdict.t_scaled * (F32Lanes::ONE / verdict.det);
            for j in lanes::each_set(hits & !on_edge) {
                let (lane, slot) = pair(j);
                hit(lane, slot, t.as_array()[j]);
            }
            for j in lanes::each_set(on_edge) {
                let (lane, slot) = pair(j);
                let [p0, p1, p2] = packet.triangle(slot);
                let ray = WatertightRay::new(&self.rays.lane(lane));
                if let Some((t, _)) = ray.intersect(p0, p1, p2, t_max) {
                    hit(lane, slot, t);
                }
            }
        }
    }

    /// The lanes `on_edge`, whose ray passes exactly through an edge or a
    /// corner, tested alone: the scalar test recomputes their edge functions
    /// in double precision.
    #[cold]
    #[inline(never)]
    fn on_edges(
        &self,
        [p0, p1, p2]: &[Vec3; 3],
        t_max: F32Lanes,
        (mut hits, mut t): (u32, F32Lanes),
        on_edge: u32,
    ) -> (u32, F32Lanes) {
        hits &= !on_edge;
        for lane in lanes::each_set(on_edge) {
            let ray = WatertightRay::new(&self.rays.lane(lane));
            if let Some((t_hit, _)) = ray.intersect(*p0, *p1, *p2, t_max.as_array()[lane]) {
                hits |= 1 << lane;
                t.as_mut_array()[lane] = t_hit;
            }
        }
        (hits, t)
    }
}

/// Takes up to [`PAIR_RAYS`] of the lanes of `rest`, lowest first: their
/// indices (the first repeated into the unused places) and the lanes of a
/// [`WatertightLanes::packet_hits`] test that hold them, four per ray.
#[inline(always)]
fn next_rays(rest: &mut u32) -> ([u32; PAIR_RAYS], u32) {
    let mut rays = [rest.trailing_zeros(); PAIR_RAYS];
    let mut used = 0;
    while used < PAIR_RAYS && *rest != 0 {
        rays[used] = rest.trailing_zeros();
        *rest &= *rest - 1;
        used += 1;
    }
    let pairs = (1u64 << (used * PACKET_WIDTH)) - 1;
    (rays, pairs as u32)
}

/// A packet's row of four (one coordinate of one corner of each triangle)
/// repeated across the lanes: lane `j` holds triangle `j % 4`'s
/// (`vbroadcastf32x4` on AVX-512).
#[inline(always)]
fn each_triangle(row: glam::Vec4) -> F32Lanes {
    let row: [f32; PACKET_WIDTH] = row.into();
    lanes::from_fn(|j| row[j % PACKET_WIDTH])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::test_support::XorShift;
    use crate::lanes::LANES;
    use crate::Ray;

    /// Each lane's verdict and distance are the scalar test's, bit for bit:
    /// rays along and against every axis (every permutation and both
    /// windings, mixed in one set and shared by all), rays through the
    /// corners and edges (the double-precision fallback), grazing rays in
    /// the triangle's plane, degenerate triangles, and per-lane limits.
    #[test]
    fn every_lane_is_the_scalar_test_bit_for_bit() {
        let mut rng = XorShift(0x7a1e);
        let (mut hits, mut on_edges, mut mixed) = (0, 0, 0);
        for round in 0..4000 {
            let (corners, rays) = awkward_case(&mut rng, round);
            let lanes = RayLanes::new(rays);
            let t_max = F32Lanes::new(std::array::from_fn(|k| match k % 3 {
                0 => f32::INFINITY,
                _ => 4.0 * rng.unit(),
            }));
            let active = lanes::all_bits() & !(1 << (round % LANES));
            let prepared = WatertightLanes::new(&lanes, active);
            mixed += usize::from(prepared.uniform.is_none());
            let (hit, t) = prepared.hits(&corners, t_max, active);
            assert_eq!(hit & !active, 0, "an inactive lane reported");
            for (k, ray) in rays
                .iter()
                .enumerate()
                .filter(|&(k, _)| active >> k & 1 == 1)
            {
                let scalar = WatertightRay::new(ray);
                let want =
                    scalar.intersect(corners[0], corners[1], corners[2], t_max.as_array()[k]);
                let lane = (hit >> k & 1 == 1).then(|| t.as_array()[k]);
                assert_eq!(
                    lane.map(f32::to_bits),
                    want.map(|(t, _)| t.to_bits()),
                    "lane {k}: {ray:?} against {corners:?}"
                );
                hits += usize::from(want.is_some());
            }
            on_edges += prepared_on_edge(&prepared, &corners, active);
        }
        assert!(hits > 250 * LANES, "{hits} hits");
        assert!(on_edges > 100, "{on_edges} lanes through an edge or corner");
        assert!(mixed > 1_000, "{mixed} sets with mixed frames");
        assert!(mixed < 3_000, "{mixed} sets with mixed frames of 4000");
    }

    /// Round `round`'s triangle and rays: a degenerate triangle every few
    /// rounds (a repeated corner, or three in a row); rays along and against
    /// every axis (every permutation and both windings, mixed in one set or
    /// one frame shared by all), rays along an axis exactly through a corner
    /// (two edge functions exactly zero), through the middle of an edge, and
    /// along an edge, in the triangle's plane.
    fn awkward_case(rng: &mut XorShift, round: usize) -> ([Vec3; 3], [Ray; LANES]) {
        let mut corners = [
            rng.vec3(-2.0, 2.0),
            rng.vec3(-2.0, 2.0),
            rng.vec3(-2.0, 2.0),
        ];
        match round % 7 {
            0 => corners[2] = corners[1],
            1 => corners[2] = corners[0] + 2.0 * (corners[1] - corners[0]),
            _ => {}
        }
        let shared = round.is_multiple_of(3);
        let axis = Vec3::AXES[round % 3] * if round.is_multiple_of(2) { 1.0 } else { -1.0 };
        let origin = rng.vec3(-4.0, 4.0);
        let rays = std::array::from_fn(|k| {
            let corner = corners[k % 3];
            if k % 4 == 0 {
                let along = if shared { axis } else { Vec3::AXES[k % 3] };
                return Ray::new(corner - 3.0 * along, along);
            }
            let target = match k % 4 {
                1 => 0.5 * (corner + corners[(k + 1) % 3]),
                _ => rng.vec3(-2.0, 2.0),
            };
            let direction = match shared {
                true => axis * 4.0 + 0.3 * rng.vec3(-1.0, 1.0),
                false if k == 5 => corners[1] - corners[0],
                false => target - origin,
            };
            Ray::new(origin, direction)
        });
        (corners, rays)
    }

    /// A whole packet against a few rays at a time reports each (ray,
    /// triangle) hit of the scalar test once, with its distance bit for bit,
    /// and nothing else: the awkward cases above, with the round's triangle
    /// beside its mirror image (sharing an edge), a random one and either
    /// padding or another random one; any subset of the lanes reaching it,
    /// from one ray to all; with and without a limit.
    #[test]
    fn packets_of_pairs_are_the_scalar_test_bit_for_bit() {
        let mut rng = XorShift(0x9a1e_5eed);
        let (mut hits, mut on_edges, mut padded) = (0, 0, 0);
        for round in 0..4000 {
            let (corners, rays) = awkward_case(&mut rng, round);
            let [a, b, c] = corners;
            let mut triangles = vec![
                corners,
                [b, a, a + b - c],
                [0; 3].map(|_| rng.vec3(-2.0, 2.0)),
            ];
            if round % 2 == 0 {
                triangles.push([0; 3].map(|_| rng.vec3(-2.0, 2.0)));
            }
            let mut slots: Vec<usize> = (0..triangles.len()).collect();
            slots.rotate_left(round % triangles.len());
            let triangles: Vec<[Vec3; 3]> = slots.iter().map(|&k| triangles[k]).collect();
            let packet = TrianglePacket::new(&triangles);
            padded += usize::from(triangles.len() < PACKET_WIDTH);
            let t_max = match round % 3 {
                0 => f32::INFINITY,
                _ => 4.0 * rng.unit(),
            };
            let reach = match round % 4 {
                0 => lanes::all_bits(),
                1 => 1 << (round / 4 % LANES),
                _ => rng.next_u64() as u32 & lanes::all_bits(),
            };
            let lanes = RayLanes::new(rays);
            let prepared = WatertightLanes::new(&lanes, lanes::all_bits());
            let mut reported = Vec::new();
            prepared.packet_hits(&packet, t_max, reach, |lane, slot, t| {
                reported.push((lane, slot, t.to_bits()))
            });
            let mut wanted = Vec::new();
            for lane in lanes::each_set(reach) {
                let scalar = WatertightRay::new(&rays[lane]);
                for (slot, [p0, p1, p2]) in triangles.iter().enumerate() {
                    if let Some((t, _)) = scalar.intersect(*p0, *p1, *p2, t_max) {
                        wanted.push((lane, slot, t.to_bits()));
                    }
                }
                on_edges += prepared_on_edge(&prepared, &triangles[0], 1 << lane);
            }
            reported.sort_unstable();
            assert_eq!(reported, wanted, "round {round}, reach {reach:#x}");
            hits += wanted.len();
        }
        assert!(hits > 8_000, "{hits} hits");
        assert!(
            on_edges > 4_000,
            "{on_edges} lanes through an edge or corner"
        );
        assert!(padded > 1_500, "{padded} packets with padding");
    }

    /// How many lanes of `active` hold an exactly zero edge function.
    fn prepared_on_edge(prepared: &WatertightLanes, corners: &[Vec3; 3], active: u32) -> u32 {
        let mut count = 0;
        for k in lanes::each_set(active) {
            let ray = WatertightRay::new(&prepared.rays.lane(k));
            let (kx, ky, kz) = (ray.kx.index(), ray.ky.index(), ray.kz.index());
            let permuted = |p: &Vec3| {
                let a = (*p - ray.origin).to_array();
                [a[kx], a[ky], a[kz]]
            };
            let triangle =
                ShearedTriangle::new(corners.each_ref().map(permuted), [ray.sx, ray.sy, ray.sz]);
            count += u32::from(ShearedTriangle::<f32>::on_edge(triangle.edge_functions()));
        }
        count
    }
}
