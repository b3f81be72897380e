//! [`ImageView`]: borrowed linear RGB pixels with their size.

use crate::error::check_length;
use crate::MetricsError;
use glam::Vec3;
use glint_camera::Film;

/// An image to measure: `width × height` linear RGB pixels, row-major from the
/// top-left pixel (the layout of [`Film::pixels`]). Cheap to copy.
#[derive(Clone, Copy, Debug)]
pub struct ImageView<'a> {
    pub width: u32,
    pub height: u32,
    pub pixels: &'a [Vec3],
}

impl<'a> ImageView<'a> {
    /// A view of `pixels` as a `width × height` image, or
    /// [`MetricsError::Length`] unless it holds exactly `width × height`
    /// values.
    pub fn new(width: u32, height: u32, pixels: &'a [Vec3]) -> Result<Self, MetricsError> {
        let view = Self {
            width,
            height,
            pixels,
        };
        view.check()?;
        Ok(view)
    }

    /// The pixel in column `x`, row `y` (from the top).
    pub fn pixel(&self, x: u32, y: u32) -> Vec3 {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) is outside the {}x{} image",
            self.width,
            self.height
        );
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// The pixels of row `y` (from the top).
    pub(crate) fn row(&self, y: u32) -> &'a [Vec3] {
        let w = self.width as usize;
        &self.pixels[y as usize * w..(y as usize + 1) * w]
    }

    /// `Ok` when the pixels fill the view's size (its fields are public, so
    /// every measurement checks).
    pub(crate) fn check(&self) -> Result<(), MetricsError> {
        check_length("an image", self.width, self.height, self.pixels.len())
    }
}

impl<'a> From<&'a Film> for ImageView<'a> {
    fn from(film: &'a Film) -> Self {
        let r = film.resolution();
        // A film always holds one value per pixel.
        Self {
            width: r.x,
            height: r.y,
            pixels: film.pixels(),
        }
    }
}
