//! Where Mitsuba's shapes go: the `to_world` matrices that put its unit
//! shapes on Glint's, with the maps from their uv to Glint's, and the points
//! that bound the scene.

use glam::{Affine2, Vec2, Vec3};
use glint_geometry::{Parallelogram, Plane, Ray, Shape};
use glint_integrator::Scene;
use glint_lighting::Light;

/// A Mitsuba `rectangle` ([−1, 1]² in its local xy plane, facing +z) onto
/// `origin + α·edge1 + β·edge2`, facing the front normal, and the map from its
/// uv to Glint's `(α, β)`. Mitsuba's normal is the inverse transpose of the
/// matrix applied to +z; keeping the determinant positive (swapping the
/// edges, which spans the same parallelogram, and so u and v) keeps the
/// triangles' winding in agreement with it.
pub(in crate::mitsuba) fn rectangle(p: &Parallelogram) -> ([[f32; 4]; 4], Affine2) {
    let (e1, e2) = p.edges();
    let n = p.normal();
    if e1.cross(e2).dot(n) >= 0.0 {
        (
            columns(0.5 * e1, 0.5 * e2, n, p.center()),
            Affine2::IDENTITY,
        )
    } else {
        let swap = Affine2::from_cols(Vec2::Y, Vec2::X, Vec2::ZERO);
        (columns(0.5 * e2, 0.5 * e1, n, p.center()), swap)
    }
}

/// A plane's tangent frame and tile size, as its hits report them.
pub(super) fn plane_frame(plane: &Plane) -> (Vec3, Vec3, f32) {
    let n = plane.normal();
    let hit = plane.surface_at(&Ray::new(plane.point() + n, -n), 1.0);
    let tile = hit.dpdu.length();
    (hit.dpdu / tile, hit.dpdv / hit.dpdv.length(), tile)
}

/// A Mitsuba `rectangle` standing in for `plane`: `anchor ± half·t ± half·b`
/// in its tangent frame, and the map from its uv to Glint's. The point
/// `(2u − 1)·half` along `t` from the anchor has Glint's u at the anchor plus
/// that over the tile size.
pub(in crate::mitsuba) fn plane_rectangle(
    plane: &Plane,
    anchor: Vec3,
    half: f32,
) -> ([[f32; 4]; 4], Affine2) {
    let (t, b, tile) = plane_frame(plane);
    let n = plane.normal();
    let base = Vec2::new(
        (anchor - plane.point()).dot(t),
        (anchor - plane.point()).dot(b),
    ) / tile;
    let s = 2.0 * half / tile;
    let offset = base - Vec2::splat(half / tile);
    let (first, second, uv) = if t.cross(b).dot(n) >= 0.0 {
        (
            t,
            b,
            Affine2::from_cols(Vec2::new(s, 0.0), Vec2::new(0.0, s), offset),
        )
    } else {
        (
            b,
            t,
            Affine2::from_cols(Vec2::new(0.0, s), Vec2::new(s, 0.0), offset),
        )
    };
    (columns(first * half, second * half, n, anchor), uv)
}

/// A Mitsuba `sphere` in Glint's place, and the map from its uv to Glint's.
/// Glint's sphere uv: u = atan2(−z, x)/2π about +y, v up from the bottom
/// pole. Mitsuba's: u = atan2(y, x)/2π about its local +z, v down from the top
/// pole. Local x, y, z → world x, −z, y makes the u's agree; v is mirrored.
pub(in crate::mitsuba) fn sphere(s: &glint_geometry::Sphere) -> ([[f32; 4]; 4], Affine2) {
    let (r, c) = (s.radius(), s.center());
    let to_world = columns(r * Vec3::X, -r * Vec3::Z, r * Vec3::Y, c);
    (to_world, Affine2::from_cols(Vec2::X, -Vec2::Y, Vec2::Y))
}

/// The 4×4 matrix (row by row) with these columns and translation.
fn columns(x: Vec3, y: Vec3, z: Vec3, t: Vec3) -> [[f32; 4]; 4] {
    [
        [x.x, y.x, z.x, t.x],
        [x.y, y.y, z.y, t.y],
        [x.z, y.z, z.z, t.z],
        [0.0, 0.0, 0.0, 1.0],
    ]
}

/// Whether a flat shape is seen from behind (two-sided): a ray towards its
/// front from behind `point` meets it.
pub(super) fn seen_from_behind(
    point: Vec3,
    normal: Vec3,
    hit: impl Fn(&Ray) -> Option<f32>,
) -> bool {
    let reach = 1.0 + point.abs().max_element();
    hit(&Ray::new(point - reach * normal, normal)).is_some()
}

/// Every point that bounds the scene's finite objects: spheres' and boxes'
/// corners, parallelograms' corners, mesh vertices, lights, and the camera.
pub(super) fn scene_points(scene: &Scene) -> impl Iterator<Item = Vec3> + '_ {
    let shapes = scene.shapes.shapes().iter().flat_map(|s| -> Vec<Vec3> {
        match s {
            Shape::Sphere(s) => vec![s.center() - s.radius(), s.center() + s.radius()],
            Shape::Parallelogram(p) => p.corners().to_vec(),
            Shape::Box(b) => vec![b.min(), b.max()],
            Shape::Plane(p) => vec![p.point()],
        }
    });
    let meshes = scene
        .shapes
        .meshes()
        .iter()
        .flat_map(|m| m.positions().iter().copied());
    let lights = scene.lights.iter().flat_map(|l| -> Vec<Vec3> {
        #[allow(unreachable_patterns)]
        match l {
            Light::Point(p) => vec![p.position],
            Light::Area(a) => a.surface().corners().to_vec(),
            Light::Sphere(s) => {
                let (c, r) = (s.surface().center(), s.surface().radius());
                vec![c - Vec3::splat(r), c + Vec3::splat(r)]
            }
            _ => vec![],
        }
    });
    std::iter::once(scene.camera.position())
        .chain(shapes)
        .chain(meshes)
        .chain(lights)
}
