//! End-to-end tests of Glint over the shipped scenes (`scenes/`); the tests live
//! in `tests/` and the benchmarks in `benches/`. This library locates the shipped
//! files and makes meshes for benchmarks.
//!
//! # Entry points
//! - [`scenes_dir`], [`scene_path`] and [`shipped_scenes`]: where the shipped scene
//!   files are, and their names.
//! - [`displaced_grid`]: a generated mesh of any size, for the BVH benchmark.

use std::path::PathBuf;

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

/// A displaced grid of about `triangles` triangles over [−1, 1]² in x, z with a
/// bumpy height `y = 0.1·sin(7x)·cos(5z) + 0.05·sin(23x + 17z)`: a mesh of any size
/// for benchmarks, made by code (two triangles per grid cell).
pub fn displaced_grid(triangles: usize) -> glint_geometry::TriangleMesh {
    use glam::Vec3;
    let n = ((triangles as f64 / 2.0).sqrt().ceil() as u32).max(1);
    let height = |x: f32, z: f32| {
        0.1 * (7.0 * x).sin() * (5.0 * z).cos() + 0.05 * (23.0 * x + 17.0 * z).sin()
    };
    let mut positions = Vec::with_capacity(((n + 1) * (n + 1)) as usize);
    for j in 0..=n {
        for i in 0..=n {
            let (x, z) = (
                2.0 * i as f32 / n as f32 - 1.0,
                2.0 * j as f32 / n as f32 - 1.0,
            );
            positions.push(Vec3::new(x, height(x, z), z));
        }
    }
    let indices = glint_geometry::TriangleMesh::grid_indices(n, n);
    glint_geometry::TriangleMesh::new(positions, indices, vec![], vec![]).expect("a valid grid")
}

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
