//! What a closest-hit query did, for `glint explain`: every object's own test
//! against the ray, the path the real query took through the BVH (recorded by
//! [`record_steps`]), and its work (BVH nodes and leaves, shape and triangle
//! tests), read from the query counters.

use super::{Object, ObjectRef, PrimitiveHit, ShapeList};
use crate::bvh::{record_steps, BvhChild, BvhStep, ChildTest, LEAF_WIDTH};
use crate::counters::{take_counters, QueryCounters};
use crate::triangle::WatertightRay;
use crate::Ray;
use std::collections::HashMap;

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
    /// The query's path through the BVH, step by step (empty without one).
    pub bvh: Vec<BvhVisit>,
}

/// A BVH node or leaf, by number: nodes by their index (the root is 0), leaves
/// by their place in leaf order (a leaf's first position over
/// [`LEAF_WIDTH`](crate::bvh::LEAF_WIDTH)).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BvhRef {
    Node(u32),
    Leaf(u32),
}

impl From<BvhChild> for BvhRef {
    fn from(child: BvhChild) -> BvhRef {
        match child {
            BvhChild::Node(node) => BvhRef::Node(node),
            BvhChild::Leaf { first, .. } => BvhRef::Leaf(first / LEAF_WIDTH as u32),
        }
    }
}

/// One child box of a node, as the ray met it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChildVisit {
    pub child: BvhRef,
    /// Where the ray enters the box, or `None` if it misses it before the
    /// query's limit at the time.
    pub enter: Option<f32>,
    /// Whether the query went into it: an entered child is skipped when a hit
    /// nearer than its entry is found first.
    pub visited: bool,
}

/// A primitive in a BVH leaf: an analytic shape, or a mesh's triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LeafPrimitive {
    pub object: u32,
    pub triangle: Option<u32>,
}

/// One step of the query through the BVH, in the order taken.
#[derive(Clone, Debug, PartialEq)]
pub enum BvhVisit {
    /// An interior node whose children's boxes were tested, at `depth` below
    /// the root.
    Node {
        node: u32,
        depth: u32,
        children: Vec<ChildVisit>,
    },
    /// A leaf reached while the query pruned boxes beyond `t_max` (the
    /// nearest hit so far times [`PRUNE_SCALE`](crate::PRUNE_SCALE),
    /// or the `t_max` given to [`ShapeList::explain_closest`]); its primitives
    /// are tested up to the `t_max` given.
    Leaf {
        leaf: u32,
        depth: u32,
        primitives: Vec<LeafPrimitive>,
        t_max: f32,
    },
}

/// The node or leaf a step is at.
fn step_ref(step: &BvhStep) -> BvhRef {
    match *step {
        BvhStep::Node { node, .. } => BvhRef::Node(node),
        BvhStep::Leaf { first, count, .. } => BvhChild::Leaf { first, count }.into(),
    }
}

/// A child's test, and whether one of the `later` steps went into it.
fn child_visit(test: &ChildTest, later: &[BvhStep]) -> ChildVisit {
    let child = BvhRef::from(test.child);
    ChildVisit {
        child,
        enter: test.enter,
        visited: later.iter().any(|s| step_ref(s) == child),
    }
}

impl ShapeList {
    /// [`ShapeList::closest_primitive`] for `ray`, with each object's own test
    /// and the query's work. The answer is the renderer's: the nearest of the
    /// objects' tests, ties going to the lowest object and triangle.
    pub fn explain_closest(&self, ray: &Ray, t_max: f32) -> ClosestExplained {
        let tests = (0..self.objects.len() as u32)
            .map(|object| self.test_object(object, ray, t_max))
            .collect();
        let ((closest, work), steps) = record_steps(|| {
            let _ = take_counters();
            let closest = self.closest_primitive(ray, t_max);
            (closest, take_counters())
        });
        ClosestExplained {
            tests,
            closest,
            work,
            bvh: self.bvh_visits(&steps),
        }
    }

    /// The recorded steps with depths, visits and leaf primitives filled in.
    fn bvh_visits(&self, steps: &[BvhStep]) -> Vec<BvhVisit> {
        // A step's depth is one more than its parent's, recorded earlier.
        let mut depths = HashMap::from([(BvhRef::Node(0), 0)]);
        steps
            .iter()
            .enumerate()
            .map(|(k, step)| {
                let depth = depths.get(&step_ref(step)).copied().unwrap_or(0);
                match *step {
                    BvhStep::Node { node, ref children } => {
                        let later = &steps[k + 1..];
                        let children: Vec<ChildVisit> =
                            children.iter().map(|c| child_visit(c, later)).collect();
                        depths.extend(children.iter().map(|c| (c.child, depth + 1)));
                        BvhVisit::Node {
                            node,
                            depth,
                            children,
                        }
                    }
                    BvhStep::Leaf {
                        first,
                        count,
                        t_max,
                    } => BvhVisit::Leaf {
                        leaf: first / LEAF_WIDTH as u32,
                        depth,
                        primitives: (first..first + count)
                            .map(|k| self.leaf_primitive(k))
                            .collect(),
                        t_max,
                    },
                }
            })
            .collect()
    }

    /// The primitive at position `k` of the BVH's leaf order.
    fn leaf_primitive(&self, k: u32) -> LeafPrimitive {
        let p = self.primitives[k as usize];
        let mesh = matches!(self.objects.get(p.object as usize), Some(Object::Mesh(_)));
        LeafPrimitive {
            object: p.object,
            triangle: mesh.then_some(p.triangle),
        }
    }

