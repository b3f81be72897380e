//! `glint render --stats` and `--stats-json`: what a render did, as a table on
//! standard output and as a JSON document (schema in docs/command-line.md).

use glint_integrator::{LookupKind, RenderStats, Scene, Skips};
use glint_scene::LoadTimings;
use glint_texture::Texture;
use serde_json::{json, Value};
use std::time::Duration;

/// Everything `--stats` reports.
pub(crate) struct StatsReport<'a> {
    pub stats: &'a RenderStats,
    pub scene: &'a Scene,
    pub load: LoadTimings,
    pub write: Duration,
}

impl StatsReport<'_> {
    /// The report as JSON.
    pub(crate) fn to_json(&self) -> Value {
        let s = self.stats;
        let sh = &s.shading;
        let q = &s.queries;
        let textures: serde_json::Map<String, Value> = LookupKind::ALL
            .iter()
            .filter(|&&k| s.textures.total(k) > 0)
            .map(|&k| {
                let levels = s.textures.lookups[k as usize];
                let last = levels.iter().rposition(|&n| n > 0).unwrap_or(0);
                (k.name().to_string(), json!(levels[..=last]))
            })
            .collect();
        let (images, pyramids) = self.pyramids();
        json!({
            "rays": {
                "camera": s.camera_rays,
                "shadow_to_lights": sh.light_shadow_rays,
                "shadow_to_environment": sh.environment_shadow_rays,
                "reflection": sh.reflection_rays,
                "towards_lobe_samples": sh.brdf_rays,
                "environment_lookups": sh.environment_lookups,
            },
            "light_samples": {
                "area": sh.light_samples,
                "point": sh.point_light_samples,
                "shadow_rays": sh.light_shadow_rays,
                "skipped": skips_json(&sh.light_skips),
            },
            "environment_samples": {
                "samples": sh.environment_samples,
                "shadow_rays": sh.environment_shadow_rays,
                "skipped": skips_json(&sh.environment_skips),
            },
            "lobe_samples": {
                "samples": sh.lobe_samples,
                "rays": sh.brdf_rays,
                "skipped": skips_json(&sh.lobe_skips),
            },
            "specular_lobes": sh.specular_lobes,
            "texture_footprints": sh.footprints,
            "nonfinite_samples_dropped": sh.nonfinite_samples,
            "intersection_tests": {
                "sphere": q.sphere_tests,
                "parallelogram": q.parallelogram_tests,
                "plane": q.plane_tests,
                "box": q.box_tests,
                "triangle": q.triangle_tests,
            },
            "bvh": {
                "built": self.scene.shapes.bvh_stats().is_some(),
                "nodes_visited": q.bvh_nodes,
                "leaves_visited": q.bvh_leaves,
            },
            "texture_lookups_by_level": textures,
            "mip_pyramids": { "image_textures": images, "built": pyramids },
            "seconds": {
                "parse": self.load.parse.as_secs_f64(),
                "load_assets": self.load.assets.as_secs_f64(),
                "build_acceleration": self.load.acceleration.as_secs_f64(),
                "render": s.elapsed.as_secs_f64(),
                "write": self.write.as_secs_f64(),
            },
            "peak_memory_bytes": peak_memory_bytes(),
        })
    }

    /// The report as a table.
    pub(crate) fn to_text(&self) -> String {
        let s = self.stats;
        let sh = &s.shading;
        let q = &s.queries;
        let rays = s.rays();
        let per_ray = |n: u64| n as f64 / rays.max(1) as f64;
        let mut lines = vec![
            "render statistics".to_string(),
            format!(
                "  rays            {} camera, {} shadow to lights, {} shadow to the environment, {} reflection, {} towards lobe samples",
                s.camera_rays, sh.light_shadow_rays, sh.environment_shadow_rays, sh.reflection_rays, sh.brdf_rays
            ),
            format!(
                "                  {} environment lookups by rays leaving the scene",
                sh.environment_lookups
            ),
            format!(
                "  light samples   {} ({} on area and sphere lights, {} on point lights): {} shadow rays, and none for {}",
                sh.light_samples + sh.point_light_samples,
                sh.light_samples,
                sh.point_light_samples,
                sh.light_shadow_rays,
                skips_text(&sh.light_skips, true)
            ),
            format!(
                "  environment     {} samples: {} shadow rays, and none for {}",
                sh.environment_samples,
                sh.environment_shadow_rays,
                skips_text(&sh.environment_skips, false)
            ),
            format!(
                "  lobe samples    {}: {} rays, and none for {}",
                sh.lobe_samples,
                sh.brdf_rays,
                skips_text(&sh.lobe_skips, false)
            ),
            format!(
                "  shading         {} specular lobes, {} texture footprints, {} NaN/Inf samples dropped",
                sh.specular_lobes, sh.footprints, sh.nonfinite_samples
            ),
            format!(
                "  tests           {} sphere, {} parallelogram, {} plane, {} box, {} triangle ({:.2} per ray)",
                q.sphere_tests,
                q.parallelogram_tests,
                q.plane_tests,
                q.box_tests,
                q.triangle_tests,
                per_ray(q.shape_tests())
            ),
        ];
        lines.push(match self.scene.shapes.bvh_stats() {
            Some(_) => format!(
                "  BVH             {} nodes, {} leaves visited ({:.2} and {:.2} per ray)",
                q.bvh_nodes,
                q.bvh_leaves,
                per_ray(q.bvh_nodes),
                per_ray(q.bvh_leaves)
            ),
            None => "  BVH             none (the linear loop: a handful of shapes)".to_string(),
        });
        let mut textures = Vec::new();
        for kind in LookupKind::ALL {
            let levels = s.textures.lookups[kind as usize];
            if levels.iter().all(|&n| n == 0) {
                continue;
            }
            let last = levels.iter().rposition(|&n| n > 0).unwrap_or(0);
            let by_level: Vec<String> = levels[..=last]
                .iter()
                .enumerate()
                .map(|(l, n)| format!("L{l} {n}"))
                .collect();
            textures.push(format!("{} ({})", kind.name(), by_level.join(", ")));
        }
        let (images, pyramids) = self.pyramids();
        lines.push(format!(
            "  textures        {}; MIP pyramids built for {pyramids} of {images} image textures",
            if textures.is_empty() {
                "no lookups".to_string()
            } else {
                textures.join("; ")
            }
        ));
        lines.push(format!(
            "  time            parse {}, load assets {}, build acceleration {}, render {}, write {}",
            seconds(self.load.parse),
            seconds(self.load.assets),
            seconds(self.load.acceleration),
            seconds(s.elapsed),
            seconds(self.write)
        ));
        lines.push(match peak_memory_bytes() {
            Some(bytes) => format!("  peak memory     {:.1} MiB", bytes as f64 / 1048576.0),
            None => "  peak memory     unknown on this system".to_string(),
        });
        lines.join("\n")
    }

    /// Image textures the materials use (each image once), and how many of them
    /// built a pyramid.
    fn pyramids(&self) -> (usize, usize) {
        let images: std::collections::BTreeMap<_, bool> = self
            .scene
            .materials
            .iter()
            .flat_map(|m| std::iter::once(&m.diffuse).chain(m.specular.as_ref()))
            .filter_map(|t| match t {
                Texture::Image(i) => {
                    Some((std::sync::Arc::as_ptr(&i.image), i.image.has_pyramid()))
                }
                _ => None,
            })
            .collect();
        (
            images.len(),
            images.values().filter(|&&built| built).count(),
        )
    }
}

/// The skips of one kind of sample as JSON.
fn skips_json(s: &Skips) -> Value {
    json!({
        "below_surface": s.below_surface,
        "behind_light": s.behind_light,
        "zero_brdf": s.zero_brdf,
        "zero_density": s.zero_density,
    })
}

/// The skips of one kind of sample, each with why; `behind_light` only for
/// lights (nothing else has a back).
fn skips_text(s: &Skips, lights: bool) -> String {
    let mut parts = vec![format!("{} (below the surface)", s.below_surface)];
    if lights {
        parts.push(format!("{} (surface behind the light)", s.behind_light));
    }
    parts.push(format!("{} (zero BRDF)", s.zero_brdf));
    parts.push(format!("{} (zero density)", s.zero_density));
    parts.join(", ")
}

fn seconds(d: Duration) -> String {
    format!("{:.3} s", d.as_secs_f64())
}

/// The process's peak resident memory (Linux: `VmHWM` of /proc/self/status).
pub(crate) fn peak_memory_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}
