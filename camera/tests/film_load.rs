//! `Film::load`: what `Film::save` writes comes back (PNG within 8-bit
//! quantisation, EXR and PFM bit for bit, NaN and negative values included), the
//! other layouts each format allows, and one clear error per bad file.

use glam::{UVec2, Vec3};
use glint_camera::{
    linear_to_srgb8, srgb_to_linear, Film, FilmError, SampleEncoding, MAX_LOAD_SIDE,
};
use std::path::{Path, PathBuf};

/// A 5 × 3 film (not square, so a row flip shows) of varied values in [0, 1].
fn gradient() -> Film {
    let mut film = Film::new(UVec2::new(5, 3));
    for y in 0..3 {
        for x in 0..5 {
            let v = Vec3::new(
                x as f32 / 4.0,
                y as f32 / 2.0,
                ((x * 7 + y * 3) % 11) as f32 / 10.0,
            );
            film.set_pixel(x, y, v * v);
        }
    }
    film
}

/// Values a float format must keep exactly: negative, huge, tiny, infinite, NaN.
fn awkward() -> Film {
    let mut film = gradient();
    film.set_pixel(0, 0, Vec3::new(-1.5, 1e30, 1e-40));
    film.set_pixel(4, 2, Vec3::new(f32::INFINITY, f32::NEG_INFINITY, f32::NAN));
    film.set_pixel(2, 1, Vec3::new(-0.0, 65504.0, 123.456));
    film
}

fn bits(film: &Film) -> Vec<u32> {
    film.pixels()
        .iter()
        .flat_map(|p| p.to_array())
        .map(f32::to_bits)
        .collect()
}

fn saved(film: &Film, dir: &Path, name: &str) -> PathBuf {
    let path = dir.join(name);
    film.save(&path).unwrap();
    path
}

#[test]
fn png_round_trips_within_8_bit_quantisation() {
    let dir = tempfile::tempdir().unwrap();
    let film = gradient();
    let loaded = Film::load(&saved(&film, dir.path(), "g.png")).unwrap();
    assert_eq!(loaded.resolution(), film.resolution());
    for (a, b) in film.pixels().iter().zip(loaded.pixels()) {
        for (a, b) in a.to_array().into_iter().zip(b.to_array()) {
            // The loaded value is the 8-bit code's exact linear value.
            assert_eq!(linear_to_srgb8(a), linear_to_srgb8(b));
            assert_eq!(b, srgb_to_linear(linear_to_srgb8(a) as f32 / 255.0));
            assert!((a - b).abs() < 0.01, "{a} {b}");
        }
    }
}

#[test]
fn every_8_bit_code_survives_decoding_and_encoding() {
    let dir = tempfile::tempdir().unwrap();
    let mut film = Film::new(UVec2::new(256, 1));
    for code in 0..=255u32 {
        film.set_pixel(code, 0, Vec3::splat(srgb_to_linear(code as f32 / 255.0)));
    }
    for code in 0..=255u8 {
        assert_eq!(linear_to_srgb8(srgb_to_linear(code as f32 / 255.0)), code);
    }
    let loaded = Film::load(&saved(&film, dir.path(), "codes.png")).unwrap();
    assert_eq!(bits(&loaded), bits(&film));
}

#[test]
fn exr_and_pfm_round_trip_bit_for_bit_with_non_finite_values() {
    let dir = tempfile::tempdir().unwrap();
    let film = awkward();
    for name in ["a.exr", "a.pfm", "A.PFM"] {
        let loaded = Film::load(&saved(&film, dir.path(), name)).unwrap();
        assert_eq!(loaded.resolution(), film.resolution(), "{name}");
        assert_eq!(bits(&loaded), bits(&film), "{name}");
    }
}

fn pfm(header: &str, floats: &[f32], big_endian: bool) -> Vec<u8> {
    let mut bytes = header.as_bytes().to_vec();
    for f in floats {
        bytes.extend(if big_endian {
            f.to_be_bytes()
        } else {
            f.to_le_bytes()
        });
    }
    bytes
}

fn load_bytes(name: &str, bytes: &[u8]) -> Result<Film, FilmError> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    Film::load(&path)
}

