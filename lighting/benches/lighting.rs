//! Phong shading and the environment light, per evaluation.
//!
//! `cargo bench -p glint-lighting --bench lighting`
//!
//! - `phong_reflect/*` and `phong_brdf_cos/*`: [`PhongMaterial::reflect`] (one
//!   light's reflection) and [`PhongMaterial::brdf_cos`] (the normalised BRDF
//!   times the cosine, for environment samples) over 256 random unit `(n, l, v)`
//!   in one hemisphere, with `ks = 0` (the lobe still computed, times zero), the
//!   diffuse-only shortcuts the integrator takes when `ks = 0`
//!   (`reflect_diffuse`, `brdf_cos_diffuse`), and `ks > 0` with shininess 1,
//!   16, 120 (integral: repeated squaring) and 33.5 (`powf`), and the
//!   Blinn–Phong lobe at 16.
//! - `environment/*`: [`EnvironmentLight::radiance`] along 256 random directions
//!   with no footprint (`width0`: bilinear on level 0) and with cone widths of
//!   0.03 and 0.1 radians (trilinear between pyramid levels about 1.3 and 3 of
//!   the lat-long map), and
//!   [`EnvironmentLight::sample`] for 256 random `u` (importance sampling by
//!   luminance), on the shipped `studio` environment as a lat-long map
//!   (`scenes/environments/studio-latlong.hdr`, 512 × 256) and as a cube map
//!   (`scenes/environments/studio/*.hdr`, 6 × 128 × 128), rotated 0.5 rad.
//!
//! Throughput is in evaluations; pyramids are built before timing. See
//! `docs/microbenchmarks.md`.

use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion, Throughput};
use glam::{Vec2, Vec3};
use glint_lighting::{EnvironmentLight, PhongMaterial, SpecularLobe};
use glint_texture::{load_image, CubeMap, Environment, LatLongMap};
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Duration;

const BATCH: usize = 256;

struct Xorshift(u64);

impl Xorshift {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A uniform direction on the unit sphere.
    fn direction(&mut self) -> Vec3 {
        let z = 2.0 * self.next() - 1.0;
        let phi = std::f32::consts::TAU * self.next();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    /// A uniform direction in the hemisphere about `n`.
    fn hemisphere(&mut self, n: Vec3) -> Vec3 {
        let d = self.direction();
        if d.dot(n) < 0.0 {
            -d
        } else {
            d
        }
    }
}

fn configure(group: &mut BenchmarkGroup<'_, criterion::measurement::WallTime>) {
    group
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .throughput(Throughput::Elements(BATCH as u64));
}

/// `(n, l, v)`: unit vectors, `l` and `v` above the surface.
fn shading_vectors(rng: &mut Xorshift) -> Vec<(Vec3, Vec3, Vec3)> {
    (0..BATCH)
        .map(|_| {
            let n = rng.direction();
            (n, rng.hemisphere(n), rng.hemisphere(n))
        })
        .collect()
}

fn phong(c: &mut Criterion) {
    let mut rng = Xorshift(0x2545_f491_4f6c_dd1d);
    let vectors = shading_vectors(&mut rng);
    let kd = Vec3::new(0.7, 0.5, 0.3);
    let material = |shininess: f32, lobe: SpecularLobe| PhongMaterial {
        lobe,
        ..PhongMaterial::new(kd, shininess)
    };
    // (name, material, ks)
    let mut cases = vec![("ks0_s16", material(16.0, SpecularLobe::Phong), Vec3::ZERO)];
    for s in [1.0, 16.0, 120.0, 33.5] {
        cases.push((
            match s {
                1.0 => "ks_s1",
                16.0 => "ks_s16",
                120.0 => "ks_s120",
                _ => "ks_s33.5_powf",
            },
            material(s, SpecularLobe::Phong),
            kd,
        ));
    }
    cases.push(("ks_s16_blinn", material(16.0, SpecularLobe::BlinnPhong), kd));

    let mut group = c.benchmark_group("phong_reflect");
    configure(&mut group);
    for (name, material, ks) in &cases {
        group.bench_function(*name, |b| {
            b.iter(|| {
                for &(n, l, v) in &vectors {
                    black_box(material.reflect(kd, *ks, black_box(n), l, v));
                }
            })
        });
    }
    let diffuse = &cases[0].1;
    group.bench_function("reflect_diffuse", |b| {
        b.iter(|| {
            for &(n, l, _) in &vectors {
                black_box(diffuse.reflect_diffuse(kd, black_box(n), l));
            }
        })
    });
    group.finish();

    let mut group = c.benchmark_group("phong_brdf_cos");
    configure(&mut group);
    for (name, material, ks) in &cases {
        group.bench_function(*name, |b| {
            b.iter(|| {
                for &(n, l, v) in &vectors {
                    black_box(material.brdf_cos(kd, *ks, black_box(n), l, v));
                }
            })
        });
    }
    group.bench_function("brdf_cos_diffuse", |b| {
        b.iter(|| {
            for &(n, l, _) in &vectors {
                black_box(diffuse.brdf_cos_diffuse(kd, black_box(n), l));
            }
        })
    });
    group.finish();
}

fn environments() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/environments")
}

fn load(path: &Path) -> glint_texture::Image {
    load_image(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn environment(c: &mut Criterion) {
    let dir = environments();
    let latlong = Environment::LatLong(LatLongMap::new(load(&dir.join("studio-latlong.hdr"))));
    let faces =
        ["px", "nx", "py", "ny", "pz", "nz"].map(|f| load(&dir.join(format!("studio/{f}.hdr"))));
    let cube = Environment::CubeMap(CubeMap::new(faces).expect("a valid cube map"));

    let mut rng = Xorshift(0x9e37_79b9_7f4a_7c15);
    let directions: Vec<Vec3> = (0..BATCH).map(|_| rng.direction()).collect();
    let normals: Vec<Vec3> = (0..BATCH).map(|_| rng.direction()).collect();
    let us: Vec<Vec2> = (0..BATCH)
        .map(|_| Vec2::new(rng.next(), rng.next()))
        .collect();

    for (name, environment) in [("latlong", latlong), ("cube", cube)] {
        let light = EnvironmentLight::new(environment, 0.5, 1.0);
        // Build the pyramids now, not in the first timed lookup.
        black_box(light.radiance(Vec3::Y, 0.1));
        let mut group = c.benchmark_group(format!("environment/{name}"));
        configure(&mut group);
        for (case, width) in [("width0", 0.0), ("width0.03", 0.03), ("width0.1", 0.1)] {
            group.bench_function(format!("radiance/{case}"), |b| {
                b.iter(|| {
                    for &d in &directions {
                        black_box(light.radiance(black_box(d), width));
                    }
                })
            });
        }
        group.bench_function("sample", |b| {
            b.iter(|| {
                for (&n, &u) in normals.iter().zip(&us) {
                    black_box(light.sample(n, black_box(u)));
                }
            })
        });
        group.finish();
    }
}

criterion_group!(benches, phong, environment);
criterion_main!(benches);
