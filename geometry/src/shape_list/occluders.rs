//! Shadow rays towards an area light, with the shapes that cannot be in their way
//! culled once per shading point.
//!
//! Every shadow ray from a point `p` to a point of a light lies in the convex hull
//! of `p` and the light's corners: a pyramid with apex `p` over the light. A shape
//! whose bounding sphere lies wholly outside one of the pyramid's five face planes
//! (by more than a margin covering the rays' offset origins and rounding) cannot
//! block any of them, so [`ShapeList::occluders_towards`] leaves it out once for all
//! the light's samples at that point, and [`ShapeList::any_hit_among`] tests only
//! the rest. The answers are [`ShapeList::any_hit`]'s: only shapes that cannot be hit
//! are skipped. (In the Cornell box a floor point's 16 shadow rays to the light
//! then test one or two spheres instead of ten shapes.)

use super::{LinearShapes, ObjectRef, ShapeList};
use crate::bvh::Bounds3;
use crate::counters::count;
use crate::lanes::{self, F32Lanes, LANES};
use crate::triangle_lanes::WatertightLanes;
use crate::{Ray, RayLanes, Shape};
use glam::{Vec3, Vec4};
use glint_lanes::Vector3;
use wide::f32x4;

/// The shapes of a [`ShapeList`] that may block shadow rays from one point to one
/// light: bit `4k + lane` for lane `lane` of the linear loop's packet `k` (sphere
/// packets, then parallelogram packets), and bit `i` of `others` for the linear
/// loop's other object `i` (planes can be culled; boxes and meshes, and
/// whatever a BVH holds, are always tested).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Occluders {
    lanes: u64,
    others: u32,
    /// Whether the shapes were culled for one point's segments (else the
    /// rays may still be culled as a batch, by their segments' bounds).
    culled: bool,
}

impl Occluders {
    /// Every shape (no culling).
    pub const ALL: Occluders = Occluders {
        lanes: u64::MAX,
        others: u32::MAX,
        culled: false,
    };

    /// Whether the linear loop's other object `i` is kept (past 32, always).
    #[inline]
    pub(super) fn keeps_other(&self, i: usize) -> bool {
        self.others
            .checked_shr(i as u32)
            .is_none_or(|bits| bits & 1 == 1)
    }

    /// How many packed shapes may block the rays (64 meaning "all").
    pub fn count(&self) -> u32 {
        self.lanes.count_ones()
    }

    /// The lanes kept of packet `k`.
    #[inline]
    fn packet(&self, k: usize) -> u32 {
        (self.lanes.checked_shr(4 * k as u32).unwrap_or(0) & 0xf) as u32
    }
}

/// The most packets whose lanes [`Occluders`] can name; a linear loop never has
/// more (it holds at most 32 shapes, so at most 8 packets of each kind).
const MAX_PACKETS: usize = 16;

impl ShapeList {
    /// The shapes that may block a segment from any point within `reach` of
    /// `from` to any point of the convex
    /// polygon `light` (an area light's corners, in order around it), short of
    /// its ends. The objects `exclude` names are left out if flat: the surface the
    /// segments leave (a flat shape cannot block rays leaving it) and the light's
    /// own surface (shadow rays stop short of it). So are one-sided parallelograms
    /// with the whole light in front of them
    /// ([`ParallelogramPacket::facing_away_from`](crate::ParallelogramPacket::facing_away_from)),
    /// before any test against the pyramid. Culls only in the linear loop's
    /// layout; otherwise [`Occluders::ALL`].
    ///
    /// With `reach` > 0 one answer serves nearby points (a pixel's samples on
    /// one surface): a point `x = (1−s)p + s·q` of a segment from `p`, within
    /// `reach` of `from`, to `q` on the light lies within `(1−s)·reach ≤ reach`
    /// of the segment from `from` to `q`, so widening each face of the pyramid
    /// by `reach` keeps every shape such segments can meet.
    pub fn occluders_towards(
        &self,
        from: Vec3,
        reach: f32,
        light: &[Vec3; 4],
        exclude: [u32; 2],
    ) -> Occluders {
        let Some(linear) = self.linear.as_ref().filter(|l| l.packets() <= MAX_PACKETS) else {
            return Occluders::ALL;
        };
        let Some(planes) = pyramid_planes(from, light, reach) else {
            return self.occluders_but(exclude);
        };
        let mut lanes = 0u64;
        let mut bit = 0;
        for (center, radius) in &linear.sphere_bounds {
            // A sphere is kept unless it lies wholly outside a face.
            let mut keep = Vec4::ONE.cmpgt(Vec4::ZERO);
            for plane in &planes {
                keep &= plane
                    .distance(center)
                    .cmple(*radius + Vec4::splat(plane.margin));
            }
            lanes |= (keep.bitmask() as u64) << bit;
            bit += 4;
        }
        let margin = planes[0].margin - reach;
        for (corners, (packet, _)) in linear
            .parallelogram_corners
            .iter()
            .zip(&linear.parallelograms)
        {
            // One-sided walls with the light in front of them never block it.
            let facing_away = packet.facing_away_from(light, margin) as u64;
            let used = corners[0][0].cmpeq(corners[0][0]).bitmask() as u64;
            if used & !facing_away == 0 {
                bit += 4;
                continue;
            }
            // A parallelogram is kept unless its four corners lie outside one face.
            let mut outside = Vec4::ZERO.cmpgt(Vec4::ONE);
            for plane in &planes {
                let margin = Vec4::splat(plane.margin);
                let mut all = Vec4::ONE.cmpgt(Vec4::ZERO);
                for corner in corners {
                    all &= plane.distance(corner).cmpgt(margin);
                }
                outside |= all;
            }
            // NaN (unused) lanes are never outside: drop them by their corner.
            let used = corners[0][0].cmpeq(corners[0][0]);
            lanes |= ((used & !outside).bitmask() as u64 & !facing_away) << bit;
            bit += 4;
        }
        let others = self.planes_kept(linear, from, light, planes[0].margin, exclude);
        Occluders {
            lanes: lanes & !flat_lanes(linear, exclude),
            others,
            culled: true,
        }
    }

