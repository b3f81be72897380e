//! The path a query takes through the tree, step by step, for `glint explain`:
//! each interior node whose children's boxes were tested (with the distance
//! at which the ray enters each), and each leaf reached.
//!
//! Recording rides on the query counters: a step is recorded only where it is
//! counted, inside the one branch counting already takes, so a render that
//! neither counts nor records runs the same instructions as before, and one
//! that counts (`--stats`) pays one relaxed load per step.

use super::wide::{Link, WideNode};
use crate::CountingGuard;
use glam::Vec4;
use std::cell::RefCell;
use std::sync::atomic::{AtomicUsize, Ordering};

/// What a node holds in one of its child slots.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BvhChild {
    /// An interior node, by its index (the root is 0).
    Node(u32),
    /// A leaf: its run of positions in leaf order, `first` a multiple of
    /// [`LEAF_WIDTH`](super::LEAF_WIDTH) and `count` ≤ that.
    Leaf { first: u32, count: u32 },
}

impl BvhChild {
    fn from_link(link: Link) -> BvhChild {
        if link.is_leaf() {
            let (first, count) = link.leaf_range();
            BvhChild::Leaf { first, count }
        } else {
            BvhChild::Node(link.node() as u32)
        }
    }
}

/// One child's box tested against the ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChildTest {
    pub child: BvhChild,
    /// Where the ray enters the box (clamped to 0 for an origin inside), or
    /// `None` if it misses the box before the query's current limit.
    pub enter: Option<f32>,
}

/// One step of a traversal.
#[derive(Clone, Debug, PartialEq)]
pub enum BvhStep {
    /// Interior node `node`: its used children, in slot order, with the ray's
    /// verdict on each box.
    Node { node: u32, children: Vec<ChildTest> },
    /// A leaf reached, with the query's limit as it was entered: the ray's
    /// end, or (for a closest-hit query) just past the nearest hit so far.
    Leaf { first: u32, count: u32, t_max: f32 },
}

thread_local! {
    /// The steps recorded on this thread while [`record_steps`] runs.
    static TRAIL: RefCell<Option<Vec<BvhStep>>> = const { RefCell::new(None) };
}

/// How many threads are inside [`record_steps`].
static RECORDING: AtomicUsize = AtomicUsize::new(0);

/// Whether any thread records now; checked only where counting is on.
#[inline(always)]
pub(super) fn recording() -> bool {
    RECORDING.load(Ordering::Relaxed) != 0
}

/// Runs `query` and returns, with its result, every BVH step made on this
/// thread meanwhile, in order. Also turns the query counters on
/// ([`CountingGuard`]), since steps are recorded where they are counted.
///
/// For one single-ray query at a time: a stream's rays would interleave
/// their steps. A call nested in another's `query` keeps its steps to itself.
pub fn record_steps<R>(query: impl FnOnce() -> R) -> (R, Vec<BvhStep>) {
    let recording = Recording::start();
    let result = query();
    (result, recording.finish())
}

/// This thread records while it lives; dropping it, also on unwind, gives
/// back what an outer recording had.
struct Recording {
    outer: Option<Vec<BvhStep>>,
    _counting: CountingGuard,
}

impl Recording {
    fn start() -> Recording {
        let _counting = CountingGuard::start();
        RECORDING.fetch_add(1, Ordering::Relaxed);
        let outer = TRAIL.with(|t| t.replace(Some(Vec::new())));
        Recording { outer, _counting }
    }

    /// The steps recorded.
    fn finish(self) -> Vec<BvhStep> {
        TRAIL.with(|t| t.borrow_mut().take()).unwrap_or_default()
    }
}

impl Drop for Recording {
    fn drop(&mut self) {
        TRAIL.with(|t| *t.borrow_mut() = self.outer.take());
        RECORDING.fetch_sub(1, Ordering::Relaxed);
    }
}

/// Records a node's test, if [`record_steps`] is running on this thread. Called
/// only where counting is on.
#[cold]
pub(super) fn record_node(link: Link, node: &WideNode, hits: u32, enter: Vec4) {
    record(|| BvhStep::Node {
        node: link.node() as u32,
        children: node
            .children()
            .map(|(lane, child)| ChildTest {
                child: BvhChild::from_link(child),
                enter: (hits >> lane & 1 == 1).then(|| enter[lane]),
            })
            .collect(),
    });
}