#[test]
fn pfm_reads_big_endian_grayscale_and_scaled_files() {
    // Big-endian (positive scale), RGB, 2 × 2, bottom row first.
    let floats = [
        1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0,
    ];
    let film = load_bytes("be.pfm", &pfm("PF\n2 2\n1.0\n", &floats, true)).unwrap();
    assert_eq!(film.pixel(0, 1), Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(film.pixel(1, 1), Vec3::new(4.0, 5.0, 6.0));
    assert_eq!(film.pixel(0, 0), Vec3::new(7.0, 8.0, 9.0));
    // Grayscale, little-endian, spaces instead of newlines: replicated to RGB.
    let film = load_bytes(
        "gray.pfm",
        &pfm("Pf 3 1 -1 ", &[0.5, -2.0, f32::NAN], false),
    )
    .unwrap();
    assert_eq!(film.resolution(), UVec2::new(3, 1));
    assert_eq!(film.pixel(1, 0), Vec3::splat(-2.0));
    assert!(film.pixel(2, 0).is_nan());
    // A scale other than 1 multiplies the values.
    let film = load_bytes("scaled.pfm", &pfm("Pf\n1 1\n-4.0\n", &[0.5], false)).unwrap();
    assert_eq!(film.pixel(0, 0), Vec3::splat(2.0));
    // Bytes after the pixels are ignored.
    let mut bytes = pfm("Pf\n1 1\n-1.0\n", &[0.25], false);
    bytes.extend(b"\n");
    assert_eq!(
        load_bytes("extra.pfm", &bytes).unwrap().pixel(0, 0),
        Vec3::splat(0.25)
    );
}

#[test]
fn png_reads_16_bit_gray_and_alpha() {
    let dir = tempfile::tempdir().unwrap();
    let path16 = dir.path().join("deep.png");
    image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(
        2,
        1,
        vec![0u16, 32768, 65535, 1000, 2000, 3000],
    )
    .unwrap()
    .save(&path16)
    .unwrap();
    let film = Film::load(&path16).unwrap();
    let expect = |c: u16| srgb_to_linear(c as f32 / 65535.0);
    assert_eq!(film.pixel(0, 0), Vec3::new(0.0, expect(32768), 1.0));
    assert_eq!(
        film.pixel(1, 0),
        Vec3::new(expect(1000), expect(2000), expect(3000))
    );

    let gray_alpha = dir.path().join("ga.png");
    image::GrayAlphaImage::from_raw(2, 1, vec![128, 0, 255, 7])
        .unwrap()
        .save(&gray_alpha)
        .unwrap();
    let film = Film::load(&gray_alpha).unwrap();
    assert_eq!(film.pixel(0, 0), Vec3::splat(srgb_to_linear(128.0 / 255.0)));
    assert_eq!(film.pixel(1, 0), Vec3::ONE);

    let rgba = dir.path().join("rgba.png");
    image::RgbaImage::from_raw(1, 1, vec![255, 0, 128, 0])
        .unwrap()
        .save(&rgba)
        .unwrap();
    let p = Film::load(&rgba).unwrap().pixel(0, 0);
    assert_eq!(p, Vec3::new(1.0, 0.0, srgb_to_linear(128.0 / 255.0)));
}

#[test]
fn jpeg_is_decoded_from_srgb() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["flat.jpg", "flat.JPEG"] {
        let path = dir.path().join(name);
        image::RgbImage::from_pixel(8, 8, image::Rgb([128, 128, 128]))
            .save_with_format(&path, image::ImageFormat::Jpeg)
            .unwrap();
        let film = Film::load(&path).unwrap();
        assert_eq!(film.resolution(), UVec2::new(8, 8));
        let p = film.pixel(3, 3);
        assert!((p - Vec3::splat(0.2159)).abs().max_element() < 0.01, "{p}");
    }
}

/// Loads `bytes` as `name` and returns the error's message, checking it names the file.
fn error(name: &str, bytes: &[u8]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    let message = Film::load(&path).unwrap_err().to_string();
    assert!(
        message.starts_with(&format!("{}: ", path.display())),
        "{message}"
    );
    assert_eq!(message.lines().count(), 1, "{message}");
    message
}

#[test]
fn what_is_not_an_image_glint_reads_is_refused_by_its_content() {
    // The name does not matter: the content is not an image.
    for name in ["image.bmp", "image", "image.hdr", "image.png.txt"] {
        let message = error(name, b"whatever");
        assert!(
            message.ends_with(
                "not an image Glint knows (it starts with \"whatever\"); Glint reads PNG, JPEG, BMP, TGA, PPM/PGM, Radiance HDR, OpenEXR and PFM"
            ),
            "{message}"
        );
    }
    assert!(error("a.gif", b"GIF89a\x01\x00").contains("a GIF image; Glint reads"));
    assert!(error("empty.png", b"").ends_with("the file is empty"));
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.png");
    let message = Film::load(&missing).unwrap_err().to_string();
    assert!(
        message.starts_with(&format!("{}: cannot read the image: ", missing.display())),
        "{message}"
    );
}

