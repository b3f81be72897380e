//! Makes the FLIP test images in `tests/data/` from the public-domain astronaut
//! photograph in `scenes/textures/` (see `tests/data/README.md`):
//!
//! ```sh
//! cargo run -p glint-metrics --example make_flip_pair
//! ```
//!
//! - `reference.png`: the 64 × 64 crop at (132, 344) (the mission patch), as is.
//! - `test-blur.png`: the crop blurred with a 3 × 3 box filter.
//! - `test-strong.png`: a 5 × 5 box blur, the channels scaled by (1.15, 1.0,
//!   0.85), plus uniform noise of ±0.05 from a fixed hash.
//!
//! The filters work on linear RGB (as `Film::load` decodes the PNG), clamping at
//! the crop's edges; `Film::save` encodes the result as 8-bit sRGB.

use glam::{UVec2, Vec3};
use glint_camera::Film;
use std::path::Path;

const CROP_ORIGIN: (u32, u32) = (132, 344);
const SIZE: u32 = 64;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let photo = Film::load(&root.join("../../scenes/textures/astronaut.png"))?;
    let mut reference = Film::new(UVec2::splat(SIZE));
    for y in 0..SIZE {
        for x in 0..SIZE {
            reference.set_pixel(x, y, photo.pixel(CROP_ORIGIN.0 + x, CROP_ORIGIN.1 + y));
        }
    }
    let blurred = box_blur(&reference, 1);
    let mut strong = box_blur(&reference, 2);
    for y in 0..SIZE {
        for x in 0..SIZE {
            let p = strong.pixel(x, y) * Vec3::new(1.15, 1.0, 0.85);
            let noise =
                Vec3::from_array(std::array::from_fn(|c| 0.05 * hash_noise(x, y, c as u32)));
            strong.set_pixel(x, y, (p + noise).clamp(Vec3::ZERO, Vec3::ONE));
        }
    }
    let data = root.join("tests/data");
    reference.save(&data.join("reference.png"))?;
    blurred.save(&data.join("test-blur.png"))?;
    strong.save(&data.join("test-strong.png"))?;
    println!(
        "wrote reference.png, test-blur.png and test-strong.png in {}",
        data.display()
    );
    Ok(())
}

/// A box blur of radius `r` (a (2r + 1)² window), edges clamped.
fn box_blur(film: &Film, r: i32) -> Film {
    let size = film.resolution();
    let mut out = Film::new(size);
    let clamp = |v: i32, n: u32| v.clamp(0, n as i32 - 1) as u32;
    for y in 0..size.y {
        for x in 0..size.x {
            let mut sum = Vec3::ZERO;
            for dy in -r..=r {
                for dx in -r..=r {
                    sum += film.pixel(clamp(x as i32 + dx, size.x), clamp(y as i32 + dy, size.y));
                }
            }
            out.set_pixel(x, y, sum / ((2 * r + 1) * (2 * r + 1)) as f32);
        }
    }
    out
}

/// A uniform value in [−1, 1) from (x, y, channel): SplitMix64's finaliser.
fn hash_noise(x: u32, y: u32, channel: u32) -> f32 {
    let mut z =
        ((y as u64) << 34 | (x as u64) << 2 | channel as u64).wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    ((z >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
}
