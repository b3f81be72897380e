//! Mean squared error and its root.

use crate::difference::{channel_difference, mean_over_channels};
use crate::{ImageView, MetricsError, Region};

/// The mean squared error over `region`: the mean over its pixels and the three
/// channels of `(x − r)²`, where `x` is the test value and `r` the reference.
///
/// Identical values (the same bits) differ by 0; a NaN or infinity on one side
/// only makes the result NaN or infinite.
///
/// # Errors
/// If the images differ in size, or the region is empty or outside them.
pub fn mse(test: ImageView, reference: ImageView, region: Region) -> Result<f64, MetricsError> {
    mean_over_channels(test, reference, region, |x, r| {
        channel_difference(x, r).powi(2)
    })
}

/// The root mean squared error over `region`: `√mse`, in the images' units.
///
/// # Errors
/// As [`mse`].
pub fn rmse(test: ImageView, reference: ImageView, region: Region) -> Result<f64, MetricsError> {
    mse(test, reference, region).map(f64::sqrt)
}
