//! What a scene doesn't need, the renderer doesn't do: each skip shown by a zero
//! in the render's counts (`glint render --stats`), beside a scene that does need
//! the work and counts it.

mod common;

use common::diffuse;
use glam::{UVec2, Vec2, Vec3};
use glint_camera::Camera;
use glint_geometry::{Parallelogram, Plane, Sphere, TriangleMesh};
use glint_integrator::{render, LookupKind, RenderSettings, RenderStats, Scene, SceneBuilder};
use glint_lighting::{AreaLight, PhongMaterial, PointLight};
use glint_texture::{Checkerboard, ImageTexture, Texture, TextureFilter, TextureImage, WrapMode};

/// The tests' camera, on a tiny film.
fn camera() -> Camera {
    common::camera(UVec2::new(24, 16))
}

/// A floor and a sphere under a point light, made of `floor` and `ball`.
fn scene_with(
    floor: PhongMaterial,
    ball: PhongMaterial,
    light: impl FnOnce(&mut SceneBuilder),
) -> Scene {
    let mut b = SceneBuilder::new();
    let f = b.material(floor);
    let s = b.material(ball);
    b.shape(Plane::new(Vec3::ZERO, Vec3::Y, false).unwrap(), f)
        .shape(Sphere::new(Vec3::new(0.0, 0.7, -2.0), 0.7).unwrap(), s);
    light(&mut b);
    b.build(camera()).unwrap()
}

fn point_light(b: &mut SceneBuilder) {
    b.point_light(PointLight {
        position: Vec3::new(1.0, 3.0, -1.0),
        color: Vec3::ONE,
    });
}

fn area_light(b: &mut SceneBuilder) {
    let light = AreaLight::new(Vec3::new(0.0, 3.0, -2.0), Vec3::X, Vec3::Z, Vec3::ONE).unwrap();
    b.area_light(light.facing(-Vec3::Y));
}

fn stats_of(scene: &Scene) -> RenderStats {
    stats_with(scene, 4)
}

/// `scene`'s counts at 4 spp with `light_samples` per light.
fn stats_with(scene: &Scene, light_samples: u32) -> RenderStats {
    let settings = RenderSettings {
        spp: 4,
        light_samples,
        stats: true,
        ..RenderSettings::default()
    };
    render(scene, &settings, &|_, _| {}).unwrap().stats
}

fn plain() -> Scene {
    scene_with(
        diffuse(Vec3::splat(0.5)),
        diffuse(Vec3::splat(0.8)),
        point_light,
    )
}

#[test]
fn a_scene_without_textures_looks_up_none_and_computes_no_footprints() {
    let stats = stats_of(&plain());
    assert_eq!(stats.textures.all(), 0);
    assert_eq!(stats.shading.footprints, 0);
    // A trilinear image texture on the floor: footprints and pyramid lookups.
    let image = TextureImage::from_checkerboard(Checkerboard::new(Vec3::ONE, Vec3::ZERO, 8), 4);
    let textured = PhongMaterial {
        diffuse: Texture::Image(ImageTexture::new(
            image,
            WrapMode::Repeat,
            TextureFilter::Trilinear,
        )),
        ..diffuse(Vec3::ONE)
    };
    let stats = stats_of(&scene_with(textured, diffuse(Vec3::ONE), point_light));
    assert!(stats.textures.total(LookupKind::Trilinear) > 0);
    assert_eq!(
        stats.textures.total(LookupKind::Trilinear),
        stats.shading.footprints
    );
}

#[test]
fn textures_never_filtered_build_no_pyramid() {
    let image = TextureImage::from_checkerboard(Checkerboard::new(Vec3::ONE, Vec3::ZERO, 8), 4);
    for (filter, pyramid) in [(TextureFilter::Nearest, false), (TextureFilter::Ewa, true)] {
        let texture = ImageTexture::new(image.clone(), WrapMode::Repeat, filter);
        let material = PhongMaterial {
            diffuse: Texture::Image(texture),
            ..diffuse(Vec3::ONE)
        };
        let stats = stats_of(&scene_with(material, diffuse(Vec3::ONE), point_light));
        assert!(stats.textures.all() > 0);
        assert_eq!(image.has_pyramid(), pyramid, "{filter:?}");
    }
}

#[test]
fn no_specular_lobe_where_ks_is_zero() {
    assert_eq!(stats_of(&plain()).shading.specular_lobes, 0);
    let shiny = PhongMaterial::new(Vec3::splat(0.5), 20.0);
    let stats = stats_of(&scene_with(diffuse(Vec3::ONE), shiny, point_light));
    assert!(stats.shading.specular_lobes > 0);
}

#[test]
fn point_lights_take_one_sample_and_area_lights_take_light_samples() {
    let stats = stats_of(&plain());
    assert_eq!(stats.shading.light_samples, 0);
    assert!(stats.shading.point_light_samples > 0);
    assert!(stats.shading.light_shadow_rays > 0);
    let lit = scene_with(diffuse(Vec3::ONE), diffuse(Vec3::ONE), area_light);
    let stats = stats_of(&lit);
    // 4 samples per camera sample at every hit that is not the light itself.
    assert!(stats.shading.light_samples > 0);
    assert_eq!(stats.shading.light_samples % 4, 0);
}