    /// Every shape but the flat ones `exclude` names (the surface shadow rays
    /// leave, the light's own), which [`Self::occluders_towards`] leaves out
    /// however little else it culls: they never block such a segment, but a
    /// ray from far away at a grazing angle may meet its light's surface by
    /// rounding, just short of its end. [`Occluders::ALL`] outside the linear
    /// loop's layout.
    pub fn occluders_but(&self, exclude: [u32; 2]) -> Occluders {
        let Some(linear) = self.linear.as_ref().filter(|l| l.packets() <= MAX_PACKETS) else {
            return Occluders::ALL;
        };
        let mut others = u32::MAX;
        for (i, &object) in linear.others.iter().enumerate().take(32) {
            if exclude.contains(&object)
                && matches!(self.object(object), ObjectRef::Shape(Shape::Plane(_)))
            {
                others &= !(1 << i);
            }
        }
        Occluders {
            lanes: !flat_lanes(linear, exclude),
            others,
            culled: false,
        }
    }

    /// The linear loop's other objects that may block the segments of
    /// [`Self::occluders_towards`] (bit i for object i): all but the planes
    /// `exclude` names (flat) and those with the light and every point within
    /// `margin` of `from` strictly on one side, which no such segment crosses.
    fn planes_kept(
        &self,
        linear: &LinearShapes,
        from: Vec3,
        light: &[Vec3; 4],
        margin: f32,
        exclude: [u32; 2],
    ) -> u32 {
        let mut kept = u32::MAX;
        for (i, &object) in linear.others.iter().enumerate().take(32) {
            let ObjectRef::Shape(Shape::Plane(plane)) = self.object(object) else {
                continue;
            };
            // The margin (far past the segments' offsets and the rounding of
            // the distances) grows with the plane's point, as their error does.
            let margin = margin + 1e-3 * plane.point().abs().max_element();
            if exclude.contains(&object) || plane.separates_none(from, light, margin) {
                kept &= !(1 << i);
            }
        }
        kept
    }

    /// [`ShapeList::any_hit`] for a shadow ray from the point and towards the light
    /// `occluders` was made for: the same answer, testing only those shapes.
    pub fn any_hit_among(&self, occluders: &Occluders, ray: &Ray, t_max: f32) -> bool {
        let Some(linear) = self
            .linear
            .as_ref()
            .filter(|_| *occluders != Occluders::ALL)
        else {
            return self.any_hit(ray, t_max);
        };
        let spheres = linear.spheres.len();
        linear.spheres.iter().enumerate().any(|(k, (packet, _))| {
            let lanes = occluders.packet(k);
            lanes != 0 && packet.hit4(ray, t_max).0 & lanes != 0
        }) || linear
            .parallelograms
            .iter()
            .enumerate()
            .any(|(k, (packet, _))| {
                let lanes = occluders.packet(spheres + k);
                lanes != 0 && packet.hit4(ray, t_max).0 & lanes != 0
            })
            || self.rest_hit(linear, occluders, ray, t_max)
    }
}

