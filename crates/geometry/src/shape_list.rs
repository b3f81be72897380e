use crate::{Hit, Ray, Shape};

/// Shapes in one flat array, queried by testing each in turn.
///
/// This is the query interface the integrator uses: [`ShapeList::closest_hit`]
/// and [`ShapeList::any_hit`]. An acceleration structure can later answer the same
/// two queries without the integrator changing.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ShapeList {
    shapes: Vec<Shape>,
}

impl ShapeList {
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a shape and returns its index, which hits report in [`Hit::shape`].
    pub fn push(&mut self, shape: impl Into<Shape>) -> u32 {
        self.shapes.push(shape.into());
        (self.shapes.len() - 1) as u32
    }

    pub fn shapes(&self) -> &[Shape] {
        &self.shapes
    }

    pub fn len(&self) -> usize {
        self.shapes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.shapes.is_empty()
    }

    /// The nearest hit with `0 < t < t_max`, if any.
    pub fn closest_hit(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let mut closest = t_max;
        let mut winner = None;
        for (i, shape) in self.shapes.iter().enumerate() {
            if let Some(t) = shape.hit_distance(ray, closest) {
                closest = t;
                winner = Some(i);
            }
        }
        winner.map(|i| Hit {
            shape: i as u32,
            ..self.shapes[i].surface_at(ray, closest)
        })
    }

    /// Whether anything lies on the ray with `0 < t < t_max` (shadow query).
    pub fn any_hit(&self, ray: &Ray, t_max: f32) -> bool {
        self.shapes
            .iter()
            .any(|s| s.hit_distance(ray, t_max).is_some())
    }
}

impl FromIterator<Shape> for ShapeList {
    fn from_iter<I: IntoIterator<Item = Shape>>(iter: I) -> Self {
        Self {
            shapes: iter.into_iter().collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Plane, Sphere};
    use glam::Vec3;

    fn scene() -> ShapeList {
        let mut list = ShapeList::new();
        list.push(Sphere::new(Vec3::new(0.0, 0.0, -10.0), 1.0).unwrap());
        list.push(Sphere::new(Vec3::new(0.0, 0.0, -5.0), 1.0).unwrap());
        list.push(Plane::new(Vec3::new(0.0, 0.0, -20.0), Vec3::Z, false).unwrap());
        list
    }

    #[test]
    fn closest_hit_picks_the_nearest_shape_whatever_the_order() {
        let ray = Ray::new(Vec3::ZERO, -Vec3::Z);
        let hit = scene().closest_hit(&ray, f32::INFINITY).unwrap();
        assert_eq!(hit.shape, 1);
        assert!((hit.t - 4.0).abs() < 1e-6);
        let reversed: ShapeList = scene().shapes().iter().rev().copied().collect();
        assert_eq!(reversed.closest_hit(&ray, f32::INFINITY).unwrap().shape, 1);
    }

    #[test]
    fn any_hit_respects_t_max() {
        let ray = Ray::new(Vec3::ZERO, -Vec3::Z);
        assert!(scene().any_hit(&ray, 4.5));
        assert!(!scene().any_hit(&ray, 3.5));
        assert!(!scene().any_hit(&Ray::new(Vec3::ZERO, Vec3::Z), f32::INFINITY));
    }
}
