//! The lighting stage (report sections 2.4 and 2.5, the course's Phong
//! model): at a hit, each given light sample's shadow verdict and its
//! diffuse and specular terms, the ambient term, and the point's total.
//!
//! The samples are Glint's own at that camera sample, on the grid pattern:
//! [`LIGHT_GRID`]² points on each area light, one at each point light. The
//! numbers are the integrator's, as it recorded them rendering the pixel
//! ([`glint_integrator::explain_pixel`]: its `LightSample` events), so there
//! is one code path; nothing here recomputes the shading.
//!
//! - A sample's `diffuse` is `kd·(n·l)` and its `specular` `ks·lobe`
//!   (`max(0, r·v)^s`, `r = 2(n·l)n − l`, or Blinn–Phong's `max(0, n·h)^s`),
//!   both 0 where `n·l ≤ 0`, for a light of color 1, whatever the verdict.
//! - Its `verdict` is `unlit` where no shadow ray is traced: the point is
//!   behind the light's emitting side, the light is below the geometric
//!   surface (`ng·l ≤ 0`), or the Phong term `diffuse + specular` is 0;
//!   else `blocked` (with the nearest `blocker` between the point and the
//!   sample) or `visible`.
//! - `total = ambient_term + Σ_lights color · (Σ of its visible samples'
//!   diffuse + specular) / (its sample count)`, the point's local radiance
//!   (before any mirror reflection; no environment light).

use super::answers::Answer;
use super::probe::{collect, Plan, Probe, LIGHT_GRID};
use super::survey::camera_ray;
use super::table::{Case, Check, Field, Kind, Layout, Value, RGB, XYZ};
use super::Context;
use crate::text::number;
use crate::GradeError;
use glam::Vec3;
use glint_explain::rules::SHADOW_EPSILON;
use glint_geometry::bvh::Bounds3;
use glint_geometry::{spawn_ray_to, Hit, Ray, RayTarget};
use glint_integrator::trace::{Event, Shadow, Skip};
use glint_integrator::{Scene, ShadingModel, SurfaceKind};
use glint_lighting::{Light, SpecularLobe};
use std::collections::BTreeMap;

/// How near (relative) a sample may come to a decision boundary: the light's
/// plane, the surface's horizon, `n·l = 0`, or an edge of a shadow (its
/// shadow ray moved by this much of its length must get the same verdict).
const MARGIN: f32 = 1e-4;

/// The samples each light of `scene` gives a case: [`LIGHT_GRID`]² for an
/// area light, 1 for a point light, none for a sphere light (physical
/// shading only).
pub fn sample_counts(scene: &Scene) -> Vec<usize> {
    let area = (LIGHT_GRID * LIGHT_GRID) as usize;
    scene
        .lights
        .iter()
        .map(|light| match light {
            Light::Point(_) => 1,
            Light::Area(_) => area,
            Light::Sphere(_) => 0,
        })
        .collect()
}

/// The prefix of sample `k`'s columns: `s00`, `s01`, … (more digits past 100).
fn sample_name(k: usize, total: usize) -> String {
    let digits = total.saturating_sub(1).to_string().len().max(2);
    format!("s{k:0digits$}")
}

fn suffixed(name: &str, suffixes: &[&str]) -> Vec<String> {
    suffixes.iter().map(|s| format!("{name}_{s}")).collect()
}

