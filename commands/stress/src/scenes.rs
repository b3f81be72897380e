//! The shipped scenes (the Cornell box of Set 1, the open bunny in the Cornell
//! box, the closed bunny on a ground plane) scaled and moved, traced pixel by
//! pixel through the scene as the renderer loads it, and judged against the
//! same scene at scale 1 at the origin.
//!
//! The course's Phong model has no distance falloff, so a scene scaled about any
//! point, camera included, renders the same image: every camera ray, shadow ray
//! and mirror ray should meet the same surfaces as at scale 1. Rounding moves
//! what a ray meets only near an edge or a silhouette, so the reference judges a
//! ray only where it is **robust**: four copies of it moved sideways by 1e-3 of
//! the camera's distance to the scene meet the same surface (or all miss).

use crate::{finite, Counts};
use glam::{DVec3, Vec2, Vec3};
use glint_camera::Film;
use glint_geometry::{reflect, spawn_ray, spawn_ray_to, Hit, Occluders, Ray, RayTarget};
use glint_integrator::{render, RenderOutput, RenderSettings, Scene, SurfaceKind};
use glint_lighting::Light;
use glint_scene::SceneDescription;
use std::path::Path;

/// A shipped scene, as text, with the meshes it reads (path, OBJ text).
pub(crate) struct ShippedScene {
    pub name: &'static str,
    toml: &'static str,
    meshes: &'static [(&'static str, &'static str)],
}

pub(crate) const SHIPPED: [ShippedScene; 3] = [
    ShippedScene {
        name: "scene cornell-set1",
        toml: include_str!("../../../scenes/cornell-set1.toml"),
        meshes: &[],
    },
    ShippedScene {
        name: "scene bunny-cornell",
        toml: include_str!("../../../scenes/bunny-cornell.toml"),
        meshes: &[(
            "meshes/bunny.obj",
            include_str!("../../../scenes/meshes/bunny.obj"),
        )],
    },
    ShippedScene {
        name: "scene bunny",
        toml: include_str!("../../../scenes/bunny.toml"),
        meshes: &[(
            "meshes/bunny-closed.obj",
            include_str!("../../../scenes/meshes/bunny-closed.obj"),
        )],
    },
];

/// Area-light sample coordinates per side: the centres of a 3 × 3 grid.
const LIGHT_GRID: [f32; 3] = [1.0 / 6.0, 0.5, 5.0 / 6.0];

/// How far the reference moves a ray sideways to call it robust, as a fraction
/// of the camera's distance to the first surface along its central ray (3.6 to
/// 20 scale units in the shipped scenes): beyond the rounding of a scene moved
/// 1000 scale units from the origin (6e-5 of a unit per coordinate), and of the
/// ray offsets there (a few 1e-4 of a unit).
const ROBUST_SHIFT: f32 = 1e-3;

impl ShippedScene {
    /// The scene scaled by `scale` about the origin and then moved by `offset`,
    /// at `width` pixels across, loaded as the renderer loads it (its meshes
    /// written under `dir`).
    pub(crate) fn load(
        &self,
        dir: &Path,
        scale: f64,
        offset: DVec3,
        width: u32,
    ) -> SceneDescription {
        // Written once per folder: every scale and offset reads the same files.
        for (path, text) in self.meshes.iter().filter(|(p, _)| !dir.join(p).exists()) {
            let file = dir.join(path);
            std::fs::create_dir_all(file.parent().expect("a mesh path has a folder"))
                .expect("the temporary folder takes the meshes");
            std::fs::write(file, text).expect("the temporary folder takes the meshes");
        }
        let text = transformed(self.toml, scale, offset, width);
        match glint_scene::parse_in(&text, self.name, dir) {
            Ok(description) => description,
            Err(e) => panic!("{} at scale {scale:e}, offset {offset}: {e}", self.name),
        }
    }
}

