//! From the file as read to the integrator's scene: name resolution and the
//! checks that involve more than one value.

use crate::error::Problem;
use crate::format::*;
use crate::obj::load_obj;
use crate::values::Pattern;
use glam::Vec3;
use glam::{Affine3A, EulerRot, Quat};
use glint_camera::{Camera, CameraError};
use glint_geometry::TriangleMesh;
use glint_geometry::{AaBox, Parallelogram, Plane, Sphere};
use glint_integrator::{RenderSettings, SampleCount, Scene, SceneBuilder, SettingsError};
use glint_lighting::{
    AreaLight, EnvironmentLight, PhongMaterial, PointLight, ShadingModel, SphereLight, UvTransform,
};
use glint_texture::{
    load_image, Checkerboard, CubeMap, Environment, Image, ImageTexture, LatLongMap, Texture,
    TextureImage, MAX_IMAGE_TEXELS,
};
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use toml::Spanned;

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
    let mut asset_time = Duration::ZERO;
    let settings = settings(&file.render)?;
    let camera = camera(&file.camera, file.render.resolution.0)?;
    let regions = regions(&file)?;
    let mut assets = Vec::new();
    let clock = Instant::now();
    let referenced = referenced_textures(&file.materials);
    let textures = textures(&file.textures, &referenced, base_dir, &mut assets)?;
    asset_time += clock.elapsed();
    let mut builder = SceneBuilder::new();
    let mut names = ObjectNames::default();
    let mut extra_material_names = Vec::new();
    let mut material_ids = BTreeMap::new();
    for (name, table) in &file.materials {
        let material = material(name, table, &textures)?;
        material_ids.insert(name.as_str(), builder.material(material));
    }
    let lookup = |field: String, name: &Spanned<String>| {
        material_ids
            .get(name.get_ref().as_str())
            .copied()
            .ok_or_else(|| {
                let known: Vec<_> = material_ids.keys().map(|k| format!("\"{k}\"")).collect();
                Problem::new(
                    name.span(),
                    field,
                    format!(
                        "no material named \"{}\" (defined: {})",
                        name.get_ref(),
                        if known.is_empty() {
                            "none".into()
                        } else {
                            known.join(", ")
                        }
                    ),
                )
            })
    };

    for (i, s) in file.sphere.iter().enumerate() {
        let m = lookup(format!("sphere[{i}].material"), &s.material)?;
        let sphere = Sphere::new(s.center.0, s.radius.0).expect("radius read as positive");
        names.add(s.name.as_ref(), format!("sphere[{i}]"))?;
        builder.shape(sphere, m);
    }
    for (i, p) in file.parallelogram.iter().enumerate() {
        let field = format!("parallelogram[{i}]");
        let m = lookup(format!("{field}.material"), &p.material)?;
        let shape = Parallelogram::new(p.origin.0, p.edge1.get_ref().0, p.edge2.0, p.two_sided)
            .ok_or_else(|| no_area(&field, &p.edge1))?;
        let front = front_side(&field, shape.normal(), p.normal.as_ref())?;
        names.add(p.name.as_ref(), field)?;
        builder.shape(shape.facing(front), m);
    }
    for (i, p) in file.plane.iter().enumerate() {
        let m = lookup(format!("plane[{i}].material"), &p.material)?;
        // `Direction` guarantees a normal that normalizes.
        let plane = Plane::new(p.point.0, p.normal.0, p.two_sided)
            .and_then(|plane| plane.with_tile_size(p.tile_size.0))
            .expect("normalizable normal, positive tile size");
        names.add(p.name.as_ref(), format!("plane[{i}]"))?;
        builder.shape(plane, m);
    }
    for (i, b) in file.boxes.iter().enumerate() {
        let field = format!("box[{i}]");
        let aabox = AaBox::new(b.min.0, b.max.get_ref().0).ok_or_else(|| {
            Problem::new(
                b.max.span(),
                format!("{field}.max"),
                "expected max to be greater than min on every axis",
            )
        })?;
        match (&b.material, &b.face_materials) {
            (Some(material), None) => {
                let m = lookup(format!("{field}.material"), material)?;
                names.add(b.name.as_ref(), field.clone())?;
                builder.shape(aabox, m);
            }
            (None, Some(materials)) if materials.get_ref().len() == 6 => {
                for (face, (shape, name)) in aabox
                    .face_parallelograms()
                    .into_iter()
                    .zip(materials.get_ref())
                    .enumerate()
                {
                    let m = lookup(format!("{field}.face_materials[{face}]"), name)?;
                    names.add_face(b.name.as_ref(), &field, face)?;
                    builder.shape(shape, m);
                }
            }
            (None, Some(materials)) => {
                return Err(Problem::new(
                    materials.span(),
                    format!("{field}.face_materials"),
                    format!(
                        "expected 6 materials (px nx py ny pz nz), got {}",
                        materials.get_ref().len()
                    ),
                ))
            }
            _ => {
                let span = b.max.span();
                return Err(Problem::new(
                    span,
                    field,
                    "expected exactly one of `material` or `face_materials`",
                ));
            }
        }
    }
    let mut default_mesh_material = None;
    for (i, m) in file.mesh.iter().enumerate() {
        let field = format!("mesh[{i}]");
        // Names before files: a typo is reported without reading the mesh.
        let material = m
            .material
            .as_ref()
            .map(|name| lookup(format!("{field}.material"), name))
            .transpose()?;
        let clock = Instant::now();
        let obj = load_obj(&base_dir.join(m.file.get_ref()), material.is_none())
            .map_err(|e| Problem::new(m.file.span(), format!("{field}.file"), e))?;
        asset_time += clock.elapsed();
        assets.extend(obj.files.iter().cloned());
        let triangle_materials: Vec<u32> = match material {
            Some(id) => vec![id; obj.indices.len()],
            None => {
                // The OBJ's own materials, named FILE:NAME; faces without one get a
                // light gray diffuse material.
                let ids: Vec<u32> = obj
                    .materials
                    .iter()
                    .map(|(name, material)| {
                        extra_material_names.push(format!("{}:{name}", m.file.get_ref()));
                        builder.material(material.clone())
                    })
                    .collect();
                obj.triangle_materials
                    .iter()
                    .map(|t| match t {
                        Some(k) => ids[*k as usize],
                        None => *default_mesh_material.get_or_insert_with(|| {
                            extra_material_names.push("(default mesh material)".into());
                            builder.material(PhongMaterial {
                                specular: Some(Texture::Constant(Vec3::ZERO)),
                                ..PhongMaterial::new(Vec3::splat(0.8), 1.0)
                            })
                        }),
                    })
                    .collect()
            }
        };
        let mesh =
            TriangleMesh::new(obj.positions, obj.indices, obj.normals, obj.uvs).map_err(|e| {
                Problem::new(
                    m.file.span(),
                    format!("{field}.file"),
                    format!("{}: {e}", m.file.get_ref()),
                )
            })?;
        let mesh = if mesh.has_normals() {
            mesh
        } else {
            mesh.with_angle_weighted_normals()
        };
        let (r, s) = (m.rotate.0 * std::f32::consts::PI / 180.0, m.scale.0);
        let rotation = Quat::from_euler(EulerRot::ZYX, r.z, r.y, r.x);
        let transform = Affine3A::from_scale_rotation_translation(s, rotation, m.translate.0);
        let mesh = mesh.transformed(&transform);
        let extent = mesh.max_coordinate();
        if extent.is_nan() || extent > crate::values::MAX_MAGNITUDE {
            return Err(Problem::new(
                m.file.span(),
                format!("{field}.file"),
                format!(
                    "{}: after the transform a vertex lies beyond {:e} (or is not finite)",
                    m.file.get_ref(),
                    crate::values::MAX_MAGNITUDE
                ),
            ));
        }
        names.add(m.name.as_ref(), field)?;
        builder.mesh(mesh, triangle_materials);
    }
    let shading = file.shading.0;
    builder.shading(shading);
    for (i, p) in file.point_light.iter().enumerate() {
        let field = format!("point_light[{i}]");
        let power = LightPower {
            shading,
            table: p.span(),
            color: p.get_ref().color.as_ref(),
            physical: p.get_ref().intensity.as_ref(),
            physical_key: "intensity",
            physical_unit: "W/sr",
            kind: "a point light",
        };
        builder.point_light(PointLight {
            position: p.get_ref().position.0,
            color: power.value(&field)?,
        });
    }
    for (i, a) in file.area_light.iter().enumerate() {
        let field = format!("area_light[{i}]");
        let power = LightPower {
            shading,
            table: a.span(),
            color: a.get_ref().color.as_ref(),
            physical: a.get_ref().radiance.as_ref(),
            physical_key: "radiance",
            physical_unit: "W/(sr·m²)",
            kind: "an area light",
        };
        let color = power.value(&field)?;
        let a = a.get_ref();
        let light = AreaLight::new(a.center.0, a.edge1.get_ref().0, a.edge2.0, color)
            .ok_or_else(|| no_area(&field, &a.edge1))?;
        let front = front_side(&field, light.surface().normal(), a.normal.as_ref())?;
        names.add(a.name.as_ref(), field)?;
        builder.area_light(light.facing(front));
    }
    for (i, s) in file.sphere_light.iter().enumerate() {
        if shading != ShadingModel::Physical {
            return Err(Problem::new(
                s.span(),
                format!("sphere_light[{i}]"),
                "sphere lights are for shading = \"physical\"; the course's model \
                 (shading = \"phong\", the default) has point and area lights only",
            ));
        }
        let s = s.get_ref();
        let light = SphereLight::new(s.center.0, s.radius.0, s.radiance.0)
            .expect("radius read as positive");
        names.add(s.name.as_ref(), format!("sphere_light[{i}]"))?;
        builder.sphere_light(light);
    }
    builder.ambient(file.ambient.0);
    if let Some(env) = &file.environment {
        let clock = Instant::now();
        builder.environment(environment(env, base_dir, &mut assets)?);
        asset_time += clock.elapsed();
    }
    let clock = Instant::now();
    let scene = builder
        .build(camera)
        .expect("material ids were resolved above");
    let acceleration = clock.elapsed();
    let material_names = file
        .materials
        .keys()
        .cloned()
        .chain(extra_material_names)
        .collect();
    let mut seen = std::collections::HashSet::new();
    assets.retain(|p| seen.insert(p.clone()));
    Ok(SceneDescription {
        scene,
        settings,
        material_names,
        object_names: names.names,
        assets,
        regions,
        timings: LoadTimings {
            parse: start.elapsed().saturating_sub(asset_time + acceleration),
            assets: asset_time,
            acceleration,
        },
    })
}