#[test]
fn bad_pfm_headers_are_refused_before_allocating() {
    for (header, expected) in [
        ("PF ", "the header ends before the width"),
        ("PF\n2", "the header ends within the width"),
        (
            "PF\n-2 1\n-1\n",
            "the width in the header is \"-2\", not a whole number",
        ),
        ("PF\n2 two\n-1\n", "the height in the header is \"two\""),
        ("PF\n0 5\n-1\n", "the image is 0x5: it has no pixels"),
        (
            "PF\n20000 1\n-1\n",
            "the image is 20000x1, larger than the limit of 16384 pixels a side",
        ),
        ("PF\n99999999999999999 1\n-1\n", "larger than the limit"),
        (
            "PF\n1 1\n0\n",
            "the scale in the header is \"0\", not a non-zero number",
        ),
        ("PF\n1 1\nnan\n", "not a non-zero number"),
        ("PF\n1 1\n-1", "the header ends within the scale"),
    ] {
        let message = error("bad.pfm", header.as_bytes());
        assert!(message.contains(expected), "{header:?}: {message}");
    }
    assert_eq!(MAX_LOAD_SIDE, 16384);
}

#[test]
fn truncated_files_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let film = gradient();
    let message = error("short.pfm", &pfm("PF\n2 2\n-1.0\n", &[0.0; 11], false));
    assert!(
        message
            .contains("the file is truncated: a 2x2 RGB PFM needs 48 bytes of pixels, it has 44"),
        "{message}"
    );
    for name in ["t.png", "t.exr"] {
        let bytes = std::fs::read(saved(&film, dir.path(), name)).unwrap();
        let message = error(name, &bytes[..bytes.len() * 2 / 3]);
        assert!(message.contains("cannot read the image: "), "{message}");
    }
    for name in ["garbage.png", "garbage.exr", "garbage.jpg"] {
        let message = error(name, b"this is not an image at all");
        assert!(message.contains("cannot read the image: "), "{message}");
    }
}

/// CRC-32 (as PNG chunks use it).
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xedb8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

#[test]
fn a_png_claiming_a_huge_size_is_refused_from_its_header() {
    // A valid PNG signature, an IHDR chunk of 100000 × 8, an empty IDAT and IEND:
    // the header's size alone must stop it.
    let mut ihdr = b"IHDR".to_vec();
    ihdr.extend(100_000u32.to_be_bytes());
    ihdr.extend(8u32.to_be_bytes());
    ihdr.extend([8, 2, 0, 0, 0]); // 8-bit RGB
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    for chunk in [ihdr, b"IDAT".to_vec(), b"IEND".to_vec()] {
        png.extend((chunk.len() as u32 - 4).to_be_bytes());
        png.extend(&chunk);
        png.extend(crc32(&chunk).to_be_bytes());
    }
    let message = error("huge.png", &png);
    assert!(
        message.ends_with("cannot read the image: the image is 100000x8, larger than the limit of 16384 pixels a side"),
        "{message}"
    );
}

/// A PNG of `width × height` 8-bit RGB whose IDAT holds no pixels.
fn empty_png(width: u32, height: u32) -> Vec<u8> {
    let mut ihdr = b"IHDR".to_vec();
    ihdr.extend(width.to_be_bytes());
    ihdr.extend(height.to_be_bytes());
    ihdr.extend([8, 2, 0, 0, 0]);
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    for chunk in [ihdr, b"IDAT".to_vec(), b"IEND".to_vec()] {
        png.extend((chunk.len() as u32 - 4).to_be_bytes());
        png.extend(&chunk);
        png.extend(crc32(&chunk).to_be_bytes());
    }
    png
}