    fn test_object(&self, object: u32, ray: &Ray, t_max: f32) -> ObjectTest {
        let kind = self.object(object).kind();
        match self.object(object) {
            ObjectRef::Shape(shape) => ObjectTest {
                object,
                kind,
                t: shape.hit_distance(ray, t_max),
                triangle: None,
            },
            ObjectRef::Mesh(mesh) => {
                let watertight = WatertightRay::new(ray);
                let nearest = (0..mesh.triangle_count() as u32)
                    .filter_map(|i| Some((mesh.hit_distance(i, &watertight, t_max)?, i)))
                    .fold(None, |best: Option<(f32, u32)>, (t, i)| match best {
                        Some((bt, _)) if bt <= t => best,
                        _ => Some((t, i)),
                    });
                ObjectTest {
                    object,
                    kind,
                    t: nearest.map(|(t, _)| t),
                    triangle: nearest.map(|(_, i)| i),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{BvhRef, BvhVisit, LeafPrimitive};
    use crate::{Parallelogram, Ray, ShapeList, Sphere, TriangleMesh};
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

    /// A grid of `n × n` unit squares (two triangles each) in the plane z = `z`.
    fn grid(n: u32, z: f32) -> TriangleMesh {
        let positions = (0..=n)
            .flat_map(|y| (0..=n).map(move |x| Vec3::new(x as f32, y as f32, z)))
            .collect();
        let corner = |x: u32, y: u32| y * (n + 1) + x;
        let indices = (0..n)
            .flat_map(|y| (0..n).map(move |x| (x, y)))
            .flat_map(|(x, y)| {
                let (a, b) = (corner(x, y), corner(x + 1, y));
                let (c, d) = (corner(x + 1, y + 1), corner(x, y + 1));
                [[a, b, c], [a, c, d]]
            })
            .collect();
        TriangleMesh::new(positions, indices, vec![], vec![]).unwrap()
    }

    #[test]
    fn the_bvh_path_leads_from_the_root_to_the_leaf_of_the_hit() {
        let mut list = ShapeList::new();
        list.push(Sphere::new(Vec3::new(50.0, 50.0, 0.0), 1.0).unwrap());
        list.push_mesh(grid(16, -2.0));
        list.push_mesh(grid(16, -4.0));
        list.build_acceleration();
        let ray = Ray::new(Vec3::new(5.3, 7.6, 3.0), -Vec3::Z);
        let explained = list.explain_closest(&ray, f32::INFINITY);
        let closest = explained.closest.unwrap();
        assert_eq!((closest.object, closest.t), (1, 5.0));
        let bvh = &explained.bvh;
        let nodes = bvh
            .iter()
            .filter(|v| matches!(v, BvhVisit::Node { .. }))
            .count() as u64;
        assert_eq!(nodes, explained.work.bvh_nodes);
        assert_eq!(bvh.len() as u64 - nodes, explained.work.bvh_leaves);
        assert!(matches!(
            bvh[0],
            BvhVisit::Node {
                node: 0,
                depth: 0,
                ..
            }
        ));
        // The hit triangle sits in a leaf reached with no hit yet, one level
        // below the node that entered it.
        let (depth, t_max) = bvh
            .iter()
            .find_map(|v| match v {
                BvhVisit::Leaf {
                    depth,
                    primitives,
                    t_max,
                    ..
                } if primitives.contains(&LeafPrimitive {
                    object: 1,
                    triangle: Some(closest.primitive),
                }) =>
                {
                    Some((*depth, *t_max))
                }
                _ => None,
            })
            .expect("the hit's leaf is on the path");
        assert!(depth >= 1);
        assert_eq!(t_max, f32::INFINITY);
        // The lower grid's boxes are entered beyond the hit: none is visited.
        for v in bvh {
            if let BvhVisit::Node { children, .. } = v {
                for c in children {
                    if c.enter.is_some_and(|t| t > 5.5) {
                        assert!(!c.visited, "{c:?} entered beyond the hit was visited");
                    }
                }
            }
        }
        // Every visited child is a later step, and each step but the root one.
        let steps: Vec<BvhRef> = bvh
            .iter()
            .map(|v| match *v {
                BvhVisit::Node { node, .. } => BvhRef::Node(node),
                BvhVisit::Leaf { leaf, .. } => BvhRef::Leaf(leaf),
            })
            .collect();
        let visited: Vec<BvhRef> = bvh
            .iter()
            .flat_map(|v| match v {
                BvhVisit::Node { children, .. } => children.clone(),
                BvhVisit::Leaf { .. } => vec![],
            })
            .filter(|c| c.visited)
            .map(|c| c.child)
            .collect();
        assert_eq!(visited.len(), steps.len() - 1);
        assert!(visited.iter().all(|c| steps[1..].contains(c)));
        // Each step lies one level below the node that entered it.
        for (k, v) in bvh.iter().enumerate().skip(1) {
            let parent = bvh[..k].iter().find_map(|p| match p {
                BvhVisit::Node {
                    depth, children, ..
                } if children.iter().any(|c| c.child == steps[k]) => Some(*depth),
                _ => None,
            });
            let depth = match v {
                BvhVisit::Node { depth, .. } | BvhVisit::Leaf { depth, .. } => *depth,
            };
            assert_eq!(Some(depth), parent.map(|d| d + 1), "step {k}");
        }
    }
}