/// Object names in the order objects enter the scene's shape list.
#[derive(Default)]
struct ObjectNames {
    names: Vec<String>,
}

/// The longest object name accepted, in characters.
const MAX_NAME: usize = 60;

impl ObjectNames {
    /// The next object's name: `given`, checked, or `default`.
    fn add(&mut self, given: Option<&Spanned<String>>, default: String) -> Result<(), Problem> {
        let name = self.checked(given, default)?;
        self.names.push(name);
        Ok(())
    }

    /// Face `face` (in `px nx py ny pz nz` order) of the box `field`: the box's
    /// name or field, then the face.
    fn add_face(
        &mut self,
        given: Option<&Spanned<String>>,
        field: &str,
        face: usize,
    ) -> Result<(), Problem> {
        const FACES: [&str; 6] = ["px", "nx", "py", "ny", "pz", "nz"];
        let base = self.checked(given, field.to_owned())?;
        self.names.push(format!("{base}.{}", FACES[face]));
        Ok(())
    }

    /// `given` if it is a usable name no other object has, else the problem;
    /// `default` when there is none.
    fn checked(&self, given: Option<&Spanned<String>>, default: String) -> Result<String, Problem> {
        let Some(name) = given else {
            return Ok(default);
        };
        let text = name.get_ref().trim();
        let problem =
            |message: String| Problem::new(name.span(), format!("{default}.name"), message);
        let length = text.chars().count();
        if length == 0 || length > MAX_NAME {
            return Err(problem(format!(
                "expected a name of 1 to {MAX_NAME} characters, got {length}"
            )));
        }
        if text.chars().any(char::is_control) {
            return Err(problem("a name cannot hold control characters".into()));
        }
        if self.names.iter().any(|n| n == text) {
            return Err(problem(format!(
                "another object is already named \"{text}\"; names must differ"
            )));
        }
        Ok(text.to_owned())
    }
}

