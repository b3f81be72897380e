//! Any bytes as an image file named by the first byte (PNG, JPEG, Radiance
//! HDR, OpenEXR, PFM, PPM, BMP, TGA; `Film::read` tells them by content, TGA
//! by its name): the texture loader, `Film::read` (what `glint diff` and
//! `glint grade` read) and
//! `PartialFilm::load` (what `--resume` reads: an EXR's pixels, coverage and
//! header) each give an image or an error, never a panic, and refuse absurd
//! sizes before allocating.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;
use std::sync::OnceLock;

fn dir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| tempfile::tempdir().expect("a temporary directory").keep())
}

fuzz_target!(|data: &[u8]| {
    let Some((&kind, bytes)) = data.split_first() else {
        return;
    };
    let extension = ["png", "jpg", "hdr", "exr", "pfm", "ppm", "bmp", "tga"][kind as usize % 8];
    let path = dir().join(format!("image.{extension}"));
    std::fs::write(&path, bytes).unwrap();
    let _ = glint_texture::load_image(&path);
    let _ = glint_camera::Film::read(&path);
    let _ = glint_camera::PartialFilm::load(&path);
});