/// Scene text with every position `p` replaced by `scale·p + offset`, every
/// length and edge scaled, and the resolution set to `width` pixels across
/// (keeping the file's aspect ratio).
pub(crate) fn transformed(toml: &str, scale: f64, offset: DVec3, width: u32) -> String {
    use toml::{Table, Value};
    let mut doc: Table = toml.parse().expect("shipped scenes parse");
    // Named pixel regions are of the file's resolution, not this one.
    doc.remove("regions");
    let point = |v: &mut Value| {
        let Value::Array(a) = v else { return };
        for (x, o) in a.iter_mut().zip(offset.to_array()) {
            *x = Value::Float(scale * number(x) + o);
        }
    };
    let length = |v: &mut Value| match v {
        Value::Array(a) => a
            .iter_mut()
            .for_each(|x| *x = Value::Float(scale * number(x))),
        x => *x = Value::Float(scale * number(x)),
    };
    let each = |doc: &mut Table, table: &str, f: &dyn Fn(&mut Table)| match doc.get_mut(table) {
        Some(Value::Array(items)) => items.iter_mut().filter_map(Value::as_table_mut).for_each(f),
        Some(Value::Table(t)) => f(t),
        _ => {}
    };
    let with_default =
        |t: &mut Table, key: &str, default: Value| -> Value { t.remove(key).unwrap_or(default) };
    each(&mut doc, "camera", &|t| {
        point(t.get_mut("position").expect("a camera position"));
        point(t.get_mut("look_at").expect("a camera target"));
        let mut f = with_default(t, "focal_length", Value::Float(1.0));
        length(&mut f);
        t.insert("focal_length".into(), f);
    });
    let placed: [(&str, &[&str], &[&str]); 7] = [
        ("sphere", &["center"], &["radius"]),
        ("parallelogram", &["origin"], &["edge1", "edge2"]),
        ("plane", &["point"], &[]),
        ("box", &["min", "max"], &[]),
        ("point_light", &["position"], &[]),
        ("area_light", &["center"], &["edge1", "edge2"]),
        ("mesh", &[], &[]),
    ];
    for (table, points, lengths) in placed {
        each(&mut doc, table, &|t| {
            points
                .iter()
                .for_each(|k| point(t.get_mut(*k).expect("a position")));
            lengths
                .iter()
                .for_each(|k| length(t.get_mut(*k).expect("a length")));
            if table == "plane" {
                let mut size = with_default(t, "tile_size", Value::Float(1.0));
                length(&mut size);
                t.insert("tile_size".into(), size);
            }
            if table == "mesh" {
                let origin = Value::Array(vec![Value::Float(0.0); 3]);
                let mut at = with_default(t, "translate", origin);
                point(&mut at);
                t.insert("translate".into(), at);
                let mut size = with_default(t, "scale", Value::Float(1.0));
                length(&mut size);
                t.insert("scale".into(), size);
            }
        });
    }
    let render = doc
        .entry("render")
        .or_insert_with(|| Value::Table(Table::new()))
        .as_table_mut()
        .expect("[render] is a table");
    let [w, h] = match render.get("resolution") {
        Some(Value::Array(r)) => [number(&r[0]), number(&r[1])],
        _ => [512.0, 512.0], // the format's default
    };
    let height = (width as f64 * h / w).round().max(1.0) as i64;
    render.insert(
        "resolution".into(),
        Value::Array(vec![Value::Integer(width.into()), Value::Integer(height)]),
    );
    doc.to_string()
}

fn number(v: &toml::Value) -> f64 {
    match v {
        toml::Value::Integer(i) => *i as f64,
        toml::Value::Float(f) => *f,
        other => panic!("a number in a shipped scene, not {other}"),
    }
}

/// What a surface a ray met is: its shape and primitive.
type Surface = (u32, u32);

fn surface(hit: &Hit) -> Surface {
    (hit.shape, hit.primitive)
}

/// A light point a shading point's shadow ray aims at, with the light it
/// belongs to (an index into the scene's lights).
struct LightPoint {
    light: usize,
    target: RayTarget,
    /// The light's plane (an area light's normal), if any.
    plane_normal: Option<Vec3>,
}

