//! Reading images from disk into linear RGB.

use crate::Image;
use glam::Vec3;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Why an image file could not be read.
#[derive(Debug, thiserror::Error)]
#[error("{}: cannot read the image: {message}", path.display())]
pub struct ImageLoadError {
    pub path: PathBuf,
    pub message: String,
}

/// The largest image side accepted, in texels.
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// The most texels an image may have (a 4096 × 4096 image): 192 MiB as linear
/// f32 RGB, and its MIP pyramid builds from a copy of it.
pub const MAX_IMAGE_TEXELS: u64 = 1 << 24;

/// Reads a PNG, JPEG, Radiance HDR or OpenEXR file as linear RGB.
///
/// Integer formats (8- and 16-bit, as PNG and JPEG store them) are taken to be
/// sRGB-encoded and decoded to linear here, once; float formats (HDR, EXR) are
/// already linear. Grayscale is replicated to RGB; alpha is ignored. Images larger
/// than [`MAX_IMAGE_SIDE`] or [`MAX_IMAGE_TEXELS`] are refused before decoding.
pub fn load_image(path: &Path) -> Result<Image, ImageLoadError> {
    let fail = |message: String| ImageLoadError {
        path: path.to_path_buf(),
        message,
    };
    if std::fs::metadata(path).is_ok_and(|m| !m.is_file()) {
        return Err(fail(
            "not a regular file (a folder, FIFO or device); an image must be a file".into(),
        ));
    }
    let mut reader = image::ImageReader::open(path)
        .map_err(|e| fail(e.to_string()))?
        .with_guessed_format()
        .map_err(|e| fail(e.to_string()))?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_IMAGE_SIDE);
    limits.max_image_height = Some(MAX_IMAGE_SIDE);
    reader.limits(limits);
    let header = reader.into_decoder().map_err(|e| fail(e.to_string()))?;
    let (w, h) = image::ImageDecoder::dimensions(&header);
    check_size(w, h).map_err(fail)?;
    let file_len = std::fs::metadata(path)
        .map_err(|e| fail(e.to_string()))?
        .len();
    // No codec expands a file more than about 1032 times (deflate): a header
    // claiming more texels than its file could hold is refused before decoding.
    let decoded = image::ImageDecoder::total_bytes(&header);
    if decoded > 2048 * file_len.max(1) {
        return Err(fail(format!(
            "the header says {w}x{h} texels ({decoded} bytes decoded), more than a file of {file_len} bytes can hold"
        )));
    }
    let decoded = image::ImageReader::open(path)
        .and_then(|r| r.with_guessed_format())
        .map_err(|e| fail(e.to_string()))?
        .decode()
        .map_err(|e| fail(e.to_string()))?;
    from_dynamic(decoded).map_err(fail)
}

fn check_size(w: u32, h: u32) -> Result<(), String> {
    if w == 0 || h == 0 {
        return Err(format!("the image is {w}x{h}: it has no texels"));
    }
    if w > MAX_IMAGE_SIDE || h > MAX_IMAGE_SIDE || w as u64 * h as u64 > MAX_IMAGE_TEXELS {
        return Err(format!(
            "the image is {w}x{h}, larger than the limit of {MAX_IMAGE_TEXELS} texels (4096 x 4096), each side at most {MAX_IMAGE_SIDE}"
        ));
    }
    Ok(())
}

/// Converts a decoded image to linear RGB (see [`load_image`] for the rules).
/// Non-finite texels (NaN, ∞ in float files) become 0 and negative ones 0, so
/// that one bad texel cannot spread through every MIP level.
pub fn from_dynamic(decoded: image::DynamicImage) -> Result<Image, String> {
    use image::DynamicImage as D;
    let (w, h) = (decoded.width(), decoded.height());
    check_size(w, h)?;
    let texels: Vec<Vec3> = match decoded {
        D::ImageRgb32F(_) | D::ImageRgba32F(_) => {
            let rgb = decoded.into_rgb32f();
            rgb.pixels().map(|p| Vec3::from_array(p.0)).collect()
        }
        D::ImageLuma8(_) | D::ImageLumaA8(_) | D::ImageRgb8(_) | D::ImageRgba8(_) => {
            let lut = srgb8_to_linear_table();
            let rgb = decoded.into_rgb8();
            rgb.pixels()
                .map(|p| Vec3::from_array(p.0.map(|c| lut[c as usize])))
                .collect()
        }
        _ => {
            let rgb = decoded.into_rgb16();
            rgb.pixels()
                .map(|p| Vec3::from_array(p.0.map(|c| srgb_to_linear(c as f32 / 65535.0))))
                .collect()
        }
    };
    let sanitize = |c: f32| if c.is_finite() { c.max(0.0) } else { 0.0 };
    let texels = texels
        .into_iter()
        .map(|t| Vec3::from_array(t.to_array().map(sanitize)))
        .collect();
    Ok(Image::new(w, h, texels))
}

