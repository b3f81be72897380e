//! [`compare`]: every metric of a test image against a reference at once.

use crate::difference::comparable;
use crate::{
    channel_means, flip, max_difference, rel_mse, rmse, ErrorMap, ImageView, MaxDifference,
    MetricsError, Region,
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
/// # Errors
/// If the images differ in size, a view's pixels do not fill it, or the
/// region is empty or outside them.
pub fn compare(
    test: ImageView,
    reference: ImageView,
    region: Region,
) -> Result<Comparison, MetricsError> {
    comparable(&test, &reference, region)?;
    compare_with_flip_map(test, reference, region, &flip(test, reference)?)
}

/// [`compare`] with a FLIP map already computed (`flip(test, reference)`), for a
/// caller that also wants the map itself, e.g. for a heat map.
///
/// # Errors
/// As [`compare`], and if the map's size is not the images'.
pub fn compare_with_flip_map(
    test: ImageView,
    reference: ImageView,
    region: Region,
    flip_map: &ErrorMap,
) -> Result<Comparison, MetricsError> {
    comparable(&test, &reference, region)?;
    if (flip_map.width, flip_map.height) != (test.width, test.height) {
        return Err(MetricsError::SizeMismatch {
            test: (flip_map.width, flip_map.height),
            reference: (test.width, test.height),
        });
    }
    Ok(Comparison {
        means_test: channel_means(test, region)?,
        means_reference: channel_means(reference, region)?,
        rmse: rmse(test, reference, region)?,
        rel_mse: rel_mse(test, reference, region)?,
        flip: flip_map.mean(region)?,
        max_difference: max_difference(test, reference, region)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn compare_refuses_images_that_do_not_fit() {
        let four = [Vec3::ONE; 4];
        let six = [Vec3::ONE; 6];
        let (a, b) = (
            ImageView::new(2, 2, &four).unwrap(),
            ImageView::new(3, 2, &six).unwrap(),
        );
        let whole = Region::full(2, 2);
        let err = compare(a, b, whole).unwrap_err().to_string();
        assert_eq!(err, "the images differ in size: 2x2 and 3x2");
        let short = ImageView {
            width: 3,
            height: 3,
            pixels: &six,
        };
        let err = compare(short, short, whole).unwrap_err().to_string();
        assert_eq!(err, "an image of 3x3 pixels needs 9 values, it has 6");
        let outside = Region {
            x0: 0,
            y0: 0,
            x1: 3,
            y1: 2,
        };
        assert!(matches!(
            compare(a, a, outside),
            Err(MetricsError::Region(_))
        ));
        let map = flip(a, a).unwrap();
        assert!(compare_with_flip_map(b, b, Region::full(3, 2), &map).is_err());
        assert_eq!(compare(a, a, whole).unwrap().rmse, 0.0);
    }
}