/// The names of the textures some material reads: only those are loaded (an
/// image nothing references is neither read nor checked).
fn referenced_textures(materials: &BTreeMap<String, Spanned<MaterialTable>>) -> BTreeSet<&str> {
    materials
        .values()
        .map(Spanned::get_ref)
        .flat_map(|m| [m.diffuse.as_ref(), m.specular.as_ref()])
        .flatten()
        .filter_map(|value| match value.get_ref() {
            ColorOrTexture::Texture(name) => Some(name.as_str()),
            ColorOrTexture::Color(_) => None,
        })
        .collect()
}

/// The `[regions]` table: each a non-empty rectangle inside the render resolution.
fn regions(file: &SceneFile) -> Result<Vec<(String, [u32; 4])>, Problem> {
    let size = file.render.resolution.0;
    file.regions
        .iter()
        .map(|(name, spanned)| {
            let [x0, y0, x1, y1] = spanned.get_ref().0;
            if x0 >= x1 || y0 >= y1 || x1 > size.x || y1 > size.y {
                return Err(Problem::new(
                    spanned.span(),
                    format!("regions.{name}"),
                    format!(
                        "expected [x0, y0, x1, y1] with x0 < x1 <= {} and y0 < y1 <= {} (pixels of the {}x{} render, x1 and y1 excluded), got [{x0}, {y0}, {x1}, {y1}]",
                        size.x, size.y, size.x, size.y
                    ),
                ));
            }
            Ok((name.clone(), [x0, y0, x1, y1]))
        })
        .collect()
}

