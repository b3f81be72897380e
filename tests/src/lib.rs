//! End-to-end tests of Glint over the shipped scenes (`scenes/`); the tests live
//! in `tests/` and the benchmarks in `benches/`. This library locates the shipped
//! files and makes meshes for benchmarks.
//!
//! # Entry points
//! - [`scenes_dir`], [`scene_path`] and [`shipped_scenes`]: where the shipped scene
//!   files are, and their names.
//! - [`displaced_grid`]: a generated mesh of any size, for the BVH benchmarks;
//!   [`camera_rays`] and [`random_rays`]: the rays they trace into it;
//!   [`median_time`]: their timings.

use glam::Vec3;
use glint_geometry::Ray;
use std::path::PathBuf;
use std::time::Duration;

/// The repository's `scenes/` directory.
pub fn scenes_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}

/// The path of the shipped scene `name` (without `.toml`).
pub fn scene_path(name: &str) -> PathBuf {
    scenes_dir().join(format!("{name}.toml"))
}

/// The names of all shipped scenes, sorted.
pub fn shipped_scenes() -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(scenes_dir())
        .expect("scenes/ exists")
        .filter_map(|e| {
            let path = e.ok()?.path();
            (path.extension()? == "toml").then(|| path.file_stem()?.to_str().map(str::to_owned))?
        })
        .collect();
    names.sort();
    names
}

/// A displaced grid of about `triangles` triangles
/// ([`TriangleMesh::displaced_grid`](glint_geometry::TriangleMesh::displaced_grid)
/// with a side of `⌈√(triangles / 2)⌉` quads): a mesh of any size for benchmarks.
pub fn displaced_grid(triangles: usize) -> glint_geometry::TriangleMesh {
    let n = ((triangles as f64 / 2.0).sqrt().ceil() as u32).max(1);
    glint_geometry::TriangleMesh::displaced_grid(n)
}

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

/// xorshift64*: uniform numbers in [0, 1) from a seed, for benchmark rays.
pub struct XorShift(pub u64);

impl XorShift {
    /// The next number in [0, 1).
    pub fn unit(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32) / (1u64 << 24) as f32
    }
}

/// About `n` rays of a pinhole camera over a square image, looking down at
/// [`displaced_grid`]: row by row, or (`tiled`) in 4 × 4 pixel tiles, each
/// sixteen consecutive rays one tile, as the renderer traces a pixel's samples.
pub fn camera_rays(n: usize, tiled: bool) -> Vec<Ray> {
    let side = match tiled {
        true => (n as f64).sqrt() as usize / 4 * 4,
        false => (n as f64).sqrt() as usize,
    };
    let eye = Vec3::new(0.0, 1.5, 2.0);
    let forward = (Vec3::new(0.0, 0.0, -0.2) - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let count = if tiled { side * side } else { n };
    (0..count)
        .map(|i| {
            let (px, py) = match tiled {
                true => {
                    let (tile, k, tiles) = (i / 16, i % 16, side / 4);
                    ((tile % tiles) * 4 + k % 4, (tile / tiles) * 4 + k / 4)
                }
                false => (i % side, i / side),
            };
            let (x, y) = (px as f32 / side as f32 - 0.5, py as f32 / side as f32 - 0.5);
            Ray::new(eye, forward + 0.9 * (x * right - y * up))
        })
        .collect()
}

/// `n` rays from random origins above and around [`displaced_grid`] in
/// random directions on the sphere.
pub fn random_rays(n: usize) -> Vec<Ray> {
    let mut rng = XorShift(0x2545_f491_4f6c_dd1d);
    (0..n)
        .map(|_| {
            let origin = Vec3::new(
                2.0 * rng.unit() - 1.0,
                0.5 * rng.unit() - 0.1,
                2.0 * rng.unit() - 1.0,
            );
            let z = 2.0 * rng.unit() - 1.0;
            let phi = std::f32::consts::TAU * rng.unit();
            let r = (1.0 - z * z).sqrt();
            Ray::new(origin, Vec3::new(r * phi.cos(), z, r * phi.sin()))
        })
        .collect()
}

/// The median of `runs` timings by `f` (for the benchmarks).
pub fn median_time(runs: usize, mut f: impl FnMut() -> Duration) -> Duration {
    let mut times: Vec<Duration> = (0..runs).map(|_| f()).collect();
    times.sort();
    times[runs / 2]
}
