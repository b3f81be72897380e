//! Numerical stress: configurations whose visibility is known analytically,
//! generated at every scale from 1e-4 to 1e6 and moved far from the origin,
//! traced through the geometry stage exactly as the integrator traces them
//! (closest hits, shadow rays from `spawn_ray_to`, reflection rays from
//! `spawn_ray`), counting what must be zero:
//!
//! - **shadow acne**: a lit point whose shadow ray is blocked where nothing
//!   can block it (a floor alone under a light down to 0.01° above its
//!   horizon, or seen from as low; a lone sphere; a tiny sphere resting on a
//!   huge one; a closed mesh lit from outside);
//! - **light leaks**: from inside a closed box (six parallelograms meeting at
//!   their edges, one `AaBox`, or a triangle mesh) or a closed icosahedron, a
//!   shadow ray that reaches a light outside or a camera ray that escapes,
//!   aimed exactly at edges, corners and shared vertices included;
//! - **self-hits**: a reflection ray off a floor or a sphere that hits it again;
//! - **off-surface** hit points: farther from the exact surface (computed in
//!   f64) than the error bound the offsets assume (`Hit::error`);
//! - **non-finite** hit points, normals or spawned origins, rays along a plane
//!   seen exactly edge-on included.
//!
//! The shipped scenes (the Cornell box, the open bunny in it, the closed bunny
//! on a plane) are scaled and moved the same way and judged pixel by pixel
//! against themselves at scale 1 (see `scenes.rs`); each is also rendered as
//! `glint render` renders it, its non-finite samples counted and the pixels
//! that changed reported.
//!
//! [`run`] builds the table, [`table`] prints it; `glint stress` is the command.
//! Units: lengths in scene units; angles in degrees where named so.

mod closed;
mod flat;
mod scenes;
mod spheres;

use glam::{DVec3, Vec3};
use glint_geometry::{reflect, spawn_ray, spawn_ray_to, Hit, Ray, RayTarget, ShapeList};

/// The scales every configuration is built at.
pub const SCALES: [f32; 6] = [1e-4, 1e-2, 1.0, 1e2, 1e4, 1e6];

/// Light elevations above a floor's horizon, in degrees (the first three
/// are also the elevations a floor is seen from).
pub const GRAZING_DEGREES: [f32; 4] = [0.01, 0.1, 1.0, 30.0];

/// Pixels across the shipped scenes' renders per ray of the grid's side.
const SCENE_PIXELS_PER_GRID: u32 = 4;

/// How far a pixel of a shipped scene's render may move from the render at
/// scale 1 (linear radiance) before it counts as changed.
pub const CHANGED: f32 = 1e-3;

/// What one configuration counted.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    pub rays: u64,
    pub acne: u64,
    pub leaks: u64,
    pub self_hits: u64,
    pub off_surface: u64,
    pub non_finite: u64,
    /// For a shipped scene: pixels of its render that differ from the render
    /// at scale 1 at the origin by more than [`CHANGED`] in a channel. Reported,
    /// not required to be zero: rays within the rounding of an edge, a
    /// silhouette or a mesh's crease may go either way far from the origin.
    pub changed_pixels: Option<u64>,
}

impl Counts {
    /// Whether every count that must be zero is.
    pub fn clean(&self) -> bool {
        self.acne == 0
            && self.leaks == 0
            && self.self_hits == 0
            && self.off_surface == 0
            && self.non_finite == 0
    }

    fn add(&mut self, other: &Counts) {
        self.rays += other.rays;
        self.acne += other.acne;
        self.leaks += other.leaks;
        self.self_hits += other.self_hits;
        self.off_surface += other.off_surface;
        self.non_finite += other.non_finite;
        if let Some(c) = other.changed_pixels {
            self.changed_pixels = Some(self.changed_pixels.unwrap_or(0) + c);
        }
    }
}

/// One row of the table: a configuration at a scale and offset.
#[derive(Clone, Debug)]
pub struct Row {
    pub configuration: String,
    pub scale: f32,
    pub offset: f32,
    pub counts: Counts,
}

