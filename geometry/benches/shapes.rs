//! Ray–shape intersection and shadow-ray queries, per ray.
//!
//! `cargo bench -p glint-geometry --bench shapes`
//!
//! - `hit_distance/*`, `surface/*`, `closest_hit/*`: each shape alone (sphere,
//!   plane, parallelogram, axis-aligned box, one mesh triangle), for a batch of 256
//!   rays from near the origin towards it that all hit it (`hit`) or all pass it
//!   by (`miss`). `hit_distance` is the shape's own distance test; `surface` adds
//!   the surface record (`surface_at`); `closest_hit` asks a one-shape
//!   [`ShapeList`] (after `build_acceleration`, so the linear loop with its
//!   four-wide packets), which is what the integrator calls. The triangle's
//!   distance test includes making its `WatertightRay`, and its `surface` is
//!   `TriangleMesh::surface_at`, which runs the test again itself.
//! - `shadow_cornell/*`, `shadow_mesh/*`: 256 shadow rays (16 shading points × 16
//!   points on a 2 × 2 light) on a Cornell-like list of 5 parallelograms and 4
//!   spheres (linear loop), and on a displaced grid of about 10k triangles (BVH),
//!   asked one at a time (`any_hit`), as one batch (`any_hits`), and, for the
//!   Cornell list, the way the integrator asked from 4 light samples on
//!   (`occluders_towards` once per shading point, then `any_hit_among`), and
//!   for both, the way it asks now: a point's rays `LANES` at a time in SIMD lanes
//!   (`any_hits_among`, the BVH walked by them together).
//!
//! Throughput is in rays; the time per ray is the iteration time / 256. See
//! `docs/microbenchmarks.md`.

use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion, Throughput};
use glam::{Vec2, Vec3};
use glint_geometry::lanes::LANES;
use glint_geometry::triangle::WatertightRay;
use glint_geometry::{
    spawn_ray_to, AaBox, Hit, Parallelogram, Plane, Ray, RayLanes, RayTarget, ShapeList, Sphere,
    TriangleMesh,
};
use std::hint::black_box;
use std::time::Duration;

/// Rays per iteration.
const BATCH: usize = 256;
/// Where every shape is centred.
const TARGET: Vec3 = Vec3::new(0.0, 0.0, -5.0);

/// A small deterministic generator: uniform f32 in [0, 1).
struct Xorshift(u64);

impl Xorshift {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A point of the disc of radii `inner..outer` in the xy plane.
    fn ring(&mut self, inner: f32, outer: f32) -> Vec2 {
        let r = inner + (outer - inner) * self.next();
        let phi = std::f32::consts::TAU * self.next();
        r * Vec2::new(phi.cos(), phi.sin())
    }
}

fn configure(group: &mut BenchmarkGroup<'_, criterion::measurement::WallTime>, elements: usize) {
    group
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .throughput(Throughput::Elements(elements as u64));
}

/// Rays from a small square around the origin towards points of the plane
/// z = −5 at distances `inner..outer` from its centre (0, 0, −5).
fn rays_towards(rng: &mut Xorshift, inner: f32, outer: f32) -> Vec<Ray> {
    (0..BATCH)
        .map(|_| {
            let origin = 0.05 * Vec3::new(rng.next() - 0.5, rng.next() - 0.5, 0.0);
            let target = TARGET + rng.ring(inner, outer).extend(0.0);
            Ray::new(origin, target - origin)
        })
        .collect()
}

/// The five shapes, each centred on `TARGET` and facing the origin: every ray
/// aimed within 0.45 of the centre hits each of them, every ray aimed 2 to 3
/// away misses each bounded one.
struct Shapes {
    sphere: Sphere,
    plane: Plane,
    parallelogram: Parallelogram,
    aabox: AaBox,
    /// One triangle, its incircle (radius 0.618) centred on `TARGET`.
    triangle: TriangleMesh,
}

impl Shapes {
    fn new() -> Self {
        let incentre = Vec3::new(0.0, -1.0 + 0.618, 0.0);
        let corners = [
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ]
        .map(|p| TARGET + p - incentre)
        .to_vec();
        Self {
            sphere: Sphere::new(TARGET, 1.0).unwrap(),
            plane: Plane::new(TARGET, Vec3::Z, false).unwrap(),
            parallelogram: Parallelogram::new(
                TARGET - Vec3::new(1.0, 1.0, 0.0),
                2.0 * Vec3::X,
                2.0 * Vec3::Y,
                false,
            )
            .unwrap(),
            aabox: AaBox::new(TARGET - Vec3::ONE, TARGET + Vec3::ONE).unwrap(),
            triangle: TriangleMesh::new(corners, vec![[0, 1, 2]], vec![], vec![]).unwrap(),
        }
    }

