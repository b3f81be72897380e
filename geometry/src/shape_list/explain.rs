//! What a closest-hit query did, for `glint explain`: every object's own test
//! against the ray, and the work the real query did (BVH nodes and leaves,
//! shape and triangle tests), read from the query counters.

use super::{Object, PrimitiveHit, ShapeList};
use crate::counters::{take_counters, CountingGuard, QueryCounters};
use crate::triangle::WatertightRay;
use crate::{Ray, Shape};

/// One object tested against a ray on its own.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObjectTest {
    /// The object's index ([`crate::Hit::shape`]).
    pub object: u32,
    /// `sphere`, `parallelogram`, `plane`, `box` or `mesh`.
    pub kind: &'static str,
    /// The nearest hit distance in `(0, t_max)`, if the ray meets it there.
    pub t: Option<f32>,
    /// For a mesh, the triangle of that nearest hit (the lowest index on a tie).
    pub triangle: Option<u32>,
}

/// A closest-hit query explained: [`ShapeList::explain_closest`].
#[derive(Clone, Debug, PartialEq)]
pub struct ClosestExplained {
    /// Every object, in order, tested alone (meshes triangle by triangle).
    pub tests: Vec<ObjectTest>,
    /// What [`ShapeList::closest_primitive`] answered: the query the renderer
    /// makes, through the BVH or the linear loop.
    pub closest: Option<PrimitiveHit>,
    /// The work that query did: interior BVH nodes whose children were tested,
    /// leaves reached, and ray–shape and ray–triangle tests.
    pub work: QueryCounters,
}

impl ShapeList {
    /// [`ShapeList::closest_primitive`] for `ray`, with each object's own test
    /// and the query's work. The answer is the renderer's: the nearest of the
    /// objects' tests, ties going to the lowest object and triangle.
    pub fn explain_closest(&self, ray: &Ray, t_max: f32) -> ClosestExplained {
        let tests = (0..self.objects.len() as u32)
            .map(|object| self.test_object(object, ray, t_max))
            .collect();
        let _counting = CountingGuard::start();
        let _ = take_counters();
        let closest = self.closest_primitive(ray, t_max);
        let work = take_counters();
        ClosestExplained {
            tests,
            closest,
            work,
        }
    }

    fn test_object(&self, object: u32, ray: &Ray, t_max: f32) -> ObjectTest {
        match self.objects[object as usize] {
            Object::Shape(s) => {
                let shape = &self.shapes[s as usize];
                let kind = match shape {
                    Shape::Sphere(_) => "sphere",
                    Shape::Parallelogram(_) => "parallelogram",
                    Shape::Plane(_) => "plane",
                    Shape::Box(_) => "box",
                };
                ObjectTest {
                    object,
                    kind,
                    t: shape.hit_distance(ray, t_max),
                    triangle: None,
                }
            }
            Object::Mesh(m) => {
                let mesh = &self.meshes[m as usize];
                let watertight = WatertightRay::new(ray);
                let nearest = (0..mesh.triangle_count() as u32)
                    .filter_map(|i| Some((mesh.hit_distance(i, &watertight, t_max)?, i)))
                    .fold(None, |best: Option<(f32, u32)>, (t, i)| match best {
                        Some((bt, _)) if bt <= t => best,
                        _ => Some((t, i)),
                    });
                ObjectTest {
                    object,
                    kind: "mesh",
                    t: nearest.map(|(t, _)| t),
                    triangle: nearest.map(|(_, i)| i),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::{Parallelogram, Ray, ShapeList, Sphere};
    use glam::Vec3;

    #[test]
    fn every_object_is_tested_and_the_nearest_wins() {
        let mut list = ShapeList::new();
        list.push(Sphere::new(Vec3::new(0.0, 0.0, -5.0), 1.0).unwrap());
        list.push(Sphere::new(Vec3::new(0.0, 0.0, -3.0), 1.0).unwrap());
        list.push(Parallelogram::new(Vec3::new(5.0, -1.0, -1.0), Vec3::X, Vec3::Y, false).unwrap());
        list.build_bvh();
        let ray = Ray::new(Vec3::ZERO, -Vec3::Z);
        let explained = list.explain_closest(&ray, f32::INFINITY);
        let ts: Vec<Option<f32>> = explained.tests.iter().map(|t| t.t).collect();
        assert_eq!(ts, [Some(4.0), Some(2.0), None]);
        let closest = explained.closest.unwrap();
        assert_eq!((closest.object, closest.t), (1, 2.0));
        assert!(explained.work.shape_tests() >= 1);
    }
}