/// A light's strength as the scene's shading model reads it: the course's
/// `color` (default white) under `"phong"`, a radiometric key (`intensity`,
/// `radiance`) under `"physical"`, where it is required. Each key is refused
/// under the other model, so that a light is never read in the wrong units.
struct LightPower<'a> {
    shading: ShadingModel,
    table: std::ops::Range<usize>,
    color: Option<&'a Spanned<crate::values::Color>>,
    physical: Option<&'a Spanned<crate::values::Color>>,
    physical_key: &'static str,
    physical_unit: &'static str,
    /// "a point light" or "an area light", for messages.
    kind: &'static str,
}

impl LightPower<'_> {
    fn value(&self, field: &str) -> Result<Vec3, Problem> {
        let key = self.physical_key;
        match self.shading {
            ShadingModel::Phong => {
                if let Some(value) = self.physical {
                    return Err(Problem::new(
                        value.span(),
                        format!("{field}.{key}"),
                        format!(
                            "`{key}` is for shading = \"physical\"; this scene uses the \
                             course's model (shading = \"phong\", the default), whose lights \
                             take a `color`"
                        ),
                    ));
                }
                Ok(self.color.map_or(Vec3::ONE, |c| c.get_ref().0))
            }
            ShadingModel::Physical => {
                if let Some(color) = self.color {
                    return Err(Problem::new(
                        color.span(),
                        format!("{field}.color"),
                        format!(
                            "with shading = \"physical\" a light's strength is its `{key}` \
                             (in {}), not a `color`",
                            self.physical_unit
                        ),
                    ));
                }
                match self.physical {
                    Some(value) => Ok(value.get_ref().0),
                    None => Err(Problem::new(
                        self.table.clone(),
                        format!("{field}.{key}"),
                        format!(
                            "missing `{key}`: with shading = \"physical\" {} needs one \
                             (in {}, per channel)",
                            self.kind, self.physical_unit
                        ),
                    )),
                }
            }
        }
    }
}