fn light_points(scene: &Scene) -> Vec<LightPoint> {
    let mut points = Vec::new();
    for (light, l) in scene.lights.iter().enumerate() {
        match l {
            Light::Point(p) => points.push(LightPoint {
                light,
                target: RayTarget::exact(p.position),
                plane_normal: None,
            }),
            Light::Area(a) => {
                for v in LIGHT_GRID {
                    for u in LIGHT_GRID {
                        let target = a.shadow_target(a.sample_point(Vec2::new(u, v)));
                        points.push(LightPoint {
                            light,
                            target,
                            plane_normal: Some(a.surface().normal()),
                        });
                    }
                }
            }
            // Sphere lights are physical shading's; the stressed scenes have none.
            Light::Sphere(_) => {}
        }
    }
    points
}

/// The shadow ray from `hit` to light point `p`, if the light is above the
/// surface as the ray came to it.
fn shadow_ray(hit: &Hit, incoming: Vec3, p: &LightPoint) -> Option<Ray> {
    let towards = p.target.point - hit.point;
    let arrived_on_front = hit.geometric_normal.dot(incoming) < 0.0;
    let light_on_front = hit.geometric_normal.dot(towards) > 0.0;
    (arrived_on_front == light_on_front).then(|| spawn_ray_to(hit, &p.target))
}

/// The reference's answer for one pixel (the ray through its centre), where
/// the ray is robust.
struct PixelTruth {
    /// The surface the camera ray meets, or `None` if it escapes.
    surface: Option<Surface>,
    /// How far along the unit camera ray it meets it.
    distance: f32,
    /// Per light point, whether its shadow ray is blocked, where that is robust
    /// and the light is above the surface (else `None`).
    blocked: Vec<Option<bool>>,
}

/// Four sideways shifts of length `shift` perpendicular to `direction`.
fn shifts(direction: Vec3, shift: f32) -> [Vec3; 4] {
    let (a, b) = direction.normalize().any_orthonormal_pair();
    [a * shift, -a * shift, b * shift, -b * shift]
}

/// The scale-1 scene's robust answers, pixel by pixel (`None` where the camera
/// ray is not robust).
pub(crate) struct Reference {
    pixels: Vec<Option<PixelTruth>>,
}

impl Reference {
    pub(crate) fn new(scene: &Scene) -> Reference {
        let camera = &scene.camera;
        let res = camera.resolution();
        let shift = ROBUST_SHIFT * camera_distance(scene);
        let lights = light_points(scene);
        let mut pixels = Vec::new();
        for y in 0..res.y {
            for x in 0..res.x {
                let c = camera.generate_ray(x as f32 + 0.5, y as f32 + 0.5);
                let ray = Ray::new(c.origin, c.direction);
                pixels.push(truth(scene, &ray, shift, &lights));
            }
        }
        Reference { pixels }
    }
}

fn camera_distance(scene: &Scene) -> f32 {
    // The camera's position to the nearest surface along its central ray, or
    // to the origin, as the scene's size.
    let camera = &scene.camera;
    let res = camera.resolution().as_vec2();
    let c = camera.generate_ray(res.x / 2.0, res.y / 2.0);
    scene
        .shapes
        .closest_hit(&Ray::new(c.origin, c.direction), f32::INFINITY)
        .map_or(c.origin.length(), |h| h.t)
}

