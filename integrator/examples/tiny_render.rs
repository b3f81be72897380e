//! Renders a tiny scene built in code — a ground plane, a sphere, an area light, a
//! point light and some ambient light — with the direct-lighting integrator, and
//! prints it to the terminal as ASCII art by luminance, followed by the render stats.
//!
//! Terminal characters are about twice as tall as they are wide, so the image is
//! rendered square at 48x48 pixels and each character shows the average of two
//! pixel rows: 48 columns by 24 lines, with the sphere still round.
//!
//! `cargo run -p glint-integrator --example tiny_render`

use glam::{UVec2, Vec3};
use glint_camera::Camera;
use glint_geometry::{Plane, Sphere};
use glint_integrator::{render, RenderSettings, SceneBuilder};
use glint_lighting::{AreaLight, PhongMaterial, PointLight};

const COLUMNS: u32 = 48;
const LINES: u32 = 24;
/// From dark to bright.
const RAMP: &[u8] = b" .:-=+*#%@";

fn main() {
    let mut builder = SceneBuilder::new();
    let matte_grey = builder.material(PhongMaterial {
        specular: Some(Vec3::ZERO.into()),
        ..PhongMaterial::new(Vec3::splat(0.6), 1.0)
    });
    let shiny_orange = builder.material(PhongMaterial::new(Vec3::new(0.9, 0.6, 0.4), 32.0));
    builder
        .shape(Plane::new(Vec3::ZERO, Vec3::Y, false).unwrap(), matte_grey)
        .shape(
            Sphere::new(Vec3::new(0.0, 1.0, 0.0), 1.0).unwrap(),
            shiny_orange,
        )
        // A 2x2 square light above the sphere; edge1 × edge2 = −y, so it shines down.
        .area_light(
            AreaLight::new(
                Vec3::new(0.0, 3.0, 0.0),
                2.0 * Vec3::X,
                2.0 * Vec3::Z,
                Vec3::splat(0.7),
            )
            .unwrap(),
        )
        .point_light(PointLight {
            position: Vec3::new(4.0, 3.0, 2.0),
            color: Vec3::splat(0.4),
        })
        .ambient(Vec3::splat(0.05));

    let camera = Camera::new(
        Vec3::new(0.0, 1.6, 5.0),
        Vec3::new(0.0, 1.1, 0.0),
        Vec3::Y,
        50.0,
        1.0,
        UVec2::new(COLUMNS, 2 * LINES),
    )
    .unwrap();
    let scene = builder.build(camera).unwrap();
    let settings = RenderSettings::default();
    let output = render(&scene, &settings, &|_, _| {}).unwrap();

    for line in 0..LINES {
        let text: String = (0..COLUMNS)
            .map(|x| {
                let radiance =
                    0.5 * (output.film.pixel(x, 2 * line) + output.film.pixel(x, 2 * line + 1));
                ramp_char(radiance)
            })
            .collect();
        println!("{text}");
    }

    let stats = output.stats;
    println!(
        "{}x{} pixels, {} samples per pixel, {} per area light",
        COLUMNS,
        2 * LINES,
        settings.spp,
        settings.light_samples
    );
    println!(
        "camera rays {}, shadow rays {}, time {:.1} ms ({:.2} Mrays/s)",
        stats.camera_rays,
        stats.shadow_rays,
        stats.elapsed.as_secs_f64() * 1e3,
        stats.rays_per_second() / 1e6
    );
}

/// The ramp character for linear radiance: Rec. 709 luminance, clamped to [0, 1]
/// and gamma-encoded (1/2.2) so that the dark half of the image gets its share of
/// the ramp.
fn ramp_char(radiance: Vec3) -> char {
    let luminance = radiance.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    let level = luminance.clamp(0.0, 1.0).powf(1.0 / 2.2);
    RAMP[(level * (RAMP.len() - 1) as f32).round() as usize] as char
}
