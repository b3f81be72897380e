//! Mean squared error and its root.

use crate::difference::{channel_difference, mean_over_channels};
use crate::{ImageView, Region};

/// The mean squared error over `region`: the mean over its pixels and the three
/// channels of `(x − r)²`, where `x` is the test value and `r` the reference.
///
/// Identical values (the same bits) differ by 0; a NaN or infinity on one side
/// only makes the result NaN or infinite.
///
/// # Panics
/// If the images differ in size, or the region is empty or outside them.
pub fn mse(test: ImageView, reference: ImageView, region: Region) -> f64 {
    mean_over_channels(test, reference, region, |x, r| {
        channel_difference(x, r).powi(2)
    })
}

/// The root mean squared error over `region`: `√mse`, in the images' units.
///
/// # Panics
/// As [`mse`].
pub fn rmse(test: ImageView, reference: ImageView, region: Region) -> f64 {
    mse(test, reference, region).sqrt()
}