/// The sRGB electro-optical transfer function (IEC 61966-2-1): encoded → linear.
pub fn srgb_to_linear(encoded: f32) -> f32 {
    if encoded <= 0.040_45 {
        encoded / 12.92
    } else {
        ((encoded + 0.055) / 1.055).powf(2.4)
    }
}

fn srgb8_to_linear_table() -> &'static [f32; 256] {
    static TABLE: OnceLock<[f32; 256]> = OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_png_pixels_decode_to_linear() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("known.png");
        let mut img = image::RgbImage::new(2, 1);
        img.put_pixel(0, 0, image::Rgb([128, 0, 255]));
        img.put_pixel(1, 0, image::Rgb([10, 188, 64]));
        img.save(&path).unwrap();
        let linear = load_image(&path).unwrap();
        let p = linear.texel(0, 0);
        // sRGB 128 is linear 0.21586 (IEC 61966-2-1).
        assert!((p.x - 0.215_861).abs() < 1e-6, "{p}");
        assert_eq!((p.y, p.z), (0.0, 1.0));
        let q = linear.texel(1, 0);
        assert!(
            (q.x - 0.003_035).abs() < 1e-6 && (q.y - 0.502_886).abs() < 1e-5,
            "{q}"
        );
    }

    #[test]
    fn grayscale_replicates_and_float_stays_linear() {
        let dir = tempfile::tempdir().unwrap();
        let gray = dir.path().join("gray.png");
        image::GrayImage::from_pixel(1, 1, image::Luma([128]))
            .save(&gray)
            .unwrap();
        let g = load_image(&gray).unwrap().texel(0, 0);
        assert!(g.x == g.y && g.y == g.z && (g.x - 0.215_861).abs() < 1e-6);
        let hdr = image::DynamicImage::ImageRgb32F(image::Rgb32FImage::from_pixel(
            1,
            1,
            image::Rgb([2.5, 0.5, 0.125]),
        ));
        assert_eq!(
            from_dynamic(hdr).unwrap().texel(0, 0),
            Vec3::new(2.5, 0.5, 0.125)
        );
    }

    #[test]
    fn bad_float_texels_are_made_zero_and_empty_images_refused() {
        let hdr = image::DynamicImage::ImageRgb32F(
            image::Rgb32FImage::from_raw(
                3,
                1,
                vec![f32::NAN, 1.0, f32::INFINITY, -2.0, 0.5, 0.25, 1.0, 1.0, 1.0],
            )
            .unwrap(),
        );
        let img = from_dynamic(hdr).unwrap();
        assert_eq!(img.texel(0, 0), Vec3::new(0.0, 1.0, 0.0));
        assert_eq!(img.texel(1, 0), Vec3::new(0.0, 0.5, 0.25));
        let empty = image::DynamicImage::ImageRgb32F(image::Rgb32FImage::new(0, 5));
        assert!(from_dynamic(empty).unwrap_err().contains("no texels"));
    }

    #[test]
    fn oversized_images_are_refused_before_decoding() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("huge.png");
        // A 5000 x 4000 grayscale PNG compresses to a few kilobytes.
        image::GrayImage::new(5000, 4000).save(&path).unwrap();
        let e = load_image(&path).unwrap_err().to_string();
        assert!(e.contains("5000x4000, larger than the limit"), "{e}");
    }

    #[test]
    fn missing_and_corrupt_files_are_errors_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("missing.png");
        let e = load_image(&missing).unwrap_err();
        assert!(
            e.to_string().contains("missing.png: cannot read the image"),
            "{e}"
        );
        let corrupt = dir.path().join("corrupt.png");
        std::fs::write(&corrupt, b"\\x89PNG not really").unwrap();
        assert!(load_image(&corrupt).is_err());
    }
}
