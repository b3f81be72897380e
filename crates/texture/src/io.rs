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

/// Reads a PNG, JPEG, Radiance HDR or OpenEXR file as linear RGB.
///
/// Integer formats (8- and 16-bit, as PNG and JPEG store them) are taken to be
/// sRGB-encoded and decoded to linear here, once; float formats (HDR, EXR) are
/// already linear. Grayscale is replicated to RGB; alpha is ignored.
pub fn load_image(path: &Path) -> Result<Image, ImageLoadError> {
    let fail = |message: String| ImageLoadError {
        path: path.to_path_buf(),
        message,
    };
    let decoded = image::ImageReader::open(path)
        .map_err(|e| fail(e.to_string()))?
        .with_guessed_format()
        .map_err(|e| fail(e.to_string()))?
        .decode()
        .map_err(|e| fail(e.to_string()))?;
    Ok(from_dynamic(decoded))
}

/// Converts a decoded image to linear RGB (see [`load_image`] for the rules).
pub fn from_dynamic(decoded: image::DynamicImage) -> Image {
    use image::DynamicImage as D;
    let (w, h) = (decoded.width(), decoded.height());
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
    Image::new(w, h, texels)
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
        assert_eq!(from_dynamic(hdr).texel(0, 0), Vec3::new(2.5, 0.5, 0.125));
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
