//! Relative mean squared error: squared error divided by the reference's
//! squared value, so that dark and bright parts of an image weigh alike, as
//! pbrt-v4's `imgtool diff --metric MRSE` computes it (`Image::MRSE`).

use crate::difference::{channel_difference, mean_over_channels, same_size};
use crate::{ErrorMap, ImageView, MetricsError, Region};

/// The constant added to `r` in the denominator `(r + 0.01)²`, so that black
/// reference pixels do not divide by zero.
pub const REL_MSE_EPSILON: f64 = 0.01;

/// One channel's relative squared error `(x − r)² / (r + 0.01)²`; exactly 0 for
/// identical values, even a NaN reference (whose denominator is NaN).
fn term(x: f32, r: f32) -> f64 {
    let d = channel_difference(x, r);
    if d == 0.0 {
        return 0.0;
    }
    let r64 = r as f64;
    d * d / ((r64 + REL_MSE_EPSILON) * (r64 + REL_MSE_EPSILON))
}

/// The relative mean squared error over `region`: the mean over its pixels and
/// the three channels of `(x − r)² / (r + 0.01)²`, `x` the test value and `r`
/// the reference: pbrt-v4's MRSE (which, unlike this, skips infinite terms),
/// averaged over the channels.
///
/// Identical values (the same bits) contribute 0; a NaN or infinity that the
/// other image does not share makes the result NaN or infinite.
///
/// # Errors
/// If the images differ in size, or the region is empty or outside them.
pub fn rel_mse(test: ImageView, reference: ImageView, region: Region) -> Result<f64, MetricsError> {
    mean_over_channels(test, reference, region, term)
}

/// The relative squared error of every pixel: the mean over its three channels
/// of `(x − r)² / (r + 0.01)²`. Its [`ErrorMap::mean`] over a region is
/// [`rel_mse`] over that region (up to rounding, as the map holds f32).
///
/// # Errors
/// If the images differ in size.
pub fn rel_mse_map(test: ImageView, reference: ImageView) -> Result<ErrorMap, MetricsError> {
    same_size(&test, &reference)?;
    let values = test
        .pixels
        .iter()
        .zip(reference.pixels)
        .map(|(t, r)| ((term(t.x, r.x) + term(t.y, r.y) + term(t.z, r.z)) / 3.0) as f32)
        .collect();
    Ok(ErrorMap {
        width: test.width,
        height: test.height,
        values,
    })
}