    /// A one-object list of shape `name`, ready for queries.
    fn list(&self, name: &str) -> ShapeList {
        let mut list = ShapeList::new();
        match name {
            "sphere" => {
                list.push(self.sphere);
            }
            "plane" => {
                list.push(self.plane);
            }
            "parallelogram" => {
                list.push(self.parallelogram);
            }
            "box" => {
                list.push(self.aabox);
            }
            "triangle" => {
                list.push_mesh(self.triangle.clone());
            }
            _ => unreachable!("{name}"),
        }
        list.build_acceleration();
        list
    }

    fn hit_distance(&self, name: &str, ray: &Ray) -> Option<f32> {
        let t_max = f32::INFINITY;
        match name {
            "sphere" => self.sphere.hit_distance(ray, t_max),
            "plane" => self.plane.hit_distance(ray, t_max),
            "parallelogram" => self.parallelogram.hit_distance(ray, t_max),
            "box" => self.aabox.hit_distance(ray, t_max),
            "triangle" => self
                .triangle
                .hit_distance(0, &WatertightRay::new(ray), t_max),
            _ => unreachable!("{name}"),
        }
    }

    fn surface(&self, name: &str, ray: &Ray) -> Option<Hit> {
        let t_max = f32::INFINITY;
        match name {
            "sphere" => self
                .sphere
                .hit_distance(ray, t_max)
                .map(|t| self.sphere.surface_at(ray, t)),
            "plane" => self
                .plane
                .hit_distance(ray, t_max)
                .map(|t| self.plane.surface_at(ray, t)),
            "parallelogram" => self
                .parallelogram
                .hit_distance(ray, t_max)
                .map(|t| self.parallelogram.surface_at(ray, t)),
            "box" => self
                .aabox
                .hit_distance(ray, t_max)
                .map(|t| self.aabox.surface_at(ray, t)),
            "triangle" => self.triangle.surface_at(0, ray, t_max),
            _ => unreachable!("{name}"),
        }
    }
}

const SHAPES: [&str; 5] = ["sphere", "plane", "parallelogram", "box", "triangle"];

fn single_shapes(c: &mut Criterion) {
    let shapes = Shapes::new();
    let mut rng = Xorshift(0x9e37_79b9_7f4a_7c15);
    let hit_rays = rays_towards(&mut rng, 0.0, 0.45);
    let pass_rays = rays_towards(&mut rng, 2.0, 3.0);
    // The unbounded plane is missed by rays leaving it behind them.
    let away_rays: Vec<Ray> = hit_rays
        .iter()
        .map(|r| Ray::new(r.origin, -r.direction))
        .collect();
    let miss_rays = |name: &str| {
        if name == "plane" {
            &away_rays
        } else {
            &pass_rays
        }
    };

    // The cases are what they say.
    for name in SHAPES {
        assert!(hit_rays
            .iter()
            .all(|r| shapes.hit_distance(name, r).is_some()));
        assert!(miss_rays(name)
            .iter()
            .all(|r| shapes.hit_distance(name, r).is_none()));
    }

    let mut group = c.benchmark_group("hit_distance");
    configure(&mut group, BATCH);
    for name in SHAPES {
        for (case, rays) in [("hit", &hit_rays), ("miss", miss_rays(name))] {
            group.bench_function(format!("{name}/{case}"), |b| {
                b.iter(|| {
                    for ray in rays {
                        black_box(shapes.hit_distance(name, black_box(ray)));
                    }
                })
            });
        }
    }
    group.finish();

    let mut group = c.benchmark_group("surface");
    configure(&mut group, BATCH);
    for name in SHAPES {
        group.bench_function(format!("{name}/hit"), |b| {
            b.iter(|| {
                for ray in &hit_rays {
                    black_box(shapes.surface(name, black_box(ray)));
                }
            })
        });
    }
    group.finish();

    let mut group = c.benchmark_group("closest_hit");
    configure(&mut group, BATCH);
    for name in SHAPES {
        let list = shapes.list(name);
        for (case, rays) in [("hit", &hit_rays), ("miss", miss_rays(name))] {
            group.bench_function(format!("{name}/{case}"), |b| {
                b.iter(|| {
                    for ray in rays {
                        black_box(list.closest_hit(black_box(ray), f32::INFINITY));
                    }
                })
            });
        }
    }
    group.finish();
}

