//! Glint's side of the peer benchmark against Embree (`measure/embree/compare.sh`,
//! which builds `measure/embree/peer.cpp` and runs both in turn on the same files).
//!
//! `cargo bench -p glint-tests --bench peer -- write DIR TRIANGLES...` writes the
//! inputs: for each size a displaced grid (`grid-N.mesh`) and, for each, three
//! sets of rays: a camera's (`coherent`, in 4 × 4 pixel tiles, so that each
//! sixteen consecutive rays are one tile), random ones (`incoherent`) and
//! shadow rays from the camera rays' hits to an area light above (`shadow`).
//!
//! `cargo bench -p glint-tests --bench peer -- run DIR N THREADS [ONLY]` builds the BVH
//! over `grid-N.mesh` and prints, one line each, the build time, the bytes the
//! mesh and its acceleration structure hold per triangle, and the rays per
//! second of each query on each set of rays (median of three runs): closest
//! hits one ray at a time (`ShapeList::closest_primitive`), sixteen at a time in
//! lanes (`ShapeList::closest_lanes`, as the renderer traces a pixel's camera
//! rays) and as an interleaved stream (`ShapeList::closest_primitives`); any
//! hits one at a time, sixteen in lanes (`ShapeList::any_hits_among`, as the
//! renderer traces shadow rays) and as a stream; with `ONLY`, the queries whose
//! line starts with it (`"coherent closest, 16"`), for profiling one; the
//! environment variable `GLINT_PEER_RUNS` sets how many times each query runs
//! (default 3: the median is printed), so that a profile of one query is not
//! the build's.
//!
//! File formats (little-endian): a mesh is `u32 vertices, u32 triangles`, then
//! the positions (`3 × f32` each) and the corner indices (`3 × u32` each); a
//! set of rays is `u32 count`, then per ray origin, direction (`3 × f32` each)
//! and `t_max` (`f32`, infinite for closest hits).

use glam::Vec3;
use glint_geometry::lanes::{self, LANES};
use glint_geometry::{Occluders, Ray, RayLanes, ShapeList, TriangleMesh};
use glint_tests::{camera_rays, random_rays, XorShift};
use rayon::prelude::*;
use std::alloc::{GlobalAlloc, Layout, System};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// Counts the bytes allocated and not yet freed, for the structures' size.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call is forwarded to the system allocator unchanged; the
// counter only observes the sizes.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        LIVE.fetch_add(layout.size(), Ordering::Relaxed);
        // SAFETY: the caller's contract for `alloc` is passed on as is.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        // SAFETY: as for `alloc`.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

const RUNS: usize = 3;
/// Rays in each set.
const RAYS: usize = 1 << 20;
/// Rays per parallel task.
const BATCH: usize = 4096;

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    match args.iter().map(String::as_str).collect::<Vec<_>>()[..] {
        ["write", dir, ref sizes @ ..] if !sizes.is_empty() => {
            for size in sizes {
                let size = size.parse().expect("a triangle count");
                write_inputs(Path::new(dir), size);
            }
        }
        ["run", dir, size, threads, ref only @ ..] if only.len() <= 1 => {
            let threads: usize = threads.parse().expect("a thread count");
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a thread pool");
            pool.install(|| run(Path::new(dir), size, only.first().copied().unwrap_or("")));
        }
        _ => {
            eprintln!("usage: peer write DIR TRIANGLES... | peer run DIR TRIANGLES THREADS [ONLY]");
            std::process::exit(2);
        }
    }
}

fn mesh_path(dir: &Path, size: &str) -> PathBuf {
    dir.join(format!("grid-{size}.mesh"))
}

fn rays_path(dir: &Path, size: &str, kind: &str) -> PathBuf {
    dir.join(format!("grid-{size}.{kind}.rays"))
}

