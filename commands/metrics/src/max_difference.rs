//! [`max_difference`]: the largest single difference, and where it is.

use crate::difference::{channel_difference, comparable};
use crate::{ImageView, MetricsError, Region};

/// The largest absolute difference of one channel of one pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaxDifference {
    /// `|x − r|`; 0 when the images are identical in the region. NaN when a
    /// channel is NaN in one image only, infinite when an infinity is.
    pub value: f32,
    /// The pixel's column.
    pub x: u32,
    /// The pixel's row, from the top.
    pub y: u32,
    /// 0, 1 or 2 for red, green, blue.
    pub channel: usize,
}

impl MaxDifference {
    /// `"R"`, `"G"` or `"B"`.
    pub fn channel_name(&self) -> &'static str {
        ["R", "G", "B"][self.channel]
    }
}

/// Whether difference `d` should replace the largest so far: NaN beats every
/// number (it is the difference most worth seeing), then the larger wins; ties
/// keep the first found.
fn beats(d: f64, best: f64) -> bool {
    match (d.is_nan(), best.is_nan()) {
        (true, false) => true,
        (_, true) => false,
        (false, false) => d > best,
    }
}

/// The largest `|x − r|` over the region's pixels and channels, with its pixel and
/// channel. A NaN difference (NaN in one image only) counts as the largest, so
/// the first one is reported; among equal differences the first in reading order
/// (rows from the top, then columns, then R, G, B) wins. Identical images give
/// value 0 at the region's first pixel, channel 0.
///
/// # Errors
/// If the images differ in size, or the region is empty or outside them.
pub fn max_difference(
    test: ImageView,
    reference: ImageView,
    region: Region,
) -> Result<MaxDifference, MetricsError> {
    comparable(&test, &reference, region)?;
    let mut best = (0.0f64, region.x0, region.y0, 0usize);
    for y in region.rows() {
        let (t, r) = (test.row(y), reference.row(y));
        for x in region.columns() {
            let (t, r) = (t[x].to_array(), r[x].to_array());
            for channel in 0..3 {
                let d = channel_difference(t[channel], r[channel]).abs();
                if beats(d, best.0) {
                    best = (d, x as u32, y, channel);
                }
            }
        }
    }
    Ok(MaxDifference {
        value: best.0 as f32,
        x: best.1,
        y: best.2,
        channel: best.3,
    })
}
