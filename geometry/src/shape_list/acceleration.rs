//! The acceleration structure of a [`ShapeList`]: a BVH over the bounded
//! primitives (each analytic shape, each triangle; or, beside the linear
//! layout's packets of spheres and parallelograms, the others), with the
//! primitives stored in the BVH's leaf order and each leaf's triangles as one
//! four-lane packet.

use super::{LinearShapes, Object, Primitive, ShapeList};
use crate::bvh::{Bounds3, Bvh, BvhStats, LEAF_WIDTH};
use crate::counters::count;
use crate::lanes::F32Lanes;
use crate::triangle::WatertightRay;
use crate::triangle_lanes::WatertightLanes;
use crate::{Ray, RayLanes, Shape, TrianglePacket};
use glam::Vec4;

/// Below this many primitives [`ShapeList::build_acceleration`] builds no BVH.
pub const LINEAR_LIMIT: usize = 32;

impl ShapeList {
    /// Builds what makes the scene's queries fastest, with the same answers
    /// whichever it builds:
    /// - below 32 primitives (`LINEAR_LIMIT`), no BVH: the linear loop, with
    ///   spheres and parallelograms laid out in packets of four;
    /// - with more, and at most 32 spheres and parallelograms (a mesh in a
    ///   room, say), those in packets and a BVH over the rest. Big walls in a
    ///   BVH would widen every box above them; in packets, shadow rays skip
    ///   them wholesale ([`ShapeList::occluders_towards`]);
    /// - otherwise a BVH over every bounded primitive.
    pub fn build_acceleration(&mut self) {
        let primitives: usize = self
            .objects
            .iter()
            .map(|o| match *o {
                Object::Shape(_) => 1,
                Object::Mesh(m) => self.meshes[m as usize].triangle_count(),
            })
            .sum();
        let packed = (0..self.objects.len() as u32)
            .filter(|&o| self.packs(o))
            .count();
        if primitives < LINEAR_LIMIT || packed == primitives && packed <= LINEAR_LIMIT {
            self.bvh = None;
            self.linear = Some(LinearShapes::new(self, true));
        } else if packed > 0 && packed <= LINEAR_LIMIT {
            self.build_bvh_over(|list, object| !list.packs(object));
            self.linear = Some(LinearShapes::new(self, false));
        } else {
            self.build_bvh();
        }
    }

    /// Whether object `object` goes in a packet of the linear layout: a sphere
    /// or a parallelogram.
    fn packs(&self, object: u32) -> bool {
        match self.objects[object as usize] {
            Object::Shape(s) => matches!(
                self.shapes[s as usize],
                Shape::Sphere(_) | Shape::Parallelogram(_)
            ),
            Object::Mesh(_) => false,
        }
    }

    /// Builds the BVH over every bounded primitive (binned SAH; see [`Bvh`]).
    pub fn build_bvh(&mut self) {
        self.build_bvh_over(|_, _| true);
    }

    /// Builds the BVH over the bounded primitives of the objects `include`
    /// takes, and drops the linear layout.
    fn build_bvh_over(&mut self, include: impl Fn(&ShapeList, u32) -> bool) {
        self.linear = None;
        // Sized up front: a mesh's millions of triangles, grown by doubling,
        // would briefly hold half again.
        let most: usize = (self.objects.iter())
            .map(|kind| match *kind {
                Object::Shape(_) => 1,
                Object::Mesh(m) => self.meshes[m as usize].triangle_count(),
            })
            .sum();
        let mut bounds = Vec::with_capacity(most);
        // Each object's first primitive, in the order of `bounds`: a list of
        // the primitives themselves would be held through the build.
        let mut runs = Vec::new();
        self.unbounded.clear();
        for (object, kind) in self.objects.iter().enumerate() {
            let object = object as u32;
            if !include(self, object) {
                continue;
            }
            match *kind {
                Object::Shape(s) => match self.shapes[s as usize].bounds() {
                    Some(b) => {
                        runs.push((bounds.len(), object));
                        bounds.push(b);
                    }
                    None => self.unbounded.push(object),
                },
                Object::Mesh(m) => {
                    let mesh = &self.meshes[m as usize];
                    runs.push((bounds.len(), object));
                    for triangle in 0..mesh.triangle_count() as u32 {
                        let (lo, hi) = mesh.triangle_bounds(triangle);
                        bounds.push(Bounds3::new(lo, hi));
                    }
                }
            }
        }
        let count = bounds.len();
        let mut bvh = Bvh::build_owned(bounds);
        let order = bvh.take_primitive_order();
        // Primitive `i` is triangle `i − first` of the last run starting at
        // or before it (a shape's run has one); past the end, padding.
        let primitive = |i: usize| {
            let run = runs.partition_point(|&(first, _)| first <= i) - 1;
            let (first, object) = runs[run];
            let triangle = (i - first) as u32;
            Primitive { object, triangle }
        };
        self.primitives = order
            .iter()
            .map(|&i| match (i as usize) < count {
                true => primitive(i as usize),
                false => Primitive::PADDING,
            })
            .collect();
        let leaves = self.primitives.chunks_exact(LEAF_WIDTH);
        self.packets = leaves.clone().map(|leaf| self.packet_of(leaf)).collect();
        self.shape_lanes = leaves
            .map(|leaf| {
                leaf.iter().enumerate().fold(0u8, |lanes, (lane, p)| {
                    match self.objects.get(p.object as usize) {
                        Some(Object::Shape(_)) => lanes | 1 << lane,
                        _ => lanes,
                    }
                })
            })
            .collect();
        self.bvh = Some(bvh);
    }

