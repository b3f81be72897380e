//! `glint explain`: every stage's numbers for one pixel of a render, so that
//! a student can find the first stage where their ray tracer parts from
//! Glint, and a grader can check one stage of a submission.
//!
//! [`explain`] renders the pixel through the integrator's own code with a
//! tracer ([`glint_integrator::explain_pixel`]: the radiance is the render's,
//! bit for bit) and adds what the trace does not carry: each object's test
//! against each ray, the query's path through the BVH and its work
//! ([`glint_geometry::ShapeList::explain_closest`]), and what each texture
//! lookup read, every texel of an EWA ellipse included
//! ([`glint_texture::Texture::explain`]). The result is a JSON
//! document (schema `glint-explain/1`, documented in
//! `docs/checking-your-ray-tracer.md`) and its text form. [`against`]
//! compares a student's document with it, stage by stage in pipeline order
//! (`glint explain --against`).
//!
//! # Conventions
//! - World space, right-handed, y up; angles in radians; radiance linear RGB.
//! - Every number is rounded to 5 significant digits, as the snapshot tests
//!   round them; non-finite numbers are `null` in JSON.
//! - Raster positions are in pixels from the image's top left corner; normalised
//!   device coordinates run from −1 to 1 with y up.

pub mod against;
mod json;
pub mod rules;
mod text;

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

use glam::Vec3;
use glint_integrator::trace::{Event, SampleSelection, Shadow, Skip, Technique};
use glint_integrator::{
    explain_pixel, report_level, ExplainError, RenderSettings, Scene, SurfaceKind,
};
use glint_lighting::Light;
use glint_texture::Texture;
use json::{num, v2, v3};
use serde_json::{json, Map, Value};

/// A stage of the pipeline, to limit the output to; in pipeline order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Stage {
    Camera,
    Intersect,
    Texture,
    Light,
    Film,
}

impl Stage {
    /// The stages in pipeline order.
    pub const ALL: [Stage; 5] = [
        Stage::Camera,
        Stage::Intersect,
        Stage::Texture,
        Stage::Light,
        Stage::Film,
    ];

    /// The names `--stage` takes, in pipeline order.
    pub const NAMES: [&'static str; 5] = ["camera", "intersect", "texture", "light", "film"];

    /// The stage named `name`: one of [`Self::NAMES`], or the heading the text
    /// output prints for it ([`Self::heading`]: `intersection`, `lighting`).
    pub fn from_name(name: &str) -> Option<Stage> {
        Some(match name {
            "camera" => Stage::Camera,
            "intersect" | "intersection" => Stage::Intersect,
            "texture" => Stage::Texture,
            "light" | "lighting" => Stage::Light,
            "film" => Stage::Film,
            _ => return None,
        })
    }

    /// The name `--stage` takes for this stage.
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// The heading the text output prints for this stage.
    pub fn heading(self) -> &'static str {
        match self {
            Stage::Intersect => "intersection",
            Stage::Light => "lighting",
            other => other.name(),
        }
    }
}

/// A pixel explained: the JSON document, from which the text is printed.
#[derive(Clone, Debug, PartialEq)]
pub struct Explanation {
    pub document: Value,
    /// The pixel's radiance as the render writes it (unrounded).
    pub radiance: Vec3,
}

impl Explanation {
    /// The document, limited to `stage` if given.
    pub fn json(&self, stage: Option<Stage>) -> Value {
        match stage {
            None => self.document.clone(),
            Some(stage) => json::only_stage(&self.document, stage),
        }
    }

    /// The text form, limited to `stage` if given.
    pub fn text(&self, stage: Option<Stage>) -> String {
        text::render(&self.json(stage))
    }

    /// The document with the pixel as a tracer with a mistake in one stage
    /// renders it (`radiance`, by the one-ray integrator with the stage
    /// swapped): under `mistake`, beside the right stages' numbers, which
    /// it does not trace.
    pub fn with_mistake(&mut self, mistake: &MistakenPixel, radiance: Vec3) {
        let srgb: Vec<u8> = (radiance.to_array().iter())
            .map(|&c| glint_camera::linear_to_srgb8(c))
            .collect();
        self.document["mistake"] = json!({
            "id": mistake.id,
            "stage": mistake.stage,
            "description": mistake.description,
            "radiance": v3(radiance),
            "srgb8": srgb,
        });
    }
}

/// A classic mistake in one stage, as [`Explanation::with_mistake`] shows it.
pub struct MistakenPixel<'a> {
    pub id: &'a str,
    pub stage: &'a str,
    pub description: &'a str,
}