/// Inputs: the `object`, the `point`, the shading normal `n` (facing the
/// viewer), the geometric normal `ng` (on `n`'s side), the direction `v` to
/// the viewer, `kd` and `ks` after texturing, `shininess`, `lobe` (`phong`
/// or `blinn-phong`), the scene's `ambient`; each light `j`'s `lightJ_kind`
/// (`point` or `area`), color `lightJ_r/g/b` and emitting side
/// `lightJ_normal` (empty for a point light); each sample's light `sNN_light`
/// and position `sNN_x/y/z`. Expected: the `ambient_term`, each sample's
/// `sNN_verdict`, `sNN_blocker`, `sNN_diffuse`, `sNN_specular`, and the `total`.
pub fn layout(scene: &Scene) -> Layout {
    let counts = sample_counts(scene);
    let total: usize = counts.iter().sum();
    let mut inputs = vec!["object".to_owned()];
    for name in ["point", "n", "ng", "v"] {
        inputs.extend(suffixed(name, &XYZ));
    }
    inputs.extend(suffixed("kd", &RGB));
    inputs.extend(suffixed("ks", &RGB));
    inputs.extend(["shininess", "lobe"].map(String::from));
    inputs.extend(suffixed("ambient", &RGB));
    for j in 0..counts.len() {
        inputs.push(format!("light{j}_kind"));
        inputs.extend(suffixed(&format!("light{j}"), &RGB));
        inputs.extend(suffixed(&format!("light{j}_normal"), &XYZ));
    }
    let mut expected = vec![Field::rgb("ambient_term", Check::Vector)];
    for k in 0..total {
        let s = sample_name(k, total);
        inputs.push(format!("{s}_light"));
        inputs.extend(suffixed(&s, &XYZ));
        expected.extend([
            Field::scalar(&format!("{s}_verdict"), Kind::Text, Check::Exact),
            Field::scalar(&format!("{s}_blocker"), Kind::Int, Check::Exact),
            Field::rgb(&format!("{s}_diffuse"), Check::Vector),
            Field::rgb(&format!("{s}_specular"), Check::Vector),
        ]);
    }
    expected.push(Field::rgb("total", Check::Vector));
    Layout { inputs, expected }
}

/// `n` cases at shaded points (none under physical shading, whose lights
/// are not the course's): spread over the image, in shadow penumbrae, at
/// silhouettes, edges, corners and grazing angles, and behind a light's
/// plane (every sample unlit).
pub fn cases(cx: &Context, n: usize) -> Result<Vec<Case>, GradeError> {
    if cx.scene.shading != ShadingModel::Phong {
        return Ok(Vec::new());
    }
    let s = &cx.survey;
    let shaded = |p| s.info(p).shaded;
    let plans = vec![
        Plan::new("spread over shaded objects", 0.0, s.stratified(shaded)),
        Plan::new(
            "a shadow's penumbra",
            0.25,
            s.awkward(|p| p[0] % 3 == 0 && p[1] % 3 == 0 && shaded(p) && penumbra(cx.scene, p))
                .into_iter(),
        ),
        Plan::new(
            "a sphere's silhouette",
            0.1,
            s.awkward(|p| shaded(p) && s.on_silhouette(p)).into_iter(),
        ),
        Plan::new(
            "an edge or corner between objects",
            0.1,
            s.awkward(|p| shaded(p) && s.on_edge(p) && !s.on_silhouette(p))
                .into_iter(),
        ),
        Plan::new(
            "a grazing angle",
            0.1,
            s.awkward(|p| shaded(p) && s.grazing(p)).into_iter(),
        ),
        Plan::new(
            "behind a light's plane",
            0.05,
            s.awkward(|p| shaded(p) && behind_a_light(cx.scene, p))
                .into_iter(),
        ),
    ];
    collect(cx.scene, cx.settings, n, plans, |p| case(cx, p))
}

/// The closest hit seen through pixel `p`'s centre.
fn centre_hit(scene: &Scene, [x, y]: [u32; 2]) -> Option<Hit> {
    let ray = camera_ray(scene, x as f32 + 0.5, y as f32 + 0.5);
    scene.shapes.closest_hit(&ray, f32::INFINITY)
}

/// Whether the point pixel `p`'s centre sees has some, not all, of the
/// corners and centres of the area lights in view.
fn penumbra(scene: &Scene, p: [u32; 2]) -> bool {
    let Some(hit) = centre_hit(scene, p) else {
        return false;
    };
    let mut seen = [false, false];
    for light in &scene.lights {
        let Light::Area(area) = light else { continue };
        let surface = area.surface();
        let points = surface.corners().into_iter().chain([surface.center()]);
        for q in points.filter(|&q| area.illuminates(q, hit.point)) {
            let shadow = spawn_ray_to(&hit, &area.shadow_target(q));
            seen[usize::from(scene.shapes.any_hit(&shadow, 1.0))] = true;
        }
    }
    seen == [true, true]
}