/// The lanes whose shadow rays are not tested against a flat object: none
/// (`()`), or those whose ray leaves it (`leaving[k]` is the object).
trait SkippedLanes: Copy {
    fn of(self, object: u32) -> u32;
}

impl SkippedLanes for () {
    #[inline(always)]
    fn of(self, _: u32) -> u32 {
        0
    }
}

impl SkippedLanes for &[u32; LANES] {
    #[inline(always)]
    fn of(self, object: u32) -> u32 {
        lanes::bits_eq(self, object)
    }
}

impl ShapeList {
    /// [`ShapeList::any_hit_among`] for the rays in the lanes of `rays` that
    /// `active` names (bit k for lane k), all with the same `t_max`: the lanes
    /// whose ray is blocked. Each lane's answer is the one its ray gets alone.
    /// (The `--stats` counts differ: a kept shape counts one test per active
    /// ray, and BVH nodes and leaves count once per ray that reaches them.)
    /// One shape is tested against all the rays at once
    /// ([`Sphere::hits_lanes`](crate::Sphere::hits_lanes)), which pays for the
    /// shadow rays of one point, all meeting the same few shapes.
    pub fn any_hits_among(
        &self,
        occluders: &Occluders,
        rays: &RayLanes,
        t_max: f32,
        active: u32,
    ) -> u32 {
        self.hits_among(occluders, rays, t_max, active, ())
    }

    /// [`ShapeList::any_hits_among`] for rays that each leave a surface of
    /// their own: lane k's ray is not tested against object `leaving[k]`
    /// where that is flat (a parallelogram or a plane), as
    /// [`ShapeList::occluders_but`] leaves a point's own flat surface out of
    /// its shadow rays' shapes: the same answers as each ray tested alone
    /// against the occluders of its own point, for rays from points on
    /// several surfaces.
    // Out of line: only chunks of lanes on several objects take it (inlined,
    // it measured the same).
    #[inline(never)]
    pub fn any_hits_among_leaving(
        &self,
        occluders: &Occluders,
        rays: &RayLanes,
        t_max: f32,
        active: u32,
        leaving: &[u32; LANES],
    ) -> u32 {
        // Where `occluders_but` leaves nothing out, neither does this.
        match self.linear.as_ref().filter(|l| l.packets() <= MAX_PACKETS) {
            Some(_) => self.hits_among(occluders, rays, t_max, active, leaving),
            None => self.hits_among(occluders, rays, t_max, active, ()),
        }
    }

    /// The one kernel of [`ShapeList::any_hits_among`] and
    /// [`ShapeList::any_hits_among_leaving`]: `skip` names the lanes each
    /// flat object is not tested against.
    #[inline(always)]
    fn hits_among(
        &self,
        occluders: &Occluders,
        rays: &RayLanes,
        t_max: f32,
        active: u32,
        skip: impl SkippedLanes,
    ) -> u32 {
        let tested_on = |object: u32| active & !skip.of(object);
        let Some(linear) = &self.linear else {
            return match self.bvh {
                Some(_) => self.bvh_hits_lanes(rays, t_max, active),
                // Not built: the rays one by one, through every object.
                None => self.lane_by_lane(active, |lane| self.any_hit(&rays.lane(lane), t_max)),
            };
        };
        let tested = u64::from(active.count_ones());
        let mut blocked = 0;
        // Rays from several points, not culled for one point (`Occluders::ALL`):
        // only the shapes near their segments. After a point's own culling
        // this would cost more than it saves.
        let reach = (!occluders.culled).then(|| segments_bounds(rays, t_max, active));
        let spheres = linear.spheres.iter().map(|(_, objects)| objects);
        let parallelograms = linear.parallelograms.iter().map(|(_, objects)| objects);
        for (k, objects) in spheres.chain(parallelograms).enumerate() {
            let kept = occluders.packet(k);
            for (lane, &object) in objects.iter().enumerate() {
                if kept >> lane & 1 == 0 || object == u32::MAX {
                    continue;
                }
                let bounds = &linear.object_bounds[object as usize].0;
                if reach.as_ref().is_some_and(|reach| !reach.overlaps(bounds)) {
                    continue;
                }
                blocked |= active
                    & match self.object(object) {
                        ObjectRef::Shape(Shape::Sphere(s)) => {
                            count(|c| c.sphere_tests += tested);
                            s.hits_lanes(rays, t_max)
                        }
                        ObjectRef::Shape(Shape::Parallelogram(p)) => {
                            count(|c| c.parallelogram_tests += tested);
                            p.hits_lanes(rays, t_max) & tested_on(object)
                        }
                        _ => unreachable!("packets hold spheres and parallelograms"),
                    };
                if blocked == active {
                    return blocked;
                }
            }
        }
        let others = (occluders, tested_on);
        blocked |= self.others_hits_lanes(linear, others, rays, t_max, active & !blocked);
        blocked | self.bvh_hits_lanes(rays, t_max, active & !blocked)
    }

