//! Numerical stress: configurations whose visibility is known analytically,
//! generated at every scale from 1e-4 to 1e6 and moved far from the origin,
//! traced through the geometry stage exactly as the integrator traces them
//! (closest hits, shadow rays from `spawn_ray_to`, reflection rays from
//! `spawn_ray`), counting what must be zero:
//!
//! - **shadow acne**: a lit point whose shadow ray is blocked, where nothing
//!   can block it (a floor alone under a light down to 0.01° above its
//!   horizon; a sphere alone, lit where n·l > 0);
//! - **light leaks**: from inside a closed box (six parallelograms meeting at
//!   their edges, or one `AaBox`), a shadow ray that reaches a light outside,
//!   or a camera ray that escapes, aimed at edges and corners included;
//! - **self-hits**: a reflection ray off a floor or a sphere that hits it again;
//! - **non-finite** hit points, normals or spawned origins.
//!
//! Units: lengths in scene units; angles in degrees where named so.

use glam::Vec3;
use glint_geometry::{
    reflect, spawn_ray, spawn_ray_to, AaBox, Hit, Parallelogram, Ray, RayTarget, ShapeList, Sphere,
};

/// The scales every configuration is built at.
pub const SCALES: [f32; 6] = [1e-4, 1e-2, 1.0, 1e2, 1e4, 1e6];

/// Light elevations above a floor's horizon, in degrees.
pub const GRAZING_DEGREES: [f32; 4] = [0.01, 0.1, 1.0, 30.0];

/// What one configuration counted.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    pub rays: u64,
    pub acne: u64,
    pub leaks: u64,
    pub self_hits: u64,
    pub non_finite: u64,
}

