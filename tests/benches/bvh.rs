//! The BVH, measured: build time and closest-hit rays per second on generated
//! meshes of 10k to 4M triangles, for coherent (camera) and incoherent (random)
//! rays, on every core. A closest hit is the nearest primitive and its distance
//! ([`ShapeList::closest_primitive`], what Embree's `rtcIntersect1` reports); the
//! surface column adds the surface record the integrator shades with
//! ([`ShapeList::closest_hit`]: normals, uv, derivatives), and the stream column
//! hands the rays over in batches ([`ShapeList::closest_primitives`]), which
//! traces several at once with their memory reads overlapped.
//!
//! `cargo bench -p glint-tests --bench bvh [-- TRIANGLES...]` (default: 10k, 100k,
//! 1M and 4M triangles)
//!
//! Each figure is the median of 3 runs. Rays are traced in parallel (rayon) over
//! batches; the rays themselves are made before the clock starts.

use glint_geometry::{Ray, ShapeList};
use glint_tests::{camera_rays, displaced_grid, random_rays};
use rayon::prelude::*;
use std::time::{Duration, Instant};

const RUNS: usize = 3;
const RAYS: usize = 2_000_000;
/// Rays per parallel task, and per stream.
const BATCH: usize = 4096;

fn main() {
    println!(
        "| triangles | BVH build | coherent rays/s | incoherent rays/s | incoherent µs/ray (one core) | incoherent with surface rays/s | incoherent stream rays/s |"
    );
    println!("|---|---|---|---|---|---|---|");
    let sizes: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let sizes = if sizes.is_empty() {
        vec![10_000, 100_000, 1_000_000, 4_000_000]
    } else {
        sizes
    };
    for triangles in sizes {
        let mesh = displaced_grid(triangles);
        let actual = mesh.triangle_count();
        let mut list = ShapeList::new();
        list.push_mesh(mesh);
        let build = median(|| {
            let mut l = list.clone();
            let start = Instant::now();
            l.build_bvh();
            start.elapsed()
        });
        list.build_bvh();
        let coherent = camera_rays(RAYS, false);
        let incoherent = random_rays(RAYS);
        let coherent_time = median(|| trace(&list, &coherent, Query::Primitive));
        let incoherent_time = median(|| trace(&list, &incoherent, Query::Primitive));
        let surface_time = median(|| trace(&list, &incoherent, Query::Surface));
        let stream_time = median(|| trace(&list, &incoherent, Query::Stream));
        let per_second = |t: Duration| RAYS as f64 / t.as_secs_f64();
        let threads = rayon::current_num_threads() as f64;
        println!(
            "| {actual} | {:.0} ms | {:.1} M | {:.1} M | {:.3} | {:.1} M | {:.1} M |",
            build.as_secs_f64() * 1e3,
            per_second(coherent_time) / 1e6,
            per_second(incoherent_time) / 1e6,
            incoherent_time.as_secs_f64() * 1e6 * threads / RAYS as f64,
            per_second(surface_time) / 1e6,
            per_second(stream_time) / 1e6,
        );
    }
}

#[derive(Clone, Copy)]
enum Query {
    /// [`ShapeList::closest_primitive`]
    Primitive,
    /// [`ShapeList::closest_hit`]
    Surface,
    /// [`ShapeList::closest_primitives`] over each batch
    Stream,
}

/// Traces every ray for its closest hit, in parallel; returns the wall time.
fn trace(list: &ShapeList, rays: &[Ray], query: Query) -> Duration {
    let start = Instant::now();
    let hits: usize = rays
        .par_chunks(BATCH)
        .map(|chunk| match query {
            Query::Primitive => chunk
                .iter()
                .filter(|r| list.closest_primitive(r, f32::INFINITY).is_some())
                .count(),
            Query::Surface => chunk
                .iter()
                .filter(|r| list.closest_hit(r, f32::INFINITY).is_some())
                .count(),
            Query::Stream => {
                let mut hits = [None; BATCH];
                let hits = &mut hits[..chunk.len()];
                list.closest_primitives(chunk, &[f32::INFINITY; BATCH][..chunk.len()], hits);
                hits.iter().filter(|h| h.is_some()).count()
            }
        })
        .sum();
    let elapsed = start.elapsed();
    assert!(hits > 0);
    elapsed
}

fn median(f: impl FnMut() -> Duration) -> Duration {
    glint_tests::median_time(RUNS, f)
}
