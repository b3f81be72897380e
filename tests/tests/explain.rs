//! `glint explain`'s guarantees over the shipped scenes: an explained pixel
//! is the rendered pixel, bit for bit, its steps recorded in the render's own
//! lanes; the recorded steps add up to it; a crop renders the same pixels as
//! the whole image.

use glam::{UVec2, Vec3};
use glint_integrator::trace::{Event, SampleSelection};
use glint_integrator::{
    explain_pixel, render, render_with, Crop, EnvironmentSampling, ExplainError, RenderControl,
    RenderSettings, SamplePattern, Scene,
};
use glint_scene::load;
use glint_tests::scene_path;
use glint_texture::Texture;

/// A shipped scene at `size`, with its settings changed by `tweak`.
fn scene(
    name: &str,
    size: UVec2,
    tweak: impl FnOnce(&mut RenderSettings),
) -> (Scene, RenderSettings) {
    let d = load(&scene_path(name)).unwrap();
    let camera = d.scene.camera.with_resolution(size).unwrap();
    let mut settings = d.settings.clone();
    tweak(&mut settings);
    (Scene { camera, ..d.scene }, settings)
}

fn bits(v: Vec3) -> [u32; 3] {
    v.to_array().map(f32::to_bits)
}

/// Each case takes another of the lanes' routes: one light sample and
/// several, several pixels' samples in one chunk's lanes, footprints read
/// lane by lane, mirrors and environment samples, the BVH, physical shading
/// with MIS and without, and every pattern of light and environment points.
fn cases() -> Vec<(&'static str, Scene, RenderSettings)> {
    let size = UVec2::new(24, 18);
    let few = |s: &mut RenderSettings| {
        s.spp = 4;
        s.light_samples = s.light_samples.min(4);
        s.environment_samples = s.environment_samples.min(4);
    };
    vec![
        ("cornell-set1, 1 light sample", {
            let (a, b) = scene("cornell-set1", size, |s| {
                few(s);
                s.light_samples = 1;
            });
            (a, b)
        }),
        (
            "cornell-set1, 4 light samples",
            scene("cornell-set1", size, few),
        ),
        // Pixels of one or two samples: runs of 16 and 8 pixels share a chunk.
        ("cornell-set1, 1 spp", {
            scene("cornell-set1", size, |s| {
                few(s);
                s.spp = 1;
            })
        }),
        ("ground-mipmap, 2 spp", {
            scene("ground-mipmap", size, |s| {
                few(s);
                s.spp = 2;
            })
        }),
        ("cornell-set3", scene("cornell-set3", size, few)),
        ("environment", scene("environment", size, few)),
        ("ground-mipmap", scene("ground-mipmap", size, few)),
        ("bunny-cornell", scene("bunny-cornell", size, few)),
        ("physical-glossy", scene("physical-glossy", size, few)),
        // Environment samples one or four a point (the first pair joint
        // with the pixel's), and behind a mirror.
        ("physical-textured-ground, 1 sample", {
            scene("physical-textured-ground", size, |s| {
                few(s);
                (s.light_samples, s.environment_samples) = (1, 1);
            })
        }),
        (
            "physical-textured-ground",
            scene("physical-textured-ground", size, few),
        ),
        (
            "physical-environment",
            scene("physical-environment", size, few),
        ),
        ("cornell-physical", scene("cornell-physical", size, few)),
        // A constant sky, sampled by the cosine in lanes.
        ("analytic-sky", scene("analytic-sky", size, few)),
        // A plane's points made in lanes.
        (
            "analytic-area-light",
            scene("analytic-area-light", size, few),
        ),
        // Point and sphere lights under physical shading, in the
        // camera-sample lanes.
        (
            "analytic-point-light",
            scene("analytic-point-light", size, few),
        ),
        ("analytic-sphere-light, every material diffuse", {
            let (mut scene, settings) = scene("analytic-sphere-light", size, few);
            for m in &mut scene.materials {
                m.specular = Some(Texture::Constant(Vec3::ZERO));
            }
            (scene, settings)
        }),
        // Environment directions by the cosine about each point's normal:
        // in lanes at first hits, a point's own in the scalar path.
        ("physical-environment, by the cosine", {
            scene("physical-environment", size, |s| {
                few(s);
                s.environment_sampling = EnvironmentSampling::Cosine;
            })
        }),
        ("environment, by the cosine", {
            scene("environment", size, |s| {
                few(s);
                s.environment_sampling = EnvironmentSampling::Cosine;
            })
        }),
        // Points from each sample's own stream, in the camera-sample lanes
        // too: random and stratified (drawn only where the scalar path
        // draws), and the grid's.
        ("physical-glossy, random points", {
            scene("physical-glossy", size, |s| {
                few(s);
                s.light_pattern = SamplePattern::Random;
            })
        }),
        ("physical-environment, stratified points", {
            scene("physical-environment", size, |s| {
                few(s);
                s.light_pattern = SamplePattern::Stratified;
                s.environment_pattern = SamplePattern::Stratified;
            })
        }),
        ("environment, random and grid points", {
            scene("environment", size, |s| {
                few(s);
                s.light_pattern = SamplePattern::Grid;
                s.environment_pattern = SamplePattern::Random;
            })
        }),
    ]
    .into_iter()
    .map(|(name, (scene, settings))| (name, scene, settings))
    .collect()
}

