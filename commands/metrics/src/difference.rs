//! The per-channel difference every metric is built on, and the checks every
//! metric makes on its arguments.

use crate::{ImageView, MetricsError, Region};

/// `x − r` in f64, except that two identical values (the same bits: equal
/// numbers, the same infinity, the same NaN) differ by exactly 0. So identical
/// images always measure 0, while a NaN or infinity on one side only makes the
/// difference NaN or infinite.
pub(crate) fn channel_difference(x: f32, r: f32) -> f64 {
    if x.to_bits() == r.to_bits() {
        0.0
    } else {
        x as f64 - r as f64
    }
}

/// `Ok` when both images have full pixel buffers of the same size.
pub(crate) fn same_size(test: &ImageView, reference: &ImageView) -> Result<(), MetricsError> {
    test.check()?;
    reference.check()?;
    match (test.width, test.height) == (reference.width, reference.height) {
        true => Ok(()),
        false => Err(MetricsError::SizeMismatch {
            test: (test.width, test.height),
            reference: (reference.width, reference.height),
        }),
    }
}

/// `Ok` when the images are the same size and `region` lies inside them.
pub(crate) fn comparable(
    test: &ImageView,
    reference: &ImageView,
    region: Region,
) -> Result<(), MetricsError> {
    same_size(test, reference)?;
    region.inside(test.width, test.height)
}

/// The mean over the region's pixels and the three channels of
/// `term(x, r)`, summed per row in f64 and then over rows.
pub(crate) fn mean_over_channels(
    test: ImageView,
    reference: ImageView,
    region: Region,
    term: impl Fn(f32, f32) -> f64,
) -> Result<f64, MetricsError> {
    comparable(&test, &reference, region)?;
    let mut total = 0.0;
    for y in region.rows() {
        let (t, r) = (
            &test.row(y)[region.columns()],
            &reference.row(y)[region.columns()],
        );
        let row: f64 = t
            .iter()
            .zip(r)
            .map(|(t, r)| term(t.x, r.x) + term(t.y, r.y) + term(t.z, r.z))
            .sum();
        total += row;
    }
    Ok(total / (3 * region.pixel_count()) as f64)
}
