//! Loads a scene file with the scene stage alone and prints what it describes:
//! the camera, render settings, named regions, materials, shapes and lights — or
//! the one-line error a bad file gets.
//!
//! `cargo run -p glint-scene --example inspect -- scenes/cornell-set1.toml`

use glint_geometry::ObjectRef;
use glint_integrator::Surface;
use glint_lighting::Light;
use std::path::PathBuf;

fn main() -> std::process::ExitCode {
    let path: PathBuf = std::env::args_os()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| "scenes/cornell-set1.toml".into());
    let d = match glint_scene::load(&path) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("{e}");
            return std::process::ExitCode::from(2);
        }
    };
    let (s, r) = (&d.scene, &d.settings);
    let c = &s.camera;
    println!("{}", path.display());
    println!(
        "camera   at {} looking along {} (up {}), fov {:.3}°, focal length {}, film {}x{}",
        c.position(),
        c.forward(),
        c.up(),
        c.fov_y().to_degrees(),
        c.focal_length(),
        c.resolution().x,
        c.resolution().y
    );
    // Environment samples only matter when there is an environment, as in the
    // summary line of `glint render`.
    let environment = match s.environment {
        Some(_) => format!(
            ", {} environment samples ({})",
            r.environment_samples,
            r.environment_pattern.name()
        ),
        None => String::new(),
    };
    println!(
        "render   {} spp ({}), {} light samples ({}){environment}, max depth {}, seed {}",
        r.spp,
        r.pixel_pattern.name(),
        r.light_samples,
        r.light_pattern.name(),
        r.max_depth,
        r.seed
    );
    for (name, [x0, y0, x1, y1]) in &d.regions {
        println!("region   \"{name}\": x {x0}..{x1}, y {y0}..{y1} (x1, y1 excluded)");
    }
    println!("ambient  {}", s.ambient);
    for (i, m) in s.materials.iter().enumerate() {
        println!(
            "material #{i} \"{}\": diffuse {:?}, specular {}, shininess {}, {:?} lobe",
            d.material_names[i],
            m.diffuse,
            m.specular
                .as_ref()
                .map_or("= diffuse".into(), |t| format!("{t:?}")),
            m.shininess,
            m.lobe
        );
    }
    for (i, surface) in s.surfaces.iter().enumerate() {
        let what = match surface {
            Surface::Material(m) => format!("\"{}\"", d.material_names[*m as usize]),
            Surface::Emitter(l) => format!("emitter of light #{l}"),
            Surface::Mesh(k) => format!(
                "{} per-triangle materials",
                s.mesh_materials[*k as usize].len()
            ),
        };
        match s.shapes.object(i as u32) {
            ObjectRef::Shape(shape) => println!("shape    {what}: {shape:?}"),
            ObjectRef::Mesh(mesh) => println!(
                "mesh     {what}: {} triangles, {} vertices, {}",
                mesh.triangle_count(),
                mesh.vertex_count(),
                if mesh.has_normals() {
                    "smooth normals"
                } else {
                    "flat"
                }
            ),
        }
    }
    if let Some(stats) = s.shapes.bvh_stats() {
        println!(
            "BVH      {} nodes, {} leaves, depth {}, SAH cost {:.2}",
            stats.nodes, stats.leaves, stats.max_depth, stats.sah_cost
        );
    }
    for (i, light) in s.lights.iter().enumerate() {
        match light {
            Light::Point(p) => println!("light #{i}: point at {}, color {}", p.position, p.color),
            Light::Sphere(s) => println!(
                "light #{i}: sphere centred at {}, radius {}, radiance {}",
                s.surface().center(),
                s.surface().radius(),
                s.color
            ),
            Light::Area(a) => println!(
                "light #{i}: area centred at {}, normal {}, area {}, color {}",
                a.surface().center(),
                a.surface().normal(),
                a.surface().area(),
                a.color
            ),
        }
    }
    std::process::ExitCode::SUCCESS
}
