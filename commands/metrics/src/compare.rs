//! [`compare`]: every metric of a test image against a reference at once.

use crate::{
    channel_means, flip, max_difference, rel_mse, rmse, ErrorMap, ImageView, MaxDifference, Region,
};
use glam::DVec3;

/// Every metric of one comparison, over one region.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Comparison {
    /// [`channel_means`] of the test image.
    pub means_test: DVec3,
    /// [`channel_means`] of the reference.
    pub means_reference: DVec3,
    /// [`rmse`].
    pub rmse: f64,
    /// [`rel_mse`].
    pub rel_mse: f64,
    /// The mean of the [`flip`] map over the region.
    pub flip: f64,
    /// [`max_difference`].
    pub max_difference: MaxDifference,
}

/// Measures `test` against `reference` over `region` with every metric. The FLIP
/// map is computed on the whole images (its filters see past the region's edge)
/// and averaged over the region.
///
/// # Panics
/// If the images differ in size, or the region is empty or outside them.
pub fn compare(test: ImageView, reference: ImageView, region: Region) -> Comparison {
    compare_with_flip_map(test, reference, region, &flip(test, reference))
}

/// [`compare`] with a FLIP map already computed (`flip(test, reference)`), for a
/// caller that also wants the map itself, e.g. for a heat map.
///
/// # Panics
/// As [`compare`], and if the map's size is not the images'.
pub fn compare_with_flip_map(
    test: ImageView,
    reference: ImageView,
    region: Region,
    flip_map: &ErrorMap,
) -> Comparison {
    crate::difference::assert_comparable(&test, &reference, region);
    assert!(
        flip_map.width == test.width && flip_map.height == test.height,
        "the FLIP map is {}x{}, the images {}x{}",
        flip_map.width,
        flip_map.height,
        test.width,
        test.height
    );
    Comparison {
        means_test: channel_means(test, region),
        means_reference: channel_means(reference, region),
        rmse: rmse(test, reference, region),
        rel_mse: rel_mse(test, reference, region),
        flip: flip_map.mean(region),
        max_difference: max_difference(test, reference, region),
    }
}
