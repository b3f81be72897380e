//! Ray-casts a small hand-made scene (three spheres, a parallelogram, a box and a
//! ground plane) with nothing but the geometry stage, and writes the surface normal
//! of the closest hit as a color (`normal · 0.5 + 0.5`; black where a ray misses)
//! to a binary PPM (P6) image. It also prints a one-line summary of hits and misses.
//!
//! The camera is a few lines of pinhole arithmetic written out by hand, so the
//! example does not depend on the camera crate.
//!
//! `cargo run -p glint-geometry --example normals [OUTPUT.ppm]` (default `normals.ppm`)

use glam::Vec3;
use glint_geometry::{AaBox, Parallelogram, Plane, Ray, ShapeList, Sphere};
use std::io::Write;

const WIDTH: u32 = 320;
const HEIGHT: u32 = 240;

fn main() {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "normals.ppm".into());

    // The scene; `names[i]` describes the shape with index i.
    let mut shapes = ShapeList::new();
    let names = [
        "ground plane",
        "sphere",
        "sphere",
        "sphere",
        "parallelogram",
        "box",
    ];
    shapes.push(Plane::new(Vec3::new(0.0, -1.0, 0.0), Vec3::Y, false).unwrap());
    shapes.push(Sphere::new(Vec3::new(0.0, 0.0, -1.0), 1.0).unwrap());
    shapes.push(Sphere::new(Vec3::new(-2.2, -0.4, 0.2), 0.6).unwrap());
    shapes.push(Sphere::new(Vec3::new(0.9, -0.7, 1.2), 0.3).unwrap());
    // A panel standing behind the spheres, turned a little towards +x; its front
    // side (edge1 × edge2) faces the camera.
    shapes.push(
        Parallelogram::new(
            Vec3::new(-3.5, -1.0, -3.5),
            Vec3::new(3.0, 0.0, 0.8),
            Vec3::new(0.0, 2.5, 0.0),
            false,
        )
        .unwrap(),
    );
    shapes.push(AaBox::new(Vec3::new(1.4, -1.0, -1.6), Vec3::new(2.6, 0.2, -0.4)).unwrap());

    // A pinhole camera: eye, orthonormal basis, 40° vertical field of view.
    let eye = Vec3::new(0.0, 1.2, 6.0);
    let forward = (Vec3::new(0.0, -0.3, -1.0) - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let half_height = (20f32).to_radians().tan();
    let half_width = half_height * WIDTH as f32 / HEIGHT as f32;

    let mut rgb = Vec::with_capacity((3 * WIDTH * HEIGHT) as usize);
    let mut hits_per_shape = vec![0u32; shapes.len()];
    let mut misses = 0;
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            // Pixel centre → [−1, 1]², y flipped so that the image's top is +up.
            let sx = 2.0 * (x as f32 + 0.5) / WIDTH as f32 - 1.0;
            let sy = 1.0 - 2.0 * (y as f32 + 0.5) / HEIGHT as f32;
            let direction = forward + sx * half_width * right + sy * half_height * up;
            let ray = Ray::new(eye, direction.normalize());
            let color = match shapes.closest_hit(&ray, f32::INFINITY) {
                Some(hit) => {
                    hits_per_shape[hit.shape as usize] += 1;
                    hit.shading_normal * 0.5 + 0.5
                }
                None => {
                    misses += 1;
                    Vec3::ZERO
                }
            };
            rgb.extend(
                color
                    .to_array()
                    .map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8),
            );
        }
    }

    if let Err(e) = write_ppm(&path, WIDTH, HEIGHT, &rgb) {
        eprintln!("normals: cannot write {path}: {e}");
        std::process::exit(1);
    }
    let hits: u32 = hits_per_shape.iter().sum();
    let per_shape: Vec<String> = names
        .iter()
        .zip(&hits_per_shape)
        .enumerate()
        .map(|(i, (name, n))| format!("#{i} {name} {n}"))
        .collect();
    println!(
        "wrote {path} ({WIDTH}x{HEIGHT}): {hits} hits, {misses} misses; hits per shape: {}",
        per_shape.join(", ")
    );
}

/// A binary PPM: the header `P6\n<width> <height>\n255\n`, then 8-bit RGB
/// triples row by row from the top-left pixel.
fn write_ppm(path: &str, width: u32, height: u32, rgb: &[u8]) -> std::io::Result<()> {
    let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
    write!(out, "P6\n{width} {height}\n255\n")?;
    out.write_all(rgb)?;
    out.flush()
}