fn write_inputs(dir: &Path, triangles: usize) {
    let mesh = glint_tests::displaced_grid(triangles);
    let size = triangles.to_string();
    let mut bytes = Vec::new();
    let words = |bytes: &mut Vec<u8>, values: &mut dyn Iterator<Item = u32>| {
        values.for_each(|v| bytes.extend_from_slice(&v.to_le_bytes()))
    };
    words(
        &mut bytes,
        &mut [mesh.positions().len() as u32, mesh.indices().len() as u32].into_iter(),
    );
    words(
        &mut bytes,
        &mut mesh
            .positions()
            .iter()
            .flat_map(|p| p.to_array().map(f32::to_bits)),
    );
    words(&mut bytes, &mut mesh.indices().iter().flat_map(|i| *i));
    std::fs::write(mesh_path(dir, &size), bytes).expect("the mesh written");
    let mut list = ShapeList::new();
    list.push_mesh(mesh);
    list.build_bvh();
    let coherent: Vec<(Ray, f32)> = camera_rays(RAYS, true)
        .into_iter()
        .map(|r| (r, f32::INFINITY))
        .collect();
    let shadow = shadow_rays(&list, &coherent);
    let incoherent: Vec<(Ray, f32)> = random_rays(RAYS)
        .into_iter()
        .map(|r| (r, f32::INFINITY))
        .collect();
    for (kind, rays) in [
        ("coherent", &coherent),
        ("incoherent", &incoherent),
        ("shadow", &shadow),
    ] {
        let mut file = std::fs::File::create(rays_path(dir, &size, kind)).expect("a rays file");
        let mut bytes = (rays.len() as u32).to_le_bytes().to_vec();
        for (ray, t_max) in rays {
            let values = ray
                .origin
                .to_array()
                .into_iter()
                .chain(ray.direction.to_array())
                .chain([*t_max]);
            values.for_each(|v| bytes.extend_from_slice(&v.to_le_bytes()));
        }
        file.write_all(&bytes).expect("the rays written");
    }
    println!(
        "wrote {}: {} triangles, {} shadow rays",
        dir.display(),
        triangles,
        shadow.len()
    );
}

fn read_words(path: &Path) -> Vec<u32> {
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|mut f| f.read_to_end(&mut bytes))
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    bytes
        .chunks_exact(4)
        .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
        .collect()
}

fn read_mesh(path: &Path) -> TriangleMesh {
    let words = read_words(path);
    let (vertices, triangles) = (words[0] as usize, words[1] as usize);
    let float = |w: u32| f32::from_bits(w);
    let positions = words[2..2 + 3 * vertices]
        .chunks_exact(3)
        .map(|p| Vec3::new(float(p[0]), float(p[1]), float(p[2])))
        .collect();
    let indices = words[2 + 3 * vertices..2 + 3 * vertices + 3 * triangles]
        .chunks_exact(3)
        .map(|i| [i[0], i[1], i[2]])
        .collect();
    TriangleMesh::new(positions, indices, vec![], vec![]).expect("a valid mesh")
}

fn read_rays(path: &Path) -> (Vec<Ray>, Vec<f32>) {
    let words = read_words(path);
    let f: Vec<f32> = words[1..].iter().map(|&w| f32::from_bits(w)).collect();
    f.chunks_exact(7)
        .map(|r| {
            (
                Ray::new(Vec3::new(r[0], r[1], r[2]), Vec3::new(r[3], r[4], r[5])),
                r[6],
            )
        })
        .unzip()
}

