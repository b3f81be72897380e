//! A pattern's N points held as SIMD lanes: [`LANES`] x and [`LANES`] y
//! coordinates per chunk, the layout the lanes of a shading point's samples
//! read, so a Sobol fill hands its lanes over without a trip through memory.

use glam::Vec2;
use glint_geometry::lanes::{self, F32Lanes, LANES};

/// Up to [`LANES`] points as lanes of x and of y.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PointLanes {
    pub x: F32Lanes,
    pub y: F32Lanes,
}

impl PointLanes {
    /// Lane `k`'s point.
    #[inline]
    pub fn lane(&self, k: usize) -> Vec2 {
        Vec2::new(self.x.as_array()[k], self.y.as_array()[k])
    }

    /// `points` in the first lanes, the others 0.
    pub fn from_points(points: &[Vec2]) -> Self {
        debug_assert!(points.len() <= LANES);
        let coordinate = |axis: usize| lanes::from_fn(|k| points.get(k).map_or(0.0, |u| u[axis]));
        Self {
            x: coordinate(0),
            y: coordinate(1),
        }
    }
}

/// One chunk of [`SamplePoints`]: its points in lanes, of which the first
/// `len` are points.
#[derive(Clone, Copy, Debug)]
pub struct PointChunk {
    pub lanes: PointLanes,
    pub len: usize,
}

impl PointChunk {
    /// The chunk's points, in order.
    pub fn iter(&self) -> impl Iterator<Item = Vec2> + '_ {
        (0..self.len).map(|k| self.lanes.lane(k))
    }

    /// The lanes holding points, bit k for lane k.
    #[inline]
    pub fn used(&self) -> u32 {
        lanes::bits(lanes::first_lanes(self.len))
    }
}

/// N points in [0, 1)², [`LANES`] to a chunk; a thread's buffer, reused from
/// sample to sample.
#[derive(Clone, Debug, Default)]
pub struct SamplePoints {
    chunks: Vec<PointLanes>,
    len: usize,
    /// The points one by one, for the patterns that place them so.
    scratch: Vec<Vec2>,
}

impl SamplePoints {
    /// Room for `len` points, all at the origin.
    pub fn new(len: usize) -> Self {
        Self {
            chunks: vec![PointLanes::default(); len.div_ceil(LANES)],
            len,
            scratch: Vec::new(),
        }
    }

    /// The points `points`.
    pub fn from_points(points: &[Vec2]) -> Self {
        let mut out = Self::new(points.len());
        out.scratch = points.to_vec();
        out.pack_scratch();
        out
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Point `i`.
    #[inline]
    pub fn get(&self, i: usize) -> Vec2 {
        self.chunks[i / LANES].lane(i % LANES)
    }

    /// The points, in order.
    pub fn iter(&self) -> impl Iterator<Item = Vec2> + '_ {
        (0..self.len).map(|i| self.get(i))
    }

    /// The points [`LANES`] at a time, in order.
    pub fn chunks(&self) -> impl Iterator<Item = PointChunk> + '_ {
        self.chunks
            .iter()
            .enumerate()
            .map(|(c, &lanes)| PointChunk {
                lanes,
                len: (self.len - c * LANES).min(LANES),
            })
    }

    /// The chunks to fill, lanes past the last point included.
    pub(crate) fn chunks_mut(&mut self) -> &mut [PointLanes] {
        &mut self.chunks
    }

    /// Fills the points one by one: `place` writes all of them into a buffer,
    /// then they are packed into lanes.
    pub(crate) fn place(&mut self, place: impl FnOnce(&mut [Vec2])) {
        let mut scratch = std::mem::take(&mut self.scratch);
        scratch.resize(self.len, Vec2::ZERO);
        place(&mut scratch);
        self.scratch = scratch;
        self.pack_scratch();
    }

    fn pack_scratch(&mut self) {
        for (lanes, points) in self.chunks.iter_mut().zip(self.scratch.chunks(LANES)) {
            *lanes = PointLanes::from_points(points);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_come_back_in_order_by_index_iterator_and_chunk() {
        for n in [0usize, 1, 15, 16, 17, 40] {
            let points: Vec<Vec2> = (0..n).map(|i| Vec2::new(i as f32, -(i as f32))).collect();
            let held = SamplePoints::from_points(&points);
            assert_eq!(held.len(), n);
            assert_eq!(held.iter().collect::<Vec<_>>(), points);
            let chunked: Vec<Vec2> = held
                .chunks()
                .flat_map(|c| c.iter().collect::<Vec<_>>())
                .collect();
            assert_eq!(chunked, points);
            for chunk in held.chunks() {
                assert_eq!(chunk.used().count_ones() as usize, chunk.len);
            }
        }
    }
}
