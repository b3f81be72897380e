//! Builds the MIP-map pyramid of an image and prints each level's size and mean
//! color (every level keeps the mean of level 0), and the level a trilinear lookup
//! reads for a few footprint widths.
//!
//! `cargo run -p glint-texture --example pyramid [IMAGE]` — without an image, the
//! course's checkerboard (8 checks of 32 texels).

use glam::Vec3;
use glint_texture::{load_image, Checkerboard, MipMap};

fn main() -> std::process::ExitCode {
    let image = match std::env::args_os().nth(1) {
        Some(path) => match load_image(path.as_ref()) {
            Ok(image) => image,
            Err(e) => {
                eprintln!("{e}");
                return std::process::ExitCode::from(2);
            }
        },
        None => Checkerboard::new(Vec3::ONE, Vec3::ZERO, 8).to_image(32),
    };
    let pyramid = MipMap::new(image);
    println!("level      size     mean (linear RGB)");
    for (i, level) in pyramid.levels().iter().enumerate() {
        let m = level.mean();
        println!(
            "{i:>5} {:>9} {:.6} {:.6} {:.6}",
            format!("{}x{}", level.width(), level.height()),
            m.x,
            m.y,
            m.z
        );
    }
    println!("\nfootprint width (fraction of the image) -> trilinear level");
    for width in [1.0 / 4096.0, 1.0 / 256.0, 1.0 / 64.0, 1.0 / 8.0, 1.0] {
        println!("{width:>10.6} -> {:.3}", pyramid.level_for_width(width));
    }
    std::process::ExitCode::SUCCESS
}
