//! The scene stage of Glint: the TOML scene file format, its validation, and
//! loading a file into the integrator's [`Scene`](glint_integrator::Scene) and
//! [`RenderSettings`](glint_integrator::RenderSettings).
//!
//! # Conventions
//! - The file's units and frame are the renderer's: right-handed, y up, linear RGB.
//! - Angles in the file are in **degrees** (the camera's `fov`, an environment's
//!   `rotation`, a mesh's `rotate`).
//! - Every error is one [`SceneError`] that names the file, the 1-based line and
//!   column, and the dotted path of the field (`sphere[2].radius`); array indices
//!   count from 0, in file order. Unknown keys, non-finite numbers and out-of-range
//!   values are all errors, never silently accepted.
//!
//! The format is documented key by key in the repository's `docs/scene-format.md`.
//!
//! # Entry points
//! - [`load`] reads a scene file and the assets it names; [`parse`] and [`parse_in`]
//!   read scene text. Each gives a [`SceneDescription`] (the scene, its render
//!   settings and its material names) or a [`SceneError`].
//! - [`Overrides`] replace a loaded scene's settings, textures' filter and
//!   resolution, as `glint render`'s flags do.
//! - [`parse_resolution_parts`] and [`MAX_RESOLUTION`]: the resolution check the
//!   command line shares with the file format.

mod build;
mod error;
mod files;
mod format;
pub mod mitsuba;
mod obj;
mod overrides;
mod values;

pub use build::{LoadTimings, SceneDescription};
pub use error::SceneError;
pub use files::{read_text, MAX_DOCUMENT_BYTES, MAX_MESH_BYTES, MAX_SCENE_BYTES};
pub use overrides::{OverrideError, Overrides};
pub use values::{parse_resolution_parts, MAX_RESOLUTION};

use std::path::Path;

/// Reads and validates the scene file at `path`, and the assets it names
/// (paths relative to the scene file's directory).
pub fn load(path: &Path) -> Result<SceneDescription, SceneError> {
    let read = |message: String| SceneError::Read {
        path: path.to_path_buf(),
        source: std::io::Error::other(message),
    };
    files::check_regular(path, MAX_SCENE_BYTES, "a scene file").map_err(read)?;
    let bytes = std::fs::read(path).map_err(|source| SceneError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let file = path.display().to_string();
    let source = files::utf8(&bytes).map_err(|(line, column, message)| SceneError::Invalid {
        file: file.clone(),
        line,
        column,
        field: None,
        message,
    })?;
    let base_dir = path.parent().unwrap_or(Path::new(""));
    parse_in(source, &file, base_dir)
}

/// Parses and validates scene text; `file` names it in error messages, and asset
/// paths are taken relative to the current directory.
pub fn parse(source: &str, file: &str) -> Result<SceneDescription, SceneError> {
    parse_in(source, file, Path::new(""))
}

/// Parses and validates scene text whose asset paths are relative to `base_dir`.
pub fn parse_in(source: &str, file: &str, base_dir: &Path) -> Result<SceneDescription, SceneError> {
    let start = std::time::Instant::now();
    let deserializer = toml::de::Deserializer::parse(source)
        .map_err(|e| error::invalid(file, source, e.span(), None, e.message()))?;
    let scene_file: format::SceneFile =
        serde_path_to_error::deserialize(deserializer).map_err(|e| {
            // `Spanned` wraps values in a private struct; keep it out of the path.
            let path = e
                .path()
                .to_string()
                .replace(".$__serde_spanned_private_value", "");
            let field = (path != ".").then_some(path);
            let inner = e.into_inner();
            error::invalid(file, source, inner.span(), field, inner.message())
        })?;
    let read = start.elapsed();
    let mut description = build::build(scene_file, base_dir)
        .map_err(|p| error::invalid(file, source, Some(p.span), Some(p.field), &p.message))?;
    description.timings.parse += read;
    Ok(description)
}

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