fn no_area(field: &str, edge1: &Spanned<crate::values::Point>) -> Problem {
    Problem::new(
        edge1.span(),
        format!("{field}.edge1"),
        "edge1 and edge2 are parallel or zero, so the shape has no area",
    )
}

/// The front side of a flat shape: its `normal` key if given (which must be
/// perpendicular to the edges), else `edge1 × edge2`.
fn front_side(
    field: &str,
    cross: Vec3,
    normal: Option<&Spanned<crate::values::Direction>>,
) -> Result<Vec3, Problem> {
    let Some(normal) = normal else {
        return Ok(cross);
    };
    let n = normal.get_ref().0.normalize();
    if n.dot(cross).abs() < 0.999 {
        return Err(Problem::new(
            normal.span(),
            format!("{field}.normal"),
            format!(
                "expected a normal perpendicular to edge1 and edge2, i.e. along ±[{}, {}, {}]",
                cross.x, cross.y, cross.z
            ),
        ));
    }
    Ok(n)
}

fn settings(render: &RenderTable) -> Result<RenderSettings, Problem> {
    let settings = RenderSettings {
        spp: render.spp.get_ref().0,
        pixel_pattern: render.pixel_sampler.get_ref().0,
        light_samples: render.light_samples.get_ref().0,
        light_pattern: render.light_sampler.get_ref().0,
        seed: render.seed,
        threads: None,
        aov: None,
        max_depth: *render.max_depth.get_ref(),
        environment_samples: *render.environment_samples.get_ref(),
        environment_pattern: render.environment_sampler.get_ref().0,
        stats: false,
        area_sampling: render.area_sampling.0,
        mis: render.mis,
    };
    settings.validate().map_err(|e| {
        // Point at the count if the file set it, else at its sampler.
        fn at<T>(count: &Spanned<T>, sampler: &Spanned<Pattern>) -> std::ops::Range<usize> {
            if count.span().is_empty() {
                sampler.span()
            } else {
                count.span()
            }
        }
        let (field, span) = match &e {
            SettingsError::Zero { what }
            | SettingsError::TooMany { what, .. }
            | SettingsError::GridNotSquare { what, .. } => match what {
                SampleCount::PerPixel => ("render.spp", at(&render.spp, &render.pixel_sampler)),
                SampleCount::PerLight => (
                    "render.light_samples",
                    at(&render.light_samples, &render.light_sampler),
                ),
                SampleCount::PerEnvironment => (
                    "render.environment_samples",
                    at(&render.environment_samples, &render.environment_sampler),
                ),
            },
            SettingsError::Depth(_) => ("render.max_depth", render.max_depth.span()),
            // The file sets no thread count, partial render or crop, so these
            // cannot come from it.
            SettingsError::Threads(_)
            | SettingsError::ThreadPool(_)
            | SettingsError::ResumeResolution { .. }
            | SettingsError::Crop { .. } => ("render", 0..0),
        };
        Problem::new(span, field, e.to_string())
    })?;
    Ok(settings)
}

fn camera(c: &CameraTable, resolution: glam::UVec2) -> Result<Camera, Problem> {
    Camera::new(
        c.position.0,
        c.look_at.get_ref().0,
        c.up.get_ref().0,
        c.fov.0,
        c.focal_length.0,
        resolution,
    )
    .map_err(|e| {
        // fov, focal length and resolution were range-checked while reading.
        let (field, span) = match e {
            CameraError::UpParallelToForward if !c.up.span().is_empty() => {
                ("camera.up", c.up.span())
            }
            CameraError::UpParallelToForward => ("camera.look_at", c.look_at.span()),
            _ => ("camera.look_at", c.look_at.span()),
        };
        Problem::new(span, field, e.to_string())
    })
}