    /// The lanes of `active` whose ray meets an object of the linear loop
    /// outside its packets, kept by `occluders`: planes, boxes and each
    /// triangle of a mesh (where the loop holds one) against all the rays at
    /// once, each lane's verdict its ray's alone.
    // Inlined into the kernel's two instances, as it was into the one
    // before (out of line, callgrind counted 2.7% more instructions on
    // `cornell-set1`).
    #[inline(always)]
    fn others_hits_lanes(
        &self,
        linear: &LinearShapes,
        (occluders, tested_on): (&Occluders, impl Fn(u32) -> u32),
        rays: &RayLanes,
        t_max: f32,
        active: u32,
    ) -> u32 {
        let tested = u64::from(active.count_ones());
        let mut blocked = 0;
        let mut watertight = None;
        let kept = (linear.others.iter().enumerate()).filter(|&(i, _)| occluders.keeps_other(i));
        for (_, &object) in kept {
            if blocked == active {
                return blocked;
            }
            blocked |= active
                & match self.object(object) {
                    ObjectRef::Shape(Shape::Plane(p)) => {
                        count(|c| c.plane_tests += tested);
                        p.hit_distance_lanes(rays, t_max).0 & tested_on(object)
                    }
                    ObjectRef::Shape(Shape::Box(b)) => {
                        count(|c| c.box_tests += tested);
                        b.hit_distance_lanes(rays, t_max).0
                    }
                    ObjectRef::Mesh(mesh) => {
                        let watertight =
                            watertight.get_or_insert_with(|| WatertightLanes::new(rays, active));
                        let limit = F32Lanes::splat(t_max);
                        let mut hits = 0;
                        for triangle in 0..mesh.triangle_count() as u32 {
                            let open = active & !blocked & !hits;
                            if open == 0 {
                                break;
                            }
                            count(|c| c.triangle_tests += tested);
                            hits |= watertight.hits(&mesh.corners(triangle), limit, open).0;
                        }
                        hits
                    }
                    ObjectRef::Shape(_) => {
                        unreachable!("spheres and parallelograms are in the packets")
                    }
                };
        }
        blocked
    }

    /// The lanes of `active` whose ray meets an unbounded plane or a primitive
    /// of the BVH (none without one): each plane against all the rays at once,
    /// the BVH walked by all of them together
    /// ([`Bvh::any_hit_lanes`](crate::bvh::Bvh::any_hit_lanes)).
    fn bvh_hits_lanes(&self, rays: &RayLanes, t_max: f32, active: u32) -> u32 {
        let Some(bvh) = &self.bvh else {
            return 0;
        };
        let tested = u64::from(active.count_ones());
        let blocked =
            (self.unbounded.iter()).fold(0, |blocked, &object| match self.object(object) {
                ObjectRef::Shape(plane) => {
                    blocked | plane.hit_distance_lanes(rays, t_max, tested).0
                }
                ObjectRef::Mesh(_) => unreachable!("the unbounded objects are planes"),
            }) & active;
        // The rays' triangle tests, prepared once, when a leaf is first reached.
        let watertight = std::cell::OnceCell::new();
        let leaf_blocked = |first, _, reach| {
            let watertight =
                watertight.get_or_init(|| WatertightLanes::new(rays, active & !blocked));
            let mut blocked = 0;
            if let Some(packet) = self.triangle_packet(first) {
                watertight.packet_hits(packet, t_max, reach, |lane, _, _| blocked |= 1 << lane);
                return blocked;
            }
            self.leaf_hits_lanes(first, (rays, watertight), t_max, reach, |_, hits, _| {
                blocked |= hits;
                blocked == reach
            });
            blocked
        };
        let leaf_address = |first| self.leaf_address(first);
        blocked | bvh.any_hit_lanes(rays, t_max, active & !blocked, leaf_blocked, leaf_address)
    }

    /// The lanes of `active` for which `blocked(lane)` holds.
    fn lane_by_lane(&self, active: u32, mut blocked: impl FnMut(usize) -> bool) -> u32 {
        (0..LANES)
            .filter(|&lane| active >> lane & 1 == 1 && blocked(lane))
            .fold(0, |bits, lane| bits | 1 << lane)
    }
}