#[test]
fn explained_pixels_are_the_rendered_pixels_bit_for_bit() {
    for (name, scene, settings) in cases() {
        let film = render(&scene, &settings, &|_, _| {}).unwrap().film;
        let size = scene.camera.resolution();
        for y in (0..size.y).step_by(3) {
            for x in (0..size.x).step_by(2) {
                let explained =
                    explain_pixel(&scene, &settings, x, y, SampleSelection::One(0)).unwrap();
                assert_eq!(
                    bits(explained.radiance),
                    bits(film.pixel(x, y)),
                    "{name}: pixel ({x}, {y}): explained {} rendered {}",
                    explained.radiance,
                    film.pixel(x, y)
                );
            }
        }
    }
}

#[test]
fn the_recorded_samples_make_the_pixel_and_the_light_samples_their_lights() {
    for (name, scene, settings) in cases() {
        let explained = explain_pixel(&scene, &settings, 12, 12, SampleSelection::All).unwrap();
        assert_eq!(explained.samples.len(), settings.spp as usize, "{name}");
        let mut sum = Vec3::ZERO;
        for sample in &explained.samples {
            let (mut samples, mut physical) = (Vec::new(), Vec::new());
            for event in &sample.events {
                match event {
                    Event::SampleRadiance { value } => sum += *value,
                    Event::Light { .. } => {
                        samples.clear();
                        physical.clear();
                    }
                    Event::LightSample { value, .. } => samples.push(*value),
                    Event::PhysicalSample { value, .. } => physical.push(*value),
                    Event::LightTotal { light, value }
                        if !samples.is_empty() || !physical.is_empty() =>
                    {
                        let color = match &scene.lights[*light] {
                            glint_lighting::Light::Area(a) => a.color,
                            glint_lighting::Light::Point(p) => p.color,
                            glint_lighting::Light::Sphere(s) => s.color,
                        };
                        // The course's model: the light's color times the mean
                        // of its samples. Physical shading: its radiance times
                        // the sum of both techniques' samples over the light
                        // sample count (a point light: its one sample).
                        let want = if physical.is_empty() {
                            color * samples.iter().sum::<Vec3>() / samples.len() as f32
                        } else if matches!(scene.lights[*light], glint_lighting::Light::Point(_)) {
                            color * physical[0]
                        } else {
                            color * physical.iter().sum::<Vec3>() / settings.light_samples as f32
                        };
                        assert!(
                            (want - *value).abs().max_element()
                                <= 1e-5 * want.max_element().max(1.0),
                            "{name}: light {light}: samples give {want}, total {value}"
                        );
                    }
                    _ => {}
                }
            }
        }
        let mean = sum / settings.spp as f32;
        assert!(
            (mean - explained.radiance).abs().max_element()
                <= 1e-5 * explained.radiance.max_element().max(1.0),
            "{name}: samples' mean {mean}, pixel {}",
            explained.radiance
        );
    }
}