    /// The triangles of one leaf as a packet; other lanes NaN.
    fn packet_of(&self, leaf: &[Primitive]) -> TrianglePacket {
        let mut packet = TrianglePacket::EMPTY;
        for (lane, p) in leaf.iter().enumerate() {
            if let Some(Object::Mesh(m)) = self.objects.get(p.object as usize) {
                packet.set_lane(lane, &self.meshes[*m as usize].corners(p.triangle));
            }
        }
        packet
    }

    /// The hits of the leaf at `first` (a multiple of [`LEAF_WIDTH`]) in
    /// (0, t_max): bit `k` of the mask for the primitive at `first + k`, lane `k`
    /// its distance. Triangles are tested four at a time, shapes one by one.
    #[inline]
    pub(super) fn leaf_hits(
        &self,
        first: u32,
        ray: &Ray,
        watertight: &WatertightRay,
        t_max: f32,
    ) -> (u32, Vec4) {
        let leaf = first as usize / LEAF_WIDTH;
        let shapes = self.shape_lanes[leaf];
        if shapes != 0xf {
            count(|c| c.triangle_tests += 4);
        }
        let (mut hits, mut t) = watertight.intersect4(&self.packets[leaf], t_max);
        for lane in crate::lanes::each_set(u32::from(shapes)) {
            let p = self.primitives[first as usize + lane];
            if let Object::Shape(s) = self.objects[p.object as usize] {
                if let Some(d) = self.shapes[s as usize].hit_distance(ray, t_max) {
                    hits |= 1 << lane;
                    t[lane] = d;
                }
            }
        }
        (hits, t)
    }

    /// The hits of the leaf at `first` for the rays of `reach` (lanes of
    /// `rays`, prepared as `watertight`): `visit(slot, hits, t)` for each
    /// primitive the leaf holds, in slot order, with the lanes of `reach`
    /// whose ray hits it in (0, `t_max`) and their distances, bit for bit
    /// each ray's [`Self::leaf_hits`]. A visit that returns `true` ends the
    /// leaf.
    #[inline(always)]
    pub(super) fn leaf_hits_lanes(
        &self,
        first: u32,
        (rays, watertight): (&RayLanes, &WatertightLanes),
        t_max: f32,
        reach: u32,
        mut visit: impl FnMut(usize, u32, F32Lanes) -> bool,
    ) {
        let leaf = first as usize / LEAF_WIDTH;
        let shapes = self.shape_lanes[leaf];
        let tested = u64::from(reach.count_ones());
        if shapes != 0xf {
            count(|c| c.triangle_tests += LEAF_WIDTH as u64 * tested);
        }
        let packet = &self.packets[leaf];
        let t_max_lanes = F32Lanes::splat(t_max);
        for slot in 0..LEAF_WIDTH {
            let (hits, t) = match shapes >> slot & 1 {
                1 => {
                    let p = self.primitives[first as usize + slot];
                    let Object::Shape(s) = self.objects[p.object as usize] else {
                        unreachable!("a shape's slot holds a shape");
                    };
                    self.shapes[s as usize].hit_distance_lanes(rays, t_max, tested)
                }
                _ => {
                    // Through the array: indexing a `Vec4` by a lane not known
                    // at compile time compiles to a jump table.
                    let coordinate = |vertex: usize, axis: usize| {
                        let lanes: &[f32; 4] = packet.corners[vertex][axis].as_ref();
                        lanes[slot]
                    };
                    // Padding (NaN) ends a leaf's run.
                    if coordinate(0, 0).is_nan() {
                        break;
                    }
                    watertight.hits_of(coordinate, t_max_lanes, reach)
                }
            };
            if visit(slot, hits & reach, t) {
                break;
            }
        }
    }

    /// The packet of the leaf at `first`, where the leaf holds only triangles.
    #[inline(always)]
    pub(super) fn triangle_packet(&self, first: u32) -> Option<&TrianglePacket> {
        let leaf = first as usize / LEAF_WIDTH;
        (self.shape_lanes[leaf] == 0).then(|| &self.packets[leaf])
    }

    /// Statistics of the BVH, once built.
    pub fn bvh_stats(&self) -> Option<BvhStats> {
        self.bvh.as_ref().map(Bvh::stats)
    }

    /// Where the packet of the leaf at `first` is, for prefetching: only an
    /// address (see [`RayStream::leaf_address`](crate::bvh::RayStream::leaf_address)).
    #[inline(always)]
    pub(super) fn leaf_address(&self, first: u32) -> *const u8 {
        let packets = self.packets.as_ptr();
        packets.wrapping_add(first as usize / LEAF_WIDTH).cast()
    }
}