/// Every named texture, with image files read from `base_dir` once each.
fn textures<'a>(
    tables: &'a BTreeMap<String, TextureTable>,
    referenced: &BTreeSet<&str>,
    base_dir: &Path,
    assets: &mut Vec<PathBuf>,
) -> Result<BTreeMap<&'a str, Texture>, Problem> {
    let mut images: HashMap<PathBuf, Arc<TextureImage>> = HashMap::new();
    let mut textures = BTreeMap::new();
    for (name, table) in tables {
        // Every texture is checked; only those a material reads are loaded.
        if let TextureTable::CheckerImage(c) = table {
            checker_image_size(name, c)?;
        }
        if !referenced.contains(name.as_str()) {
            // Kept by name only, for the list of known names in errors.
            textures.insert(name.as_str(), Texture::Constant(Vec3::ZERO));
            continue;
        }
        let texture = match table {
            TextureTable::Checkerboard(c) => Texture::Checkerboard(Checkerboard {
                analytic: c.filter.0,
                ..Checkerboard::new(c.colors[0].0, c.colors[1].0, c.checks.0)
            }),
            TextureTable::CheckerImage(c) => {
                let (checks, per_check) = (c.checks.get_ref().0, c.pixels_per_check.get_ref().0);
                let checker = Checkerboard::new(c.colors[0].0, c.colors[1].0, checks);
                let image = TextureImage::from_checkerboard(checker, per_check);
                Texture::Image(ImageTexture::new(image, c.wrap.0, c.filter.0))
            }
            TextureTable::Image(i) => {
                // The same file under two spellings (./a.png, a.png) is loaded once.
                let joined = base_dir.join(i.file.get_ref());
                let path = std::fs::canonicalize(&joined).unwrap_or(joined.clone());
                let image = match images.get(&path) {
                    Some(image) => image.clone(),
                    None => {
                        // Read under the name the scene gives, which errors then show.
                        let loaded = load_image(&joined).map_err(|e| {
                            Problem::new(
                                i.file.span(),
                                format!("textures.{name}.image.file"),
                                e.to_string(),
                            )
                        })?;
                        let image = TextureImage::new(loaded);
                        assets.push(path.clone());
                        images.insert(path, image.clone());
                        image
                    }
                };
                Texture::Image(ImageTexture::new(image, i.wrap.0, i.filter.0))
            }
        };
        textures.insert(name.as_str(), texture);
    }
    Ok(textures)
}

/// A checker image's side, `checks × pixels_per_check`, within
/// [`MAX_IMAGE_TEXELS`] (in u64 and saturating: the product of two large
/// counts must not wrap).
fn checker_image_size(name: &str, c: &CheckerImageTable) -> Result<(), Problem> {
    let (checks, per_check) = (c.checks.get_ref().0, c.pixels_per_check.get_ref().0);
    let side = checks as u64 * per_check as u64;
    if side.saturating_mul(side) <= MAX_IMAGE_TEXELS {
        return Ok(());
    }
    // Point at pixels_per_check if the file set it, else at checks.
    let (key, span) = if c.pixels_per_check.span().is_empty() {
        ("checks", c.checks.span())
    } else {
        ("pixels_per_check", c.pixels_per_check.span())
    };
    Err(Problem::new(
        span,
        format!("textures.{name}.checker_image.{key}"),
        format!(
            "the image would be {side}x{side} texels (checks × pixels_per_check per side), more than the limit of {MAX_IMAGE_TEXELS} texels"
        ),
    ))
}