fn truth(scene: &Scene, ray: &Ray, shift: f32, lights: &[LightPoint]) -> Option<PixelTruth> {
    let first = |r: &Ray| scene.shapes.closest_hit(r, f32::INFINITY);
    let hit = first(ray);
    let moved = shifts(ray.direction, shift);
    let same = moved.iter().all(|s| {
        first(&Ray::new(ray.origin + *s, ray.direction)).map(|h| surface(&h))
            == hit.as_ref().map(surface)
    });
    if !same {
        return None;
    }
    let Some(hit) = hit else {
        return Some(PixelTruth {
            surface: None,
            distance: f32::INFINITY,
            blocked: Vec::new(),
        });
    };
    // A camera ray that meets a light sees its radiance: no shadow rays.
    let lights = match scene.surface_of(&hit) {
        SurfaceKind::Emitter(_) => &[][..],
        SurfaceKind::Material(_) => lights,
    };
    let blocked = lights
        .iter()
        .map(|p| {
            let shadow = shadow_ray(&hit, ray.direction, p)?;
            let verdicts: Vec<bool> = std::iter::once(shadow)
                .chain(nearby_shadow_rays(&hit, &shadow, p, shift))
                .map(|r| scene.shapes.any_hit(&r, 1.0))
                .collect();
            verdicts
                .iter()
                .all(|&b| b == verdicts[0])
                .then_some(verdicts[0])
        })
        .collect();
    Some(PixelTruth {
        surface: Some(surface(&hit)),
        distance: hit.t,
        blocked,
    })
}

/// Five shadow rays near `shadow`: its origin moved by `shift` along two
/// tangents of the surface either way (on the surface, as a shift below it
/// would meet it) and once along the normal on the light's side (a ray leaving
/// at a grazing angle, blocked by the surface's own curve nearby, is not
/// robust), and its end moved alike but kept on the light's plane.
fn nearby_shadow_rays(hit: &Hit, shadow: &Ray, p: &LightPoint, shift: f32) -> [Ray; 5] {
    let n = hit.geometric_normal * hit.geometric_normal.dot(shadow.direction).signum();
    let (t1, t2) = n.any_orthonormal_pair();
    let end = shadow.origin + shadow.direction;
    [t1, -t1, t2, -t2, n].map(|s| {
        let s = s * shift;
        let on_light = p.plane_normal.map_or(s, |m| s - s.dot(m) * m);
        let origin = shadow.origin + s;
        Ray::new(origin, end + on_light - origin)
    })
}

/// Traces every pixel of `scene` (the reference's scene scaled and moved) and
/// counts the pixels where a ray does what it must not.
pub(crate) fn judge(scene: &Scene, reference: &Reference, scale: f32) -> Counts {
    let camera = &scene.camera;
    let res = camera.resolution();
    let lights = light_points(scene);
    let mut counts = Counts::default();
    for y in 0..res.y {
        for x in 0..res.x {
            let truth = reference.pixels[(y * res.x + x) as usize].as_ref();
            let c = camera.generate_ray(x as f32 + 0.5, y as f32 + 0.5);
            let ray = Ray::new(c.origin, c.direction);
            let pixel = judge_pixel(scene, &ray, truth, &lights, scale, &mut counts.rays);
            counts.acne += u64::from(pixel.acne);
            counts.leaks += u64::from(pixel.leak);
            counts.self_hits += u64::from(pixel.self_hit);
            counts.off_surface += u64::from(pixel.off_surface);
            counts.non_finite += u64::from(pixel.non_finite);
        }
    }
    counts
}

#[derive(Default)]
struct PixelFlags {
    acne: bool,
    leak: bool,
    self_hit: bool,
    off_surface: bool,
    non_finite: bool,
}