impl Counts {
    /// Whether every count that must be zero is.
    pub fn clean(&self) -> bool {
        self.acne == 0 && self.leaks == 0 && self.self_hits == 0 && self.non_finite == 0
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

/// Every configuration at every scale, each at the origin and moved away from
/// it by up to 1e6 (as far as f32 resolves the configuration: 1000 times its
/// size). `grid` is the number of rays per side aimed at each configuration
/// (a face of a box, a floor, a sphere's disc); with `joints`, the grid's
/// first and last rays are aimed exactly at the edges, where walls meet.
pub fn run(grid: u32, joints: bool) -> Vec<Row> {
    let steps = |n: u32| steps(n, joints);
    let mut rows = Vec::new();
    for scale in SCALES {
        for offset in [0.0, (1e3 * scale).min(1e6)] {
            let at = Vec3::new(offset, -0.7 * offset, 0.4 * offset);
            let mut row = |configuration: String, counts: Counts| {
                rows.push(Row {
                    configuration,
                    scale,
                    offset,
                    counts,
                })
            };
            for degrees in GRAZING_DEGREES {
                let name = format!("floor, light {degrees}° up");
                row(name, floor(at, scale, degrees, &steps(grid)));
            }
            row("sphere".into(), sphere(at, scale, &steps(grid)));
            row(
                "box of 6 walls".into(),
                closed_box(at, scale, &steps(grid), false),
            );
            row("AaBox".into(), closed_box(at, scale, &steps(grid), true));
        }
    }
    rows
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
    hit.point.is_finite() && hit.geometric_normal.is_finite()
}

/// A one-sided floor of 20 × 20 scale units alone under a point light
/// `degrees` above its horizon, seen from above at a grid of points: every
/// point is lit, and a mirror ray off it meets nothing.
fn floor(at: Vec3, scale: f32, degrees: f32, steps: &[f32]) -> Counts {
    let mut list = ShapeList::new();
    let half = 10.0 * scale;
    let wall = Parallelogram::new(
        at + Vec3::new(-half, 0.0, half),
        Vec3::X * 2.0 * half,
        Vec3::NEG_Z * 2.0 * half,
        false,
    )
    .expect("a floor");
    list.push(wall.facing(Vec3::Y));
    list.build_acceleration();
    let elevation = degrees.to_radians();
    let light = at + Vec3::new(elevation.cos(), elevation.sin(), 0.3).normalize() * 100.0 * scale;
    let eye = at + Vec3::new(-3.0, 8.0, 5.0) * scale;
    let mut counts = Counts::default();
    for &u in steps {
        for &v in steps {
            let target = at + Vec3::new(-0.9 + 1.8 * u, 0.0, -0.9 + 1.8 * v) * half;
            lit_and_mirrored(&list, &Ray::new(eye, target - eye), light, &mut counts);
        }
    }
    counts
}

/// Traces `ray` into `list`, where nothing can shadow a point from `light`
/// on the side its normal points to, nor meet its mirror ray: counts a blocked
/// shadow ray as acne, a hit of the mirror ray as a self-hit.
fn lit_and_mirrored(list: &ShapeList, ray: &Ray, light: Vec3, counts: &mut Counts) {
    counts.rays += 1;
    let Some(hit) = list.closest_hit(ray, f32::INFINITY) else {
        return;
    };
    if !finite(&hit) {
        counts.non_finite += 1;
        return;
    }
    if hit.geometric_normal.dot(light - hit.point) > 0.0 {
        let shadow = spawn_ray_to(&hit, &RayTarget::exact(light));
        counts.non_finite += u64::from(!shadow.origin.is_finite());
        counts.acne += u64::from(list.any_hit(&shadow, 1.0));
    }
    let wo = -ray.direction.normalize();
    let mirror = spawn_ray(&hit, reflect(wo, hit.geometric_normal));
    counts.self_hits += u64::from(list.closest_hit(&mirror, f32::INFINITY).is_some());
}

/// A sphere alone, lit from one side: no point with n·l > 0 is shadowed, and no
/// mirror ray off it hits it again.
fn sphere(at: Vec3, scale: f32, steps: &[f32]) -> Counts {
    let mut list = ShapeList::new();
    list.push(Sphere::new(at, scale).expect("a sphere"));
    list.build_acceleration();
    let light = at + Vec3::new(3.0, 4.0, 2.0) * 10.0 * scale;
    let eye = at + Vec3::new(0.5, 1.0, 6.0) * scale;
    let mut counts = Counts::default();
    for &u in steps {
        for &v in steps {
            // Across the disc the sphere covers, out to its silhouette.
            let target = at + Vec3::new(-1.0 + 2.0 * u, -1.0 + 2.0 * v, 0.0) * scale;
            lit_and_mirrored(&list, &Ray::new(eye, target - eye), light, &mut counts);
        }
    }
    counts
}

/// A closed cube of side 2·scale, as six two-sided walls meeting at their
/// edges or as one `AaBox`, seen from inside, with a light outside: every
/// camera ray hits a wall, and every shadow ray traced (from a wall the light
/// is in front of, seen from inside) is blocked by another. Rays are aimed at
/// `steps` × `steps` points over each face.
fn closed_box(at: Vec3, scale: f32, steps: &[f32], as_aabox: bool) -> Counts {
    let mut list = ShapeList::new();
    let (lo, hi) = (at - Vec3::splat(scale), at + Vec3::splat(scale));
    if as_aabox {
        list.push(AaBox::new(lo, hi).expect("a box"));
    } else {
        let s = 2.0 * scale;
        for (origin, e1, e2) in [
            (lo, Vec3::X * s, Vec3::Y * s),
            (lo, Vec3::Y * s, Vec3::Z * s),
            (lo, Vec3::Z * s, Vec3::X * s),
            (hi, Vec3::NEG_X * s, Vec3::NEG_Y * s),
            (hi, Vec3::NEG_Y * s, Vec3::NEG_Z * s),
            (hi, Vec3::NEG_Z * s, Vec3::NEG_X * s),
        ] {
            list.push(Parallelogram::new(origin, e1, e2, true).expect("a wall"));
        }
    }
    list.build_acceleration();
    let light = at + Vec3::new(7.0, 5.0, -6.0) * scale;
    let eye = at + Vec3::new(0.1, -0.2, 0.15) * scale;
    let mut counts = Counts::default();
    for face in 0..6 {
        let (axis, sign) = (face % 3, if face < 3 { -1.0 } else { 1.0 });
        for &u in steps {
            for &v in steps {
                let mut p = [0.0; 3];
                p[axis] = sign;
                p[(axis + 1) % 3] = -1.0 + 2.0 * u;
                p[(axis + 2) % 3] = -1.0 + 2.0 * v;
                let target = at + Vec3::from(p) * scale;
                let ray = Ray::new(eye, target - eye);
                counts.rays += 1;
                let Some(hit) = list.closest_hit(&ray, f32::INFINITY) else {
                    counts.leaks += 1;
                    continue;
                };
                if !finite(&hit) {
                    counts.non_finite += 1;
                    continue;
                }
                // As the integrator does: a light behind the wall as seen from
                // the viewer's side is below the horizon, and gets no shadow ray.
                let facing = if hit.geometric_normal.dot(ray.direction) < 0.0 {
                    hit.geometric_normal
                } else {
                    -hit.geometric_normal
                };
                if facing.dot(light - hit.point) > 0.0 {
                    let shadow = spawn_ray_to(&hit, &RayTarget::exact(light));
                    counts.leaks += u64::from(!list.any_hit(&shadow, 1.0));
                }
            }
        }
    }
    counts
}

/// The table of `rows`, in Markdown.
pub fn table(rows: &[Row]) -> String {
    let mut out = String::from(
        "| configuration | scale | offset | rays | acne | leaks | self-hits | non-finite |\n|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let c = &r.counts;
        out += &format!(
            "| {} | {:e} | {:e} | {} | {} | {} | {} | {} |\n",
            r.configuration, r.scale, r.offset, c.rays, c.acne, c.leaks, c.self_hits, c.non_finite
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Off the joints (no ray aimed exactly where two walls meet), nothing
    /// that must be zero is anything else, at any scale or offset.
    #[test]
    fn off_the_joints_every_count_is_zero() {
        let rows = run(6, false);
        assert!(rows.iter().all(|r| r.counts.clean()), "{}", table(&rows));
        let rays: u64 = rows.iter().map(|r| r.counts.rays).sum();
        // 6 scales × 2 offsets × (4 floors and a sphere of 6², 2 boxes of 6 × 6²).
        assert_eq!(rays, 12 * (5 * 36 + 2 * 6 * 36));
    }

    #[test]
    fn steps_span_the_unit_interval_with_or_without_its_ends() {
        assert_eq!(steps(3, true), [0.0, 0.5, 1.0]);
        assert_eq!(steps(2, false), [0.25, 0.75]);
    }
}
