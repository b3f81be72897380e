//! Counts of the work intersection queries do, for `glint render --stats`: BVH
//! nodes and leaves visited, and ray–shape tests by kind.
//!
//! Counting is off unless a caller turns it on ([`CountingGuard`]); the queries
//! then check one relaxed atomic flag per count site, a predictable branch.
//! Counts accumulate per thread ([`take_counters`]), so that a parallel render
//! reads each of its tiles' counts from the thread that rendered it.

use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

/// How much work queries did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct QueryCounters {
    /// Interior BVH nodes whose children a ray was tested against.
    pub bvh_nodes: u64,
    /// BVH leaves a ray reached.
    pub bvh_leaves: u64,
    pub sphere_tests: u64,
    pub parallelogram_tests: u64,
    pub plane_tests: u64,
    pub box_tests: u64,
    /// Ray–triangle tests (four per packet a BVH leaf holds, padding included).
    pub triangle_tests: u64,
}

impl QueryCounters {
    /// Every ray–shape test.
    pub fn shape_tests(&self) -> u64 {
        self.sphere_tests
            + self.parallelogram_tests
            + self.plane_tests
            + self.box_tests
            + self.triangle_tests
    }
}

impl std::ops::AddAssign for QueryCounters {
    fn add_assign(&mut self, o: Self) {
        self.bvh_nodes += o.bvh_nodes;
        self.bvh_leaves += o.bvh_leaves;
        self.sphere_tests += o.sphere_tests;
        self.parallelogram_tests += o.parallelogram_tests;
        self.plane_tests += o.plane_tests;
        self.box_tests += o.box_tests;
        self.triangle_tests += o.triangle_tests;
    }
}

/// How many callers want counts now (several renders may run at once).
static COUNTING: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    static COUNTERS: Cell<QueryCounters> = const {
        Cell::new(QueryCounters {
            bvh_nodes: 0,
            bvh_leaves: 0,
            sphere_tests: 0,
            parallelogram_tests: 0,
            plane_tests: 0,
            box_tests: 0,
            triangle_tests: 0,
        })
    };
}

/// Counting is on while a guard lives.
#[must_use = "counting stops when the guard is dropped"]
pub struct CountingGuard(());

impl CountingGuard {
    pub fn start() -> Self {
        COUNTING.fetch_add(1, Ordering::Relaxed);
        CountingGuard(())
    }
}

impl Drop for CountingGuard {
    fn drop(&mut self) {
        COUNTING.fetch_sub(1, Ordering::Relaxed);
    }
}

/// This thread's counts since the last call, and zero from now.
pub fn take_counters() -> QueryCounters {
    COUNTERS.with(|c| c.take())
}

/// Adds to this thread's counts, if counting is on.
#[inline(always)]
pub(crate) fn count(add: impl FnOnce(&mut QueryCounters)) {
    if COUNTING.load(Ordering::Relaxed) != 0 {
        COUNTERS.with(|c| {
            let mut counters = c.get();
            add(&mut counters);
            c.set(counters);
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Ray, Shape, Sphere};
    use glam::Vec3;

    #[test]
    fn tests_are_counted_only_while_a_guard_lives() {
        let sphere: Shape = Sphere::new(Vec3::ZERO, 1.0).unwrap().into();
        let ray = Ray::new(Vec3::Z * 5.0, -Vec3::Z);
        let _ = take_counters();
        {
            let _guard = CountingGuard::start();
            sphere.hit_distance(&ray, f32::INFINITY);
            sphere.hit_distance(&ray, f32::INFINITY);
            assert_eq!(take_counters().sphere_tests, 2);
        }
        sphere.hit_distance(&ray, f32::INFINITY);
        // Other tests may count on this thread meanwhile only under their guards.
        assert!(take_counters().sphere_tests <= 1);
    }
}
