//! Prints the rays of the course's "Set1" camera (eye at (0, 0, 10) looking at the
//! origin, up +y, 45° vertical field of view, focal length 1) on a tiny film: the
//! camera basis, then the unit direction of the ray through every pixel centre.
//! Only the camera stage is involved: no scene, no intersection.
//!
//! `cargo run -p glint-camera --example rays [WIDTH] [HEIGHT]` (default 4x3)

use glam::{UVec2, Vec3};
use glint_camera::Camera;

fn main() {
    let width = arg(1, "WIDTH", 4);
    let height = arg(2, "HEIGHT", 3);
    let camera = Camera::new(
        Vec3::new(0.0, 0.0, 10.0),
        Vec3::ZERO,
        Vec3::Y,
        45.0,
        1.0,
        UVec2::new(width, height),
    )
    .unwrap_or_else(|e| fail(&e.to_string()));

    let (half_w, half_h) = camera.film_half_extent();
    println!("Set1 camera: eye (0, 0, 10), look-at (0, 0, 0), up +y, fov_y 45°, focal length 1");
    println!(
        "film {width}x{height} pixels, half extent {} x {} at the focal distance",
        f5(half_w),
        f5(half_h)
    );
    println!("forward {}", v5(camera.forward()));
    println!("right   {}", v5(camera.right()));
    println!("up      {}", v5(camera.up()));
    println!("every ray starts at {}", v5(camera.position()));
    println!();
    println!(
        "{:>5} {:>5} {:>9} {:>9} {:>9}",
        "x", "y", "dir.x", "dir.y", "dir.z"
    );
    for y in 0..height {
        for x in 0..width {
            // Pixel (x, y) has its centre at raster position (x + 0.5, y + 0.5).
            let ray = camera.generate_ray(x as f32 + 0.5, y as f32 + 0.5);
            let d = ray.direction;
            println!("{x:>5} {y:>5} {:>9} {:>9} {:>9}", f5(d.x), f5(d.y), f5(d.z));
        }
    }
}

/// The `index`-th command-line argument as a number, or `default` if absent.
fn arg(index: usize, name: &str, default: u32) -> u32 {
    match std::env::args().nth(index) {
        None => default,
        Some(a) => a
            .parse()
            .unwrap_or_else(|_| fail(&format!("{name} must be a whole number, got {a:?}"))),
    }
}

fn fail(message: &str) -> ! {
    eprintln!("rays: {message}");
    std::process::exit(2);
}

/// `x` with five decimals; values that round to zero print as `0.00000`, never `-0.00000`.
fn f5(x: f32) -> String {
    let s = format!("{x:.5}");
    match s.strip_prefix('-') {
        Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_string(),
        _ => s,
    }
}

fn v5(v: Vec3) -> String {
    format!("({}, {}, {})", f5(v.x), f5(v.y), f5(v.z))
}