/// Measures the queries on the mesh of `size` triangles: all of them, or
/// those whose line starts with `only` (for profiling one).
fn run(dir: &Path, size: &str, only: &str) {
    let before = LIVE.load(Ordering::Relaxed);
    let mesh = read_mesh(&mesh_path(dir, size));
    let triangles = mesh.indices().len();
    let mut list = ShapeList::new();
    list.push_mesh(mesh);
    let unbuilt = list.clone();
    let build = median(|| {
        let mut list = unbuilt.clone();
        let start = Instant::now();
        list.build_bvh();
        start.elapsed()
    });
    drop(unbuilt);
    list.build_bvh();
    let bytes = LIVE.load(Ordering::Relaxed).saturating_sub(before);
    println!("build\t{:.1} ms", build.as_secs_f64() * 1e3);
    println!("bytes per triangle\t{:.0}", bytes as f64 / triangles as f64);
    for kind in ["coherent", "incoherent", "shadow"] {
        let (rays, t_max) = read_rays(&rays_path(dir, size, kind));
        let closest = kind != "shadow";
        let queries: &[Query] = match closest {
            true => &[Query::ClosestOne, Query::ClosestLanes, Query::ClosestStream],
            false => &[Query::AnyOne, Query::AnyLanes, Query::AnyStream],
        };
        let any_hit_too: &[Query] = match kind {
            "incoherent" => &[Query::AnyOne, Query::AnyLanes, Query::AnyStream],
            _ => &[],
        };
        for &query in queries.iter().chain(any_hit_too) {
            // Incoherent rays' any hits: up to distance 1, so that some get through.
            let t_max: Vec<f32> = match (kind, query.is_any()) {
                ("incoherent", true) => vec![1.0; rays.len()],
                _ => t_max.clone(),
            };
            let line = format!("{kind} {}", query.name());
            if !line.starts_with(only) {
                continue;
            }
            let time =
                glint_tests::median_time(query_runs(), || trace(&list, &rays, &t_max, query));
            println!(
                "{line}\t{:.2} M rays/s",
                rays.len() as f64 / time.as_secs_f64() / 1e6
            );
        }
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Query {
    ClosestOne,
    ClosestLanes,
    ClosestStream,
    AnyOne,
    AnyLanes,
    AnyStream,
}

impl Query {
    fn name(self) -> &'static str {
        match self {
            Query::ClosestOne => "closest, one ray",
            Query::ClosestLanes => "closest, 16 in lanes",
            Query::ClosestStream => "closest, stream",
            Query::AnyOne => "any, one ray",
            Query::AnyLanes => "any, 16 in lanes",
            Query::AnyStream => "any, stream",
        }
    }

    fn is_any(self) -> bool {
        matches!(self, Query::AnyOne | Query::AnyLanes | Query::AnyStream)
    }
}

/// Traces every ray, in parallel over batches; returns the wall time.
fn trace(list: &ShapeList, rays: &[Ray], t_max: &[f32], query: Query) -> Duration {
    let start = Instant::now();
    let found: usize = rays
        .par_chunks(BATCH)
        .zip(t_max.par_chunks(BATCH))
        .map(|(rays, t_max)| match query {
            Query::ClosestOne => rays
                .iter()
                .zip(t_max)
                .filter(|(r, &t)| list.closest_primitive(r, t).is_some())
                .count(),
            Query::ClosestLanes => rays
                .chunks(LANES)
                .map(|chunk| {
                    let (lanes, active) = in_lanes(chunk);
                    let found = list.closest_lanes(&lanes, chunk.len());
                    (found.hits & active).count_ones() as usize
                })
                .sum(),
            Query::ClosestStream => {
                let mut hits = vec![None; rays.len()];
                list.closest_primitives(rays, t_max, &mut hits);
                hits.iter().filter(|h| h.is_some()).count()
            }
            Query::AnyOne => rays
                .iter()
                .zip(t_max)
                .filter(|(r, &t)| list.any_hit(r, t))
                .count(),
            Query::AnyLanes => rays
                .chunks(LANES)
                .map(|chunk| {
                    let (lanes, active) = in_lanes(chunk);
                    // One limit for the lanes: every ray of a set has the same.
                    list.any_hits_among(&Occluders::ALL, &lanes, t_max[0], active)
                        .count_ones() as usize
                })
                .sum(),
            Query::AnyStream => {
                let mut occluded = vec![false; rays.len()];
                list.any_hits(rays, t_max, &mut occluded);
                occluded.iter().filter(|&&o| o).count()
            }
        })
        .sum();
    let elapsed = start.elapsed();
    assert!(found > 0);
    elapsed
}

/// Up to [`LANES`] rays in lanes (the last repeated into the unused ones),
/// and the lanes that hold them.
fn in_lanes(chunk: &[Ray]) -> (RayLanes, u32) {
    let lanes = RayLanes::new(std::array::from_fn(|k| chunk[k.min(chunk.len() - 1)]));
    (lanes, lanes::bits(lanes::first_lanes(chunk.len())))
}

/// How many times each query runs: `GLINT_PEER_RUNS`, or [`RUNS`].
fn query_runs() -> usize {
    std::env::var("GLINT_PEER_RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .filter(|&n| n > 0)
        .unwrap_or(RUNS)
}

fn median(f: impl FnMut() -> Duration) -> Duration {
    glint_tests::median_time(RUNS, f)
}

/// From each camera ray's hit on the grid (just above the surface) to a
/// point of a square light above it, in the camera rays' order.
fn shadow_rays(list: &ShapeList, camera: &[(Ray, f32)]) -> Vec<(Ray, f32)> {
    let mut rng = XorShift(0x9e37_79b9_7f4a_7c15);
    camera
        .iter()
        .filter_map(|(ray, t)| list.closest_hit(ray, *t))
        .map(|hit| {
            let n = hit.geometric_normal.normalize();
            let origin = hit.point + 1e-4 * if n.y < 0.0 { -n } else { n };
            let light = Vec3::new(2.0 * rng.unit() - 1.0, 3.0, 2.0 * rng.unit() - 1.0);
            (Ray::new(origin, light - origin), 1.0 - 1e-4)
        })
        .collect()
}