/// Pixel `(x, y)` of `scene` under `settings`, the samples `selection` names.
pub fn explain(
    scene: &Scene,
    settings: &RenderSettings,
    x: u32,
    y: u32,
    selection: SampleSelection,
) -> Result<Explanation, ExplainError> {
    let explained = explain_pixel(scene, settings, x, y, selection)?;
    let samples: Vec<Value> = explained
        .samples
        .iter()
        .map(|s| sample_document(scene, s.sample, &s.events))
        .collect();
    let r = explained.radiance;
    let srgb: Vec<u8> = r
        .to_array()
        .iter()
        .map(|&c| glint_camera::linear_to_srgb8(c))
        .collect();
    let document = json!({
        "schema": "glint-explain/1",
        "pixel": [x, y],
        "resolution": [scene.camera.resolution().x, scene.camera.resolution().y],
        "spp": explained.spp,
        "sampler": settings.pixel_pattern.name(),
        "light_samples": settings.light_samples,
        "light_sampler": settings.light_pattern.name(),
        "environment_samples": settings.environment_samples,
        "texture_level": scene.texture_level.name(),
        "seed": settings.seed,
        "samples": samples,
        "film": {
            "radiance": v3(r),
            "samples_averaged": explained.spp,
            "srgb8": srgb,
        },
    });
    Ok(Explanation {
        document,
        radiance: r,
    })
}

/// One camera sample's document: its camera stage, its ray (each mirror
/// reflection nested in the ray it leaves from, as `reflection`) and its
/// radiance.
fn sample_document(scene: &Scene, sample: u64, events: &[Event]) -> Value {
    let mut camera = Value::Null;
    // The rays being followed, one per depth; a finished ray is moved into
    // its parent.
    let mut stack: Vec<Map<String, Value>> = Vec::new();
    let mut root = Value::Null;
    let mut radiance = Value::Null;
    let mut running = Running::default();
    // The camera ray and its hit, while the event being read belongs to it:
    // the report's MIP level is defined for camera rays only.
    let mut camera_hit: Option<(glint_geometry::Ray, glint_geometry::Hit)> = None;
    let close_to = |stack: &mut Vec<Map<String, Value>>, root: &mut Value, depth: usize| {
        while stack.len() > depth {
            let ray = Value::Object(stack.pop().expect("non-empty"));
            match stack.last_mut() {
                Some(parent) => {
                    parent.insert("reflection".into(), ray);
                }
                None => *root = ray,
            }
        }
    };
    for event in events {
        match event {
            Event::Camera {
                raster,
                ndc,
                film_point,
                ray,
                differential,
            } => {
                camera = json!({
                    "raster": v2(*raster),
                    "ndc": v2(*ndc),
                    "film_point": v3(*film_point),
                    "origin": v3(ray.origin),
                    "direction": v3(ray.direction),
                    "differentials": differential.map(|d| json!({
                        "rx_origin": v3(d.rx_origin),
                        "rx_direction": v3(d.rx_direction),
                        "ry_origin": v3(d.ry_origin),
                        "ry_direction": v3(d.ry_direction),
                    })),
                });
            }
            Event::Ray { depth, ray, hit } => {
                close_to(&mut stack, &mut root, *depth as usize);
                stack.push(ray_record(scene, *depth, ray, hit.as_deref()));
                camera_hit = hit.as_deref().filter(|_| *depth == 0).map(|h| (*ray, *h));
            }
            Event::SampleRadiance { value } => radiance = v3(*value),
            other => {
                if let Event::Radiance { depth, .. } = other {
                    close_to(&mut stack, &mut root, *depth as usize + 1);
                }
                if let Some(ray) = stack.last_mut() {
                    ray_event(scene, ray, other, &mut running, camera_hit.as_ref());
                }
            }
        }
    }
    close_to(&mut stack, &mut root, 0);
    json!({
        "sample": sample,
        "camera": camera,
        "ray": root,
        "radiance": radiance,
    })
}

