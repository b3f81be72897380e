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
