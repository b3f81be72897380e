//! Axis-aligned boxes: the ray–box test and the per-face uv squares.

use crate::error_bounds::gamma;
use crate::lanes::{F32Lanes, Float, Mask, Vec3Lanes, Vector3};
use crate::{Hit, Parallelogram, Ray, RayLanes};
use glam::{Vec2, Vec3};

/// An axis-aligned box `[min, max]`, a closed solid seen from outside and inside.
///
/// Each face carries its own uv square, upright as seen from outside the box: on the
/// four side faces u runs to the viewer's right and v up (+y); on the top face v
/// runs towards −z, on the bottom face towards +z (see `FACES`).
///
/// A hit point's face coordinate is the face's own, exactly; its other two are
/// kept one float inside the box, so that a ray leaving a point on an edge
/// leaves through the box's inside ([`crate::error_bounds`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AaBox {
    min: Vec3,
    max: Vec3,
}

/// How a face's uv runs: the box axis it follows and the direction along it.
type FaceAxis = (usize, f32);

/// A face's frame: outward axis and sign, then for u and v the axis they run
/// along and its direction, so that `s = sign · q[axis]` for the box-local
/// coordinate `q ∈ [−1, 1]³`, and `u = (s + 1)/2`. Order: +x −x +y −y +z −z.
const FACES: [(usize, f32, FaceAxis, FaceAxis); 6] = [
    (0, 1.0, (2, -1.0), (1, 1.0)),
    (0, -1.0, (2, 1.0), (1, 1.0)),
    (1, 1.0, (0, 1.0), (2, -1.0)),
    (1, -1.0, (0, 1.0), (2, 1.0)),
    (2, 1.0, (0, 1.0), (1, 1.0)),
    (2, -1.0, (0, -1.0), (1, 1.0)),
];

impl AaBox {
    /// Returns `None` unless `min < max` on every axis.
    pub fn new(min: Vec3, max: Vec3) -> Option<Self> {
        min.cmplt(max).all().then_some(Self { min, max })
    }

    pub fn min(&self) -> Vec3 {
        self.min
    }

    /// The six faces as two-sided parallelograms in `+x −x +y −y +z −z` order,
    /// with the same uv (upright seen from outside) and outward normals as the box's
    /// own hits: for a box whose faces carry different materials.
    pub fn face_parallelograms(&self) -> [Parallelogram; 6] {
        let extent = self.max - self.min;
        FACES.map(|(axis, sign, (ua, us), (va, vs))| {
            let mut origin = Vec3::ZERO;
            origin[axis] = if sign > 0.0 {
                self.max[axis]
            } else {
                self.min[axis]
            };
            origin[ua] = if us > 0.0 { self.min[ua] } else { self.max[ua] };
            origin[va] = if vs > 0.0 { self.min[va] } else { self.max[va] };
            let mut edge1 = Vec3::ZERO;
            edge1[ua] = us * extent[ua];
            let mut edge2 = Vec3::ZERO;
            edge2[va] = vs * extent[va];
            Parallelogram::new(origin, edge1, edge2, true).expect("a box face has area")
        })
    }
    pub fn max(&self) -> Vec3 {
        self.max
    }

    /// Slab test: the entry distance if the ray starts outside, else the exit distance.
    #[inline]
    pub fn hit_distance(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        let (min, max) = (self.min.into(), self.max.into());
        let (hit, t) = box_hits(&min, &max, &ray.origin.into(), &ray.direction.into(), t_max);
        hit.then_some(t)
    }

    /// [`Self::hit_distance`] for each lane's ray: the lanes that hit (bit k
    /// for lane k) and their distances, bit for bit the scalar test's.
    #[inline]
    pub fn hit_distance_lanes(&self, rays: &RayLanes, t_max: f32) -> (u32, F32Lanes) {
        let (min, max) = (Vec3Lanes::splat(self.min), Vec3Lanes::splat(self.max));
        let t_max = F32Lanes::splat(t_max);
        let (hit, t) = box_hits(&min, &max, &rays.origin, &rays.direction, t_max);
        (hit.bits(), t)
    }

