//! The linear loop of a small scene, in structure-of-arrays form: spheres and
//! parallelograms four to a packet ([`SpherePacket`], [`ParallelogramPacket`]),
//! each packet one four-lane test, and the other objects (planes, boxes, small
//! meshes) one by one. The answers are the scalar loop's, bit for bit: each lane
//! computes exactly the scalar test, and the closest hit is chosen by the same
//! rule (nearest, ties to the lowest object).

use super::{Object, ShapeList};
use crate::bvh::Bounds3;
use crate::{ParallelogramPacket, Shape, SpherePacket};
use glam::{Vec3, Vec4};

/// A scene's objects laid out for the linear loop.
#[derive(Clone, Debug, Default)]
pub(super) struct LinearShapes {
    /// Packets of four spheres, with each lane's object index.
    pub(super) spheres: Vec<(SpherePacket, [u32; 4])>,
    /// Packets of four parallelograms, with each lane's object index.
    pub(super) parallelograms: Vec<(ParallelogramPacket, [u32; 4])>,
    /// Objects tested one by one.
    pub(super) others: Vec<u32>,
    /// Per sphere packet, the spheres as `[x, y, z]` centre lanes and radii.
    pub(super) sphere_bounds: Vec<([Vec4; 3], Vec4)>,
    /// Per parallelogram packet, the four corners of each lane's parallelogram.
    pub(super) parallelogram_corners: Vec<[[Vec4; 3]; 4]>,
    /// Per object, the bit [`Occluders`](super::Occluders) names a flat shape by
    /// (a parallelogram's packet and lane), or `None`.
    pub(super) flat_bits: Vec<Option<u8>>,
    /// Per object, its bounds and bounding sphere (centre, radius), for culling
    /// whole batches of rays; empty bounds for objects outside the packets.
    pub(super) object_bounds: Vec<(Bounds3, Vec3, f32)>,
}

impl LinearShapes {
    /// The sphere and parallelogram packets.
    pub(super) fn packets(&self) -> usize {
        self.sphere_bounds.len() + self.parallelogram_corners.len()
    }

    /// The packets of `list`'s spheres and parallelograms, and with `others`
    /// its other objects to be tested one by one (without, a BVH holds them).
    pub(super) fn new(list: &ShapeList, with_others: bool) -> Self {
        let mut spheres = Vec::new();
        let mut parallelograms = Vec::new();
        let mut others = Vec::new();
        for (object, kind) in list.objects.iter().enumerate() {
            let object = object as u32;
            match *kind {
                Object::Shape(s) => match &list.shapes[s as usize] {
                    Shape::Sphere(sphere) => spheres.push((object, *sphere)),
                    Shape::Parallelogram(p) => parallelograms.push((object, *p)),
                    _ => others.push(object),
                },
                Object::Mesh(_) => others.push(object),
            }
        }
        if !with_others {
            others.clear();
        }
        let mut flat_bits = vec![None; list.objects.len()];
        let first_flat = 4 * spheres.len().div_ceil(4);
        for (k, (object, _)) in parallelograms.iter().enumerate() {
            flat_bits[*object as usize] = u8::try_from(first_flat + k).ok();
        }
        let mut object_bounds = vec![(Bounds3::EMPTY, Vec3::ZERO, 0.0); list.objects.len()];
        for (object, sphere) in &spheres {
            let bounds = Shape::Sphere(*sphere)
                .bounds()
                .expect("a sphere is bounded");
            object_bounds[*object as usize] = (bounds, sphere.center(), sphere.radius());
        }
        for (object, p) in &parallelograms {
            let bounds = Shape::Parallelogram(*p).bounds().expect("bounded");
            let (e1, e2) = p.edges();
            let radius = 0.5 * (e1 + e2).length().max((e1 - e2).length());
            object_bounds[*object as usize] = (bounds, p.center(), radius);
        }
        Self {
            object_bounds,
            sphere_bounds: lanes_of(&spheres, |s| {
                let (c, r) = (s.center(), s.radius());
                ([c.x, c.y, c.z].map(Vec4::splat), Vec4::splat(r))
            }),
            parallelogram_corners: lanes_of(&parallelograms, |p| {
                p.corners().map(|c| [c.x, c.y, c.z].map(Vec4::splat))
            }),
            flat_bits,
            spheres: packets(&spheres, SpherePacket::EMPTY, SpherePacket::set_lane),
            parallelograms: packets(
                &parallelograms,
                ParallelogramPacket::EMPTY,
                ParallelogramPacket::set_lane,
            ),
            others,
        }
    }
}

/// `shapes` four to a packet, with their object indices (`u32::MAX` in unused lanes).
fn packets<S, P: Copy>(
    shapes: &[(u32, S)],
    empty: P,
    set_lane: impl Fn(&mut P, usize, &S),
) -> Vec<(P, [u32; 4])> {
    shapes
        .chunks(4)
        .map(|chunk| {
            let mut packet = empty;
            let mut objects = [u32::MAX; 4];
            for (lane, (object, shape)) in chunk.iter().enumerate() {
                set_lane(&mut packet, lane, shape);
                objects[lane] = *object;
            }
            (packet, objects)
        })
        .collect()
}

/// Per packet of `shapes` (four to a packet), what `describe` gives of each lane's
/// shape, gathered into lanes (`describe` returns it splatted; unused lanes NaN).
fn lanes_of<S, T: Lanes>(shapes: &[(u32, S)], describe: impl Fn(&S) -> T) -> Vec<T> {
    shapes
        .chunks(4)
        .map(|chunk| {
            let mut gathered = T::nan();
            for (lane, (_, shape)) in chunk.iter().enumerate() {
                gathered.take_lane(lane, &describe(shape));
            }
            gathered
        })
        .collect()
}

/// Values made of `Vec4` lanes.
trait Lanes {
    fn nan() -> Self;
    /// Copies lane `lane` of `from` into `self`.
    fn take_lane(&mut self, lane: usize, from: &Self);
}

impl Lanes for Vec4 {
    fn nan() -> Self {
        Vec4::NAN
    }
    fn take_lane(&mut self, lane: usize, from: &Self) {
        self[lane] = from[lane];
    }
}

impl<A: Lanes, B: Lanes> Lanes for (A, B) {
    fn nan() -> Self {
        (A::nan(), B::nan())
    }
    fn take_lane(&mut self, lane: usize, from: &Self) {
        self.0.take_lane(lane, &from.0);
        self.1.take_lane(lane, &from.1);
    }
}

impl<T: Lanes, const N: usize> Lanes for [T; N] {
    fn nan() -> Self {
        std::array::from_fn(|_| T::nan())
    }
    fn take_lane(&mut self, lane: usize, from: &Self) {
        for (to, from) in self.iter_mut().zip(from) {
            to.take_lane(lane, from);
        }
    }
}
