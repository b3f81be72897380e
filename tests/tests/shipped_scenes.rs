//! The shipped scenes load, describe what the course describes, and render
//! reproducibly.

use glam::{UVec2, Vec3};
use glint_camera::Film;
use glint_integrator::{render, RenderSettings, SamplePattern, Surface};
use glint_lighting::Light;
use glint_scene::{load, SceneDescription};
use glint_snapfmt::sig5;
use glint_tests::{scene_path, shipped_scenes};
use std::fmt::Write;

fn cornell(set: u32) -> SceneDescription {
    load(&scene_path(&format!("cornell-set{set}"))).unwrap()
}

/// Every pixel's RGB, rounded to five significant digits, one line per pixel.
fn pixel_table(film: &Film) -> String {
    let mut s = String::new();
    let size = film.resolution();
    for y in 0..size.y {
        for x in 0..size.x {
            let p = film.pixel(x, y);
            writeln!(s, "({x:2},{y:2}) {} {} {}", sig5(p.x), sig5(p.y), sig5(p.z)).unwrap();
        }
    }
    s
}

/// Renders a loaded scene at another resolution, with its settings changed by `tweak`.
fn render_at(
    d: &SceneDescription,
    width: u32,
    height: u32,
    tweak: impl FnOnce(&mut RenderSettings),
) -> Film {
    let camera = d
        .scene
        .camera
        .with_resolution(UVec2::new(width, height))
        .unwrap();
    let scene = glint_integrator::Scene {
        camera,
        ..d.scene.clone()
    };
    let mut settings = d.settings.clone();
    tweak(&mut settings);
    render(&scene, &settings, &|_, _| {}).unwrap().film
}

#[test]
fn every_shipped_scene_loads() {
    let names = shipped_scenes();
    for expected in [
        "cornell-set1",
        "cornell-set2",
        "cornell-set3",
        "point-light",
    ] {
        assert!(names.iter().any(|n| n == expected), "{expected} missing");
    }
    for name in names {
        let d = load(&scene_path(&name)).unwrap_or_else(|e| panic!("{e}"));
        assert!(d.settings.validate().is_ok(), "{name}");
        let lit = !d.scene.lights.is_empty() || d.scene.environment.is_some();
        assert!(lit, "{name} has neither a light nor an environment");
    }
}

#[test]
fn cornell_sets_match_the_course_numbers() {
    let sets = [
        (
            Vec3::new(0.0, 0.0, 10.0),
            Vec3::new(0.0, 5.9, -6.0),
            Vec3::ONE,
        ),
        (
            Vec3::new(5.0, 3.0, 12.0),
            Vec3::new(3.0, 5.9, -6.0),
            Vec3::new(0.9, 0.8, 0.0),
        ),
        (
            Vec3::new(0.0, -4.0, 15.0),
            Vec3::new(-3.0, 5.9, -6.0),
            Vec3::new(0.0, 0.9, 0.7),
        ),
    ];
    for (i, (eye, light_centre, light_color)) in sets.into_iter().enumerate() {
        let d = cornell(i as u32 + 1);
        let s = &d.scene;
        assert_eq!(s.camera.position(), eye);
        assert!((s.camera.fov_y().to_degrees() - 45.0).abs() < 1e-4);
        assert_eq!(s.ambient, Vec3::splat(0.1));
        assert_eq!(s.shapes.len(), 5 + 4 + 1, "walls, spheres, light");
        let emitters = s
            .surfaces
            .iter()
            .filter(|x| matches!(x, Surface::Emitter(_)))
            .count();
        assert_eq!(emitters, 1);
        let Light::Area(light) = &s.lights[0] else {
            panic!("set {} light is not an area light", i + 1)
        };
        assert_eq!(light.color, light_color);
        assert_eq!(light.surface().center(), light_centre);
        assert_eq!(light.surface().normal(), -Vec3::Y);
        assert!((light.surface().area() - 4.0).abs() < 1e-6);
    }
    // The three sets share everything but camera and light.
    let (a, b) = (cornell(1).scene, cornell(3).scene);
    assert_eq!(a.materials, b.materials);
    assert_eq!(a.shapes.shapes()[..9], b.shapes.shapes()[..9]);
}

/// A 16×16 render of Set1 with the course's grid patterns (4 spp, 4 light
/// samples), every pixel's RGB locked to five significant digits.
#[test]
fn cornell_set1_16x16_render_snapshot() {
    let film = render_at(&cornell(1), 16, 16, |s| {
        (s.spp, s.pixel_pattern) = (4, SamplePattern::Grid);
        (s.light_samples, s.light_pattern) = (4, SamplePattern::Grid);
    });
    insta::assert_snapshot!(pixel_table(&film));
}