/// Whether the point pixel `p`'s centre sees lies behind an area light's
/// emitting side.
fn behind_a_light(scene: &Scene, p: [u32; 2]) -> bool {
    let Some(hit) = centre_hit(scene, p) else {
        return false;
    };
    scene.lights.iter().any(|light| match light {
        Light::Area(area) => !area.illuminates(area.surface().center(), hit.point),
        _ => false,
    })
}

/// One light sample as the integrator recorded it.
#[derive(Clone, Copy, Debug)]
struct Sample {
    position: Vec3,
    l: Vec3,
    n_dot_l: f32,
    diffuse: Vec3,
    specular: Vec3,
    shadow: Shadow,
}

/// The camera ray's shading as the integrator recorded it.
#[derive(Clone, Debug)]
struct Shading {
    hit: Hit,
    kd: Vec3,
    ks: Vec3,
    n: Vec3,
    ng: Vec3,
    v: Vec3,
    ambient: Vec3,
    /// Per light: its samples and what it adds.
    lights: Vec<(usize, Vec<Sample>, Vec3)>,
}

/// The camera ray's local shading in a sample's events: up to its mirror
/// reflection or its radiance. `None` where the ray is not shaded (a miss, a
/// light, a pure mirror).
fn shading(events: &[Event]) -> Option<Shading> {
    let mut hit = None;
    let mut found: Option<Shading> = None;
    for event in events {
        match event {
            Event::Ray {
                depth: 0, hit: h, ..
            } => hit = h.as_deref().copied(),
            Event::Surface {
                kd, ks, n, ng, v, ..
            } => {
                found = Some(Shading {
                    hit: hit?,
                    kd: *kd,
                    ks: *ks,
                    n: *n,
                    ng: *ng,
                    v: *v,
                    ambient: Vec3::ZERO,
                    lights: Vec::new(),
                });
            }
            Event::Ambient { value } => found.as_mut()?.ambient = *value,
            Event::Light { light } => found
                .as_mut()?
                .lights
                .push((*light, Vec::new(), Vec3::ZERO)),
            Event::LightSample {
                position,
                l,
                n_dot_l,
                diffuse,
                specular,
                shadow,
                ..
            } => found.as_mut()?.lights.last_mut()?.1.push(Sample {
                position: *position,
                l: *l,
                n_dot_l: *n_dot_l,
                diffuse: *diffuse,
                specular: *specular,
                shadow: *shadow,
            }),
            Event::LightTotal { value, .. } => found.as_mut()?.lights.last_mut()?.2 = *value,
            Event::Mirror { .. } | Event::Radiance { .. } => break,
            _ => {}
        }
    }
    found
}

fn verdict(shadow: &Shadow) -> (&'static str, Value) {
    match shadow {
        Shadow::Unoccluded => ("visible", Value::Empty),
        Shadow::Blocked { object, .. } => ("blocked", Value::Int((*object).into())),
        Shadow::Skipped(_) | Shadow::MissedLight { .. } => ("unlit", Value::Empty),
    }
}

fn case(cx: &Context, p: &Probe) -> Option<Case> {
    let s = shading(&p.events)?;
    let SurfaceKind::Material(m) = cx.scene.surface_of(&s.hit) else {
        return None;
    };
    let counts = sample_counts(cx.scene);
    let as_laid_out = s.lights.len() == counts.len()
        && s.lights
            .iter()
            .zip(&counts)
            .enumerate()
            .all(|(j, ((light, samples, _), &c))| *light == j && samples.len() == c);
    if !as_laid_out || !steady(cx.scene, &s) {
        return None;
    }
    let mut case = Case::new(Some(p.from.clone()));
    case.int("object", s.hit.shape.into())
        .xyz("point", s.hit.point)
        .xyz("n", s.n)
        .xyz("ng", s.ng)
        .xyz("v", s.v)
        .rgb("kd", s.kd)
        .rgb("ks", s.ks)
        .float("shininess", m.shininess)
        .set("lobe", Value::Text(lobe_name(m.lobe).into()))
        .rgb("ambient", cx.scene.ambient)
        .rgb("ambient_term", s.ambient);
    let total: usize = counts.iter().sum();
    let mut k = 0;
    let mut radiance = s.ambient;
    for (j, (_, samples, value)) in s.lights.iter().enumerate() {
        light_inputs(&mut case, j, &cx.scene.lights[j]);
        for sample in samples {
            sample_cells(&mut case, &sample_name(k, total), j, sample);
            k += 1;
        }
        // What the integrator added for the light: its color times the
        // average of its samples.
        radiance += *value;
    }
    case.rgb("total", radiance);
    Some(case)
}