/// How many rays, and where they are aimed.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    /// Rays per side aimed at each configuration (a face of a box, a floor, a
    /// sphere's disc).
    pub grid: u32,
    /// Whether the grid's first and last rays are aimed exactly at the edges,
    /// where walls meet (else at the centres of `grid` equal cells).
    pub joints: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            grid: 16,
            joints: true,
        }
    }
}

/// Every configuration at every scale, each at the origin and moved away from
/// it by up to 1e6 (as far as f32 resolves the configuration: 1000 times its
/// size).
pub fn run(settings: Settings) -> Vec<Row> {
    let steps = steps(settings.grid, settings.joints);
    let assets = tempfile::tempdir().expect("a temporary folder for the scenes' meshes");
    let width = SCENE_PIXELS_PER_GRID * settings.grid;
    let references: Vec<_> = scenes::SHIPPED
        .iter()
        .map(|s| {
            let unit = s.load(assets.path(), 1.0, DVec3::ZERO, width);
            (
                scenes::Reference::new(&unit.scene),
                scenes::rendered(&unit).film,
            )
        })
        .collect();
    let mut rows = Vec::new();
    for scale in SCALES {
        for offset in [0.0, (1e3 * scale).min(1e6)] {
            let at = Vec3::new(offset, -0.7 * offset, 0.4 * offset);
            let mut row = |configuration: &str, counts: Counts| {
                rows.push(Row {
                    configuration: configuration.to_string(),
                    scale,
                    offset,
                    counts,
                })
            };
            for degrees in GRAZING_DEGREES {
                let name = format!("floor, light {degrees}° up");
                row(
                    &name,
                    flat::floor(at, scale, degrees, flat::View::Above, &steps),
                );
            }
            for degrees in &GRAZING_DEGREES[..3] {
                let name = format!("floor, seen {degrees}° up");
                let view = flat::View::Grazing(*degrees);
                row(&name, flat::floor(at, scale, 30.0, view, &steps));
            }
            row("plane seen edge-on", flat::edge_on(at, scale, &steps));
            row("sphere", spheres::lone(at, scale, &steps));
            row(
                "tiny sphere on huge",
                spheres::tiny_on_huge(at, scale, &steps),
            );
            for kind in closed::BoxKind::ALL {
                row(kind.name(), closed::closed_box(at, scale, &steps, kind));
            }
            row(
                "icosahedron, inside",
                closed::icosahedron_inside(at, scale, &steps),
            );
            row(
                "icosahedron, outside",
                closed::icosahedron_outside(at, scale, &steps),
            );
            for (shipped, (reference, film)) in scenes::SHIPPED.iter().zip(&references) {
                let scene = shipped.load(assets.path(), scale as f64, at.as_dvec3(), width);
                let mut counts = scenes::judge(&scene.scene, reference, scale);
                let out = scenes::rendered(&scene);
                counts.non_finite += out.stats.shading.nonfinite_samples;
                counts.changed_pixels = Some(scenes::changed_pixels(&out.film, film, CHANGED));
                row(shipped.name, counts);
            }
        }
    }
    rows
}

/// The sum of every row's counts.
pub fn total(rows: &[Row]) -> Counts {
    let mut sum = Counts::default();
    for r in rows {
        sum.add(&r.counts);
    }
    sum
}

/// `n` values spread over [0, 1]: both ends included with `ends`, else the
/// centres of `n` equal cells.
fn steps(n: u32, ends: bool) -> Vec<f32> {
    (0..n)
        .map(|i| match ends {
            true => i as f32 / (n - 1).max(1) as f32,
            false => (i as f32 + 0.5) / n as f32,
        })
        .collect()
}

fn finite(hit: &Hit) -> bool {
    hit.point.is_finite() && hit.geometric_normal.is_finite() && hit.error.is_finite()
}

/// Whether `hit`'s point is farther from the exact surface than its error
/// bound allows along the normal, given the point's exact signed distance
/// from the surface (in f64).
fn off_surface(hit: &Hit, distance: f64) -> bool {
    let bound = hit.geometric_normal.abs().dot(hit.error) as f64;
    distance.abs() > bound
}

