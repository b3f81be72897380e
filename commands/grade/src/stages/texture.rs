//! The texture stage (report sections 2.6 and 2.8): at a hit on a textured
//! object, the MIP level the report chooses, `log2(L/W)` with its `L` and
//! `W` ([`glint_integrator::report_level`]), and the filtered value.
//!
//! "The filtered value" is the report's: for an image, trilinear at the
//! report's level (bilinear lookups in the two levels around it, blended by
//! its fraction; the level clamped to the pyramid, so a level below 0 reads
//! the image bilinearly) through the texture's wrap mode
//! ([`glint_texture::MipMap::trilinear_at_level`]), whatever filter the
//! scene sets for Glint's render; for the course's procedural checkerboard,
//! which has no texels and so no level, the check's color at the point (the
//! course's point sampling), even where the scene box-filters it.

use super::probe::{collect, Plan, Probe};
use super::table::{Case, Check, Field, Kind, Layout, Value};
use super::Context;
use crate::GradeError;
use glam::Vec2;
use glint_integrator::{pixel_height_on_surface, report_level, uv_unit_length, Scene, SurfaceKind};
use glint_lighting::PhongMaterial;
use glint_texture::{Checkerboard, ImageTexture, TexCoord, Texture};

/// How near (in checks, relative to the coordinate's size) a uv may come to
/// a check's edge: nearer, a correct program in other arithmetic may read the
/// other check.
const CHECK_EDGE: f32 = 1e-4;

/// The input columns: see `docs/grading-stages.md`.
pub const INPUTS: [&str; 14] = [
    "object", "texture", "kind", "u", "v", "scale_u", "scale_v", "offset_u", "offset_v", "t",
    "n_dot_d", "r", "fov", "m",
];

/// Inputs: the `object`, which of its material's textures (`texture`:
/// `diffuse`, or `specular` where only that one varies) and its `kind`
/// (`checkerboard` or `image`), the hit's `u`, `v`, the material's uv
/// transform (`uv' = uv · scale + offset`), the hit's distance `t` along the
/// unit camera ray, `n_dot_d` (`N·D`, geometric normal and ray direction),
/// the image's rows `r`, the vertical field of view `fov` in degrees, and
/// the texture's resolution `m` (its larger side in texels; empty for a
/// checkerboard). Expected: `l`, `jacobian` (`|J_T|`), `w` and `level`
/// (empty for a checkerboard), and the filtered `value`.
pub fn layout() -> Layout {
    Layout {
        inputs: INPUTS.map(String::from).to_vec(),
        expected: vec![
            Field::scalar("l", Kind::Float, Check::Relative),
            Field::scalar("jacobian", Kind::Float, Check::Relative),
            Field::scalar("w", Kind::Float, Check::Relative),
            Field::scalar("level", Kind::Float, Check::Level),
            Field::rgb("value", Check::Vector),
        ],
    }
}

/// `n` cases at hits on textured objects: spread over them, and at their
/// silhouettes (high levels), grazing angles and the sphere's u seam.
pub fn cases(cx: &Context, n: usize) -> Result<Vec<Case>, GradeError> {
    let s = &cx.survey;
    let textured = |p| s.info(p).textured;
    let plans = vec![
        Plan::new("spread over textured objects", 0.0, s.stratified(textured)),
        Plan::new(
            "a sphere's silhouette",
            0.2,
            s.awkward(|p| textured(p) && s.on_silhouette(p)).into_iter(),
        ),
        Plan::new(
            "a grazing angle",
            0.15,
            s.awkward(|p| textured(p) && s.grazing(p)).into_iter(),
        ),
        Plan::new(
            "near the sphere's u seam",
            0.15,
            s.awkward(|p| textured(p) && s.near_seam(p)).into_iter(),
        ),
        Plan::new(
            "a pyramid level halved from an odd size",
            0.1,
            s.awkward(|p| textured(p) && reads_an_odd_halving(cx.scene, p))
                .into_iter(),
        ),
    ];
    collect(cx.scene, cx.settings, n, plans, |p| case(cx, p))
}