    /// Index into [`FACES`] of the face that holds `p`.
    fn face_of(&self, p: Vec3) -> usize {
        let half = 0.5 * (self.max - self.min);
        let q = (p - 0.5 * (self.min + self.max)) / half;
        let axis = q.abs().max_position();
        2 * axis + usize::from(q[axis] < 0.0)
    }

    pub fn surface_at(&self, ray: &Ray, t: f32) -> Hit {
        let raw = ray.at(t);
        let face = self.face_of(raw);
        let (axis, sign, (ua, us), (va, vs)) = FACES[face];
        let mut point = raw.clamp(self.min, self.max);
        point[axis] = if sign > 0.0 {
            self.max[axis]
        } else {
            self.min[axis]
        };
        let extent = self.max - self.min;
        let q = 2.0 * (point - self.min) / extent - Vec3::ONE;
        let mut normal = Vec3::ZERO;
        normal[axis] = sign;
        let mut dpdu = Vec3::ZERO;
        dpdu[ua] = us * extent[ua];
        let mut dpdv = Vec3::ZERO;
        dpdv[va] = vs * extent[va];
        let inner_min = Vec3::from_array(self.min.to_array().map(f32::next_up));
        let inner_max = Vec3::from_array(self.max.to_array().map(f32::next_down));
        let face_coordinate = point[axis];
        // max then min, not clamp: a box a few floats wide has inner_min > inner_max.
        point = point.max(inner_min).min(inner_max);
        point[axis] = face_coordinate;
        Hit {
            t,
            point,
            error: gamma(1) * point.abs(),
            geometric_normal: normal,
            shading_normal: normal,
            uv: 0.5 * (Vec2::new(us * q[ua], vs * q[va]) + Vec2::ONE),
            dpdu,
            dpdv,
            dndu: Vec3::ZERO,
            dndv: Vec3::ZERO,
            front_face: normal.dot(ray.direction) < 0.0,
            shape: 0,
            primitive: 0,
        }
    }
}

/// The slab test of [`AaBox::hit_distance`] over any [`Float`]: the mask of
/// the rays that hit `[min, max]` in `(0, t_max)`, and there the entry
/// distance if the ray starts outside, else the exit distance (Kay and
/// Kajiya 1986; pbrt-v4 §6.1.2). The minima and maxima are glam's, `a < b ?
/// a : b`, at every width (so a NaN slab distance is treated alike).
///
/// An axis the ray runs parallel to (direction component ±0) gives no slab
/// interval: the ray is inside that slab for every t, or never. Handling it
/// explicitly avoids 0·∞ = NaN when the origin lies on the slab's boundary.
#[inline(always)]
pub(crate) fn box_hits<F: Float>(
    min: &Vector3<F>,
    max: &Vector3<F>,
    origin: &Vector3<F>,
    direction: &Vector3<F>,
    t_max: F,
) -> (F::Mask, F) {
    let lesser = |a: F, b: F| F::select(a.lt(b), a, b);
    let greater = |a: F, b: F| F::select(a.gt(b), a, b);
    let slab = |o: F, d: F, lo: F, hi: F| {
        let parallel = d.eq(F::ZERO);
        let outside = parallel & !(o.ge(lo) & o.le(hi));
        let inv = F::ONE / d;
        let (t_a, t_b) = ((lo - o) * inv, (hi - o) * inv);
        let near = F::select(parallel, F::splat(f32::NEG_INFINITY), lesser(t_a, t_b));
        let far = F::select(parallel, F::splat(f32::INFINITY), greater(t_a, t_b));
        (outside, near, far)
    };
    let (ox, nx, fx) = slab(origin.x, direction.x, min.x, max.x);
    let (oy, ny, fy) = slab(origin.y, direction.y, min.y, max.y);
    let (oz, nz, fz) = slab(origin.z, direction.z, min.z, max.z);
    let outside = ox | oy | oz;
    if outside.all() {
        return (F::Mask::FALSE, F::ZERO);
    }
    let t_near = greater(nx, greater(ny, nz));
    let t_far = lesser(fx, lesser(fy, fz));
    let crossed = !outside & !t_near.gt(t_far);
    let near = t_near.in_ray_range(t_max);
    let hit = crossed & (near | t_far.in_ray_range(t_max));
    (hit, F::select(near, t_near, t_far))
}