/// Every case, mirror waves and every pattern in lanes included: a crop
/// starting mid-run regroups the chunks' lanes, and no pixel may change.
#[test]
fn a_crop_renders_the_same_pixels_as_the_whole_image() {
    for (name, scene, settings) in cases() {
        let whole = render(&scene, &settings, &|_, _| {}).unwrap().film;
        let crop = Crop {
            x0: 5,
            y0: 3,
            x1: 19,
            y1: 17,
        };
        let control = RenderControl {
            crop: Some(crop),
            ..RenderControl::default()
        };
        let part = render_with(&scene, &settings, &|_, _| {}, control).unwrap();
        assert_eq!(part.film.resolution(), UVec2::new(14, 14));
        for y in 0..14 {
            for x in 0..14 {
                assert_eq!(
                    bits(part.film.pixel(x, y)),
                    bits(whole.pixel(crop.x0 + x, crop.y0 + y)),
                    "{name}: ({x}, {y}) of the crop"
                );
            }
        }
    }
}

/// A resumed render keeps the finished pixels and renders the rest, each the
/// whole render's pixel, where the finished ones break up the runs of
/// pixels that share a chunk.
#[test]
fn a_resumed_render_is_the_whole_render_where_runs_are_broken() {
    for (name, scene, settings) in cases() {
        let whole = render(&scene, &settings, &|_, _| {}).unwrap().film;
        let size = scene.camera.resolution();
        let finished: Vec<bool> = (0..size.x * size.y)
            .map(|i| i % 7 == 3 || i % 11 == 0)
            .collect();
        let mut film = glint_camera::Film::new(size);
        for (i, _) in finished.iter().enumerate().filter(|(_, &f)| f) {
            let (x, y) = (i as u32 % size.x, i as u32 / size.x);
            film.set_pixel(x, y, whole.pixel(x, y));
        }
        let partial = glint_camera::PartialFilm::new(film, finished);
        let control = RenderControl {
            resume: Some(&partial),
            ..RenderControl::default()
        };
        let resumed = render_with(&scene, &settings, &|_, _| {}, control).unwrap();
        assert!(resumed.finished.iter().all(|&f| f), "{name}");
        for y in 0..size.y {
            for x in 0..size.x {
                assert_eq!(
                    bits(resumed.film.pixel(x, y)),
                    bits(whole.pixel(x, y)),
                    "{name}: ({x}, {y})"
                );
            }
        }
    }
}

#[test]
fn pixels_and_samples_outside_the_render_are_refused() {
    let (scene, settings) = scene("cornell-set1", UVec2::new(8, 6), |s| s.spp = 4);
    assert!(matches!(
        explain_pixel(&scene, &settings, 8, 0, SampleSelection::One(0)),
        Err(ExplainError::Outside { .. })
    ));
    assert!(matches!(
        explain_pixel(&scene, &settings, 0, 6, SampleSelection::One(0)),
        Err(ExplainError::Outside { .. })
    ));
    assert!(matches!(
        explain_pixel(&scene, &settings, 0, 0, SampleSelection::One(4)),
        Err(ExplainError::NoSuchSample { sample: 4, spp: 4 })
    ));
    let outside = Crop {
        x0: 0,
        y0: 0,
        x1: 9,
        y1: 6,
    };
    let control = RenderControl {
        crop: Some(outside),
        ..RenderControl::default()
    };
    assert!(render_with(&scene, &settings, &|_, _| {}, control).is_err());
}

#[test]
fn a_sample_traced_alone_has_the_steps_it_has_among_all_the_pixels_samples() {
    for (name, scene, settings) in cases() {
        let all = explain_pixel(&scene, &settings, 12, 12, SampleSelection::All).unwrap();
        for (k, traced) in all.samples.iter().enumerate() {
            let alone = SampleSelection::One(k as u64);
            let one = explain_pixel(&scene, &settings, 12, 12, alone).unwrap();
            assert_eq!(
                one.samples,
                std::slice::from_ref(traced),
                "{name}: sample {k}"
            );
            assert!(
                matches!(traced.events.first(), Some(Event::Camera { .. }))
                    && matches!(traced.events.last(), Some(Event::SampleRadiance { .. })),
                "{name}: sample {k} starts at the camera and ends with its radiance"
            );
        }
    }
}