/// Whether pixel `p`'s centre reads, at the report's level, a pyramid level
/// made from a level of odd width or height (37 × 25 from 75 × 50): where
/// a pyramid built with the sizes rounded the other way parts from Glint's.
fn reads_an_odd_halving(scene: &Scene, [x, y]: [u32; 2]) -> bool {
    let ray = super::survey::camera_ray(scene, x as f32 + 0.5, y as f32 + 0.5);
    let Some(hit) = scene.shapes.closest_hit(&ray, f32::INFINITY) else {
        return false;
    };
    let SurfaceKind::Material(m) = scene.surface_of(&hit) else {
        return false;
    };
    let Some((_, texture @ Texture::Image(image))) = varying(m) else {
        return false;
    };
    let Some(report) = report_level(&scene.camera, &ray, &hit, m, texture) else {
        return false;
    };
    let levels = image.image.pyramid().levels();
    let odd = |k: usize| {
        k >= 1
            && k < levels.len()
            && (levels[k - 1].width() % 2 == 1 || levels[k - 1].height() % 2 == 1)
    };
    let level = image.image.pyramid().clamp_level(report.level);
    let lower = level as usize;
    odd(lower) || (level > lower as f32 && odd(lower + 1))
}

/// The texture a case reads: the diffuse one if it varies, else the specular.
fn varying(m: &PhongMaterial) -> Option<(&'static str, &Texture)> {
    let varies = |t: &&Texture| !matches!(t, Texture::Constant(_));
    match (
        Some(&m.diffuse).filter(varies),
        m.specular.as_ref().filter(varies),
    ) {
        (Some(t), _) => Some(("diffuse", t)),
        (None, Some(t)) => Some(("specular", t)),
        (None, None) => None,
    }
}

fn case(cx: &Context, p: &Probe) -> Option<Case> {
    let hit = p.hit?;
    let SurfaceKind::Material(m) = cx.scene.surface_of(&hit) else {
        return None;
    };
    let (which, texture) = varying(m)?;
    let camera = &cx.scene.camera;
    let uv = m.uv_transform.apply(&TexCoord::point(hit.uv)).uv;
    let l = pixel_height_on_surface(camera, &p.ray, &hit);
    let jacobian = uv_unit_length(&hit, m);
    let mut case = Case::new(Some(p.from.clone()));
    match texture {
        Texture::Checkerboard(c) => {
            if near_check_edge(c, uv) {
                return None;
            }
            case.set("kind", Value::Text("checkerboard".into()))
                .rgb("value", c.evaluate(uv));
        }
        Texture::Image(image) => {
            let report = report_level(camera, &p.ray, &hit, m, texture)?;
            // Image coordinates st = (u', 1 − v'), t down the image
            // (glint-texture's convention).
            let st = Vec2::new(uv.x, 1.0 - uv.y);
            let pyramid = image.image.pyramid();
            case.set("kind", Value::Text("image".into()))
                .int("m", report.m.into())
                .float("w", report.w)
                .float("level", report.level)
                .rgb(
                    "value",
                    pyramid.trilinear_at_level(st, report.level, image.wrap),
                );
        }
        Texture::Constant(_) => return None,
    }
    let d = p.ray.direction;
    let fov = f64::from(camera.fov_y()).to_degrees() as f32;
    case.int("object", hit.shape.into())
        .set("texture", Value::Text(which.into()))
        .uv(hit.uv)
        .float("scale_u", m.uv_transform.scale.x)
        .float("scale_v", m.uv_transform.scale.y)
        .float("offset_u", m.uv_transform.offset.x)
        .float("offset_v", m.uv_transform.offset.y)
        .float("t", hit.t * d.length())
        .float("n_dot_d", hit.geometric_normal.dot(d) / d.length())
        .int("r", camera.resolution().y.into())
        .float("fov", fov)
        .float("l", l)
        .float("jacobian", jacobian);
    let finite = case.values.values().all(|v| match v {
        Value::Float(x) => x.is_finite(),
        _ => true,
    });
    finite.then_some(case)
}