/// Sample `name`'s input (its light `j` and position) and expected cells.
fn sample_cells(case: &mut Case, name: &str, j: usize, sample: &Sample) {
    let (word, blocker) = verdict(&sample.shadow);
    case.int(&format!("{name}_light"), j as i64)
        .xyz(name, sample.position)
        .set(format!("{name}_verdict"), Value::Text(word.into()))
        .set(format!("{name}_blocker"), blocker)
        .rgb(&format!("{name}_diffuse"), sample.diffuse)
        .rgb(&format!("{name}_specular"), sample.specular);
}

fn lobe_name(lobe: SpecularLobe) -> &'static str {
    match lobe {
        SpecularLobe::Phong => "phong",
        SpecularLobe::BlinnPhong => "blinn-phong",
    }
}

/// Light `j`'s kind, color and emitting side.
fn light_inputs(case: &mut Case, j: usize, light: &Light) {
    let (kind, color, normal) = match light {
        Light::Point(p) => ("point", p.color, None),
        Light::Area(a) => ("area", a.color, Some(a.surface().normal())),
        Light::Sphere(s) => ("sphere", s.color, None),
    };
    let name = format!("light{j}");
    case.set(format!("{name}_kind"), Value::Text(kind.into()))
        .rgb(&name, color);
    if let Some(normal) = normal {
        case.xyz(&format!("{name}_normal"), normal);
    }
}

/// Whether every sample's verdict and terms are clear of the boundaries
/// where a correct program in other arithmetic could decide otherwise
/// ([`MARGIN`]).
fn steady(scene: &Scene, s: &Shading) -> bool {
    let size = scene_size(scene);
    s.lights.iter().all(|(j, samples, _)| {
        samples.iter().all(|sample| {
            sample_steady(scene, s, &scene.lights[*j], sample)
                && fixed_offsets_agree(scene, s, sample, size)
        })
    })
}

/// For a failing case's report: each light sample whose verdict the
/// student's `answered` row gives otherwise than Glint, with both blockers
/// named (`names`: the scene's object names), and the shadow ray Glint
/// traced.
pub fn verdict_steps(
    names: &[String],
    case: &Case,
    answered: &BTreeMap<String, Answer>,
) -> Vec<String> {
    let name = |object: f64| {
        let name = names.get(object as usize).map_or("?", String::as_str);
        format!("object {object} ({name})")
    };
    let verdict = |v: Option<&str>, blocker: Option<f64>| match (v, blocker) {
        (Some("blocked"), Some(b)) => format!("blocked by {}", name(b)),
        (Some(v), _) => v.to_owned(),
        (None, _) => "(none)".to_owned(),
    };
    let mut lines = Vec::new();
    let samples = case
        .values
        .keys()
        .filter_map(|k| k.strip_suffix("_verdict"))
        .map(str::to_owned)
        .collect::<Vec<_>>();
    for sample in samples {
        let column = |suffix: &str| format!("{sample}_{suffix}");
        let glints = match case.get(&column("verdict")) {
            Value::Text(v) => v.as_str(),
            _ => continue,
        };
        let yours = match answered.get(&column("verdict")) {
            Some(Answer::Text(v)) => Some(v.as_str()),
            _ => None,
        };
        if yours == Some(glints) {
            continue;
        }
        let your_blocker = match answered.get(&column("blocker")) {
            Some(Answer::Number(b)) => Some(*b),
            _ => None,
        };
        let point = |prefix: &str| {
            let at = |c: &str| {
                case.get(&format!("{prefix}_{c}"))
                    .number()
                    .unwrap_or(f64::NAN)
            };
            format!(
                "({}, {}, {})",
                number(at("x")),
                number(at("y")),
                number(at("z"))
            )
        };
        lines.push(format!(
            "{sample}: Glint's {}, yours {}; the shadow ray from the point {} to the sample {}, offsets as scene-format.md step 9 says",
            verdict(Some(glints), case.get(&column("blocker")).number()),
            verdict(yours, your_blocker),
            point("point"),
            point(&sample),
        ));
    }
    lines
}

