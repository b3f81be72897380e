//! The loaded scene as a Mitsuba 3 XML document and the files beside it.

use super::xml::{number, vector, Xml};
use super::{environment, ply, Warning};
use crate::SceneDescription;
use glam::{Affine2, Vec2, Vec3};
use glint_camera::Film;
use glint_geometry::{AaBox, ObjectRef, Parallelogram, Plane, Ray, Shape, TriangleMesh};
use glint_integrator::{Scene, ShadingModel, Surface};
use glint_lighting::{Light, PhongMaterial, SpecularLobe};
use glint_texture::{Checkerboard, Environment, ImageTexture, Texture, TextureFilter, WrapMode};
use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};

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

/// How far a plane's stand-in rectangle reaches, in units of the scene's size:
/// its half side is this many times the largest distance from the point below
/// the camera to anything else in the scene.
const PLANE_REACH: f32 = 10_000.0;

/// Converts `description` for Mitsuba 3. Files are referred to as
/// `ASSETS/NAME`, `assets` being the assets folder's path relative to the XML
/// file (its name, as [`super::export`] places it beside the XML).
pub fn convert(description: &SceneDescription, assets: &str) -> Conversion {
    Converter::new(description, assets).run()
}

/// A BSDF as written once and referred to by id: the material, the map from
/// Mitsuba's uv to Glint's (only for textured materials) and whether it is
/// wrapped in `twosided`.
type BsdfKey = (u32, Option<[u32; 6]>, bool);