fn judge_pixel(
    scene: &Scene,
    ray: &Ray,
    truth: Option<&PixelTruth>,
    lights: &[LightPoint],
    scale: f32,
    rays: &mut u64,
) -> PixelFlags {
    let mut flags = PixelFlags::default();
    *rays += 1;
    if !(ray.origin.is_finite() && ray.direction.is_finite()) {
        flags.non_finite = true;
        return flags;
    }
    let hit = scene.shapes.closest_hit(ray, f32::INFINITY);
    if let Some(t) = truth {
        let met = hit.as_ref().map(surface);
        if met != t.surface {
            // Past the surface the reference meets: through it. Short of it:
            // a surface where the reference robustly has none.
            let farther = hit.as_ref().map_or(f32::INFINITY, |h| h.t / scale);
            flags.leak |= t.surface.is_some() && farther > t.distance;
            flags.off_surface |= farther < t.distance;
        }
    }
    let Some(hit) = hit else { return flags };
    if !finite(&hit) {
        flags.non_finite = true;
        return flags;
    }
    if matches!(scene.surface_of(&hit), SurfaceKind::Emitter(_)) {
        return flags;
    }
    let same_surface = truth.is_some_and(|t| t.surface == Some(surface(&hit)));
    for (i, p) in lights.iter().enumerate() {
        let Some(shadow) = shadow_ray(&hit, ray.direction, p) else {
            continue;
        };
        *rays += 1;
        if !shadow.origin.is_finite() {
            flags.non_finite = true;
            continue;
        }
        let blocker = scene.shapes.closest_hit(&shadow, 1.0);
        // From a few light samples up, the integrator tests only the shapes
        // that can lie between the point and an area light (leaving out the
        // point's own shape and the light's where they are flat or convex).
        let culled = match &scene.lights[p.light] {
            Light::Area(a) => scene.shapes.occluders_towards(
                hit.point,
                0.0,
                &a.surface().corners(),
                [hit.shape, scene.light_objects[p.light]],
            ),
            Light::Point(_) | Light::Sphere(_) => Occluders::ALL,
        };
        let blocked_as_rendered = scene.shapes.any_hit_among(&culled, &shadow, 1.0);
        flags.acne |= blocker
            .as_ref()
            .is_some_and(|b| surface(b) == surface(&hit));
        let expected = same_surface
            .then(|| truth.and_then(|t| t.blocked.get(i).copied().flatten()))
            .flatten();
        match expected {
            Some(false) => flags.acne |= blocker.is_some() || blocked_as_rendered,
            Some(true) => flags.leak |= blocker.is_none() || !blocked_as_rendered,
            None => {}
        }
    }
    let wo = -ray.direction.normalize();
    let mirror = spawn_ray(&hit, reflect(wo, hit.facing_normal(ray.direction)));
    *rays += 1;
    flags.non_finite |= !mirror.origin.is_finite();
    flags.self_hit |= scene
        .shapes
        .closest_hit(&mirror, f32::INFINITY)
        .is_some_and(|m| surface(&m) == surface(&hit));
    flags
}

/// Samples per pixel of the stress renders.
const RENDER_SPP: u32 = 4;

/// The scene rendered as `glint render` renders it (its own samplers and light
/// samples, its seed), at [`RENDER_SPP`] samples per pixel.
pub(crate) fn rendered(description: &SceneDescription) -> RenderOutput {
    let settings = RenderSettings {
        spp: RENDER_SPP,
        ..description.settings.clone()
    };
    render(&description.scene, &settings, &|_, _| {}).expect("the stress settings are valid")
}

