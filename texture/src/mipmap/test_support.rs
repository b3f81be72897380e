//! Test images and checks shared by the MIP-map tests.

use glam::{Vec2, Vec3};

use crate::{Checkerboard, Image, WrapMode};

pub(super) const WRAPS: [WrapMode; 3] = [WrapMode::Repeat, WrapMode::Clamp, WrapMode::Mirror];

/// Deterministic, non-trivial contents: one of four colors by a hash of (x, y),
/// scaled by a ramp along x.
pub(super) fn palette_image(w: u32, h: u32) -> Image {
    const PALETTE: [Vec3; 4] = [
        Vec3::new(0.9, 0.1, 0.1),
        Vec3::new(0.1, 0.8, 0.2),
        Vec3::new(0.2, 0.3, 0.9),
        Vec3::new(0.95, 0.9, 0.3),
    ];
    Image::from_fn(w, h, |x, y| {
        let ramp = 0.5 + 0.5 * (x + 1) as f32 / w as f32;
        PALETTE[((3 * x + 5 * y + x * y) % 4) as usize] * ramp
    })
}

/// The course's checkerboard (`checks` checks of black and white) sampled at
/// texel centres.
pub(super) fn checker_image(side: u32, checks: u32) -> Image {
    let c = Checkerboard::new(Vec3::ZERO, Vec3::ONE, checks);
    Image::from_fn(side, side, |x, y| {
        c.evaluate((Vec2::new(x as f32, y as f32) + 0.5) / side as f32)
    })
}

pub(super) fn assert_close(got: Vec3, want: Vec3, rel: f32, what: &str) {
    let tol = rel * want.abs().max_element().max(1e-3);
    assert!(
        (got - want).abs().max_element() <= tol,
        "{what}: got {got}, want {want}"
    );
}
