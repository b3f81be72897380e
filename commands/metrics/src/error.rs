//! [`MetricsError`]: why images cannot be measured as asked.

/// Why a measurement was refused: its arguments do not fit together. Every
/// function of this crate returns one instead of panicking, so that sizes and
/// regions that come from users (files, arrays, flags) fail as input errors.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MetricsError {
    /// The test image and the reference are not the same size.
    #[error("the images differ in size: {}x{} and {}x{}", .test.0, .test.1, .reference.0, .reference.1)]
    SizeMismatch {
        test: (u32, u32),
        reference: (u32, u32),
    },
    /// A buffer does not hold one value per pixel of its stated size.
    #[error("{what} of {width}x{height} pixels needs {} values, it has {len}", *.width as u64 * *.height as u64)]
    Length {
        what: &'static str,
        width: u32,
        height: u32,
        len: usize,
    },
    /// The region is empty or reaches outside the image ([`Region::check`](crate::Region::check)'s message).
    #[error("{0}")]
    Region(String),
    /// FLIP was asked of images without pixels.
    #[error("FLIP needs non-empty images, got {0}x{1}")]
    Empty(u32, u32),
    /// A heat map's scale is zero, negative or not finite.
    #[error("a heat map needs a positive, finite scale, got {0}")]
    Scale(f32),
}

/// `Ok` when `len` values fill a `width × height` buffer.
pub(crate) fn check_length(
    what: &'static str,
    width: u32,
    height: u32,
    len: usize,
) -> Result<(), MetricsError> {
    match len as u64 == width as u64 * height as u64 {
        true => Ok(()),
        false => Err(MetricsError::Length {
            what,
            width,
            height,
            len,
        }),
    }
}
