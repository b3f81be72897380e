//! End-to-end tests of Glint over the shipped scenes (`scenes/`); the tests live
//! in `tests/`. This library only locates the shipped files.

use std::path::PathBuf;

/// The repository's `scenes/` directory.
pub fn scenes_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// The path of the shipped scene `name` (without `.toml`).
pub fn scene_path(name: &str) -> PathBuf {
    scenes_dir().join(format!("{name}.toml"))
}

/// The names of all shipped scenes, sorted.
pub fn shipped_scenes() -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(scenes_dir())
        .expect("scenes/ exists")
        .filter_map(|e| {
            let path = e.ok()?.path();
            (path.extension()? == "toml").then(|| path.file_stem()?.to_str().map(str::to_owned))?
        })
        .collect();
    names.sort();
    names
}
