//! Prints the course's checkerboard as text: `#` for the first color, `.` for the
//! second, sampled at the centres of a grid over the uv square.
//!
//! `cargo run -p glint-texture --example checker [CHECKS] [SAMPLES]`

use glam::{Vec2, Vec3};
use glint_texture::{Checkerboard, TexCoord, Texture};

fn main() {
    let mut args = std::env::args().skip(1).map(|a| a.parse::<u32>());
    let checks = args.next().and_then(Result::ok).unwrap_or(4);
    let samples = args.next().and_then(Result::ok).unwrap_or(32);
    let texture = Texture::from(Checkerboard::new(Vec3::ONE, Vec3::ZERO, checks));
    println!("{checks}x{checks} checks, sampled at {samples}x{samples} points (v = 1 at the top, as on a surface)");
    for j in 0..samples {
        let row: String = (0..samples)
            .map(|i| {
                let uv = (Vec2::new(i as f32, (samples - 1 - j) as f32) + 0.5) / samples as f32;
                if texture.evaluate(&TexCoord::point(uv)).x > 0.5 {
                    '#'
                } else {
                    '.'
                }
            })
            .collect();
        println!("{row}");
    }
}