/// 256 shadow rays: from each of 16 shading points (what the camera rays
/// `camera` sees of `list`) to 16 points of the light square (4 × 4 cell
/// centres); with the shading points and the light's corners, for culling.
struct ShadowRays {
    rays: Vec<Ray>,
    t_max: Vec<f32>,
    points: Vec<Hit>,
}

const POINTS: usize = 16;
const LIGHT_SAMPLES: usize = 16;

fn shadow_rays(list: &ShapeList, camera: &[Ray], light: &Parallelogram) -> ShadowRays {
    let points: Vec<Hit> = camera
        .iter()
        .map(|r| {
            list.closest_hit(r, f32::INFINITY)
                .expect("a visible surface")
        })
        .collect();
    assert_eq!(points.len(), POINTS);
    let (mut rays, mut t_max) = (Vec::new(), Vec::new());
    for hit in &points {
        for k in 0..LIGHT_SAMPLES {
            let cell = Vec2::new((k % 4) as f32 + 0.5, (k / 4) as f32 + 0.5) / 4.0;
            let target = RayTarget {
                point: light.point_at(cell),
                error: light.error_bound(),
                normal: light.normal(),
            };
            rays.push(spawn_ray_to(hit, &target));
            t_max.push(1.0);
        }
    }
    ShadowRays {
        rays,
        t_max,
        points,
    }
}

/// The course's Cornell box, Set1: five one-sided walls facing in, four spheres.
fn cornell() -> ShapeList {
    let wall = |o: [f32; 3], e1: [f32; 3], e2: [f32; 3], n: [f32; 3]| {
        Parallelogram::new(o.into(), e1.into(), e2.into(), false)
            .unwrap()
            .facing(n.into())
    };
    let mut list = ShapeList::new();
    for p in [
        wall(
            [-10., -10., -10.],
            [20., 0., 0.],
            [0., 20., 0.],
            [0., 0., 1.],
        ),
        wall([-6., -7., -11.], [0., 0., 20.], [0., 20., 0.], [1., 0., 0.]),
        wall([6., -7., -11.], [0., 0., 20.], [0., 20., 0.], [-1., 0., 0.]),
        wall([-7., -6., -11.], [20., 0., 0.], [0., 0., 20.], [0., 1., 0.]),
        wall([-7., 6., -11.], [20., 0., 0.], [0., 0., 20.], [0., -1., 0.]),
    ] {
        list.push(p);
    }
    for (c, r) in [
        ([3., 1., -7.], 1.5),
        ([2., -3.2, -5.], 1.0),
        ([-4., 2., -5.], 1.8),
        ([-2., -4.5, -8.], 2.0),
    ] {
        list.push(Sphere::new(c.into(), r).unwrap());
    }
    list.build_acceleration();
    list
}

/// Rays from `eye` through a 4 × 4 grid of points spread over `extent` around
/// `centre` in the plane through `centre` spanned by `right` and `up`.
fn camera_grid(eye: Vec3, centre: Vec3, right: Vec3, up: Vec3) -> Vec<Ray> {
    (0..POINTS)
        .map(|k| {
            let (i, j) = ((k % 4) as f32 / 3.0 - 0.5, (k / 4) as f32 / 3.0 - 0.5);
            Ray::new(eye, centre + i * right + j * up - eye)
        })
        .collect()
}