/// The box around the segments `origin` to `origin + t_max·direction` of the
/// lanes of `active`, widened by 10⁻⁴ of its coordinates' size: every point
/// where one of those rays can hit a shape with `0 < t < t_max`, with room
/// to spare for rounding.
fn segments_bounds(rays: &RayLanes, t_max: f32, active: u32) -> Bounds3 {
    let ends = rays.at(F32Lanes::splat(t_max));
    let mask = lanes::from_bits(active);
    let axis = |o: F32Lanes, e: F32Lanes| {
        // 0·∞ = NaN: with t_max infinite, a ray keeps a coordinate its
        // direction does not change.
        let e = e.is_nan().select(o, e);
        let (lo, hi) = (o.min(e), o.max(e));
        // A ray with a NaN coordinate hits nothing (every test compares
        // false), so it needs no room.
        let (min, max) = (lanes::min_lane(lo, mask), lanes::max_lane(hi, mask));
        (min, max)
    };
    let (x, y, z) = (
        axis(rays.origin.x, ends.x),
        axis(rays.origin.y, ends.y),
        axis(rays.origin.z, ends.z),
    );
    let (min, max) = (Vec3::new(x.0, y.0, z.0), Vec3::new(x.1, y.1, z.1));
    let margin = 1e-4 * min.abs().max(max.abs()).max_element();
    Bounds3 {
        min: min - margin,
        max: max + margin,
    }
}

/// A face of the pyramid: a point `x` is outside when `normal · x − offset > margin`.
#[derive(Clone, Copy, Debug)]
struct Face {
    normal: Vec3,
    offset: f32,
    margin: f32,
}

impl Face {
    /// `normal · x − offset` for four points given as `[x, y, z]` lanes.
    #[inline]
    fn distance(&self, x: &[Vec4; 3]) -> Vec4 {
        x[0] * Vec4::splat(self.normal.x)
            + x[1] * Vec4::splat(self.normal.y)
            + x[2] * Vec4::splat(self.normal.z)
            - Vec4::splat(self.offset)
    }
}

/// The bits of the flat shapes among `objects`: a flat shape never blocks a
/// ray leaving its own surface, nor one that ends (short of) on it.
fn flat_lanes(linear: &LinearShapes, objects: [u32; 2]) -> u64 {
    let flat = |object: u32| linear.flat_bits.get(object as usize).copied().flatten();
    objects
        .into_iter()
        .filter_map(flat)
        .fold(0, |bits, flat| bits | 1 << flat)
}

/// The outward faces of the pyramid with apex `apex` over the convex polygon
/// `corners`. `None` if the apex lies in the polygon's plane (no pyramid: nothing
/// is culled).
fn pyramid_planes(apex: Vec3, corners: &[Vec3; 4], reach: f32) -> Option<[Face; 5]> {
    let centroid = 0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
    // Shadow rays start up to a few hundred ULPs off `apex` and end within rounding
    // of the polygon: a margin far above both, relative to the coordinates' size.
    let size = corners.iter().fold(apex.abs().max_element(), |m, c| {
        m.max(c.abs().max_element())
    });
    let margin = 1e-3 * (1.0 + size) + reach;
    let sides = side_faces(apex, corners, centroid, 1e-6 * (1.0 + size), margin)?;
    // The base: the polygon's plane, outward away from the apex.
    let base = (corners[1] - corners[0])
        .cross(corners[3] - corners[0])
        .try_normalize()?;
    let height = base.dot(apex - corners[0]);
    let clear = height.abs() > 1e-6 * (1.0 + size);
    if !clear {
        return None;
    }
    let normal = if height > 0.0 { -base } else { base };
    let base = Face {
        normal,
        offset: normal.dot(corners[0]),
        margin,
    };
    Some([sides[0], sides[1], sides[2], sides[3], base])
}

