//! From the file as read to the integrator's scene: name resolution and the
//! checks that involve more than one value.
//!
//! [`build`] runs the stages in the file's own order of concerns: the render
//! settings, camera and regions; textures and materials; shapes; lights; the
//! environment. Problems are reported in that order, so the first one found is
//! the same whichever stage grows.

mod camera;
mod environment;
mod lights;
mod materials;
mod meshes;
mod names;
mod settings;
mod shapes;
mod textures;

use crate::error::Problem;
use crate::format::SceneFile;
use glint_integrator::{RenderSettings, Scene, SceneBuilder};
use names::ObjectNames;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// A scene ready to render, with the render settings its file asks for.
#[derive(Clone, Debug)]
pub struct SceneDescription {
    pub scene: Scene,
    pub settings: RenderSettings,
    /// `material_names[i]` is the file's name for `scene.materials[i]`.
    pub material_names: Vec<String>,
    /// `object_names[i]` names object `i` of `scene.shapes` (the index a hit
    /// records): the table's `name`, or its table and index (`sphere[2]`; a
    /// box with six face materials is six objects, `box[0].px` …).
    pub object_names: Vec<String>,
    /// Every file the scene read besides itself (images, environment maps, OBJ
    /// and MTL files), each once, in the order first read.
    pub assets: Vec<PathBuf>,
    /// The file's `[regions]`: names and `[x0, y0, x1, y1]` pixel rectangles of
    /// the render resolution, sorted by name.
    pub regions: Vec<(String, [u32; 4])>,
    /// How long loading took, by phase.
    pub timings: LoadTimings,
}

/// Time spent loading a scene, by phase.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LoadTimings {
    /// Reading the TOML and checking every value.
    pub parse: Duration,
    /// Reading images, environment maps and meshes.
    pub assets: Duration,
    /// Building the BVH (or the linear loop's packets).
    pub acceleration: Duration,
}

pub(crate) fn build(file: SceneFile, base_dir: &Path) -> Result<SceneDescription, Problem> {
    let start = Instant::now();
    let settings = settings::settings(&file.render)?;
    let camera = camera::camera(&file.camera, file.render.resolution.0)?;
    let regions = settings::regions(&file)?;
    let mut scene = Assembly::new(base_dir);
    let referenced = textures::referenced(&file.materials);
    let textures =
        scene.timed(|assets| textures::textures(&file.textures, &referenced, base_dir, assets))?;
    let materials = scene.materials(&file.materials, &textures)?;
    scene.shapes(&file, &materials)?;
    scene.meshes(&file.mesh, &materials)?;
    scene.lights(&file)?;
    scene.builder.ambient(file.ambient.0);
    if let Some(table) = &file.environment {
        let light = scene.timed(|assets| environment::environment(table, base_dir, assets))?;
        scene.builder.environment(light);
    }
    scene.finish(file, camera, settings, regions, start)
}

/// The scene as it is put together: the builder, the names given so far, and
/// the files read (and the time spent reading them).
struct Assembly<'a> {
    builder: SceneBuilder,
    names: ObjectNames,
    /// Materials added besides the file's own (a mesh's MTL materials, the
    /// default mesh material), by name, in the order added.
    extra_material_names: Vec<String>,
    /// The light gray material of mesh faces without one, once one needs it.
    default_mesh_material: Option<u32>,
    base_dir: &'a Path,
    assets: Vec<PathBuf>,
    asset_time: Duration,
}

impl<'a> Assembly<'a> {
    fn new(base_dir: &'a Path) -> Self {
        Self {
            builder: SceneBuilder::new(),
            names: ObjectNames::default(),
            extra_material_names: Vec::new(),
            default_mesh_material: None,
            base_dir,
            assets: Vec::new(),
            asset_time: Duration::ZERO,
        }
    }

    /// Runs `read` (which reads files and lists them), counting its time as
    /// asset loading.
    fn timed<T>(
        &mut self,
        read: impl FnOnce(&mut Vec<PathBuf>) -> Result<T, Problem>,
    ) -> Result<T, Problem> {
        let clock = Instant::now();
        let result = read(&mut self.assets);
        self.asset_time += clock.elapsed();
        result
    }

    /// Builds the acceleration structure and gathers what the description
    /// reports beside the scene.
    fn finish(
        mut self,
        file: SceneFile,
        camera: glint_camera::Camera,
        settings: RenderSettings,
        regions: Vec<(String, [u32; 4])>,
        start: Instant,
    ) -> Result<SceneDescription, Problem> {
        let clock = Instant::now();
        let scene = self
            .builder
            .build(camera)
            .expect("material ids were resolved above");
        let acceleration = clock.elapsed();
        let material_names = file
            .materials
            .into_keys()
            .chain(self.extra_material_names)
            .collect();
        let mut seen = std::collections::HashSet::new();
        self.assets.retain(|p| seen.insert(p.clone()));
        Ok(SceneDescription {
            scene,
            settings,
            material_names,
            object_names: self.names.names,
            assets: self.assets,
            regions,
            timings: LoadTimings {
                parse: start
                    .elapsed()
                    .saturating_sub(self.asset_time + acceleration),
                assets: self.asset_time,
                acceleration,
            },
        })
    }
}