/// A ray's record: its intersection stage.
fn ray_record(
    scene: &Scene,
    depth: u32,
    ray: &glint_geometry::Ray,
    hit: Option<&glint_geometry::Hit>,
) -> Map<String, Value> {
    let explained = scene.shapes.explain_closest(ray, f32::INFINITY);
    let tests: Vec<Value> = explained
        .tests
        .iter()
        .map(|t| {
            let mut test = json!({
                "object": t.object,
                "kind": t.kind,
                "t": t.t.map_or(Value::Null, num),
            });
            if let Some(triangle) = t.triangle {
                test["triangle"] = json!(triangle);
            }
            test
        })
        .collect();
    let w = explained.work;
    let mut record = Map::new();
    record.insert("depth".into(), json!(depth));
    record.insert(
        "intersect".into(),
        json!({
            "origin": v3(ray.origin),
            "direction": v3(ray.direction),
            "tests": tests,
            "work": {
                "bvh_nodes": w.bvh_nodes,
                "bvh_leaves": w.bvh_leaves,
                "shape_tests": w.shape_tests() - w.triangle_tests,
                "triangle_tests": w.triangle_tests,
            },
            "bvh": json::bvh_path(&explained.bvh),
            "hit": hit.map(|h| json!({
                "object": h.shape,
                "kind": scene.shapes.object(h.shape).kind(),
                "triangle": h.primitive,
                "t": num(h.t),
                "point": v3(h.point),
                "geometric_normal": v3(h.geometric_normal),
                "shading_normal": v3(h.shading_normal),
                "uv": v2(h.uv),
                "dpdu": v3(h.dpdu),
                "dpdv": v3(h.dpdv),
                "front_face": h.front_face,
            })),
        }),
    );
    // The texture stage needs the material: looked up when the surface event comes.
    if let Some(h) = hit {
        record.insert("object".into(), json!(h.shape));
        record.insert("triangle".into(), json!(h.primitive));
    }
    record
}

fn light_kind(light: &Light) -> &'static str {
    match light {
        Light::Point(_) => "point",
        Light::Area(_) => "area",
        Light::Sphere(_) => "sphere",
    }
}

fn shadow(s: &Shadow) -> Value {
    match s {
        Shadow::Unoccluded => json!("unoccluded"),
        Shadow::Blocked { object, t } => json!({
            "blocked_by": if *object == u32::MAX { Value::Null } else { json!(object) },
            "t": num(*t),
        }),
        Shadow::MissedLight { object, t } => json!({
            "missed_light": {"hit": object, "t": num(*t)},
        }),
        Shadow::Skipped(skip) => json!({
            "not_traced": match skip {
                Skip::BehindSurface => "below the surface",
                Skip::BehindLight => "behind the light",
                Skip::ZeroBrdf => "zero BRDF",
                Skip::ZeroPdf => "zero density",
            }
        }),
    }
}

