use glam::{Vec2, Vec3};
use glint_geometry::lanes::{self, F32Lanes, Float, Vec3Lanes, Vector3};
use glint_geometry::{offset_ray_origins, Parallelogram, RayTarget};

/// A rectangular (parallelogram) light of uniform color, emitting from its front side.
///
/// Following the course, it is sampled at N points and each point acts as a point
/// light; the N contributions are averaged. The light is also a visible surface:
/// a camera ray that reaches its front side sees `color`.
#[derive(Clone, Debug, PartialEq)]
pub struct AreaLight {
    surface: Parallelogram,
    pub color: Vec3,
}

impl AreaLight {
    /// A light centred at `center` spanning `edge1` and `edge2`, whose front (emitting)
    /// side is `normalize(edge1 × edge2)`. `None` if the edges span no area.
    pub fn new(center: Vec3, edge1: Vec3, edge2: Vec3, color: Vec3) -> Option<Self> {
        let origin = center - 0.5 * (edge1 + edge2);
        let surface = Parallelogram::new(origin, edge1, edge2, false)?;
        Some(Self { surface, color })
    }

    /// The same light with its emitting side turned towards `towards`.
    pub fn facing(mut self, towards: Vec3) -> Self {
        self.surface = self.surface.facing(towards);
        self
    }

    /// The emitting surface, for intersection with camera rays.
    pub fn surface(&self) -> &Parallelogram {
        &self.surface
    }

    /// The point on the light at sample coordinates `u` ∈ [0, 1]².
    #[inline]
    pub fn sample_point(&self, u: Vec2) -> Vec3 {
        self.surface.point_at(u)
    }

    /// Whether a light point at `light_point` shines on `receiver` (front side only).
    #[inline]
    pub fn illuminates(&self, light_point: Vec3, receiver: Vec3) -> bool {
        self.surface.normal().dot(receiver - light_point) > 0.0
    }

    /// [`Self::sample_point`] for each lane's sample coordinates `(ux, uy)`,
    /// each lane bit for bit the scalar point.
    #[inline(always)]
    pub fn sample_points<F: Float>(&self, ux: F, uy: F) -> Vector3<F> {
        let (e1, e2) = self.surface.edges();
        // origin + u.x·edge1 + u.y·edge2, rounded in that order.
        Vector3::splat(self.surface.origin())
            + Vector3::scaled_splat(e1, ux)
            + Vector3::scaled_splat(e2, uy)
    }

    /// What a shadow ray towards the light point `position` aims at: the point
    /// with its error bound, to be left on the emitting side, so that the ray
    /// ends just short of the light's own surface.
    #[inline]
    pub fn shadow_target(&self, position: Vec3) -> RayTarget {
        RayTarget {
            point: position,
            error: self.surface.error_bound(),
            normal: self.surface.normal(),
        }
    }

    /// [`RayTarget::end`] of [`Self::shadow_target`] for each lane's light
    /// point, bit for bit.
    #[inline]
    pub fn shadow_ends(&self, light_points: &Vec3Lanes) -> Vec3Lanes {
        offset_ray_origins(
            light_points,
            &Vec3Lanes::splat(self.surface.error_bound()),
            &Vec3Lanes::splat(self.surface.normal()),
        )
    }

    /// [`Self::illuminates`] for [`LANES`](glint_geometry::lanes::LANES) light
    /// points at once, each seen from its own lane's receiver: the mask of the
    /// lanes whose point shines on it.
    #[inline]
    pub fn illuminates_lanes(&self, light_points: &Vec3Lanes, receivers: &Vec3Lanes) -> F32Lanes {
        let towards = *receivers - *light_points;
        lanes::gt(towards.dot_splat(self.surface.normal()), F32Lanes::ZERO)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn course_light_faces_down_and_spans_its_square() {
        let light = AreaLight::new(
            Vec3::new(0.0, 5.9, -6.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 2.0),
            Vec3::ONE,
        )
        .unwrap();
        assert_eq!(light.surface().normal(), -Vec3::Y);
        assert_eq!(light.sample_point(Vec2::ZERO), Vec3::new(-1.0, 5.9, -7.0));
        assert_eq!(light.sample_point(Vec2::ONE), Vec3::new(1.0, 5.9, -5.0));
        assert_eq!(
            light.sample_point(Vec2::splat(0.5)),
            Vec3::new(0.0, 5.9, -6.0)
        );
        let p = light.sample_point(Vec2::splat(0.5));
        assert!(light.illuminates(p, Vec3::ZERO));
        assert!(!light.illuminates(p, Vec3::new(0.0, 6.0, -6.0)));
        assert!((light.surface().area() - 4.0).abs() < 1e-6);
    }
}
