//! [`ImageView`]: borrowed linear RGB pixels with their size.

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
    /// A view of `pixels` as a `width × height` image.
    ///
    /// # Panics
    /// If `pixels` does not hold exactly `width × height` values.
    pub fn new(width: u32, height: u32, pixels: &'a [Vec3]) -> Self {
        let view = Self {
            width,
            height,
            pixels,
        };
        view.assert_consistent();
        view
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

    pub(crate) fn assert_consistent(&self) {
        assert_eq!(
            self.pixels.len() as u64,
            self.width as u64 * self.height as u64,
            "an ImageView of {}x{} pixels needs {} values, it has {}",
            self.width,
            self.height,
            self.width as u64 * self.height as u64,
            self.pixels.len()
        );
    }
}

impl<'a> From<&'a Film> for ImageView<'a> {
    fn from(film: &'a Film) -> Self {
        let r = film.resolution();
        Self::new(r.x, r.y, film.pixels())
    }
}