#[test]
fn cornell_set1_renders_the_course_picture() {
    // Coarse properties of the picture, at 64×64: the walls' colors and the
    // light's own color where the camera sees it.
    let film = render_at(&cornell(1), 64, 64, |s| (s.spp, s.light_samples) = (4, 4));
    let left_wall = film.pixel(2, 52);
    let right_wall = film.pixel(61, 52);
    let back_wall = film.pixel(32, 40);
    // Lit walls reflect more than the ambient term alone (0.1 · kd).
    assert!(
        left_wall.x > 0.12 && left_wall.y == 0.0 && left_wall.z == 0.0,
        "{left_wall}"
    );
    assert!(
        right_wall.y > 0.12 && right_wall.x == 0.0 && right_wall.z == 0.0,
        "{right_wall}"
    );
    assert!(back_wall.x > 0.084 && back_wall.x == back_wall.y && back_wall.y == back_wall.z);
    // The light's square is seen in its own color (white) near the top centre.
    let light_pixels = (0..12)
        .flat_map(|y| (24..40).map(move |x| (x, y)))
        .filter(|&(x, y)| film.pixel(x, y) == Vec3::ONE)
        .count();
    assert!(light_pixels >= 4, "light covers {light_pixels} pixels");
}

#[test]
fn shipped_scene_renders_bit_identically_on_1_and_4_threads() {
    let d = cornell(2);
    assert_eq!(
        bits_on_threads(&d, 48, 40, (4, 3), 1),
        bits_on_threads(&d, 48, 40, (4, 3), 4)
    );
}

/// The bits of every pixel of a `width × height` render with `(spp, light
/// samples)`, random light samples, on `threads` threads.
fn bits_on_threads(
    d: &SceneDescription,
    width: u32,
    height: u32,
    (spp, light_samples): (u32, u32),
    threads: usize,
) -> Vec<u32> {
    let film = render_at(d, width, height, |s| {
        (s.spp, s.light_samples) = (spp, light_samples);
        s.light_pattern = SamplePattern::Random;
        s.threads = Some(threads);
    });
    let bits = film
        .pixels()
        .iter()
        .flat_map(|p| p.to_array().map(f32::to_bits));
    bits.collect()
}

/// A 16×16 render of the environment scene (cube map, mirrors, environment light),
/// every pixel's RGB locked to five significant digits.
#[test]
fn environment_16x16_render_snapshot() {
    let d = load(&scene_path("environment")).unwrap();
    let film = render_at(&d, 16, 16, |s| {
        (s.spp, s.pixel_pattern) = (4, SamplePattern::Grid);
        s.environment_samples = 4;
    });
    insta::assert_snapshot!(pixel_table(&film));
}

/// A 16×16 render of the physical Cornell box (grid patterns, 4 spp, 4 light
/// samples), every pixel's RGB locked to five significant digits.
#[test]
fn cornell_physical_16x16_render_snapshot() {
    let d = load(&scene_path("cornell-physical")).unwrap();
    let film = render_at(&d, 16, 16, |s| {
        (s.spp, s.pixel_pattern) = (4, SamplePattern::Grid);
        (s.light_samples, s.light_pattern) = (4, SamplePattern::Grid);
    });
    insta::assert_snapshot!(pixel_table(&film));
}

/// A 24×12 render of the glossy spheres (multiple importance sampling of
/// lobes, two lights), locked the same way.
#[test]
fn physical_glossy_24x12_render_snapshot() {
    let d = load(&scene_path("physical-glossy")).unwrap();
    let film = render_at(&d, 24, 12, |s| {
        (s.spp, s.pixel_pattern) = (4, SamplePattern::Grid);
        (s.light_samples, s.light_pattern) = (4, SamplePattern::Grid);
    });
    insta::assert_snapshot!(pixel_table(&film));
}

/// Physical shading, with its lobe samples and random light samples, is
/// bit-identical for any thread count too.
#[test]
fn physical_scene_renders_bit_identically_on_1_and_4_threads() {
    let d = load(&scene_path("physical-glossy")).unwrap();
    assert_eq!(
        bits_on_threads(&d, 48, 24, (2, 3), 1),
        bits_on_threads(&d, 48, 24, (2, 3), 4)
    );
}