/// Records a leaf reached, as [`record_node`] does a node.
#[cold]
pub(super) fn record_leaf(link: Link, t_max: f32) {
    let (first, count) = link.leaf_range();
    record(|| BvhStep::Leaf {
        first,
        count,
        t_max,
    });
}

fn record(step: impl FnOnce() -> BvhStep) {
    TRAIL.with(|t| {
        if let Ok(mut trail) = t.try_borrow_mut() {
            if let Some(steps) = trail.as_mut() {
                steps.push(step());
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::test_support::{box_hit, random_boxes, XorShift};
    use crate::bvh::Bvh;
    use crate::Ray;

    #[test]
    fn the_trail_lists_each_counted_step_and_every_entered_child_it_visits() {
        let bounds = random_boxes(2000, 20.0, 0.1, 2.0, 3);
        let bvh = Bvh::build(&bounds);
        let mut rng = XorShift(7);
        for _ in 0..200 {
            let origin = rng.vec3(-5.0, 25.0);
            let ray = Ray::new(origin, rng.vec3(0.0, 20.0) - origin);
            let _ = crate::take_counters();
            let (hit, steps) = record_steps(|| {
                bvh.closest_hit(&ray, f32::INFINITY, |i, r, t| {
                    box_hit(&bounds[i as usize], r, t).filter(|&t| t > 0.0)
                })
            });
            let counted = crate::take_counters();
            let nodes = steps
                .iter()
                .filter(|s| matches!(s, BvhStep::Node { .. }))
                .count();
            assert_eq!(nodes as u64, counted.bvh_nodes);
            assert_eq!((steps.len() - nodes) as u64, counted.bvh_leaves);
            assert!(matches!(steps.first(), Some(BvhStep::Node { node: 0, .. })));
            // Every step after the root was entered from a node tested before it.
            for (k, step) in steps.iter().enumerate().skip(1) {
                let me = match *step {
                    BvhStep::Node { node, .. } => BvhChild::Node(node),
                    BvhStep::Leaf { first, count, .. } => BvhChild::Leaf { first, count },
                };
                let entered = steps[..k].iter().any(|s| match s {
                    BvhStep::Node { children, .. } => {
                        children.iter().any(|c| c.child == me && c.enter.is_some())
                    }
                    BvhStep::Leaf { .. } => false,
                });
                assert!(entered, "step {k} {step:?} was never entered");
            }
            // The limit as each leaf is entered falls to the hit found.
            let limits: Vec<f32> = steps
                .iter()
                .filter_map(|s| match *s {
                    BvhStep::Leaf { t_max, .. } => Some(t_max),
                    _ => None,
                })
                .collect();
            assert!(limits.windows(2).all(|w| w[1] <= w[0]));
            if let (Some((_, t)), Some(&last)) = (hit, limits.last()) {
                assert!(last >= t);
            }
        }
        // Outside record_steps nothing is kept.
        assert!(TRAIL.with(|t| t.borrow().is_none()));
    }

    #[test]
    fn a_nested_or_panicking_recording_leaves_the_outer_one_as_it_was() {
        let bounds = random_boxes(500, 20.0, 0.1, 2.0, 4);
        let bvh = Bvh::build(&bounds);
        let ray = Ray::new(glam::Vec3::splat(-5.0), glam::Vec3::ONE);
        let query = || bvh.any_hit(&ray, f32::INFINITY, |_, _, _| false);
        let (_, alone) = record_steps(query);
        assert!(!alone.is_empty());
        let ((_, inner), outer) = record_steps(|| {
            query();
            let inner = record_steps(query);
            query();
            inner
        });
        assert_eq!(inner, alone);
        assert_eq!(outer, [&alone[..], &alone[..]].concat());
        let panicked = std::panic::catch_unwind(|| record_steps(|| panic!("in the query")));
        assert!(panicked.is_err());
        assert!(TRAIL.with(|t| t.borrow().is_none()));
        assert_eq!(record_steps(query).1, alone);
    }
}
