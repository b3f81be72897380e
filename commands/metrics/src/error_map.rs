//! [`ErrorMap`]: one error value per pixel, and its statistics over a region.

use crate::error::check_length;
use crate::{MetricsError, Region};

/// One error value per pixel (FLIP, relative squared error, …), row-major from
/// the top-left pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorMap {
    pub width: u32,
    pub height: u32,
    pub values: Vec<f32>,
}

impl ErrorMap {
    /// The value at column `x`, row `y` (from the top).
    pub fn value(&self, x: u32, y: u32) -> f32 {
        assert!(
            x < self.width && y < self.height,
            "({x}, {y}) is outside the {}x{} map",
            self.width,
            self.height
        );
        self.values[y as usize * self.width as usize + x as usize]
    }

    /// `Ok` when the values fill the map's size.
    pub(crate) fn check(&self) -> Result<(), MetricsError> {
        check_length("an error map", self.width, self.height, self.values.len())
    }

    fn region_rows(
        &self,
        region: Region,
    ) -> Result<impl Iterator<Item = &[f32]> + '_, MetricsError> {
        self.check()?;
        region.inside(self.width, self.height)?;
        let w = self.width as usize;
        Ok(region
            .rows()
            .map(move |y| &self.values[y as usize * w..][region.columns()]))
    }

    /// The mean of the values in `region`, in f64 (NaN if any is NaN).
    ///
    /// # Errors
    /// If the region is empty or outside the map.
    pub fn mean(&self, region: Region) -> Result<f64, MetricsError> {
        let total: f64 = self
            .region_rows(region)?
            .map(|row| row.iter().map(|&v| v as f64).sum::<f64>())
            .sum();
        Ok(total / region.pixel_count() as f64)
    }

    /// The largest value in `region` (NaN if any is NaN).
    ///
    /// # Errors
    /// If the region is empty or outside the map.
    pub fn max(&self, region: Region) -> Result<f32, MetricsError> {
        Ok(self
            .region_rows(region)?
            .flatten()
            .fold(f32::NEG_INFINITY, |best, &v| {
                if v.is_nan() || best.is_nan() {
                    f32::NAN
                } else {
                    best.max(v)
                }
            }))
    }
}