/// The steps that decided `case`'s expected value, for a failing case's
/// report: the lookup the report asks for at the report's level, not the
/// render's (whose level `glint explain` prints). For an image: uv through
/// the material's transform, the level `log2(L/W)` and its parts, the two
/// pyramid levels read with their sizes and weights, each texel with its
/// weight, and their sum; for a checkerboard, the check.
pub fn expected_steps(scene: &Scene, case: &Case) -> Vec<String> {
    let number = |column: &str| case.get(column).number();
    let (Some(object), Some(u), Some(v)) = (number("object"), number("u"), number("v")) else {
        return Vec::new();
    };
    let SurfaceKind::Material(m) = scene.surface_of_primitive(object as u32, 0) else {
        return Vec::new();
    };
    let texture = match case.get("texture") {
        Value::Text(t) if t == "specular" => m.specular.as_ref(),
        _ => Some(&m.diffuse),
    };
    let uv = m
        .uv_transform
        .apply(&TexCoord::point(Vec2::new(u as f32, v as f32)))
        .uv;
    let mut lines = vec![format!(
        "uv' = uv·scale + offset = ({}, {})",
        show(uv.x),
        show(uv.y)
    )];
    match texture {
        Some(Texture::Image(image)) => {
            let Some(level) = number("level") else {
                return Vec::new();
            };
            lines.extend(image_steps(image, uv, level as f32, case));
        }
        Some(Texture::Checkerboard(c)) => {
            let q = (uv * c.checks as f32).floor();
            let which = (q.x as i64 + q.y as i64).rem_euclid(2) as usize;
            lines.push(format!(
                "check (⌊u'·{n}⌋ + ⌊v'·{n}⌋) mod 2 = ({} + {}) mod 2 = {which}: color {}",
                q.x,
                q.y,
                show3(c.colors[which]),
                n = c.checks
            ));
        }
        _ => return Vec::new(),
    }
    lines
}

/// An image lookup's steps at the report's `level`.
fn image_steps(image: &ImageTexture, uv: Vec2, level: f32, case: &Case) -> Vec<String> {
    let st = Vec2::new(uv.x, 1.0 - uv.y);
    let levels = image.image.pyramid().levels();
    let size = |i: usize| format!("{} × {}", levels[i].width(), levels[i].height());
    let texels = image.texels_at_level(st, level);
    let cell = |c: &str| case.get(c).number().map_or("?".into(), |x| show(x as f32));
    let mut lines = vec![
        format!("st = (u', 1 − v') = ({}, {})", show(st.x), show(st.y)),
        format!(
            "level = log2(L/W) = log2({} / {}) = {} (L = 2·t·tan(fov/2)/(r·|N·D|), W = jacobian/m, m = {}); the report's level, not the render's below",
            cell("l"),
            cell("w"),
            show(level),
            cell("m"),
        ),
    ];
    let mut read: Vec<(usize, f32)> = Vec::new();
    for t in &texels {
        match read.iter_mut().find(|(l, _)| *l == t.level) {
            Some((_, w)) => *w += t.weight,
            None => read.push((t.level, t.weight)),
        }
    }
    let parts: Vec<String> = read
        .iter()
        .map(|(l, w)| format!("level {l} ({}) weight {}", size(*l), show(*w)))
        .collect();
    let clamped = match level {
        l if l < 0.0 || l.is_nan() => " (clamped to level 0)",
        l if l > (levels.len() - 1) as f32 => " (clamped to the last level)",
        _ => "",
    };
    lines.push(format!(
        "reads {} of the {}-level pyramid from {}{clamped}",
        parts.join(" and "),
        levels.len(),
        size(0)
    ));
    for t in &texels {
        lines.push(format!(
            "  level {} texel ({}, {}) {} × weight {}",
            t.level,
            t.x,
            t.y,
            show3(t.value),
            show(t.weight)
        ));
    }
    let value = texels
        .iter()
        .fold(glam::Vec3::ZERO, |acc, t| acc + t.weight * t.value);
    lines.push(format!("value = Σ weight × texel = {}", show3(value)));
    lines
}

fn show(x: f32) -> String {
    crate::text::number(f64::from(x))
}

fn show3(v: glam::Vec3) -> String {
    format!("({}, {}, {})", show(v.x), show(v.y), show(v.z))
}

/// Whether `uv` lies within [`CHECK_EDGE`] of a check's edge.
fn near_check_edge(c: &Checkerboard, uv: Vec2) -> bool {
    let q = uv * c.checks as f32;
    [q.x, q.y]
        .iter()
        .any(|&x| (x - x.round()).abs() < CHECK_EDGE * x.abs().max(1.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn uvs_on_a_checks_edge_are_not_used() {
        let c = Checkerboard::new(Vec3::ZERO, Vec3::ONE, 4);
        assert!(near_check_edge(&c, Vec2::new(0.25, 0.6)));
        assert!(near_check_edge(&c, Vec2::new(0.6, 0.50001)));
        assert!(!near_check_edge(&c, Vec2::new(0.3, 0.6)));
    }
}
