//! Parallelograms (the course's walls and area lights): the ray test and the
//! uv mapping by edge coordinates.

use crate::error_bounds::gamma;
use crate::{Hit, Ray};
use glam::{Vec2, Vec3};
use glint_lanes::{Float, Mask, Vector3};

/// The parallelogram `origin + α·edge1 + β·edge2`, `α, β ∈ [0, 1]`.
///
/// Its front side is the one `normal` points to; by default
/// `normalize(edge1 × edge2)`. uv = (α, β), so `dpdu = edge1` and `dpdv = edge2`.
/// A one-sided parallelogram is seen only from its front side.
///
/// The ray test counts a point as inside when its edge coordinates are within
/// their rounding error of [0, 1] ([`Self::edge_margin`]), so that a ray aimed
/// at the edge two walls share meets at least one of them. Hit points are kept
/// inside the edges by twice their error bound (`pull`), so that a ray leaving
/// a point on an edge cannot slip out through a wall that meets it there
/// ([`crate::error_bounds`]); uv is not pulled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Parallelogram {
    pub(super) origin: Vec3,
    pub(super) edge1: Vec3,
    pub(super) edge2: Vec3,
    pub(super) normal: Vec3,
    pub(super) two_sided: bool,
    /// `(e1 × e2) / |e1 × e2|²`: turns cross products into the coordinates α, β.
    pub(super) w: Vec3,
    /// The error bound of every point of the parallelogram, per axis.
    pub(super) error: Vec3,
    /// How far in (α, β) hit points are kept from the edges: twice the error
    /// bound, in units of each edge, at most ½.
    pub(super) pull: Vec2,
    /// `‖origin‖∞ + ‖edge1‖∞ + ‖edge2‖∞`: the magnitudes the ray test rounds.
    pub(super) extent: f32,
    /// `(|e₂|, |e₁|) / |e₁ × e₂|`: how much α and β change per unit length
    /// across the edges they measure from.
    pub(super) coordinate_scale: Vec2,
}

/// `|v|` without squaring `v`'s components (which overflow f32 beyond about
/// 1e19): the vector is scaled by its largest component first.
fn unsquared_length(v: Vec3) -> f32 {
    let squared = v.length_squared();
    if squared.is_finite() {
        return squared.sqrt(); // as glam's length, bit for bit
    }
    let largest = v.abs().max_element();
    largest * (v / largest).length()
}

/// What [`Parallelogram::hit_distance`] reads of a parallelogram, over any
/// [`Float`]: one parallelogram (`f32`), one in every lane, or one per lane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ParallelogramConstants<F: Float> {
    pub(crate) origin: Vector3<F>,
    pub(crate) edge1: Vector3<F>,
    pub(crate) edge2: Vector3<F>,
    pub(crate) normal: Vector3<F>,
    pub(crate) w: Vector3<F>,
    pub(crate) extent: F,
    pub(crate) coordinate_scale: [F; 2],
    /// The lanes seen from their front side only.
    pub(crate) one_sided: F::Mask,
}

impl<F: Float> ParallelogramConstants<F> {
    /// The edge coordinates of the plane's point `p`:
    /// `α = w·((p − p₀) × e₂)`, `β = w·(e₁ × (p − p₀))`.
    #[inline(always)]
    pub(crate) fn coordinates(&self, p: &Vector3<F>) -> (F, F) {
        let local = *p - self.origin;
        (
            self.w.dot(&local.cross(&self.edge2)),
            self.w.dot(&self.edge1.cross(&local)),
        )
    }

    /// [`Parallelogram::hit_distance`] per lane: the mask of the lanes hit, and
    /// the plane's distance `t = n·(p₀ − o) / n·d`. A point is inside when its
    /// edge coordinates lie in [0, 1], or within [`Parallelogram::edge_margin`]
    /// of it (tested only where some lane needs it: inside [0, 1] is inside the
    /// margin too).
    #[inline(always)]
    pub(crate) fn hits(
        &self,
        origin: &Vector3<F>,
        direction: &Vector3<F>,
        t_max: F,
    ) -> (F::Mask, F) {
        let denom = self.normal.dot(direction);
        let facing_away = denom.eq(F::ZERO) | (self.one_sided & denom.gt(F::ZERO));
        if facing_away.all() {
            return (F::Mask::FALSE, F::ZERO);
        }
        let t = self.normal.dot(&(self.origin - *origin)) / denom;
        let candidates = t.in_ray_range(t_max) & !facing_away;
        if !candidates.any() {
            return (F::Mask::FALSE, t);
        }
        let (alpha, beta) = self.coordinates(&(*origin + direction.scale(t)));
        let unit = |x: F| x.ge(F::ZERO) & x.le(F::ONE);
        let mut inside = unit(alpha) & unit(beta);
        if (candidates & !inside).any() {
            let length = F::splat(gamma(16)) * (origin.abs().max_element() + self.extent);
            let within = |x: F, scale: F| {
                let margin = length * scale;
                x.ge(-margin) & x.le(F::ONE + margin)
            };
            inside =
                within(alpha, self.coordinate_scale[0]) & within(beta, self.coordinate_scale[1]);
        }
        (candidates & inside, t)
    }
}