#[test]
fn no_shadow_ray_for_a_light_behind_the_surface_or_a_surface_behind_the_light() {
    // A light under the floor: every floor sample is skipped, none is traced.
    let below = |b: &mut SceneBuilder| {
        b.point_light(PointLight {
            position: Vec3::new(0.0, -1.0, -2.0),
            color: Vec3::ONE,
        });
    };
    let mut b = SceneBuilder::new();
    let m = b.material(diffuse(Vec3::ONE));
    b.shape(Plane::new(Vec3::ZERO, Vec3::Y, false).unwrap(), m);
    below(&mut b);
    let stats = stats_of(&b.build(camera()).unwrap());
    assert_eq!(stats.shading.light_shadow_rays, 0);
    assert!(stats.shading.light_skips.below_surface > 0);
    // An area light facing up, above the floor: the floor is behind it.
    let mut b = SceneBuilder::new();
    let m = b.material(diffuse(Vec3::ONE));
    b.shape(Plane::new(Vec3::ZERO, Vec3::Y, false).unwrap(), m);
    let light = AreaLight::new(Vec3::new(0.0, 3.0, -2.0), Vec3::X, Vec3::Z, Vec3::ONE).unwrap();
    b.area_light(light.facing(Vec3::Y));
    let stats = stats_of(&b.build(camera()).unwrap());
    assert_eq!(stats.shading.light_shadow_rays, 0);
    assert_eq!(
        stats.shading.light_skips.behind_light,
        stats.shading.light_samples
    );
}

#[test]
fn no_environment_work_without_an_environment() {
    let stats = stats_of(&plain());
    assert_eq!(stats.shading.environment_lookups, 0);
    assert_eq!(stats.shading.environment_shadow_rays, 0);
}

#[test]
fn no_reflection_rays_without_reflectivity() {
    assert_eq!(stats_of(&plain()).shading.reflection_rays, 0);
    let mirror = PhongMaterial::mirror(Vec3::ONE);
    let stats = stats_of(&scene_with(diffuse(Vec3::ONE), mirror, point_light));
    assert!(stats.shading.reflection_rays > 0);
}

#[test]
fn a_handful_of_shapes_takes_the_linear_loop_and_a_mesh_the_bvh() {
    let stats = stats_of(&plain());
    assert_eq!((stats.queries.bvh_nodes, stats.queries.bvh_leaves), (0, 0));
    assert!(stats.queries.sphere_tests > 0 && stats.queries.plane_tests > 0);
    // A 16 × 16 grid of quads (512 triangles): through the BVH.
    let n = 16;
    let positions: Vec<Vec3> = (0..=n)
        .flat_map(|j| (0..=n).map(move |i| Vec3::new(i as f32 / 4.0 - 2.0, 0.0, -(j as f32) / 4.0)))
        .collect();
    let indices: Vec<[u32; 3]> = (0..n)
        .flat_map(|j| {
            (0..n).flat_map(move |i| {
                let k = j * (n + 1) + i;
                [[k, k + 1, k + n + 2], [k, k + n + 2, k + n + 1]]
            })
        })
        .collect();
    let triangles = indices.len();
    let mesh = TriangleMesh::new(positions, indices, vec![], Vec::<Vec2>::new()).unwrap();
    let mut b = SceneBuilder::new();
    let m = b.material(diffuse(Vec3::ONE));
    b.mesh(mesh, vec![m; triangles]);
    point_light(&mut b);
    let stats = stats_of(&b.build(camera()).unwrap());
    assert!(stats.queries.bvh_nodes > 0 && stats.queries.bvh_leaves > 0);
    assert!(stats.queries.triangle_tests > 0);
    assert_eq!(stats.queries.sphere_tests, 0);
}

#[test]
fn counting_changes_no_pixel_and_detailed_counts_wait_for_stats() {
    let scene = scene_with(
        diffuse(Vec3::ONE),
        PhongMaterial::new(Vec3::ONE, 8.0),
        area_light,
    );
    let quiet = RenderSettings {
        spp: 4,
        light_samples: 4,
        ..RenderSettings::default()
    };
    let counted = RenderSettings {
        stats: true,
        ..quiet.clone()
    };
    let a = render(&scene, &quiet, &|_, _| {}).unwrap();
    let b = render(&scene, &counted, &|_, _| {}).unwrap();
    assert_eq!(a.film.pixels(), b.film.pixels());
    assert_eq!(a.stats.shading, b.stats.shading);
    assert_eq!(a.stats.queries.shape_tests(), 0);
    assert!(b.stats.queries.shape_tests() > 0);
}

