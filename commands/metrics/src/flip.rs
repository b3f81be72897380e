//! LDR-FLIP (Andersson et al. 2020), through NVIDIA's own implementation.

use crate::difference::same_size;
use crate::{ErrorMap, ImageView, MetricsError};
use glint_camera::linear_to_srgb8;

/// The observer's pixels per degree of visual angle FLIP is evaluated at: the
/// official FLIP tool's default viewing conditions, a 0.7 m wide screen 3840
/// pixels across seen from 0.7 m, `0.7 · (3840 / 0.7) · π / 180` ≈ 67.0206.
///
/// (The `nv-flip` crate's `DEFAULT_PIXELS_PER_DEGREE` rounds this to 67.0, which
/// moves mean FLIP by a few 1e-5; with the exact value the means agree with the
/// official tool to about 1e-6.)
pub const FLIP_PIXELS_PER_DEGREE: f32 = 0.7 * (3840.0 / 0.7) * (std::f32::consts::PI / 180.0);

/// The image as FLIP's input: 8-bit sRGB, exactly as Glint's PNG writer encodes
/// it (clamped to [0, 1]; NaN becomes 0, +∞ becomes 1).
fn to_flip_image(image: &ImageView) -> nv_flip::FlipImageRgb8 {
    let bytes: Vec<u8> = image
        .pixels
        .iter()
        .flat_map(|p| p.to_array().map(linear_to_srgb8))
        .collect();
    nv_flip::FlipImageRgb8::with_data(image.width, image.height, &bytes)
}

/// The LDR-FLIP error of every pixel, in [0, 1] (0: no perceived difference).
///
/// FLIP (Andersson et al. 2020, "FLIP: A Difference Evaluator for Alternating
/// Images", HPG) models what a viewer flipping between the two images notices:
/// color differences after contrast-sensitivity filtering in a perceptual color
/// space, and edge and point features. This is the LDR version, computed by
/// NVIDIA's C++ implementation (the `nv-flip` crate) on both images encoded as
/// 8-bit sRGB, as a PNG of them would show them, at
/// [`FLIP_PIXELS_PER_DEGREE`]. `reference` is the image the test is judged
/// against; FLIP is not symmetric.
///
/// Its [`ErrorMap::mean`] over the whole image is the "Mean" the official FLIP
/// tool prints for the two images saved as PNG.
///
/// # Errors
/// If the images differ in size, or either is empty.
pub fn flip(test: ImageView, reference: ImageView) -> Result<ErrorMap, MetricsError> {
    same_size(&test, &reference)?;
    if test.width == 0 || test.height == 0 {
        return Err(MetricsError::Empty(test.width, test.height));
    }
    let map = nv_flip::flip(
        to_flip_image(&reference),
        to_flip_image(&test),
        FLIP_PIXELS_PER_DEGREE,
    );
    Ok(ErrorMap {
        width: test.width,
        height: test.height,
        values: map.to_vec(),
    })
}
