use crate::lanes::{F32Lanes, Vec3Lanes, LANES};
use glam::Vec3;

/// A ray `origin + t · direction`, valid for `t > 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub direction: Vec3,
}

impl Ray {
    pub fn new(origin: Vec3, direction: Vec3) -> Self {
        Self { origin, direction }
    }

    /// The point at parameter `t`.
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.direction
    }
}

/// [`LANES`] rays, `origin + t·direction` in each lane.
#[derive(Clone, Copy, Debug, Default)]
pub struct RayLanes {
    pub origin: Vec3Lanes,
    pub direction: Vec3Lanes,
}

impl RayLanes {
    /// The rays `rays`, lane k holding `rays[k]`.
    pub fn new(rays: [Ray; LANES]) -> Self {
        let lanes = |of: fn(&Ray) -> Vec3| Vec3Lanes {
            x: F32Lanes::new(rays.each_ref().map(|r| of(r).x)),
            y: F32Lanes::new(rays.each_ref().map(|r| of(r).y)),
            z: F32Lanes::new(rays.each_ref().map(|r| of(r).z)),
        };
        Self {
            origin: lanes(|r| r.origin),
            direction: lanes(|r| r.direction),
        }
    }

    /// Lane `lane` as a scalar ray.
    #[inline]
    pub fn lane(&self, lane: usize) -> Ray {
        Ray::new(self.origin.lane(lane), self.direction.lane(lane))
    }

    /// Each lane's point at its own parameter `t`, as [`Ray::at`] rounds it.
    #[inline]
    pub fn at(&self, t: F32Lanes) -> Vec3Lanes {
        self.origin + self.direction.scale(t)
    }
}
