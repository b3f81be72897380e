//! Any text as a scene file: parsing, validation and building the scene (its
//! asset paths name nothing) must give a scene or an error, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(source) = std::str::from_utf8(data) {
        let _ = glint_scene::parse_in(source, "fuzz.toml", std::path::Path::new("/nonexistent"));
    }
});