/// The exact signed distance of `p` from the plane through `q` with normal `n`.
fn plane_distance(p: Vec3, q: DVec3, n: DVec3) -> f64 {
    (p.as_dvec3() - q).dot(n.normalize())
}

/// What a configuration knows analytically about a surface point.
pub(crate) struct Truth<D: Fn(&Hit) -> f64, L: Fn(&Hit) -> bool> {
    /// The exact signed distance of the hit's point from its surface (f64).
    distance: D,
    /// Whether the configuration's truth covers the hit: then it is lit
    /// wherever its normal faces the light (nothing can shadow it there).
    judged: L,
    /// Whether a mirror ray off any judged point meets nothing.
    mirror_escapes: bool,
}

/// Traces `ray` into `list` and judges the hit by `truth`: counts a blocked
/// shadow ray towards `light` as acne where the point is `judged`, a hit of
/// the mirror ray of a judged point as a self-hit where mirror rays escape, and
/// a point off the surface by more than its bound as off-surface.
pub(crate) fn lit_and_mirrored<D: Fn(&Hit) -> f64, L: Fn(&Hit) -> bool>(
    list: &ShapeList,
    ray: &Ray,
    light: Vec3,
    truth: &Truth<D, L>,
    counts: &mut Counts,
) {
    counts.rays += 1;
    let Some(hit) = list.closest_hit(ray, f32::INFINITY) else {
        return;
    };
    if !finite(&hit) {
        counts.non_finite += 1;
        return;
    }
    counts.off_surface += u64::from(off_surface(&hit, (truth.distance)(&hit)));
    if !(truth.judged)(&hit) {
        return;
    }
    if hit.geometric_normal.dot(light - hit.point) > 0.0 {
        let shadow = spawn_ray_to(&hit, &RayTarget::exact(light));
        counts.non_finite += u64::from(!shadow.origin.is_finite());
        counts.acne += u64::from(list.any_hit(&shadow, 1.0));
    }
    if truth.mirror_escapes {
        let wo = -ray.direction.normalize();
        let mirror = spawn_ray(&hit, reflect(wo, hit.geometric_normal));
        counts.self_hits += u64::from(list.closest_hit(&mirror, f32::INFINITY).is_some());
    }
}

/// The table of `rows`, in Markdown.
pub fn table(rows: &[Row]) -> String {
    let mut out = String::from(
        "| configuration | scale | offset | rays | acne | leaks | self-hits | off-surface | non-finite | changed pixels |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let c = &r.counts;
        out += &format!(
            "| {} | {:e} | {:e} | {} | {} | {} | {} | {} | {} | {} |\n",
            r.configuration,
            r.scale,
            r.offset,
            c.rays,
            c.acne,
            c.leaks,
            c.self_hits,
            c.off_surface,
            c.non_finite,
            c.changed_pixels.map_or("–".to_string(), |n| n.to_string())
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// With rays aimed at the joints too, nothing that must be zero is
    /// anything else, at any scale or offset.
    #[test]
    fn every_count_is_zero_joints_included() {
        let rows = run(Settings {
            grid: 5,
            joints: true,
        });
        assert!(rows.iter().all(|r| r.counts.clean()), "{}", table(&rows));
        assert_eq!(rows.len(), 18 * 12);
        assert!(total(&rows).rays > 12 * 1000, "{}", total(&rows).rays);
    }

    #[test]
    fn steps_span_the_unit_interval_with_or_without_its_ends() {
        assert_eq!(steps(3, true), [0.0, 0.5, 1.0]);
        assert_eq!(steps(2, false), [0.25, 0.75]);
    }

    #[test]
    fn a_point_off_its_surface_by_more_than_its_bound_is_counted() {
        let mut hit = Hit {
            t: 1.0,
            point: Vec3::new(0.0, 1e-6, 0.0),
            error: Vec3::splat(1e-7),
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
        };
        let d = plane_distance(hit.point, DVec3::ZERO, DVec3::Y);
        assert!(off_surface(&hit, d));
        hit.error = Vec3::splat(1e-5);
        assert!(!off_surface(&hit, d));
    }
}