#[test]
fn nan_and_infinite_samples_are_dropped_and_counted() {
    let scene = scene_with(diffuse(Vec3::ONE), diffuse(Vec3::ONE), |b| {
        b.point_light(PointLight {
            position: Vec3::new(1.0, 3.0, -1.0),
            color: Vec3::INFINITY,
        });
    });
    let out = render(
        &scene,
        &RenderSettings {
            spp: 2,
            ..RenderSettings::default()
        },
        &|_, _| {},
    )
    .unwrap();
    assert!(out.stats.shading.nonfinite_samples > 0);
    assert!(out.film.pixels().iter().all(|p| p.is_finite()));
}

#[test]
fn parallelogram_walls_cull_their_own_shadow_rays() {
    // A floor parallelogram under an area light, a sphere between: the floor's
    // shadow rays are traced, and only against what can block them.
    let mut b = SceneBuilder::new();
    let m = b.material(diffuse(Vec3::ONE));
    let floor = Parallelogram::new(
        Vec3::new(-3.0, 0.0, 1.0),
        Vec3::X * 6.0,
        -Vec3::Z * 6.0,
        false,
    )
    .unwrap();
    b.shape(floor.facing(Vec3::Y), m)
        .shape(Sphere::new(Vec3::new(0.0, 1.0, -2.0), 0.5).unwrap(), m);
    area_light(&mut b);
    let scene = b.build(camera()).unwrap();
    // A floor point's shadow rays test neither parallelogram (they cannot hit
    // the floor, and end short of the light); only the sphere's points keep the
    // floor (the pyramid's faces do not separate it from them), so shadow rays
    // test very few. Doubling the light samples doubles the shadow rays and
    // their tests and leaves the camera rays' alone: the difference is theirs.
    let (four, eight) = (stats_with(&scene, 4), stats_with(&scene, 8));
    let shadow_rays = eight.shading.light_shadow_rays - four.shading.light_shadow_rays;
    let tests = eight.queries.parallelogram_tests - four.queries.parallelogram_tests;
    assert_eq!(eight.camera_rays, four.camera_rays);
    assert!(shadow_rays > 1000, "{shadow_rays} shadow rays");
    assert!(
        tests * 10 < shadow_rays,
        "{tests} tests by {shadow_rays} shadow rays"
    );
}

/// Whether every sample of each kind either sent a ray or was counted as
/// skipped: the counts `glint render --stats` prints add up.
fn assert_counts_add_up(stats: &RenderStats, what: &str) {
    let s = &stats.shading;
    assert_eq!(
        s.light_samples + s.point_light_samples,
        s.light_shadow_rays + s.light_skips.total(),
        "{what}: lights {s:?}"
    );
    assert_eq!(
        s.environment_samples,
        s.environment_shadow_rays + s.environment_skips.total(),
        "{what}: environment {s:?}"
    );
    assert_eq!(
        s.lobe_samples,
        s.brdf_rays + s.lobe_skips.total(),
        "{what}: lobes {s:?}"
    );
}

#[test]
fn every_sample_sends_a_ray_or_is_counted_as_skipped() {
    use glint_integrator::ShadingModel;
    use glint_lighting::EnvironmentLight;
    use glint_texture::Environment;
    let shiny = || PhongMaterial::new(Vec3::splat(0.4), 30.0);
    // Point light, area light (in lanes with one sample, one by one with four).
    let lit = scene_with(diffuse(Vec3::ONE), shiny(), area_light);
    for (what, scene) in [("point light", plain()), ("area light", lit)] {
        for light_samples in [1, 4] {
            let settings = RenderSettings {
                spp: 4,
                light_samples,
                ..RenderSettings::default()
            };
            let stats = render(&scene, &settings, &|_, _| {}).unwrap().stats;
            assert!(stats.shading.light_shadow_rays > 0, "{what}");
            assert_counts_add_up(&stats, what);
        }
    }
    // Physical shading: a glossy ball (lobe samples) under an area light, a
    // point light and a sky.
    let mut b = SceneBuilder::new();
    let f = b.material(diffuse(Vec3::splat(0.5)));
    let s = b.material(shiny());
    b.shape(Plane::new(Vec3::ZERO, Vec3::Y, false).unwrap(), f)
        .shape(Sphere::new(Vec3::new(0.0, 0.7, -2.0), 0.7).unwrap(), s)
        .shading(ShadingModel::Physical)
        .environment(EnvironmentLight::new(
            Environment::Constant(Vec3::splat(0.2)),
            0.0,
            1.0,
        ));
    area_light(&mut b);
    point_light(&mut b);
    let scene = b.build(camera()).unwrap();
    let settings = RenderSettings {
        spp: 4,
        light_samples: 4,
        environment_samples: 4,
        ..RenderSettings::default()
    };
    let stats = render(&scene, &settings, &|_, _| {}).unwrap().stats;
    let s = &stats.shading;
    assert!(s.lobe_samples > 0 && s.environment_samples > 0, "{s:?}");
    assert_counts_add_up(&stats, "physical");
}
