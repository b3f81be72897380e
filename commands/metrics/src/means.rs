//! [`channel_means`]: the average color of a region.

use crate::{ImageView, Region};
use glam::DVec3;

/// The mean of each channel over `region`, in f64.
///
/// A NaN in the region makes its channel's mean NaN; an infinity makes it
/// infinite (or NaN, if both signs occur): nothing is hidden.
///
/// # Panics
/// If the region is empty or outside the image (see [`Region::check`]).
pub fn channel_means(image: ImageView, region: Region) -> DVec3 {
    image.assert_consistent();
    region.assert_inside(image.width, image.height);
    let mut total = DVec3::ZERO;
    for y in region.rows() {
        let row: DVec3 = image.row(y)[region.columns()]
            .iter()
            .map(|p| p.as_dvec3())
            .sum();
        total += row;
    }
    total / region.pixel_count() as f64
}

/// How many channel values in `region` are NaN or infinite (0 to 3 per pixel).
///
/// # Panics
/// If the region is empty or outside the image.
pub fn non_finite_count(image: ImageView, region: Region) -> u64 {
    image.assert_consistent();
    region.assert_inside(image.width, image.height);
    region
        .rows()
        .map(|y| {
            image.row(y)[region.columns()]
                .iter()
                .flat_map(|p| p.to_array())
                .filter(|c| !c.is_finite())
                .count() as u64
        })
        .sum()
}
