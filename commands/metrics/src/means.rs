//! [`channel_means`]: the average color of a region.

use crate::{ImageView, MetricsError, Region};
use glam::DVec3;

/// The mean of each channel over `region`, in f64.
///
/// A NaN in the region makes its channel's mean NaN; an infinity makes it
/// infinite (or NaN, if both signs occur): nothing is hidden.
///
/// # Errors
/// If the region is empty or outside the image (see [`Region::check`]).
pub fn channel_means(image: ImageView, region: Region) -> Result<DVec3, MetricsError> {
    image.check()?;
    region.inside(image.width, image.height)?;
    let mut total = DVec3::ZERO;
    for y in region.rows() {
        let row: DVec3 = image.row(y)[region.columns()]
            .iter()
            .map(|p| p.as_dvec3())
            .sum();
        total += row;
    }
    Ok(total / region.pixel_count() as f64)
}

/// How many channel values in `region` are NaN or infinite (0 to 3 per pixel).
///
/// # Errors
/// If the region is empty or outside the image.
pub fn non_finite_count(image: ImageView, region: Region) -> Result<u64, MetricsError> {
    image.check()?;
    region.inside(image.width, image.height)?;
    Ok(region
        .rows()
        .map(|y| {
            image.row(y)[region.columns()]
                .iter()
                .flat_map(|p| p.to_array())
                .filter(|c| !c.is_finite())
                .count() as u64
        })
        .sum())
}
