//! `Film::read` on files other programs wrote (`tests/data/formats`, made by
//! `measure/corpus/formats.py` from one 40 × 24 render, `render.pfm`): Pillow,
//! OpenCV, OpenEXR's bindings, stb_image_write and hand-made files, in every
//! format a student's ray tracer writes. Each is read as what it is, whatever
//! its name, with the values its writer stored and what it did to them.

use glam::Vec3;
use glint_camera::{
    linear_to_srgb8, srgb_to_linear, AlphaChannel, FileFormat, Film, ImageFile, SampleEncoding,
};
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/formats")
        .join(name)
}

fn read(name: &str) -> ImageFile {
    Film::read(&data(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The render the files were made from, linear and unclamped.
fn source() -> Film {
    Film::load(&data("render.pfm")).unwrap()
}

/// The source's 8-bit sRGB codes decoded: what every lossless 8-bit file holds.
fn eight_bit() -> Vec<Vec3> {
    source()
        .pixels()
        .iter()
        .map(|p| {
            Vec3::from_array(
                p.to_array()
                    .map(|c| srgb_to_linear(linear_to_srgb8(c) as f32 / 255.0)),
            )
        })
        .collect()
}

fn srgb(levels: u32, stored: u32) -> SampleEncoding {
    SampleEncoding::Srgb {
        levels: [levels; 3],
        stored,
    }
}

/// The largest difference between two sets of pixels.
fn largest_difference(a: &[Vec3], b: &[Vec3]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(a, b)| (*a - *b).abs().max_element())
        .fold(0.0, f32::max)
}

#[test]
fn lossless_eight_bit_files_hold_the_renders_codes_exactly() {
    let expected = eight_bit();
    for (name, description) in [
        ("render-png.png", "PNG, 8-bit RGB"),
        ("render-png-stb.png", "PNG, 8-bit RGB"),
        ("render-png-chunks.png", "PNG, 8-bit RGB"),
        ("render-png-rgba.png", "PNG, 8-bit RGB, opaque alpha"),
        ("render-ppm-p6.ppm", "PPM (P6), maxval 255"),
        ("render-ppm-p3.ppm", "PPM (P3), maxval 255"),
        ("render-bmp.bmp", "BMP, 24-bit RGB"),
        ("render-bmp-stb.bmp", "BMP, 24-bit RGB"),
        ("render-tga.tga", "TGA, 24-bit RGB"),
        ("render-tga-rle.tga", "TGA, 24-bit RGB, RLE"),
        ("render-tga-stb.tga", "TGA, 24-bit RGB, RLE"),
    ] {
        let file = read(name);
        assert_eq!(file.description(), description, "{name}");
        assert_eq!(file.encoding, srgb(255, 255), "{name}");
        assert_eq!(file.film.pixels(), &expected[..], "{name}");
        assert!(!file.gray && !file.indexed, "{name}");
    }
}

#[test]
fn eight_bit_data_in_wider_files_is_graded_by_its_own_step() {
    let expected = eight_bit();
    for (name, description, stored) in [
        (
            "render-png16-of-8bit.png",
            "PNG, 16-bit RGB, values on 8-bit steps",
            65535,
        ),
        (
            "render-ppm-65535-of-8bit.ppm",
            "PPM (P6), maxval 65535, values on 8-bit steps",
            65535,
        ),
    ] {
        let file = read(name);
        assert_eq!(file.description(), description);
        assert_eq!(file.encoding, srgb(255, stored), "{name}");
        assert!(
            largest_difference(file.film.pixels(), &expected) < 1e-6,
            "{name}"
        );
    }
    // A 16-bit (5-5-5) TGA: 32 levels a channel, within one of their steps.
    let tga = read("render-tga16.tga");
    assert_eq!(tga.description(), "TGA, 16-bit RGB, values on 32 levels");
    assert_eq!(tga.encoding, srgb(31, 255));
    let clamped: Vec<Vec3> = source().pixels().iter().map(|p| p.min(Vec3::ONE)).collect();
    let encoded = |v: &[Vec3]| -> Vec<Vec3> {
        v.iter()
            .map(|p| Vec3::from_array(p.to_array().map(|c| linear_to_srgb8(c) as f32 / 255.0)))
            .collect()
    };
    let step = largest_difference(&encoded(tga.film.pixels()), &encoded(&clamped));
    assert!(step <= 1.0 / 31.0, "{step}");
}

#[test]
fn deeper_files_keep_their_depth() {
    let clamped: Vec<Vec3> = source().pixels().iter().map(|p| p.min(Vec3::ONE)).collect();
    let png16 = read("render-png16.png");
    assert_eq!(png16.description(), "PNG, 16-bit RGB");
    assert_eq!(png16.encoding, srgb(65535, 65535));
    assert!(largest_difference(png16.film.pixels(), &clamped) < 1e-4);
    let ppm = read("render-ppm-1023.ppm");
    assert_eq!(ppm.description(), "PPM (P3), maxval 1023");
    assert_eq!(ppm.encoding, srgb(1023, 1023));
    assert!(largest_difference(ppm.film.pixels(), &clamped) < 2e-3);
}

#[test]
fn float_files_keep_the_renders_radiance_to_their_precision() {
    let source = source();
    let exr = read("render-exr-float.exr");
    assert_eq!(exr.description(), "OpenEXR");
    assert_eq!(exr.encoding, SampleEncoding::Float { mantissa_bits: 23 });
    assert_eq!(exr.film.pixels(), source.pixels(), "bit for bit");
    let half = read("render-exr-half.exr");
    assert_eq!(half.description(), "OpenEXR, half float");
    assert_eq!(half.encoding, SampleEncoding::Float { mantissa_bits: 10 });
    for (h, s) in half.film.pixels().iter().zip(source.pixels()) {
        assert!((*h - *s).abs().max_element() <= s.abs().max_element() * 2f32.powi(-11) + 1e-7);
    }
    // Radiance RGBE: each channel within one step of its pixel's shared
    // exponent (stb and the flat writer truncate; OpenCV rounds).
    for name in [
        "render-hdr-stb.hdr",
        "render-hdr-flat.hdr",
        "render-hdr-cv.pic",
    ] {
        let hdr = read(name);
        assert_eq!(hdr.format, FileFormat::RadianceHdr);
        assert_eq!(hdr.encoding, SampleEncoding::SharedExponent, "{name}");
        assert!(hdr.misnamed.is_none(), "{name}");
        for (h, s) in hdr.film.pixels().iter().zip(source.pixels()) {
            let top = s.max_element();
            let step = if top > 0.0 {
                2f32.powi(top.log2().floor() as i32 + 1 - 8)
            } else {
                0.0
            };
            assert!(
                (*h - *s).abs().max_element() <= step * 1.0001,
                "{name}: {h} {s}"
            );
        }
    }
}

#[test]
fn jpegs_decode_close_to_the_render() {
    let expected = eight_bit();
    for name in [
        "render-jpeg-q75-420.jpg",
        "render-jpeg-q100-444.jpg",
        "render-jpeg-q85-progressive.jpg",
        "render-jpeg-stb.jpg",
    ] {
        let file = read(name);
        assert_eq!(file.description(), "JPEG", "{name}");
        assert_eq!(file.encoding, srgb(255, 255));
        let mean = |p: &[Vec3]| p.iter().copied().sum::<Vec3>() / p.len() as f32;
        let offset = (mean(file.film.pixels()) - mean(&expected))
            .abs()
            .max_element();
        assert!(offset < 0.01, "{name}: {offset}");
    }
    // A lossless JPEG it is not: quality 100 without subsampling still
    // rounds in YCbCr.
    let q100 = read("render-jpeg-q100-444.jpg");
    assert!(largest_difference(q100.film.pixels(), &expected) > 0.0);
}

#[test]
fn gray_palette_and_translucent_files_say_so() {
    for (name, description) in [
        ("render-png-gray.png", "PNG, 8-bit gray"),
        ("render-pgm-p5.pgm", "PGM (P5), gray, maxval 255"),
        ("render-pgm-p2.pgm", "PGM (P2), gray, maxval 255"),
        ("render-jpeg-gray.jpg", "JPEG, gray"),
    ] {
        let file = read(name);
        assert_eq!(file.description(), description);
        assert!(file.gray, "{name}");
        assert!(file.film.pixels().iter().all(|p| p.x == p.y && p.y == p.z));
    }
    let palette = read("render-png-palette.png");
    assert_eq!(palette.description(), "PNG, 8-bit palette");
    assert!(palette.indexed);
    let translucent = read("render-png-translucent.png");
    assert_eq!(
        translucent.alpha,
        AlphaChannel::Translucent { pixels: 20 * 24 }
    );
    assert_eq!(
        translucent.description(),
        "PNG, 8-bit RGB, alpha below 1 in 480 pixels"
    );
    // Its colour channels are the render's, alpha or not.
    assert_eq!(translucent.film.pixels(), &eight_bit()[..]);
}

#[test]
fn a_file_is_read_as_what_it_is_whatever_its_name() {
    let dir = tempfile::tempdir().unwrap();
    let renamed = dir.path().join("submission.png");
    std::fs::copy(data("render-jpeg-q75-420.jpg"), &renamed).unwrap();
    let file = Film::read(&renamed).unwrap();
    assert_eq!(file.format, FileFormat::Jpeg);
    assert_eq!(file.description(), "JPEG (named .png)");
    // TGA has no magic bytes: a TGA 2.0 footer (Pillow writes one) or the
    // name says what it is; stb_image_write's, nameless, is not an image.
    let pillow = dir.path().join("pillow");
    std::fs::copy(data("render-tga.tga"), &pillow).unwrap();
    assert_eq!(Film::read(&pillow).unwrap().format, FileFormat::Tga);
    let stb = dir.path().join("stb");
    std::fs::copy(data("render-tga-stb.tga"), &stb).unwrap();
    let message = Film::read(&stb).unwrap_err().to_string();
    assert!(message.contains("not an image Glint knows"), "{message}");
}
