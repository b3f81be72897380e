//! The loaded scene as a Mitsuba 3 XML document and the files beside it.
//!
//! A [`Converter`] walks the scene once, shapes first, then lights and the
//! environment, writing BSDFs on first use; the document is put together
//! last, when the integrator's sample counts and the camera's clipping
//! distances (which depend on every shape) are known.

mod document;
mod environment;
mod lights;
mod materials;
mod placement;
mod shapes;
mod textures;
mod warnings;

#[cfg(test)]
pub(super) use placement::{plane_rectangle, rectangle, sphere};

use super::xml::Xml;
use super::Warning;
use crate::SceneDescription;
use glint_camera::Film;
use glint_integrator::Scene;
use placement::scene_points;
use std::collections::{BTreeSet, HashMap, HashSet};

/// A scene converted for Mitsuba 3: the XML text, the files it names (in the
/// assets folder), and what could not be converted like for like.
pub struct Conversion {
    pub xml: String,
    pub files: Vec<SideFile>,
    pub warnings: Vec<Warning>,
    /// The `direct` integrator's `emitter_samples` and `bsdf_samples`.
    pub emitter_samples: u32,
    pub bsdf_samples: u32,
}

/// A file the XML refers to, by its name inside the assets folder.
pub struct SideFile {
    pub name: String,
    pub contents: SideContents,
}

/// What a side file holds.
pub enum SideContents {
    /// Bytes written as they are (a PLY mesh).
    Bytes(Vec<u8>),
    /// An image written as OpenEXR (linear 32-bit float RGB).
    Exr(Film),
}

/// What the Mitsuba scene may be asked to do otherwise than Glint's scene
/// says; the default follows the scene.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Options {
    /// The `direct` integrator's `bsdf_samples` instead of Glint's light
    /// samples. 0 takes emitter samples only, one shadow ray each: the work
    /// Glint's light sampling does, for comparing speed.
    pub bsdf_samples: Option<u32>,
}

/// Converts `description` for Mitsuba 3. Files are referred to as
/// `ASSETS/NAME`, `assets` being the assets folder's path relative to the XML
/// file (its name, as [`super::export`] places it beside the XML).
pub fn convert(description: &SceneDescription, assets: &str) -> Conversion {
    convert_with(description, assets, Options::default())
}

/// [`convert`] with `options`.
pub fn convert_with(description: &SceneDescription, assets: &str, options: Options) -> Conversion {
    Converter::new(description, assets, options).run()
}

/// A BSDF as written once and referred to by id: the material, the map from
/// Mitsuba's uv to Glint's (only for textured materials) and whether it is
/// wrapped in `twosided`.
type BsdfKey = (u32, Option<[u32; 6]>, bool);

struct Converter<'a> {
    scene: &'a Scene,
    description: &'a SceneDescription,
    options: Options,
    assets: String,
    bsdfs: Xml,
    shapes: Xml,
    bsdf_ids: HashMap<BsdfKey, String>,
    ids: HashSet<String>,
    files: Vec<SideFile>,
    /// Image files written, by the address of the texture image they hold.
    images: HashMap<usize, String>,
    warnings: Vec<Warning>,
    /// Materials already looked at (for their warnings).
    noted: BTreeSet<u32>,
    mirrors: Vec<String>,
    /// Materials that blend a mirror into a diffuse BSDF (`blendbsdf`).
    blends: Vec<String>,
    /// Materials whose image textures lose their MIP-map filter.
    unfiltered: BTreeSet<String>,
    /// Shapes written so far, by kind (for their ids).
    counts: HashMap<&'static str, usize>,
    /// The largest distance from the camera to any bounded point of the scene.
    extent: f32,
    /// The farthest a plane's stand-in rectangle reaches from the camera.
    far: f32,
}

impl<'a> Converter<'a> {
    fn new(description: &'a SceneDescription, assets: &str, options: Options) -> Self {
        let scene = &description.scene;
        let extent = scene_points(scene)
            .map(|p| p.distance(scene.camera.position()))
            .fold(0.0f32, f32::max);
        Self {
            scene,
            description,
            options,
            assets: assets.trim_end_matches('/').to_owned(),
            bsdfs: Xml::with_depth(1),
            shapes: Xml::with_depth(1),
            bsdf_ids: HashMap::new(),
            ids: HashSet::new(),
            files: Vec::new(),
            images: HashMap::new(),
            warnings: Vec::new(),
            noted: BTreeSet::new(),
            mirrors: Vec::new(),
            blends: Vec::new(),
            unfiltered: BTreeSet::new(),
            counts: HashMap::new(),
            extent,
            far: extent,
        }
    }

    fn warn(&mut self, message: String) {
        self.warnings.push(Warning(message));
    }

    fn run(mut self) -> Conversion {
        self.model_warnings();
        self.objects();
        self.lights();
        self.environment();
        self.late_warnings();
        self.facing_warnings();
        let (emitter_samples, bsdf_samples) = self.integrator_samples();
        let xml = self.document(emitter_samples, bsdf_samples);
        Conversion {
            xml,
            files: self.files,
            warnings: self.warnings,
            emitter_samples,
            bsdf_samples,
        }
    }

    /// An id not used yet: `base`, or `base-2`, `base-3`, …
    fn unique_id(&mut self, base: &str) -> String {
        let base: String = base
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        let mut id = base.clone();
        let mut n = 1;
        while !self.ids.insert(id.clone()) {
            n += 1;
            id = format!("{base}-{n}");
        }
        id
    }

    fn material_name(&self, m: u32) -> String {
        self.description
            .material_names
            .get(m as usize)
            .cloned()
            .unwrap_or_else(|| format!("material {m}"))
    }

    /// How many shapes of `kind` were written before this one (its number).
    fn count(&mut self, kind: &'static str) -> usize {
        let n = self.counts.entry(kind).or_default();
        *n += 1;
        *n - 1
    }
}
