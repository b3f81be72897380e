//! Any bytes as an OBJ file and its MTL library (split at the first 0xFF byte),
//! loaded through a scene that uses the MTL materials: a mesh or an error,
//! never a panic (tobj's index arithmetic included).
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;
use std::sync::OnceLock;

fn dir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| tempfile::tempdir().expect("a temporary directory").keep())
}

const SCENE: &str = r#"
[camera]
position = [0, 0, 5]
look_at = [0, 0, 0]
fov = 40
[[mesh]]
file = "m.obj"
"#;

fuzz_target!(|data: &[u8]| {
    let split = data.iter().position(|&b| b == 0xFF).unwrap_or(data.len());
    let (obj, mtl) = data.split_at(split);
    let dir = dir();
    let mut with_library = b"mtllib m.mtl\n".to_vec();
    with_library.extend_from_slice(obj);
    std::fs::write(dir.join("m.obj"), with_library).unwrap();
    std::fs::write(dir.join("m.mtl"), mtl.get(1..).unwrap_or_default()).unwrap();
    let _ = glint_scene::parse_in(SCENE, "fuzz.toml", dir);
});