/// How many pixels of `film` differ from the same pixel of `reference` by more
/// than `tolerance` in any channel.
pub(crate) fn changed_pixels(film: &Film, reference: &Film, tolerance: f32) -> u64 {
    film.pixels()
        .iter()
        .zip(reference.pixels())
        .filter(|(a, b)| (**a - **b).abs().max_element() > tolerance)
        .count() as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> toml::Table {
        text.parse().unwrap()
    }

    #[test]
    fn transforming_scales_lengths_and_moves_positions() {
        let text = transformed(SHIPPED[2].toml, 10.0, DVec3::new(1.0, 2.0, 3.0), 40);
        let doc = table(&text);
        let camera = doc["camera"].as_table().unwrap();
        let position: Vec<f64> = camera["position"]
            .as_array()
            .unwrap()
            .iter()
            .map(number)
            .collect();
        assert_eq!(position, [1.0, 15.0, 39.0]);
        assert_eq!(number(&camera["focal_length"]), 10.0, "the default, scaled");
        let mesh = doc["mesh"].as_array().unwrap()[0].as_table().unwrap();
        assert_eq!(number(&mesh["scale"]), 10.0);
        let translate_y = number(&mesh["translate"].as_array().unwrap()[1]);
        assert!((translate_y - (2.0 + 8.91)).abs() < 1e-12, "{translate_y}");
        assert_eq!(
            number(&mesh["rotate"].as_array().unwrap()[1]),
            20.0,
            "angles stay"
        );
        let plane = doc["plane"].as_array().unwrap()[0].as_table().unwrap();
        assert_eq!(number(&plane["tile_size"]), 40.0);
        let light = doc["area_light"].as_array().unwrap()[0].as_table().unwrap();
        assert_eq!(number(&light["edge1"].as_array().unwrap()[0]), 15.0);
        let resolution = doc["render"]["resolution"].as_array().unwrap();
        assert_eq!(
            (number(&resolution[0]), number(&resolution[1])),
            (40.0, 30.0)
        );
    }

    #[test]
    fn every_placed_table_is_transformed() {
        let text = r#"
            [camera]
            position = [0, 0, 5]
            look_at = [0, 0, 0]
            fov = 40
            [[box]]
            min = [-1, -1, -1]
            max = [1, 2, 3]
            [[point_light]]
            position = [4, 5, 6]
            [[sphere]]
            center = [1, 1, 1]
            radius = 0.5
            [[parallelogram]]
            origin = [0, 0, 0]
            edge1 = [1, 0, 0]
            edge2 = [0, 1, 0]
        "#;
        let doc = table(&transformed(text, 2.0, DVec3::new(10.0, 0.0, 0.0), 64));
        let first = |name: &str, key: &str| -> Vec<f64> {
            let t = doc[name].as_array().unwrap()[0].as_table().unwrap();
            match &t[key] {
                toml::Value::Array(a) => a.iter().map(number).collect(),
                v => vec![number(v)],
            }
        };
        assert_eq!(first("box", "min"), [8.0, -2.0, -2.0]);
        assert_eq!(first("box", "max"), [12.0, 4.0, 6.0]);
        assert_eq!(first("point_light", "position"), [18.0, 10.0, 12.0]);
        assert_eq!(first("sphere", "center"), [12.0, 2.0, 2.0]);
        assert_eq!(first("sphere", "radius"), [1.0]);
        assert_eq!(first("parallelogram", "origin"), [10.0, 0.0, 0.0]);
        assert_eq!(first("parallelogram", "edge2"), [0.0, 2.0, 0.0]);
        let resolution = doc["render"]["resolution"].as_array().unwrap();
        assert_eq!(number(&resolution[1]), 64.0, "512 x 512 by default");
    }

    #[test]
    fn every_shipped_scene_loads_scaled_and_moved() {
        let dir = tempfile::tempdir().unwrap();
        for s in &SHIPPED {
            let d = s.load(dir.path(), 1e4, DVec3::splat(1e6), 8);
            assert_eq!(d.scene.camera.resolution().x, 8, "{}", s.name);
            assert!(d.scene.camera.position().x > 9e5, "{}", s.name);
        }
    }

    /// The judge is not blind: the Cornell box with a sphere moved, judged
    /// against the box as shipped, has camera rays that pass where the
    /// reference meets the sphere, meet it where the reference meets a wall
    /// behind, and shadow rays blocked where the reference's are robustly
    /// clear and clear where they are robustly blocked.
    #[test]
    fn a_changed_scene_is_judged_wrong_where_it_differs() {
        let dir = tempfile::tempdir().unwrap();
        let shipped = &SHIPPED[0];
        let moved_text = shipped
            .toml
            .replace("center = [3, 1, -7]", "center = [-3, -1, -7]");
        assert_ne!(moved_text, shipped.toml);
        let moved = ShippedScene {
            name: "moved sphere",
            toml: Box::leak(moved_text.into_boxed_str()),
            meshes: &[],
        };
        let reference = Reference::new(&shipped.load(dir.path(), 1.0, DVec3::ZERO, 24).scene);
        let same = shipped.load(dir.path(), 1.0, DVec3::ZERO, 24).scene;
        assert!(judge(&same, &reference, 1.0).clean());
        let c = judge(
            &moved.load(dir.path(), 1.0, DVec3::ZERO, 24).scene,
            &reference,
            1.0,
        );
        assert!(c.leaks > 0 && c.off_surface > 0 && c.acne > 0, "{c:?}");
    }
}