#[test]
fn a_header_claiming_more_pixels_than_its_file_holds_is_refused_before_allocating() {
    // 16000 × 16000 is within the side limit, but 768 MB of pixels cannot come
    // from a file of 57 bytes: refused from the header and the file's size
    // (under a 4 GiB address space, decoding it aborted).
    let png = empty_png(16000, 16000);
    let message = error("claims.png", &png);
    assert!(
        message.ends_with(&format!(
            "the header says 16000x16000 pixels (768000000 bytes decoded), more than a file of {} bytes can hold",
            png.len()
        )),
        "{message}"
    );
    // An OpenEXR file whose windows are widened to 16000 × 16000 after it was
    // written: Film::load and a resumed render's PartialFilm::load refuse it
    // from the header (here the exr crate's own check of its chunk table
    // comes first).
    let dir = tempfile::tempdir().unwrap();
    let path = saved(&gradient(), dir.path(), "claims.exr");
    let mut exr = std::fs::read(&path).unwrap();
    for window in [&b"dataWindow\0box2i\0"[..], b"displayWindow\0box2i\0"] {
        let at = exr.windows(window.len()).position(|w| w == window).unwrap() + window.len() + 4;
        exr[at + 8..at + 16]
            .copy_from_slice(&[15999i32.to_le_bytes(), 15999i32.to_le_bytes()].concat());
    }
    std::fs::write(&path, &exr).unwrap();
    for message in [
        Film::load(&path).unwrap_err().to_string(),
        glint_camera::PartialFilm::load(&path)
            .unwrap_err()
            .to_string(),
    ] {
        assert!(message.contains("cannot read the image"), "{message}");
    }
}

const EIGHT_BIT: SampleEncoding = SampleEncoding::Srgb {
    levels: [255; 3],
    stored: 255,
};

/// The 8-bit sRGB codes of `film`, as a PPM in the layout `magic` names.
fn ppm(film: &Film, magic: &str) -> Vec<u8> {
    let size = film.resolution();
    let codes = film.to_srgb8();
    let mut bytes = format!("{magic}\n# a comment\n{} {}\n255\n", size.x, size.y).into_bytes();
    match magic {
        "P6" => bytes.extend(&codes),
        _ => {
            for row in codes.chunks(3 * size.x as usize) {
                let line: Vec<String> = row.iter().map(u8::to_string).collect();
                bytes.extend(line.join(" ").as_bytes());
                bytes.push(b'\n');
            }
        }
    }
    bytes
}

#[test]
fn ppm_binary_and_ascii_read_as_the_png_does() {
    let dir = tempfile::tempdir().unwrap();
    let film = gradient();
    let png = Film::load(&saved(&film, dir.path(), "g.png")).unwrap();
    for magic in ["P6", "P3"] {
        let path = dir.path().join(format!("{magic}.ppm"));
        std::fs::write(&path, ppm(&film, magic)).unwrap();
        let read = Film::read(&path).unwrap();
        assert_eq!(bits(&read.film), bits(&png), "{magic}");
        assert_eq!(read.encoding, EIGHT_BIT);
    }
    let png = Film::read(&dir.path().join("g.png")).unwrap();
    assert_eq!(png.encoding, EIGHT_BIT);
    let pfm = Film::read(&saved(&film, dir.path(), "g.pfm")).unwrap();
    assert_eq!(pfm.encoding, SampleEncoding::Float { mantissa_bits: 23 });
}

#[test]
fn ppm_codes_are_scaled_by_maxval() {
    // maxval 1000: code 500 is half way in the encoded domain; 16-bit samples
    // are big-endian.
    let film = load_bytes("a.ppm", b"P3 2 1 1000 0 500 1000 1000 1000 1000").unwrap();
    assert_eq!(film.pixel(0, 0).y, srgb_to_linear(0.5));
    assert_eq!(film.pixel(1, 0), Vec3::ONE);
    let film = load_bytes("b.ppm", b"P6 1 1 65535 \x80\x00\xff\xff\x00\x00").unwrap();
    assert_eq!(film.pixel(0, 0).x, srgb_to_linear(32768.0 / 65535.0));
    assert_eq!((film.pixel(0, 0).y, film.pixel(0, 0).z), (1.0, 0.0));
}

#[test]
fn bad_netpbm_files_are_refused_with_the_reason() {
    for (bytes, expected) in [
        (&b"P6 2 2 255 \x01\x02"[..], "the file is truncated"),
        (
            b"P6 16384 16384 255 \x00",
            "the header says 16384x16384 pixels (805306368 bytes decoded), more than a file of 20 bytes can hold",
        ),
        (b"P3 1 1 255 1 2", "not a valid Netpbm file: Not enough data"),
        (
            b"P3 1 1 255 1 2 x  ",
            "not a valid Netpbm file: Non-ASCII-digit character",
        ),
        (b"P6\n1 1\n0\n", "MAXVAL is zero"),
        (b"P6\n1 1\n70000\n", "MAXVAL exceeds 65535"),
        (b"P6\n0 1\n255\n", "the image is 0x1: it has no pixels"),
        (b"P6\n# no end", "the file is truncated"),
    ] {
        let message = error("bad.ppm", bytes);
        assert!(message.contains(expected), "{message}");
    }
}
