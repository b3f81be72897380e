//! The intersection stage (report section 2.3): a ray to its closest hit,
//! [`glint_geometry::ShapeList::closest_hit`] over the scene's objects.

use super::probe::{collect, Plan, Probe};
use super::survey::BACKGROUND;
use super::table::{Case, Check, Field, Kind, Layout, Value};
use super::Context;
use crate::GradeError;
use glint_geometry::{Hit, Ray};
use glint_integrator::Scene;

/// How far (radians) a ray is turned to test that its answer is not on a
/// knife's edge: about a hundredth of a pixel of a 512-pixel, 45° image.
const NUDGE: f32 = 1e-5;

/// The largest change of uv the nudged rays may see.
const UV_STEADY: f32 = 3e-4;

/// Inputs the ray's `origin` and unit `direction` (the camera stage's
/// output); expected `hit`, and for a hit `t` (along the unit direction),
/// the `point`, the `geometric_normal` (as the shape defines it: outward on
/// spheres and boxes, the front of flat shapes) and the `shading_normal`
/// (the same but on meshes with interpolated normals), `u`, `v`, the
/// `object` index and its `name` (shown, not checked).
/// The shading normal may be left out of the answers of a scene without
/// meshes, where it is the geometric normal.
pub fn layout(scene: &Scene) -> Layout {
    let has_meshes = scene
        .surfaces
        .iter()
        .any(|s| matches!(s, glint_integrator::Surface::Mesh(_)));
    let shading_normal = Field::xyz("shading_normal", Check::Direction);
    let inputs = ["origin", "direction"]
        .iter()
        .flat_map(|n| super::table::XYZ.map(|s| format!("{n}_{s}")))
        .collect();
    Layout {
        inputs,
        expected: vec![
            Field::scalar("hit", Kind::Bool, Check::Exact),
            Field::scalar("t", Kind::Float, Check::Relative),
            Field::xyz("point", Check::Vector),
            Field::xyz("geometric_normal", Check::Direction),
            match has_meshes {
                true => shading_normal,
                false => shading_normal.optional(),
            },
            Field::uv(),
            Field::scalar("object", Kind::Int, Check::Exact),
            Field::scalar("name", Kind::Text, Check::Info),
        ],
    }
}

/// `n` cases: pixels spread over the image, and awkward ones: the
/// silhouettes of spheres, edges and corners between objects, pixels that
/// see a light or nothing, and grazing angles.
pub fn cases(cx: &Context, n: usize) -> Result<Vec<Case>, GradeError> {
    let s = &cx.survey;
    let plans = vec![
        Plan::new("spread over the image", 0.0, s.stratified(|_| true)),
        Plan::new(
            "a sphere's silhouette",
            0.15,
            s.awkward(|p| s.on_silhouette(p)).into_iter(),
        ),
        Plan::new(
            "an edge between objects",
            0.1,
            s.awkward(|p| s.on_edge(p) && !s.on_silhouette(p))
                .into_iter(),
        ),
        Plan::new(
            "a corner of three objects",
            0.05,
            s.awkward(|p| s.at_corner(p)).into_iter(),
        ),
        Plan::new(
            "sees a light",
            0.05,
            s.awkward(|p| s.info(p).emitter).into_iter(),
        ),
        Plan::new(
            "sees nothing",
            0.05,
            s.awkward(|p| s.object(p) == BACKGROUND).into_iter(),
        ),
        Plan::new(
            "a grazing angle",
            0.1,
            s.awkward(|p| s.grazing(p)).into_iter(),
        ),
    ];
    collect(cx.scene, cx.settings, n, plans, |p| case(cx, p))
}

fn case(cx: &Context, p: &Probe) -> Option<Case> {
    if !steady(cx, &p.ray, p.hit.as_ref()) {
        return None;
    }
    let mut case = Case::new(Some(p.from.clone()));
    case.xyz("origin", p.ray.origin)
        .xyz("direction", p.ray.direction)
        .set("hit", Value::Bool(p.hit.is_some()));
    if let Some(h) = &p.hit {
        case.float("t", h.t)
            .xyz("point", h.point)
            .xyz("geometric_normal", h.geometric_normal)
            .xyz("shading_normal", h.shading_normal)
            .uv(h.uv)
            .int("object", h.shape.into())
            .set("name", Value::Text(cx.names[h.shape as usize].clone()));
        case.periodic_u = cx.survey.info[h.shape as usize].sphere;
    }
    Some(case)
}

/// Whether rays turned by [`NUDGE`] about the ray, four ways, see the same
/// object (or also nothing) with about the same uv: if not, the ray passes
/// within rounding of a silhouette, an edge or a tie, or near a sphere's
/// pole, where a correct program in other arithmetic may answer otherwise.
fn steady(cx: &Context, ray: &Ray, hit: Option<&Hit>) -> bool {
    let d = ray.direction;
    let a = d.any_orthonormal_vector();
    let b = d.cross(a);
    [a, -a, b, -b].iter().all(|&side| {
        let nudged = Ray::new(ray.origin, (d + NUDGE * side).normalize());
        let other = cx.scene.shapes.closest_hit(&nudged, f32::INFINITY);
        match (hit, other) {
            (None, None) => true,
            (Some(h), Some(o)) => {
                o.shape == h.shape
                    && uv_apart(h, &o, cx.survey.info[h.shape as usize].sphere) < UV_STEADY
            }
            _ => false,
        }
    })
}

/// The larger difference of the two hits' u and v (u modulo 1 if `periodic`).
fn uv_apart(a: &Hit, b: &Hit, periodic: bool) -> f32 {
    let mut du = (a.uv.x - b.uv.x).abs();
    if periodic {
        du = du.min(1.0 - du);
    }
    du.max((a.uv.y - b.uv.y).abs())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn u_is_compared_around_the_seam_on_spheres_only() {
        let hit = |u: f32| Hit {
            uv: glam::Vec2::new(u, 0.5),
            ..unit_hit()
        };
        assert!(uv_apart(&hit(0.9999), &hit(0.0001), true) < 3e-4);
        assert!(uv_apart(&hit(0.9999), &hit(0.0001), false) > 0.99);
    }

    fn unit_hit() -> Hit {
        Hit {
            t: 1.0,
            point: Vec3::ZERO,
            error: Vec3::ZERO,
            geometric_normal: Vec3::Y,
            shading_normal: Vec3::Y,
            uv: glam::Vec2::ZERO,
            dpdu: Vec3::X,
            dpdv: Vec3::Z,
            dndu: Vec3::ZERO,
            dndv: Vec3::ZERO,
            front_face: true,
            shape: 0,
            primitive: 0,
        }
    }
}