struct Converter<'a> {
    scene: &'a Scene,
    description: &'a SceneDescription,
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
    fn new(description: &'a SceneDescription, assets: &str) -> Self {
        let scene = &description.scene;
        let extent = scene_points(scene)
            .map(|p| p.distance(scene.camera.position()))
            .fold(0.0f32, f32::max);
        Self {
            scene,
            description,
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
        let scene = self.scene;
        if scene.shading == ShadingModel::Phong {
            self.warn(
                "the scene uses the course's Phong model (shading = \"phong\"), which has no \
                 physical counterpart (no distance falloff, no normalisation): its lights' colors \
                 are written as Mitsuba's point-light intensities and area-light radiances, so \
                 the images will differ in value (shading = \"physical\" makes them comparable)"
                    .into(),
            );
        }
        if scene.ambient != Vec3::ZERO {
            self.warn(format!(
                "ambient [{}] is dropped: Mitsuba 3 has no ambient term",
                vector(scene.ambient)
            ));
        }
        for object in 0..scene.shapes.len() as u32 {
            match (scene.shapes.object(object), scene.surfaces[object as usize]) {
                (ObjectRef::Shape(shape), Surface::Material(m)) => self.shape(shape, m),
                (ObjectRef::Mesh(mesh), Surface::Mesh(k)) => {
                    self.mesh(mesh, &scene.mesh_materials[k as usize], k)
                }
                // Area lights' surfaces are written with their lights.
                _ => {}
            }
        }
        for light in &scene.lights {
            #[allow(unreachable_patterns)]
            match light {
                Light::Point(p) => {
                    self.shapes.open("emitter", &[("type", "point")]);
                    self.shapes
                        .property("point", "position", &vector(p.position));
                    self.shapes.rgb("intensity", p.color);
                    self.shapes.close("emitter");
                }
                Light::Area(a) => {
                    let n = self.count("area-light");
                    let id = self.unique_id(&format!("area-light-{n}"));
                    let (to_world, _) = rectangle(a.surface());
                    self.shapes
                        .open("shape", &[("type", "rectangle"), ("id", &id)]);
                    self.shapes.matrix("to_world", to_world);
                    self.shapes.comment(
                        "Glint does not shade a light's surface: black, so that Mitsuba adds nothing to its emission",
                    );
                    self.black_emitter(a.color);
                }
                Light::Sphere(s) => {
                    let n = self.count("sphere-light");
                    let id = self.unique_id(&format!("sphere-light-{n}"));
                    let sphere = s.surface();
                    self.shapes
                        .open("shape", &[("type", "sphere"), ("id", &id)]);
                    self.shapes
                        .property("point", "center", &vector(sphere.center()));
                    self.shapes.float("radius", sphere.radius());
                    self.black_emitter(s.color);
                }
                // A kind of light added to Glint after this exporter was written.
                _ => self.warn(format!(
                    "a light of a kind the exporter does not know is left out: {light:?}"
                )),
            }
        }
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

    fn late_warnings(&mut self) {
        if !self.mirrors.is_empty() {
            let names = quoted(&self.mirrors);
            self.warn(format!(
                "Mitsuba 3's `direct` integrator does not follow mirror reflections: the mirrors \
                 of {names} show only what emits (area lights, the environment), and surfaces seen \
                 in them are black, where Glint follows up to {} reflections",
                self.description.settings.max_depth
            ));
        }
        if !self.blends.is_empty() {
            let names = quoted(&self.blends);
            let verb = if self.blends.len() == 1 {
                "blends"
            } else {
                "blend"
            };
            self.warn(format!(
                "{names} {verb} a perfect mirror into a diffuse BSDF (`blendbsdf`), which \
                 Mitsuba 3.9 renders biased with multiple importance sampling (its sampling \
                 reports the chosen lobe's density, not the blend's; a sphere of reflectivity 0.3 \
                 under a uniform sky came out 6-37% too dark per channel)"
            ));
        }
        if !self.unfiltered.is_empty() {
            let names: Vec<String> = self.unfiltered.iter().cloned().collect();
            self.warn(format!(
                "Mitsuba 3's bitmap textures have no MIP maps: the trilinear or EWA-filtered \
                 textures of {} are looked up bilinearly at full resolution (minified, they \
                 come out a little sharper and noisier than in Glint)",
                quoted(&names)
            ));
        }
        if self.description.settings.seed > u32::MAX as u64 {
            let seed = self.description.settings.seed;
            self.warn(format!(
                "seed {seed} does not fit Mitsuba's 32-bit sampler seed: written as {}",
                seed as u32
            ));
        }
    }

    /// The `direct` integrator's emitter and BSDF samples: Glint's light
    /// samples for both, except with point lights, which Mitsuba 3's `direct`
    /// counts once per emitter sample without dividing by their number
    /// (mitsuba3 issue #1861): then one emitter sample, which is exact for
    /// them.
    fn integrator_samples(&mut self) -> (u32, u32) {
        let n = self.description.settings.light_samples;
        let points = self
            .scene
            .lights
            .iter()
            .any(|l| matches!(l, Light::Point(_)));
        if points && n > 1 {
            self.warn(format!(
                "Mitsuba 3's `direct` integrator counts a point light once per emitter sample \
                 without dividing by their number (mitsuba3 issue #1861; so in 3.9.1), so this \
                 scene with point lights is written with emitter_samples = 1 and bsdf_samples = \
                 {n}, not {n} and {n}: exact for point lights, noisier for area lights and the \
                 environment"
            ));
            (1, n)
        } else {
            (n, n)
        }
    }

    /// Flat shapes and area lights that turn their backs to the camera: Glint
    /// sees through them from behind, Mitsuba sees them black.
    fn facing_warnings(&mut self) {
        let camera = self.scene.camera.position();
        let behind = |p: &Parallelogram| (camera - p.center()).dot(p.normal()) < 0.0;
        let mut shapes = Vec::new();
        let mut n = 0;
        for object in 0..self.scene.shapes.len() as u32 {
            let (ObjectRef::Shape(Shape::Parallelogram(p)), Surface::Material(_)) = (
                self.scene.shapes.object(object),
                self.scene.surfaces[object as usize],
            ) else {
                continue;
            };
            let one_sided =
                !seen_from_behind(p.center(), p.normal(), |r| p.hit_distance(r, f32::INFINITY));
            if one_sided && behind(p) {
                shapes.push(format!("parallelogram {n}"));
            }
            n += 1;
        }
        for (i, light) in self.scene.lights.iter().enumerate() {
            if let Light::Area(a) = light {
                if behind(a.surface()) {
                    shapes.push(format!("area light {i}"));
                }
            }
        }
        if !shapes.is_empty() {
            let (turn, it) = match shapes.len() {
                1 => ("turns its back", "it is"),
                _ => ("turn their backs", "they are"),
            };
            self.warn(format!(
                "{} {turn} to the camera: where {it} in view, Glint sees through (one-sided \
                 surfaces and lights are invisible from behind) and Mitsuba sees black",
                shapes.join(", ")
            ));
        }
    }

    /// The whole document: integrator, sensor, BSDFs, shapes and emitters.
    fn document(&self, emitter_samples: u32, bsdf_samples: u32) -> String {
        let settings = &self.description.settings;
        let camera = &self.scene.camera;
        let mut xml = Xml::new();
        xml.open("scene", &[("version", "3.0.0")]);
        xml.comment(
            "Written by Glint (glint export, for Mitsuba 3). Render it with `mitsuba FILE.xml`, \
             or mi.render(mi.load_file(\"FILE.xml\")) in Python.",
        );
        xml.comment(match self.scene.shading {
            ShadingModel::Physical => "Shading model: physical (radiometric units).",
            ShadingModel::Phong => {
                "Shading model: the course's Phong model, written as if it were physical (the values differ)."
            }
        });
        xml.comment(
            "Glint's light samples per camera sample become emitter and BSDF samples, \
             which Mitsuba combines by multiple importance sampling.",
        );
        xml.open("integrator", &[("type", "direct")]);
        xml.integer("emitter_samples", emitter_samples as u64);
        xml.integer("bsdf_samples", bsdf_samples as u64);
        xml.close("integrator");

        let resolution = camera.resolution();
        let near = (1e-4 * self.extent).clamp(1e-6, 1e-2);
        let far = (4.0 * self.far).max(1e4);
        xml.open("sensor", &[("type", "perspective")]);
        xml.string("fov_axis", "y");
        xml.float("fov", camera.fov_y().to_degrees());
        xml.float("near_clip", near);
        xml.float("far_clip", far);
        xml.open("transform", &[("name", "to_world")]);
        xml.leaf(
            "lookat",
            &[
                ("origin", &vector(camera.position())),
                ("target", &vector(camera.position() + camera.forward())),
                ("up", &vector(camera.up())),
            ],
        );
        xml.close("transform");
        xml.open("sampler", &[("type", "independent")]);
        xml.integer("sample_count", settings.spp as u64);
        xml.integer("seed", settings.seed as u32 as u64);
        xml.close("sampler");
        xml.open("film", &[("type", "hdrfilm")]);
        xml.integer("width", resolution.x as u64);
        xml.integer("height", resolution.y as u64);
        xml.string("pixel_format", "rgb");
        xml.leaf("rfilter", &[("type", "box")]);
        xml.close("film");
        xml.close("sensor");
        let mut text = xml.finish();
        text.push_str(self.bsdfs.text());
        text.push_str(self.shapes.text());
        text.push_str("</scene>\n");
        format!("<?xml version=\"1.0\" encoding=\"utf-8\"?>\n{text}")
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

    // -- shapes -------------------------------------------------------------

    fn shape(&mut self, shape: &Shape, material: u32) {
        match shape {
            Shape::Sphere(s) => {
                let n = self.count("sphere");
                let id = self.unique_id(&format!("sphere-{n}"));
                let (to_world, uv) = sphere(s);
                // Closed: Glint shades it from inside too.
                let bsdf = self.bsdf(material, uv, true);
                self.write_shape("sphere", &id, to_world, &bsdf, &[]);
            }
            Shape::Parallelogram(p) => {
                let n = self.count("parallelogram");
                let id = self.unique_id(&format!("parallelogram-{n}"));
                let (to_world, uv) = rectangle(p);
                let bsdf = self.bsdf(
                    material,
                    uv,
                    seen_from_behind(p.center(), p.normal(), |r| p.hit_distance(r, f32::INFINITY)),
                );
                self.write_shape("rectangle", &id, to_world, &bsdf, &[]);
            }
            Shape::Plane(p) => self.plane(p, material),
            Shape::Box(b) => self.aabox(b, material),
        }
    }

    /// How many shapes of `kind` were written before this one (its number).
    fn count(&mut self, kind: &'static str) -> usize {
        let n = self.counts.entry(kind).or_default();
        *n += 1;
        *n - 1
    }

    fn write_shape(
        &mut self,
        kind: &str,
        id: &str,
        to_world: [[f32; 4]; 4],
        bsdf: &str,
        comments: &[String],
    ) {
        self.shapes.open("shape", &[("type", kind), ("id", id)]);
        for c in comments {
            self.shapes.comment(c);
        }
        self.shapes.matrix("to_world", to_world);
        self.shapes.leaf("ref", &[("id", bsdf)]);
        self.shapes.close("shape");
    }

    fn plane(&mut self, plane: &Plane, material: u32) {
        let k = self.count("plane");
        let id = self.unique_id(&format!("plane-{k}"));
        let n = plane.normal();
        let (_, _, tile) = plane_frame(plane);
        let camera = self.scene.camera.position();
        let height = (camera - plane.point()).dot(n);
        let anchor = camera - height * n;
        let reach = scene_points(self.scene)
            .map(|p| p.distance(anchor))
            .fold(tile, f32::max);
        let half = PLANE_REACH * reach;
        self.far = self.far.max(half + reach);
        let (to_world, uv) = plane_rectangle(plane, anchor, half);
        let two_sided =
            seen_from_behind(plane.point(), n, |r| plane.hit_distance(r, f32::INFINITY));
        let bsdf = self.bsdf(material, uv, two_sided);
        let size = format_size(2.0 * half);
        let below = format_size((height.abs() / half).atan().to_degrees());
        let name = self.material_name(material);
        self.warn(format!(
            "plane {k} (material \"{name}\") is written as a {size} × {size} rectangle centred \
             below the camera: Mitsuba 3 has no infinite plane (seen from the camera, its far \
             edge lies {below}° below the horizon)"
        ));
        let comment = format!("Glint's infinite plane {k}, as a {size} × {size} rectangle");
        self.write_shape("rectangle", &id, to_world, &bsdf, &[comment]);
    }

    fn aabox(&mut self, aabox: &AaBox, material: u32) {
        let n = self.count("box");
        let id = format!("box-{n}");
        for (face, name) in aabox
            .face_parallelograms()
            .iter()
            .zip(["px", "nx", "py", "ny", "pz", "nz"])
        {
            let (to_world, uv) = rectangle(face);
            // Closed: Glint shades its faces from inside too.
            let bsdf = self.bsdf(material, uv, true);
            let face_id = self.unique_id(&format!("{id}-{name}"));
            self.write_shape("rectangle", &face_id, to_world, &bsdf, &[]);
        }
    }

    fn mesh(&mut self, mesh: &TriangleMesh, materials: &[u32], k: u32) {
        let mut groups: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
        for (triangle, &m) in materials.iter().enumerate() {
            groups.entry(m).or_default().push(triangle as u32);
        }
        let split = groups.len() > 1;
        for (g, (material, triangles)) in groups.into_iter().enumerate() {
            let stem = if split {
                format!("mesh-{k}-{g}")
            } else {
                format!("mesh-{k}")
            };
            let id = self.unique_id(&stem);
            let file = format!("{id}.ply");
            self.files.push(SideFile {
                name: file.clone(),
                contents: SideContents::Bytes(ply::ply(mesh, &triangles)),
            });
            // Glint shades a triangle on the side it is seen from.
            let bsdf = self.bsdf(material, Affine2::IDENTITY, true);
            self.shapes.open("shape", &[("type", "ply"), ("id", &id)]);
            if split {
                let name = self.material_name(material);
                self.shapes.comment(&format!(
                    "the {} triangles of mesh {k} made of \"{name}\"",
                    triangles.len()
                ));
            }
            self.shapes
                .string("filename", &format!("{}/{file}", self.assets));
            self.shapes.leaf("ref", &[("id", &bsdf)]);
            self.shapes.close("shape");
        }
    }

    // -- materials ----------------------------------------------------------

    /// The id of the BSDF of `material` on a shape whose Mitsuba uv maps to
    /// Glint's by `uv`, written on first use.
    fn bsdf(&mut self, material: u32, uv: Affine2, two_sided: bool) -> String {
        let scene = self.scene;
        let m = &scene.materials[material as usize];
        let textured = m.has_local_shading() && !matches!(m.diffuse, Texture::Constant(_));
        let key = (
            material,
            textured.then(|| uv.to_cols_array().map(f32::to_bits)),
            two_sided,
        );
        if let Some(id) = self.bsdf_ids.get(&key) {
            return id.clone();
        }
        self.note_material(material);
        let name = self.material_name(material);
        let id = self.unique_id(&name);
        let mut xml = Xml::with_depth(1);
        if id != name {
            xml.comment(&format!("material \"{name}\""));
        }
        if two_sided {
            xml.open("bsdf", &[("type", "twosided"), ("id", &id)]);
            self.write_bsdf(&mut xml, m, &name, uv, None);
            xml.close("bsdf");
        } else {
            self.write_bsdf(&mut xml, m, &name, uv, Some(&id));
        }
        self.bsdfs.append(xml);
        self.bsdf_ids.insert(key, id.clone());
        id
    }

    fn write_bsdf(
        &mut self,
        xml: &mut Xml,
        m: &PhongMaterial,
        name: &str,
        uv: Affine2,
        id: Option<&str>,
    ) {
        let r = m.reflectivity;
        if r >= 1.0 {
            mirror(xml, m.mirror_tint, id);
        } else if r > 0.0 {
            open_bsdf(xml, "blendbsdf", id);
            xml.float("weight", r);
            self.diffuse(xml, m, name, uv, None);
            mirror(xml, m.mirror_tint, None);
            xml.close("bsdf");
        } else {
            self.diffuse(xml, m, name, uv, id);
        }
    }

    fn diffuse(
        &mut self,
        xml: &mut Xml,
        m: &PhongMaterial,
        name: &str,
        uv: Affine2,
        id: Option<&str>,
    ) {
        open_bsdf(xml, "diffuse", id);
        // Texture lookups read uv · scale + offset (the material's uv transform).
        let material_uv =
            Affine2::from_scale_angle_translation(m.uv_transform.scale, 0.0, m.uv_transform.offset);
        self.texture(xml, "reflectance", &m.diffuse, material_uv * uv, name);
        xml.close("bsdf");
    }

    /// `texture` as the property `property`, read at Glint's uv `uv(Mitsuba uv)`.
    fn texture(
        &mut self,
        xml: &mut Xml,
        property: &str,
        texture: &Texture,
        uv: Affine2,
        material: &str,
    ) {
        match texture {
            Texture::Constant(c) => xml.rgb(property, *c),
            Texture::Checkerboard(c) => checkerboard(xml, property, c, uv),
            Texture::Image(image) => match image.image.pattern() {
                // A rasterised checkerboard repeats as the pattern does only when
                // it repeats and has an even number of checks.
                Some(pattern) if image.wrap == WrapMode::Repeat && pattern.checks % 2 == 0 => {
                    checkerboard(xml, property, pattern, uv)
                }
                _ => self.bitmap(xml, property, image, uv, material),
            },
        }
    }

    fn bitmap(
        &mut self,
        xml: &mut Xml,
        property: &str,
        texture: &ImageTexture,
        uv: Affine2,
        material: &str,
    ) {
        let key = std::sync::Arc::as_ptr(&texture.image) as usize;
        let file = match self.images.get(&key) {
            Some(file) => file.clone(),
            None => {
                let file = format!("texture-{}.exr", self.images.len());
                let image = texture.image.image();
                let mut film = Film::new(glam::UVec2::new(image.width(), image.height()));
                film.pixels_mut().copy_from_slice(image.texels());
                self.files.push(SideFile {
                    name: file.clone(),
                    contents: SideContents::Exr(film),
                });
                self.images.insert(key, file.clone());
                file
            }
        };
        if matches!(
            texture.filter,
            TextureFilter::Trilinear | TextureFilter::Ewa
        ) {
            self.unfiltered.insert(material.to_owned());
        }
        xml.open("texture", &[("type", "bitmap"), ("name", property)]);
        xml.string("filename", &format!("{}/{file}", self.assets));
        xml.string(
            "filter_type",
            match texture.filter {
                TextureFilter::Nearest => "nearest",
                _ => "bilinear",
            },
        );
        xml.string(
            "wrap_mode",
            match texture.wrap {
                WrapMode::Repeat => "repeat",
                WrapMode::Clamp => "clamp",
                WrapMode::Mirror => "mirror",
            },
        );
        // Glint reads images at st = (u, 1 − v) with row 0 at the top, as Mitsuba
        // reads its uv (row 0 at v = 0).
        xml.texture_transform(Affine2::from_cols(Vec2::X, -Vec2::Y, Vec2::Y) * uv);
        xml.close("texture");
    }

    /// The warnings a material earns once: its dropped specular term, its mirror.
    fn note_material(&mut self, material: u32) {
        if !self.noted.insert(material) {
            return;
        }
        let scene = self.scene;
        let m = &scene.materials[material as usize];
        let name = self.material_name(material);
        if m.reflectivity > 0.0 {
            self.mirrors.push(name.clone());
        }
        if m.reflectivity > 0.0 && m.reflectivity < 1.0 {
            self.blends.push(name.clone());
        }
        if !m.has_local_shading() {
            return;
        }
        let ks = match m.specular.as_ref() {
            None => match &m.diffuse {
                Texture::Constant(c) if *c == Vec3::ZERO => None,
                Texture::Constant(c) => Some(format!("[{}], the diffuse color", vector(*c))),
                _ => Some("the diffuse texture".to_owned()),
            },
            Some(Texture::Constant(c)) if *c == Vec3::ZERO => None,
            Some(Texture::Constant(c)) => Some(format!("[{}]", vector(*c))),
            Some(_) => Some("a texture".to_owned()),
        };
        if let Some(ks) = ks {
            let lobe = match m.lobe {
                SpecularLobe::Phong => "",
                SpecularLobe::BlinnPhong => "Blinn-Phong lobe, ",
            };
            self.warn(format!(
                "Mitsuba 3 has no Phong lobe: material \"{name}\"'s specular term (ks={ks}, \
                 {lobe}shininess {}) is dropped",
                number(m.shininess)
            ));
        }
    }

    /// Closes an open light `shape` with a black `diffuse` BSDF (Glint does
    /// not shade a light's surface) and an `area` emitter of `radiance`.
    fn black_emitter(&mut self, radiance: Vec3) {
        self.shapes.open("bsdf", &[("type", "diffuse")]);
        self.shapes.rgb("reflectance", Vec3::ZERO);
        self.shapes.close("bsdf");
        self.shapes.open("emitter", &[("type", "area")]);
        self.shapes.rgb("radiance", radiance);
        self.shapes.close("emitter");
        self.shapes.close("shape");
    }

    // -- the environment ----------------------------------------------------

    fn environment(&mut self) {
        let Some(light) = &self.scene.environment else {
            return;
        };
        match light.environment() {
            Environment::Constant(_) => {
                self.shapes.open("emitter", &[("type", "constant")]);
                self.shapes.rgb("radiance", light.radiance(Vec3::Y, 0.0));
                self.shapes.close("emitter");
            }
            map => {
                let size = environment::image_size(map).expect("a map has a size");
                let file = "environment.exr".to_owned();
                self.files.push(SideFile {
                    name: file.clone(),
                    contents: SideContents::Exr(environment::latlong_film(light, size)),
                });
                let what = match map {
                    Environment::CubeMap(_) => "the cube map",
                    _ => "the lat-long map",
                };
                self.shapes.comment(&format!(
                    "{what} with its intensity, on Mitsuba's lat-long grid (rows on the \
                     poles); to_world turns it by its rotation plus half a turn (Mitsuba's \
                     u = 0 looks down -z, Glint's u = 1/2)"
                ));
                self.shapes.open("emitter", &[("type", "envmap")]);
                self.shapes
                    .string("filename", &format!("{}/{file}", self.assets));
                self.shapes.matrix("to_world", environment::to_world(light));
                self.shapes.close("emitter");
            }
        }
    }
}

fn open_bsdf(xml: &mut Xml, kind: &str, id: Option<&str>) {
    match id {
        Some(id) => xml.open("bsdf", &[("type", kind), ("id", id)]),
        None => xml.open("bsdf", &[("type", kind)]),
    }
}

/// A perfect mirror whose reflection is multiplied by `tint`.
fn mirror(xml: &mut Xml, tint: Vec3, id: Option<&str>) {
    open_bsdf(xml, "conductor", id);
    xml.string("material", "none");
    xml.rgb("specular_reflectance", tint);
    xml.close("bsdf");
}

/// A Mitsuba `rectangle` ([−1, 1]² in its local xy plane, facing +z) onto
/// `origin + α·edge1 + β·edge2`, facing the front normal, and the map from its
/// uv to Glint's `(α, β)`. Mitsuba's normal is the inverse transpose of the
/// matrix applied to +z; keeping the determinant positive (swapping the
/// edges, which spans the same parallelogram, and so u and v) keeps the
/// triangles' winding in agreement with it.
pub(super) fn rectangle(p: &Parallelogram) -> ([[f32; 4]; 4], Affine2) {
    let (e1, e2) = p.edges();
    let n = p.normal();
    if e1.cross(e2).dot(n) >= 0.0 {
        (
            columns(0.5 * e1, 0.5 * e2, n, p.center()),
            Affine2::IDENTITY,
        )
    } else {
        let swap = Affine2::from_cols(Vec2::Y, Vec2::X, Vec2::ZERO);
        (columns(0.5 * e2, 0.5 * e1, n, p.center()), swap)
    }
}

/// A plane's tangent frame and tile size, as its hits report them.
fn plane_frame(plane: &Plane) -> (Vec3, Vec3, f32) {
    let n = plane.normal();
    let hit = plane.surface_at(&Ray::new(plane.point() + n, -n), 1.0);
    let tile = hit.dpdu.length();
    (hit.dpdu / tile, hit.dpdv / hit.dpdv.length(), tile)
}

/// A Mitsuba `rectangle` standing in for `plane`: `anchor ± half·t ± half·b`
/// in its tangent frame, and the map from its uv to Glint's. The point
/// `(2u − 1)·half` along `t` from the anchor has Glint's u at the anchor plus
/// that over the tile size.
pub(super) fn plane_rectangle(plane: &Plane, anchor: Vec3, half: f32) -> ([[f32; 4]; 4], Affine2) {
    let (t, b, tile) = plane_frame(plane);
    let n = plane.normal();
    let base = Vec2::new(
        (anchor - plane.point()).dot(t),
        (anchor - plane.point()).dot(b),
    ) / tile;
    let s = 2.0 * half / tile;
    let offset = base - Vec2::splat(half / tile);
    let (first, second, uv) = if t.cross(b).dot(n) >= 0.0 {
        (
            t,
            b,
            Affine2::from_cols(Vec2::new(s, 0.0), Vec2::new(0.0, s), offset),
        )
    } else {
        (
            b,
            t,
            Affine2::from_cols(Vec2::new(0.0, s), Vec2::new(s, 0.0), offset),
        )
    };
    (columns(first * half, second * half, n, anchor), uv)
}

/// A Mitsuba `sphere` in Glint's place, and the map from its uv to Glint's.
/// Glint's sphere uv: u = atan2(−z, x)/2π about +y, v up from the bottom
/// pole. Mitsuba's: u = atan2(y, x)/2π about its local +z, v down from the top
/// pole. Local x, y, z → world x, −z, y makes the u's agree; v is mirrored.
pub(super) fn sphere(s: &glint_geometry::Sphere) -> ([[f32; 4]; 4], Affine2) {
    let (r, c) = (s.radius(), s.center());
    let to_world = columns(r * Vec3::X, -r * Vec3::Z, r * Vec3::Y, c);
    (to_world, Affine2::from_cols(Vec2::X, -Vec2::Y, Vec2::Y))
}

/// The 4×4 matrix (row by row) with these columns and translation.
fn columns(x: Vec3, y: Vec3, z: Vec3, t: Vec3) -> [[f32; 4]; 4] {
    [
        [x.x, y.x, z.x, t.x],
        [x.y, y.y, z.y, t.y],
        [x.z, y.z, z.z, t.z],
        [0.0, 0.0, 0.0, 1.0],
    ]
}

/// Whether a flat shape is seen from behind (two-sided): a ray towards its
/// front from behind `point` meets it.
fn seen_from_behind(point: Vec3, normal: Vec3, hit: impl Fn(&Ray) -> Option<f32>) -> bool {
    let reach = 1.0 + point.abs().max_element();
    hit(&Ray::new(point - reach * normal, normal)).is_some()
}

/// A checkerboard as Mitsuba's `checkerboard`: its pattern has 2 × 2 checks
/// over the unit square (`color0` where `frac(u) > ½` equals `frac(v) > ½`),
/// which is Glint's N × N (first color where the check's indices sum to an
/// even number) once uv is scaled by N/2.
fn checkerboard(xml: &mut Xml, property: &str, c: &Checkerboard, uv: Affine2) {
    xml.open("texture", &[("type", "checkerboard"), ("name", property)]);
    xml.rgb("color0", c.colors[0]);
    xml.rgb("color1", c.colors[1]);
    xml.texture_transform(Affine2::from_scale(Vec2::splat(c.checks as f32 / 2.0)) * uv);
    xml.close("texture");
}

/// Every point that bounds the scene's finite objects: spheres' and boxes'
/// corners, parallelograms' corners, mesh vertices, lights, and the camera.
fn scene_points(scene: &Scene) -> impl Iterator<Item = Vec3> + '_ {
    let shapes = scene.shapes.shapes().iter().flat_map(|s| -> Vec<Vec3> {
        match s {
            Shape::Sphere(s) => vec![s.center() - s.radius(), s.center() + s.radius()],
            Shape::Parallelogram(p) => p.corners().to_vec(),
            Shape::Box(b) => vec![b.min(), b.max()],
            Shape::Plane(p) => vec![p.point()],
        }
    });
    let meshes = scene
        .shapes
        .meshes()
        .iter()
        .flat_map(|m| m.positions().iter().copied());
    let lights = scene.lights.iter().flat_map(|l| -> Vec<Vec3> {
        #[allow(unreachable_patterns)]
        match l {
            Light::Point(p) => vec![p.position],
            Light::Area(a) => a.surface().corners().to_vec(),
            Light::Sphere(s) => {
                let (c, r) = (s.surface().center(), s.surface().radius());
                vec![c - Vec3::splat(r), c + Vec3::splat(r)]
            }
            _ => vec![],
        }
    });
    std::iter::once(scene.camera.position())
        .chain(shapes)
        .chain(meshes)
        .chain(lights)
}

fn quoted(names: &[String]) -> String {
    let quoted: Vec<String> = names.iter().map(|n| format!("\"{n}\"")).collect();
    match quoted.len() {
        1 => format!("material {}", quoted[0]),
        _ => format!("materials {}", quoted.join(", ")),
    }
}

/// A length or an angle for a message: three significant digits.
fn format_size(x: f32) -> String {
    if x == 0.0 {
        "0".into()
    } else if (1e-4..1e5).contains(&x) {
        let digits = (2 - x.log10().floor() as i32).max(0) as usize;
        format!("{x:.digits$}")
    } else {
        format!("{x:.2e}")
    }
}