fn bench_shadows(
    c: &mut Criterion,
    group_name: &str,
    list: &ShapeList,
    shadows: &ShadowRays,
    light: &Parallelogram,
) {
    let occluded = shadows
        .rays
        .iter()
        .zip(&shadows.t_max)
        .filter(|(r, &t)| list.any_hit(r, t))
        .count();
    println!(
        "{group_name}: {} objects, {occluded} of {} shadow rays occluded",
        list.len(),
        shadows.rays.len()
    );
    let mut group = c.benchmark_group(group_name);
    configure(&mut group, shadows.rays.len());
    group.bench_function("any_hit", |b| {
        let mut answers = vec![false; shadows.rays.len()];
        b.iter(|| {
            for ((ray, &t_max), answer) in shadows.rays.iter().zip(&shadows.t_max).zip(&mut answers)
            {
                *answer = list.any_hit(black_box(ray), t_max);
            }
            black_box(&answers);
        })
    });
    group.bench_function("any_hits", |b| {
        let mut answers = vec![false; shadows.rays.len()];
        b.iter(|| {
            list.any_hits(black_box(&shadows.rays), &shadows.t_max, &mut answers);
            black_box(&answers);
        })
    });
    if list.meshes().is_empty() {
        let corners = light.corners();
        group.bench_function("occluders_towards+any_hit_among", |b| {
            let mut answers = vec![false; shadows.rays.len()];
            b.iter(|| {
                for (p, point) in shadows.points.iter().enumerate() {
                    let occluders = list.occluders_towards(
                        black_box(point.point),
                        0.0,
                        &corners,
                        [point.shape, u32::MAX],
                    );
                    let range = p * LIGHT_SAMPLES..(p + 1) * LIGHT_SAMPLES;
                    for ((ray, &t_max), answer) in shadows.rays[range.clone()]
                        .iter()
                        .zip(&shadows.t_max[range.clone()])
                        .zip(&mut answers[range])
                    {
                        *answer = list.any_hit_among(&occluders, ray, t_max);
                    }
                }
                black_box(&answers);
            })
        });
    }
    // What the integrator does: each point's rays `LANES` at a time in SIMD lanes,
    // against the shapes its culling keeps (all of them beside a mesh's BVH,
    // which they walk together).
    let corners = light.corners();
    let batches: Vec<(usize, RayLanes)> = (0..POINTS)
        .flat_map(|p| {
            (0..LIGHT_SAMPLES / LANES).map(move |half| (p, p * LIGHT_SAMPLES + half * LANES))
        })
        .map(|(p, first)| {
            let rays: [Ray; LANES] = std::array::from_fn(|k| shadows.rays[first + k]);
            (p, RayLanes::new(rays))
        })
        .collect();
    let t_max = shadows.t_max[0];
    assert!(shadows.t_max.iter().all(|&t| t == t_max));
    group.bench_function("occluders_towards+any_hits_among (lanes)", |b| {
        b.iter(|| {
            let mut blocked = 0u32;
            for pair in batches.chunks(LIGHT_SAMPLES / LANES) {
                let point = &shadows.points[pair[0].0];
                let occluders = list.occluders_towards(
                    black_box(point.point),
                    0.0,
                    &corners,
                    [point.shape, u32::MAX],
                );
                for (_, rays) in pair {
                    blocked += list
                        .any_hits_among(&occluders, black_box(rays), t_max, (1 << LANES) - 1)
                        .count_ones();
                }
            }
            black_box(blocked)
        })
    });
    group.finish();
}

fn shadows(c: &mut Criterion) {
    // The Cornell box seen from the course's Set1 camera; its 2 × 2 light.
    let list = cornell();
    let light = Parallelogram::new(
        Vec3::new(-1.0, 5.9, -7.0),
        2.0 * Vec3::X,
        2.0 * Vec3::Z,
        false,
    )
    .unwrap();
    let camera = camera_grid(
        Vec3::new(0.0, 0.0, 10.0),
        Vec3::new(0.0, 0.0, -10.0),
        Vec3::new(14.0, 0.0, 0.0),
        Vec3::new(0.0, -14.0, 0.0),
    );
    let shadows = shadow_rays(&list, &camera, &light);
    bench_shadows(c, "shadow_cornell", &list, &shadows, &light);

    // The grid from above, lit by a square low on one side: shadow rays graze
    // the bumps.
    let mut list = ShapeList::new();
    let mesh = TriangleMesh::displaced_grid(71);
    let triangles = mesh.triangle_count();
    list.push_mesh(mesh);
    list.build_acceleration();
    assert!(
        list.bvh_stats().is_some(),
        "{triangles} triangles get a BVH"
    );
    let light =
        Parallelogram::new(Vec3::new(2.0, 0.6, -0.5), Vec3::Z, 0.2 * Vec3::Y, false).unwrap();
    let camera = camera_grid(
        Vec3::new(0.0, 2.0, 2.0),
        Vec3::ZERO,
        Vec3::new(1.6, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 1.6),
    );
    let shadows = shadow_rays(&list, &camera, &light);
    bench_shadows(c, "shadow_mesh", &list, &shadows, &light);
}

criterion_group!(benches, single_shapes, shadows);
criterion_main!(benches);