/// Attaches one event to the ray it belongs to; `camera_hit` is the camera
/// ray and its hit when the event is that ray's.
fn ray_event(
    scene: &Scene,
    ray: &mut Map<String, Value>,
    event: &Event,
    running: &mut Running,
    camera_hit: Option<&(glint_geometry::Ray, glint_geometry::Hit)>,
) {
    match event {
        Event::Environment {
            direction,
            width,
            radiance,
        } => {
            ray.insert(
                "environment".into(),
                json!({"direction": v3(*direction), "filter_width": num(*width), "radiance": v3(*radiance)}),
            );
        }
        Event::Emitter { radiance } => {
            ray.insert("emitter".into(), json!({ "radiance": v3(*radiance) }));
        }
        Event::Surface {
            tc,
            kd,
            ks,
            n,
            ng,
            v,
        } => {
            let object = ray.get("object").and_then(Value::as_u64).unwrap_or(0) as u32;
            let triangle = ray.get("triangle").and_then(Value::as_u64).unwrap_or(0) as u32;
            let mut texture = json!({
                "footprint": {"uv": v2(tc.uv), "duvdx": v2(tc.duvdx), "duvdy": v2(tc.duvdy)},
                "kd": v3(*kd),
                "ks": v3(*ks),
            });
            if let SurfaceKind::Material(m) = scene.surface_of_primitive(object, triangle) {
                let report = |t: &Texture| {
                    camera_hit.and_then(|(r, h)| report_level(&scene.camera, r, h, m, t))
                };
                let tc = m.uv_transform.apply(tc);
                texture["uv_scale"] = json!(v2(m.uv_transform.scale));
                texture["material_uv"] = json!(v2(tc.uv));
                texture["diffuse"] = json::lookup(&m.diffuse.explain(&tc), report(&m.diffuse));
                texture["specular"] = match &m.specular {
                    Some(t) => json::lookup(&t.explain(&tc), report(t)),
                    None => json!("the diffuse texture's (ks = kd)"),
                };
            }
            ray.insert("texture".into(), texture);
            ray.insert(
                "shading".into(),
                json!({"n": v3(*n), "ng": v3(*ng), "v": v3(*v)}),
            );
            ray.insert(
                "light".into(),
                json!({"ambient": Value::Null, "lights": [], "environment": Value::Null}),
            );
        }
        Event::Ambient { value } => {
            ray["light"]["ambient"] = v3(*value);
        }
        Event::Light { light } => {
            *running = Running::default();
            let kind = scene.lights.get(*light).map_or("?", light_kind);
            lights(ray)
                .push(json!({"light": light, "kind": kind, "samples": [], "total": Value::Null}));
        }
        Event::LightSample {
            position,
            l,
            n_dot_l,
            reflection,
            diffuse,
            specular,
            shadow: s,
            value,
        } => {
            let sample = json!({
                "position": v3(*position),
                "l": v3(*l),
                "n_dot_l": num(*n_dot_l),
                "reflection": v3(*reflection),
                "diffuse": v3(*diffuse),
                "specular": v3(*specular),
                "shadow": shadow(s),
                "value": v3(*value),
            });
            push_light_sample(ray, sample, *value, running, false);
        }
        Event::PhysicalSample {
            technique,
            l,
            f_cos,
            light_pdf,
            lobe_pdf,
            weight,
            shadow: s,
            value,
        } => {
            let sample = json!({
                "technique": match technique {
                    Technique::PointLight => "point light",
                    Technique::Light => "light",
                    Technique::Lobe => "specular lobe",
                },
                "l": v3(*l),
                "f_cos": v3(*f_cos),
                "light_pdf": num(*light_pdf),
                "lobe_pdf": num(*lobe_pdf),
                "mis_weight": num(*weight),
                "shadow": shadow(s),
                "value": v3(*value),
            });
            push_light_sample(ray, sample, *value, running, true);
        }
        Event::LightTotal { value, .. } => {
            if let Some(last) = lights(ray).last_mut() {
                last["total"] = v3(*value);
            }
            *running = Running::default();
        }
        Event::EnvironmentSample {
            direction,
            pdf,
            radiance,
            f_cos,
            shadow: s,
            value,
        } => {
            let light = &mut ray["light"];
            if light["environment"].is_null() {
                light["environment"] = json!({"samples": [], "total": Value::Null});
            }
            if let Some(samples) = light["environment"]["samples"].as_array_mut() {
                samples.push(json!({
                    "direction": v3(*direction),
                    "pdf": num(*pdf),
                    "radiance": v3(*radiance),
                    "f_cos": v3(*f_cos),
                    "shadow": shadow(s),
                    "value": v3(*value),
                }));
            }
        }
        Event::EnvironmentTotal { value } => {
            let light = &mut ray["light"];
            if light["environment"].is_null() {
                light["environment"] = json!({"samples": [], "total": Value::Null});
            }
            light["environment"]["total"] = v3(*value);
        }
        Event::Mirror {
            reflectivity,
            tint,
            direction,
        } => {
            ray.insert(
                "mirror".into(),
                json!({"reflectivity": num(*reflectivity), "tint": v3(*tint), "direction": v3(*direction)}),
            );
        }
        Event::Radiance {
            local,
            mirror,
            value,
            ..
        } => {
            ray.insert(
                "radiance".into(),
                json!({"local": v3(*local), "mirror": v3(*mirror), "value": v3(*value)}),
            );
        }
        Event::Camera { .. } | Event::Ray { .. } | Event::SampleRadiance { .. } => {}
    }
}

fn lights(ray: &mut Map<String, Value>) -> &mut Vec<Value> {
    ray.entry("light").or_insert_with(
        || json!({"ambient": Value::Null, "lights": [], "environment": Value::Null}),
    );
    ray["light"]["lights"]
        .as_array_mut()
        .expect("lights is an array")
}

/// The sum and count of a light's sample values so far (unrounded).
#[derive(Clone, Copy, Debug, Default)]
struct Running {
    sum: Vec3,
    count: u32,
}

/// Adds a sample to the light being shaded, with its running figure: in the
/// course's model the average of the light's sample values so far; in
/// physical shading (`physical`) their sum, as light and lobe samples add
/// into one sum, which the light's radiance times, over the light sample
/// count, is its total.
fn push_light_sample(
    ray: &mut Map<String, Value>,
    mut sample: Value,
    value: Vec3,
    running: &mut Running,
    physical: bool,
) {
    running.sum += value;
    running.count += 1;
    if physical {
        sample["running_sum"] = v3(running.sum);
    } else {
        sample["running_average"] = v3(running.sum / running.count as f32);
    }
    if let Some(last) = lights(ray).last_mut() {
        if let Some(samples) = last["samples"].as_array_mut() {
            samples.push(sample);
        }
    }
}
