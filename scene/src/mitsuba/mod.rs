//! A loaded scene as a [Mitsuba 3](https://www.mitsuba-renderer.org/) scene:
//! `glint export --mitsuba`.
//!
//! [`export`] writes `OUT.xml` (`<scene version="3.0.0">`) and, when the scene
//! needs them, the files it refers to in a folder beside it, `OUT-assets/`
//! (named by [`assets_folder`]): one binary PLY per mesh and material, an
//! OpenEXR per image texture, and the environment as a lat-long EXR. It works
//! from the loaded [`SceneDescription`], so every shape kind and every asset
//! is converted as Glint sees it (meshes transformed, images decoded to linear
//! RGB). [`convert`] gives the same document without writing anything.
//!
//! | Glint | Mitsuba 3 |
//! |---|---|
//! | camera | `perspective` sensor, `fov_axis = "y"`, `to_world` = `lookat` |
//! | `[render]` | `hdrfilm` (box filter), `independent` sampler (spp, seed), `direct` integrator (`emitter_samples` = `bsdf_samples` = light samples; one emitter sample with point lights; [`Options`] may set `bsdf_samples`) |
//! | sphere | `sphere` whose `to_world` turns its pole to +y and its u to Glint's |
//! | parallelogram | `rectangle` with an affine `to_world` (any parallelogram) |
//! | plane | a large `rectangle` (a warning gives its size) |
//! | box | six `rectangle`s |
//! | mesh | `ply` files of the transformed mesh, one per material |
//! | material | `diffuse` (the `specular` term is dropped, with a warning); a mirror is a `conductor` (`material = "none"`, tinted); `0 < reflectivity < 1` a `blendbsdf` of the two; closed shapes, meshes and two-sided flat shapes get `twosided` |
//! | textures | `checkerboard`; images as `bitmap` (EXR), wrap mode and filter mapped; uv maps in `to_uv` |
//! | point light | `point` emitter, `intensity` = color |
//! | area light | `rectangle` with an `area` emitter (`radiance` = color) and a black BSDF |
//! | environment | `envmap` (a lat-long EXR on Mitsuba's texel grid; cube maps resampled to lat-long) or `constant` |
//!
//! What has no counterpart (the Phong model's units, ambient light, specular
//! lobes, mirror reflections beyond what `direct` follows, infinite planes,
//! MIP-mapped filtering) is reported as a [`Warning`].

mod convert;
mod environment;
mod output;
mod ply;
mod xml;

pub use convert::{convert, convert_with, Conversion, Options, SideContents, SideFile};
pub use output::{assets_folder, check_output};

use crate::SceneDescription;
use std::path::{Path, PathBuf};

/// Something the Mitsuba scene does not reproduce like for like, as one line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Warning(pub String);

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

/// Why an export failed; each displays as one line naming the path.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The output path cannot be used (its extension, directory, or an assets
    /// folder that Glint did not write): bad input, nothing was written.
    #[error("{}: {message}", path.display())]
    Output { path: PathBuf, message: String },
    /// Writing failed; nothing was replaced.
    #[error("{}: {source}", path.display())]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
}

impl ExportError {
    /// Whether the failure is the caller's input (a path that cannot be
    /// used) rather than the system's.
    pub fn is_bad_input(&self) -> bool {
        matches!(self, ExportError::Output { .. })
    }
}

/// What [`export`] wrote.
#[derive(Clone, Debug)]
pub struct Exported {
    /// The assets folder and the number of files in it, if the scene needed any.
    pub assets: Option<(PathBuf, usize)>,
    pub warnings: Vec<Warning>,
    /// The `direct` integrator's `emitter_samples` and `bsdf_samples`.
    pub emitter_samples: u32,
    pub bsdf_samples: u32,
}

/// Writes `description` as a Mitsuba 3 scene to `out` (a `.xml` path) and its
/// side files to [`assets_folder`]`(out)`. Everything is written to a
/// temporary folder beside `out` first and renamed into place only when
/// complete: a failed export leaves what was there before. An existing assets
/// folder is replaced only if an earlier export wrote it (it holds a
/// `.glint-export` marker).
pub fn export(description: &SceneDescription, out: &Path) -> Result<Exported, ExportError> {
    export_with(description, out, Options::default())
}

/// [`export`] with `options`.
pub fn export_with(
    description: &SceneDescription,
    out: &Path,
    options: Options,
) -> Result<Exported, ExportError> {
    check_output(out)?;
    let folder = assets_folder(out);
    let name = folder
        .file_name()
        .expect("the assets folder has a name")
        .to_string_lossy()
        .into_owned();
    let conversion = convert_with(description, &name, options);
    output::write(out, &folder, &conversion)?;
    Ok(Exported {
        assets: (!conversion.files.is_empty()).then_some((folder, conversion.files.len())),
        warnings: conversion.warnings,
        emitter_samples: conversion.emitter_samples,
        bsdf_samples: conversion.bsdf_samples,
    })
}

#[cfg(test)]
mod tests;
