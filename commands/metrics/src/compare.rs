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

/// [`compare`] where the inputs may not fit: the same comparison, or why
/// not (images of other sizes, a view whose pixels do not fill its size, an
/// empty region or one outside the images), for callers whose sizes come
/// from a user (the Python package's arrays).
pub fn try_compare(
    test: ImageView,
    reference: ImageView,
    region: Region,
) -> Result<Comparison, String> {
    for (name, view) in [("test", &test), ("reference", &reference)] {
        let (w, h) = (u64::from(view.width), u64::from(view.height));
        if view.pixels.len() as u64 != w * h {
            return Err(format!(
                "the {name} image is {w}x{h} but holds {} pixels",
                view.pixels.len()
            ));
        }
    }
    if (test.width, test.height) != (reference.width, reference.height) {
        return Err(format!(
            "the images differ in size: {}x{} and {}x{}",
            test.width, test.height, reference.width, reference.height
        ));
    }
    region.check(test.width, test.height)?;
    Ok(compare(test, reference, region))
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

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn try_compare_refuses_what_compare_panics_on() {
        let four = [Vec3::ONE; 4];
        let six = [Vec3::ONE; 6];
        let (a, b) = (ImageView::new(2, 2, &four), ImageView::new(3, 2, &six));
        let whole = Region::full(2, 2);
        let err = try_compare(a, b, whole).unwrap_err();
        assert!(err.contains("differ in size: 2x2 and 3x2"), "{err}");
        let short = ImageView {
            width: 3,
            height: 3,
            pixels: &six,
        };
        assert!(try_compare(short, short, whole)
            .unwrap_err()
            .contains("holds 6 pixels"));
        let outside = Region {
            x0: 0,
            y0: 0,
            x1: 3,
            y1: 2,
        };
        assert!(try_compare(a, a, outside).is_err());
        assert_eq!(try_compare(a, a, whole).unwrap(), compare(a, a, whole));
    }
}