impl Parallelogram {
    /// A parallelogram whose front side is `normalize(edge1 × edge2)`.
    /// Returns `None` if the edges are parallel or zero (no area): the sine of
    /// the angle between them at most 1e-6, whatever their length (lengths and
    /// the area are taken without squaring, so that edges of 1e10 neither
    /// overflow nor read as parallel).
    pub fn new(origin: Vec3, edge1: Vec3, edge2: Vec3, two_sided: bool) -> Option<Self> {
        let n = edge1.cross(edge2);
        let area = unsquared_length(n);
        let sine = area / (unsquared_length(edge1) * unsquared_length(edge2));
        if sine.is_nan() || sine <= 1e-6 || !area.is_finite() {
            return None;
        }
        let error = gamma(7) * (origin.abs() + edge1.abs() + edge2.abs());
        let reach = 2.0 * error.length();
        let pull = Vec2::new(reach / edge1.length(), reach / edge2.length()).min(Vec2::splat(0.5));
        let extent =
            origin.abs().max_element() + edge1.abs().max_element() + edge2.abs().max_element();
        let coordinate_scale = Vec2::new(unsquared_length(edge2), unsquared_length(edge1)) / area;
        let area2 = n.length_squared();
        // Where |n|² does not overflow, the plain formulas (the bits every
        // render so far was made with); beyond, the same from the unit normal.
        let (normal, w) = match area2.is_finite() {
            true => (n.normalize(), n / area2),
            false => {
                let normal = (n / n.abs().max_element()).normalize();
                (normal, normal / area)
            }
        };
        Some(Self {
            origin,
            edge1,
            edge2,
            normal,
            two_sided,
            w,
            error,
            pull,
            extent,
            coordinate_scale,
        })
    }

    /// The same parallelogram with its front side turned to the side `towards`
    /// points to (`towards` need only not be parallel to the surface).
    pub fn facing(mut self, towards: Vec3) -> Self {
        if self.normal.dot(towards) < 0.0 {
            self.normal = -self.normal;
        }
        self
    }

    pub fn origin(&self) -> Vec3 {
        self.origin
    }
    pub fn edges(&self) -> (Vec3, Vec3) {
        (self.edge1, self.edge2)
    }
    /// Unit normal of the front side.
    pub fn normal(&self) -> Vec3 {
        self.normal
    }
    pub fn area(&self) -> f32 {
        unsquared_length(self.edge1.cross(self.edge2))
    }
    pub fn center(&self) -> Vec3 {
        self.origin + 0.5 * (self.edge1 + self.edge2)
    }
    /// The four corners, in order around the parallelogram.
    pub fn corners(&self) -> [Vec3; 4] {
        let (o, e1, e2) = (self.origin, self.edge1, self.edge2);
        [o, o + e1, o + e1 + e2, o + e2]
    }
    /// The bound on the rounding error of [`Self::point_at`] anywhere on the
    /// parallelogram, per axis ([`crate::error_bounds`]).
    pub fn error_bound(&self) -> Vec3 {
        self.error
    }
    /// The point with coordinates `(α, β)` ∈ `[0, 1]²`.
    pub fn point_at(&self, ab: Vec2) -> Vec3 {
        self.origin + ab.x * self.edge1 + ab.y * self.edge2
    }

    fn coordinates(&self, p: Vec3) -> Vec2 {
        let (alpha, beta) = self.constants::<f32>().coordinates(&p.into());
        Vec2::new(alpha, beta)
    }

    pub fn hit_distance(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        let (hit, t) =
            self.constants::<f32>()
                .hits(&ray.origin.into(), &ray.direction.into(), t_max);
        hit.then_some(t)
    }

    /// The constants of the ray test, the same in every lane.
    #[inline(always)]
    pub(crate) fn constants<F: Float>(&self) -> ParallelogramConstants<F> {
        ParallelogramConstants {
            origin: Vector3::splat(self.origin),
            edge1: Vector3::splat(self.edge1),
            edge2: Vector3::splat(self.edge2),
            normal: Vector3::splat(self.normal),
            w: Vector3::splat(self.w),
            extent: F::splat(self.extent),
            coordinate_scale: [
                F::splat(self.coordinate_scale.x),
                F::splat(self.coordinate_scale.y),
            ],
            one_sided: if self.two_sided {
                F::Mask::FALSE
            } else {
                F::Mask::TRUE
            },
        }
    }

    /// How far outside [0, 1] the edge coordinates (α, β) of a hit of a ray
    /// from `origin` may be and still count as inside: the bound on their
    /// rounding error. The point `o + t·d` is within `γ₁₆(‖o‖∞ + extent)` of
    /// the exact one (the plane's distance `t` and the point each round a
    /// handful of times over these magnitudes; pbrt-v4 §6.8), turned into edge
    /// coordinates by `coordinate_scale`.
    #[inline]
    pub fn edge_margin(&self, origin: Vec3) -> Vec2 {
        let length = gamma(16) * (origin.abs().max_element() + self.extent);
        length * self.coordinate_scale
    }

    #[inline]
    pub fn surface_at(&self, ray: &Ray, t: f32) -> Hit {
        let uv = self.coordinates(ray.at(t)).clamp(Vec2::ZERO, Vec2::ONE);
        Hit {
            t,
            point: self.point_at(uv.clamp(self.pull, Vec2::ONE - self.pull)),
            error: self.error,
            geometric_normal: self.normal,
            shading_normal: self.normal,
            uv,
            dpdu: self.edge1,
            dpdv: self.edge2,
            dndu: Vec3::ZERO,
            dndv: Vec3::ZERO,
            front_face: self.normal.dot(ray.direction) < 0.0,
            shape: 0,
            primitive: 0,
        }
    }
}