fn material(
    name: &str,
    spanned: &Spanned<MaterialTable>,
    textures: &BTreeMap<&str, Texture>,
) -> Result<PhongMaterial, Problem> {
    let table = spanned.get_ref();
    if let Some(tint) = &table.mirror {
        if table.diffuse.is_some() || table.specular.is_some() || table.reflectivity.0 > 0.0 {
            return Err(Problem::new(
                tint.span(),
                format!("materials.{name}.mirror"),
                "a mirror takes no diffuse, specular or reflectivity (use reflectivity on a Phong material to blend)",
            ));
        }
        return Ok(PhongMaterial::mirror(tint.get_ref().0));
    }
    let Some(diffuse) = &table.diffuse else {
        return Err(Problem::new(
            spanned.span(),
            format!("materials.{name}"),
            "missing field `diffuse` (or `mirror` for a mirror)",
        ));
    };
    let input = |key: &str, value: &Spanned<ColorOrTexture>| match value.get_ref() {
        ColorOrTexture::Color(c) => Ok(Texture::Constant(c.0)),
        ColorOrTexture::Texture(t) => textures.get(t.as_str()).cloned().ok_or_else(|| {
            let known: Vec<_> = textures.keys().map(|k| format!("\"{k}\"")).collect();
            Problem::new(
                value.span(),
                format!("materials.{name}.{key}"),
                format!(
                    "no texture named \"{t}\" (defined: {})",
                    if known.is_empty() {
                        "none".into()
                    } else {
                        known.join(", ")
                    }
                ),
            )
        }),
    };
    Ok(PhongMaterial {
        diffuse: input("diffuse", diffuse)?,
        specular: table
            .specular
            .as_ref()
            .map(|s| input("specular", s))
            .transpose()?,
        shininess: table.shininess.0,
        lobe: table.lobe.map(|l| l.0).unwrap_or_default(),
        uv_transform: UvTransform {
            scale: table.uv_scale.0,
            offset: table.uv_offset.0,
        },
        reflectivity: table.reflectivity.0,
        mirror_tint: table.reflection_tint.0,
    })
}

/// The environment light: one source (constant, cube map, lat-long image), turned
/// and scaled.
fn environment(
    spanned: &Spanned<EnvironmentTable>,
    base_dir: &Path,
    assets: &mut Vec<PathBuf>,
) -> Result<EnvironmentLight, Problem> {
    let e = spanned.get_ref();
    let sources = [e.color.is_some(), e.cube_map.is_some(), e.latlong.is_some()];
    if sources.iter().filter(|s| **s).count() != 1 {
        return Err(Problem::new(
            spanned.span(),
            "environment",
            "expected exactly one of `color`, `cube_map` or `latlong`",
        ));
    }
    let mut load = |file: &Spanned<String>, path: &str, field: &str| {
        let path = base_dir.join(path);
        let image =
            load_image(&path).map_err(|err| Problem::new(file.span(), field, err.to_string()))?;
        assets.push(path);
        Ok(image)
    };
    let map = if let Some(c) = e.color {
        Environment::Constant(c.0)
    } else if let Some(template) = &e.cube_map {
        if !template.get_ref().contains("{face}") {
            return Err(Problem::new(
                template.span(),
                "environment.cube_map",
                "expected a path template containing {face}, e.g. \"studio/{face}.hdr\"",
            ));
        }
        let mut faces = Vec::with_capacity(6);
        for face in ["px", "nx", "py", "ny", "pz", "nz"] {
            faces.push(load(
                template,
                &template.get_ref().replace("{face}", face),
                "environment.cube_map",
            )?);
        }
        let faces: [Image; 6] = faces.try_into().expect("six faces");
        let texels: u64 = faces
            .iter()
            .map(|f| f.width() as u64 * f.height() as u64)
            .sum();
        if texels > MAX_IMAGE_TEXELS {
            return Err(Problem::new(
                template.span(),
                "environment.cube_map",
                format!("the six faces have {texels} texels in all, more than the limit of {MAX_IMAGE_TEXELS}"),
            ));
        }
        Environment::CubeMap(
            CubeMap::new(faces)
                .map_err(|m| Problem::new(template.span(), "environment.cube_map", m))?,
        )
    } else {
        let file = e.latlong.as_ref().expect("one source");
        Environment::LatLong(LatLongMap::new(load(
            file,
            file.get_ref(),
            "environment.latlong",
        )?))
    };
    Ok(EnvironmentLight::new(
        map,
        e.rotation.0.to_radians(),
        e.intensity.0,
    ))
}