/// The scene's size for its shadow-ray offsets: the longest side of the
/// box around its finite shapes (1 if it has none).
pub fn scene_size(scene: &Scene) -> f32 {
    let bounds = scene
        .shapes
        .shapes()
        .iter()
        .filter_map(|shape| shape.bounds())
        .fold(Bounds3::EMPTY, Bounds3::union);
    let side = (bounds.max - bounds.min).max_element();
    if side.is_finite() && side > 0.0 {
        side
    } else {
        1.0
    }
}

/// Whether a shadow ray with a fixed offset gets the sample's verdict at
/// both ends of the offsets the docs allow ([`SHADOW_EPSILON`] of the
/// scene's `size`), following `docs/scene-format.md`'s rule literally:
/// start at `o = x + ε·ng` (`ng` on the light's side), aim at the sample
/// `p` from `o`, and count a blocker at `0 < t < |p − o| − ε`.
fn fixed_offsets_agree(scene: &Scene, s: &Shading, sample: &Sample, size: f32) -> bool {
    let blocked = match sample.shadow {
        Shadow::Blocked { .. } => true,
        Shadow::Unoccluded => false,
        _ => return true,
    };
    SHADOW_EPSILON.iter().all(|&fraction| {
        let epsilon = fraction as f32 * size;
        fixed_offset_blocked(scene, s.hit.point, s.ng, sample.position, epsilon) == blocked
    })
}

/// The docs' fixed-offset shadow ray from `x` (geometric normal `ng`) to
/// `p`: whether anything lies on it.
pub fn fixed_offset_blocked(scene: &Scene, x: Vec3, ng: Vec3, p: Vec3, epsilon: f32) -> bool {
    let side = if ng.dot(p - x) >= 0.0 { ng } else { -ng };
    let origin = x + epsilon * side;
    let towards = p - origin;
    let length = towards.length();
    if length <= epsilon {
        return false;
    }
    scene
        .shapes
        .any_hit(&Ray::new(origin, towards), 1.0 - epsilon / length)
}

fn sample_steady(scene: &Scene, s: &Shading, light: &Light, sample: &Sample) -> bool {
    let towards = sample.position - s.hit.point;
    let distance = towards.length();
    let clear = |x: f32| x.abs() >= MARGIN;
    let in_front = match light {
        Light::Area(a) => clear(a.surface().normal().dot(towards) / distance),
        _ => true,
    };
    if !(in_front && clear(s.ng.dot(sample.l)) && clear(sample.n_dot_l)) {
        return false;
    }
    let target = |point: Vec3| match light {
        Light::Area(a) => a.shadow_target(point),
        _ => RayTarget::exact(point),
    };
    match sample.shadow {
        Shadow::Blocked {
            object: u32::MAX, ..
        } => false,
        // A zero Phong term where n·l > 0: only a specular lobe rounded to
        // nothing, which other arithmetic may not round away.
        Shadow::Skipped(Skip::ZeroBrdf) => s.ks == Vec3::ZERO,
        Shadow::Skipped(_) | Shadow::MissedLight { .. } => true,
        Shadow::Unoccluded | Shadow::Blocked { .. } => {
            let blocked = matches!(sample.shadow, Shadow::Blocked { .. });
            // Moved within an area light's plane (off it, the ray would meet
            // the light's own surface), else across the direction to it.
            let (a, b) = match light {
                Light::Area(area) => {
                    let (e1, e2) = area.surface().edges();
                    (e1.normalize(), e2.normalize())
                }
                _ => {
                    let a = sample.l.any_orthonormal_vector();
                    (a, sample.l.cross(a))
                }
            };
            [a, -a, b, -b].iter().all(|&side| {
                let moved = target(sample.position + MARGIN * distance * side);
                let ray: Ray = spawn_ray_to(&s.hit, &moved);
                scene.shapes.any_hit(&ray, 1.0) == blocked
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_columns_sort_in_sample_order() {
        assert_eq!(sample_name(3, 16), "s03");
        assert_eq!(sample_name(15, 16), "s15");
        assert_eq!(sample_name(7, 120), "s007");
    }
}