/// The pyramid's four sides, one per lane: the planes through the apex and
/// each edge of the polygon, facing away from `centroid`. `None` if a side is
/// degenerate or passes within `clearance` of the centroid.
fn side_faces(
    apex: Vec3,
    corners: &[Vec3; 4],
    centroid: Vec3,
    clearance: f32,
    margin: f32,
) -> Option<[Face; 4]> {
    let lanes = |axis: usize| f32x4::new(corners.map(|c| c[axis]));
    let corners = Vector3::new(lanes(0), lanes(1), lanes(2));
    let a = corners.sub_splat(apex);
    // Lane i holds edge i's second corner: the lanes rotated by one.
    let next = |v: f32x4| {
        let [x, y, z, w] = v.to_array();
        f32x4::new([y, z, w, x])
    };
    let b = Vector3::new(next(a.x), next(a.y), next(a.z));
    let (normal, ok) = a.cross(&b).try_normalize();
    let inside = normal.dot_splat(centroid - apex);
    // Also false for NaN: then nothing is culled.
    let usable = ok & inside.abs().simd_gt(f32x4::splat(clearance));
    if !usable.all() {
        return None;
    }
    let flip = inside.simd_gt(f32x4::ZERO);
    let normal = Vector3::select(flip, &-normal, &normal);
    let offset = normal.dot_splat(apex).to_array();
    let (nx, ny, nz) = (
        normal.x.to_array(),
        normal.y.to_array(),
        normal.z.to_array(),
    );
    Some(std::array::from_fn(|i| Face {
        normal: Vec3::new(nx[i], ny[i], nz[i]),
        offset: offset[i],
        margin,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::test_support::XorShift;
    use crate::{Parallelogram, Sphere};

    /// The course's Cornell box (walls one-sided, facing in), its four spheres and
    /// its light.
    fn cornell() -> (ShapeList, [Vec3; 4]) {
        let mut list = ShapeList::new();
        let wall = |o: [f32; 3], e1: [f32; 3], e2: [f32; 3], n: Vec3| {
            Parallelogram::new(o.into(), e1.into(), e2.into(), false)
                .unwrap()
                .facing(n)
        };
        list.push(wall(
            [-10., -10., -10.],
            [20., 0., 0.],
            [0., 20., 0.],
            Vec3::Z,
        ));
        list.push(wall(
            [-6., -7., -11.],
            [0., 0., 20.],
            [0., 20., 0.],
            Vec3::X,
        ));
        list.push(wall(
            [6., -7., -11.],
            [0., 0., 20.],
            [0., 20., 0.],
            -Vec3::X,
        ));
        list.push(wall(
            [-7., -6., -11.],
            [20., 0., 0.],
            [0., 0., 20.],
            Vec3::Y,
        ));
        list.push(wall(
            [-7., 6., -11.],
            [20., 0., 0.],
            [0., 0., 20.],
            -Vec3::Y,
        ));
        for (c, r) in [
            ([3., 1., -7.], 1.5),
            ([2., -3.2, -5.], 1.0),
            ([-4., 2., -5.], 1.8),
            ([-2., -4.5, -8.], 2.0),
        ] {
            list.push(Sphere::new(c.into(), r).unwrap());
        }
        let light = wall([-1., 5.9, -7.], [2., 0., 0.], [0., 0., 2.], -Vec3::Y);
        list.push(light);
        list.build_acceleration();
        (list, light.corners())
    }

    #[test]
    fn a_floor_point_keeps_only_what_stands_between_it_and_the_light() {
        let (list, light) = cornell();
        // Far from the spheres: nothing at all (the floor is its own surface).
        let open = list.occluders_towards(Vec3::new(4.0, -6.0, 0.0), 0.0, &light, [3, 9]);
        assert_eq!(open.count(), 0, "{open:?}");
        // Under the small sphere at (2, −3.2, −5): that sphere alone.
        let under = list.occluders_towards(Vec3::new(1.9, -6.0, -5.0), 0.0, &light, [3, 9]);
        assert_eq!(
            under,
            Occluders {
                lanes: 1 << 1,
                others: u32::MAX,
                culled: true,
            }
        );
    }

    /// From a point so far away along the floor that the pyramid over the
    /// light degenerates, nothing is culled but the flat surfaces named: the
    /// floor the rays leave and the light's own, which a grazing ray from
    /// there may meet by rounding.
    #[test]
    fn a_point_too_far_to_cull_from_still_leaves_out_its_own_and_the_lights_surface() {
        let (list, light) = cornell();
        let far = list.occluders_towards(Vec3::new(4.0e7, -6.0, 0.0), 0.0, &light, [3, 9]);
        assert_eq!(far, list.occluders_but([3, 9]));
        assert_ne!(far, Occluders::ALL);
        assert_eq!(far.count(), 64 - 2, "{far:?}");
        // Near, the same exclusions on top of the pyramid's culling.
        let near = list.occluders_towards(Vec3::new(4.0, -6.0, 0.0), 0.0, &light, [3, 9]);
        assert_eq!(near.count(), 0, "{near:?}");
    }

    /// A ground plane, a wall plane, a two-sided plane tilted across the space
    /// between the ground and the light, a sphere, and a light above them.
    fn planes() -> (ShapeList, [Vec3; 4]) {
        let mut list = ShapeList::new();
        let plane =
            |p: [f32; 3], n: [f32; 3]| crate::Plane::new(p.into(), n.into(), false).unwrap();
        list.push(plane([0.0, 0.0, 0.0], [0.0, 1.0, 0.0]));
        list.push(plane([5.0, 0.0, 0.0], [-1.0, 0.0, 0.0]));
        list.push(
            crate::Plane::new(Vec3::new(0.0, 2.0, 0.0), Vec3::new(0.3, 1.0, 0.0), true).unwrap(),
        );
        list.push(Sphere::new(Vec3::new(1.0, 1.0, 0.0), 0.5).unwrap());
        let light = Parallelogram::new(
            Vec3::new(-1.0, 4.0, -1.0),
            Vec3::X * 2.0,
            Vec3::Z * 2.0,
            false,
        )
        .unwrap()
        .facing(-Vec3::Y);
        list.push(light);
        list.build_acceleration();
        (list, light.corners())
    }

    #[test]
    fn planes_no_shadow_segment_crosses_are_culled() {
        let (list, light) = planes();
        let kept = |o: Occluders| (0..3).map(|i| o.keeps_other(i)).collect::<Vec<_>>();
        // On the ground: its own plane and the wall beside are culled; the
        // tilted plane, between the point and the light, is kept.
        let ground = list.occluders_towards(Vec3::new(2.0, 0.0, 0.0), 0.0, &light, [0, 4]);
        assert_eq!(kept(ground), [false, false, true]);
        // Above the tilted plane, on the light's side of all three: none.
        let clear = list.occluders_towards(Vec3::new(2.0, 3.0, 0.0), 0.0, &light, [3, 4]);
        assert_eq!(kept(clear), [false, false, false]);
        // Under the ground, the light above it: the ground is kept.
        let under = list.occluders_towards(Vec3::new(2.0, -1.0, 0.0), 0.0, &light, [3, 4]);
        assert!(under.keeps_other(0));
        // Past the wall: the wall is kept.
        let past = list.occluders_towards(Vec3::new(6.0, 1.0, 0.0), 0.0, &light, [3, 4]);
        assert!(past.keeps_other(1));
        assert!(Occluders::ALL.keeps_other(0) && Occluders::ALL.keeps_other(40));
    }

    /// Shadow rays from points on several surfaces, each leaving its own
    /// flat surface out (`any_hits_among_leaving`), get the answers each ray
    /// gets alone against its own point's shapes (`occluders_but`), even
    /// where a ray runs into its own surface; without, such rays would be
    /// blocked. Walls in packets and unbounded planes alike.
    #[test]
    fn rays_leaving_their_own_flat_surfaces_skip_them_lane_by_lane() {
        for (list, light_object) in [(cornell().0, 9), (planes().0, 4)] {
            let mut rng = XorShift(0x2545_f491_4f6c_dd1d);
            let mut next = move || rng.unit();
            let (mut own_hits, mut chunks) = (0, 0);
            for _ in 0..400 {
                let mut own = [u32::MAX; LANES];
                let rays: [Ray; LANES] = std::array::from_fn(|k| {
                    let eye = Vec3::new(0.5, 1.0, 8.0);
                    let aim = Vec3::new(next() * 12.0 - 6.0, next() * 12.0 - 6.0, -9.0);
                    let Some(hit) = list.closest_hit(&Ray::new(eye, aim - eye), f32::INFINITY)
                    else {
                        return Ray::new(eye, Vec3::Y);
                    };
                    own[k] = hit.shape;
                    // From just off the surface, towards anywhere: into it
                    // as often as away.
                    let n = hit.geometric_normal;
                    let away = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5);
                    Ray::new(hit.point + 1e-3 * n, away * 8.0)
                });
                let all = lanes::all_bits();
                let occluders = list.occluders_but([light_object, light_object]);
                let lanes = RayLanes::new(rays);
                let leaving = list.any_hits_among_leaving(&occluders, &lanes, 1.0, all, &own);
                let plain = list.any_hits_among(&occluders, &lanes, 1.0, all);
                for (k, ray) in rays.iter().enumerate() {
                    let alone = list.occluders_but([own[k], light_object]);
                    let expected = list.any_hit_among(&alone, ray, 1.0);
                    assert_eq!(
                        leaving >> k & 1 == 1,
                        expected,
                        "lane {k}, leaving {}",
                        own[k]
                    );
                }
                own_hits += (plain & !leaving).count_ones();
                chunks += 1;
            }
            assert!(
                own_hits > 100,
                "{own_hits} rays met their own surface in {chunks} chunks"
            );
        }
    }

    /// Culled planes never change an answer: shadow rays from points on every
    /// surface and in between get the full loop's answer, one by one and in lanes.
    #[test]
    fn culled_planes_leave_every_shadow_answer_as_it_was() {
        let (list, light) = planes();
        let mut rng = XorShift(0x9e37_79b9_7f4a_7c15);
        let mut next = move || rng.unit();
        let (mut blocked, mut culled) = (0, 0);
        for _ in 0..3000 {
            let aim = Vec3::new(next() * 12.0 - 6.0, next() * 6.0 - 2.0, next() * 8.0 - 4.0);
            // Below the tilted plane: the ground, the sphere, the plane's underside.
            let eye = Vec3::new(0.5, 1.0, 8.0);
            let ray = Ray::new(eye, aim - eye);
            let Some(hit) = list.closest_hit(&ray, f32::INFINITY) else {
                continue;
            };
            let reach = 0.2 * next();
            let occluders = list.occluders_towards(hit.point, reach, &light, [hit.shape, 4]);
            culled += (0..3).filter(|&i| !occluders.keeps_other(i)).count();
            let targets: [Vec3; LANES] = std::array::from_fn(|_| {
                let (a, b) = (next(), next());
                light[0] + a * (light[1] - light[0]) + b * (light[3] - light[0])
            });
            let shadows = targets.map(|t| crate::spawn_ray_to(&hit, &crate::RayTarget::exact(t)));
            let mut expected = 0u32;
            for (k, shadow) in shadows.iter().enumerate() {
                let full = list.any_hit(shadow, 1.0);
                assert_eq!(list.any_hit_among(&occluders, shadow, 1.0), full);
                expected |= (full as u32) << k;
                blocked += full as u32;
            }
            let lanes = RayLanes::new(shadows);
            let all = lanes::all_bits();
            assert_eq!(list.any_hits_among(&occluders, &lanes, 1.0, all), expected);
        }
        assert!(
            blocked > 500 && culled > 2000,
            "{blocked} blocked, {culled} culled"
        );
    }

    /// Culling never changes an answer: shadow rays from points all over the box's
    /// walls and spheres to points of the light get the course loop's answer.
    #[test]
    fn culled_shadow_rays_get_the_answers_of_the_full_loop() {
        let (list, light) = cornell();
        let mut plain = ShapeList::new();
        for k in 0..list.len() as u32 {
            if let crate::ObjectRef::Shape(s) = list.object(k) {
                plain.push(*s);
            }
        }
        let mut rng = XorShift(0x2545_f491_4f6c_dd1d);
        let mut next = move || rng.unit();
        let (mut blocked, mut culled, mut culled_near) = (0, 0, 0);
        for _ in 0..4000 {
            let aim = Vec3::new(
                next() * 12.0 - 6.0,
                next() * 12.0 - 6.0,
                next() * 20.0 - 11.0,
            );
            // The first surface a ray from the camera towards `aim` meets.
            let ray = Ray::new(Vec3::new(0.0, 0.0, 10.0), aim - Vec3::new(0.0, 0.0, 10.0));
            let Some(hit) = plain.closest_hit(&ray, f32::INFINITY) else {
                continue;
            };
            let occluders = list.occluders_towards(hit.point, 0.0, &light, [hit.shape, 9]);
            culled += 64 - occluders.count().min(64);
            // The answer for a ball around a point near this one serves this one.
            let reach = 0.5 * next();
            let off = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5);
            let near = hit.point + off.normalize_or_zero() * reach * next();
            let widened = list.occluders_towards(near, reach, &light, [hit.shape, 9]);
            culled_near += 64 - widened.count().min(64);
            for _ in 0..4 {
                let (a, b) = (next(), next());
                let target = light[0] + a * (light[1] - light[0]) + b * (light[3] - light[0]);
                let shadow = crate::spawn_ray_to(&hit, &crate::RayTarget::exact(target));
                let t_max = 1.0;
                let expected = plain.any_hit(&shadow, t_max);
                assert_eq!(list.any_hit_among(&occluders, &shadow, t_max), expected);
                assert_eq!(list.any_hit_among(&widened, &shadow, t_max), expected);
                blocked += expected as u32;
            }
        }
        assert!(
            blocked > 500 && culled > 1000 && culled_near > 1000,
            "{blocked} blocked, {culled} culled, {culled_near} culled near"
        );
    }
}
