//! Prints a table of the Phong and Blinn–Phong specular lobes: for a light 45°
//! from the normal, the lobe value as the viewer sweeps across the plane of incidence.
//!
//! `cargo run -p glint-lighting --example phong_lobe [SHININESS]`

use glam::Vec3;
use glint_lighting::{PhongMaterial, SpecularLobe};

fn main() {
    let shininess: f32 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(16.0);
    let n = Vec3::Y;
    let l = Vec3::new(-1.0, 1.0, 0.0).normalize();
    let phong = PhongMaterial::new(Vec3::ONE, shininess);
    let blinn = PhongMaterial {
        lobe: SpecularLobe::BlinnPhong,
        ..phong.clone()
    };
    println!("light 45° from the normal, shininess {shininess}; the mirror direction is at +45°");
    println!(
        "{:>8} {:>10} {:>12}  diffuse n·l = {:.4}",
        "view °",
        "Phong",
        "Blinn-Phong",
        n.dot(l)
    );
    for deg in (-80..=80).step_by(10) {
        let a = (deg as f32).to_radians();
        let v = Vec3::new(a.sin(), a.cos(), 0.0);
        let p = phong.specular_lobe(n, l, v, n.dot(l));
        let b = blinn.specular_lobe(n, l, v, n.dot(l));
        let bar = "#".repeat((p * 40.0).round() as usize);
        println!("{deg:>8} {p:>10.5} {b:>12.5}  {bar}");
    }
}
