use glam::Vec3;
use glint_camera::Camera;
use glint_geometry::{Hit, Shape, ShapeList, TriangleMesh};
use glint_lighting::{
    AreaLight, EnvironmentLight, Light, PhongMaterial, PointLight, ShadingModel, SphereLight,
};
use glint_texture::{Texture, TextureFilter};

/// What a shape is to the integrator: a reflecting surface or an emitter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Surface {
    /// Shaded with the material at this index of [`Scene::materials`].
    Material(u32),
    /// The visible face of the light at this index of [`Scene::lights`].
    Emitter(u32),
    /// A triangle mesh whose triangles' materials are listed at this index of
    /// [`Scene::mesh_materials`].
    Mesh(u32),
}

/// What a hit point is made of.
pub enum SurfaceKind<'a> {
    Material(&'a PhongMaterial),
    Emitter(&'a Light),
}

/// The scene as the integrator sees it: a camera, shapes in one flat list with a
/// [`Surface`] per shape, materials, lights and an ambient term.
#[derive(Clone, Debug)]
pub struct Scene {
    pub camera: Camera,
    pub shapes: ShapeList,
    /// `surfaces[i]` describes object `i` of `shapes` (a shape or a mesh).
    pub surfaces: Vec<Surface>,
    pub materials: Vec<PhongMaterial>,
    pub lights: Vec<Light>,
    /// Ambient light; a hit surface reflects `ambient · kd` regardless of shadows.
    pub ambient: Vec3,
    /// What rays that miss everything see, and a light for surfaces.
    pub environment: Option<EnvironmentLight>,
    /// Per mesh, the material index of each triangle.
    pub mesh_materials: Vec<Vec<u32>>,
    /// Per light, the object of `shapes` that is its emitting surface
    /// (`u32::MAX` for a point light).
    pub light_objects: Vec<u32>,
    /// How the lights' `color` and the materials are read: the course's Phong
    /// model, or radiometric units ([`ShadingModel`]).
    pub shading: ShadingModel,
    /// Which MIP level image textures are read at ([`TextureLevel`]).
    pub texture_level: TextureLevel,
}

/// Which MIP level image textures are read at.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TextureLevel {
    /// Glint's: from the pixel's footprint, carried by the ray
    /// differentials to each hit, as the texture's filter reads it.
    #[default]
    Footprint,
    /// The course report's `log2(L/W)` at a camera ray's hit, the pixel's
    /// height at the hit's distance over a texel's width
    /// ([`crate::report_level()`]), read trilinearly: what a ray tracer that
    /// follows the report computes. A mirror's reflection rays, for which the
    /// report has no formula, keep the footprint.
    Report,
}

impl TextureLevel {
    pub const NAMES: [&'static str; 2] = ["footprint", "report"];

    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "footprint" => Some(Self::Footprint),
            "report" => Some(Self::Report),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }
}

impl Scene {
    /// Builds what a render with `settings` will read and the scene makes
    /// on first use (the environment's luminance distribution, where its
    /// samples are drawn from it), so that no render thread waits on it.
    pub fn prepare(&self, settings: &crate::RenderSettings) {
        if let (Some(env), 1..) = (&self.environment, settings.environment_samples) {
            env.prepare(settings.environment_sampling);
        }
    }

    /// Whether anything reads a ray's differentials: a material whose textures
    /// filter over a footprint, or the environment (filtered by the ray's
    /// angular width in Phong shading; physical shading reads it unfiltered).
    /// Without either, camera rays are made without them.
    pub fn needs_differentials(&self) -> bool {
        let filtered_environment =
            self.environment.is_some() && self.shading == ShadingModel::Phong;
        filtered_environment || self.materials.iter().any(PhongMaterial::uses_footprint)
    }

    /// The material or light at `hit`.
    #[inline]
    pub fn surface_of(&self, hit: &Hit) -> SurfaceKind<'_> {
        self.surface_of_primitive(hit.shape, hit.primitive)
    }

    /// The material or light of triangle `primitive` of object `object` (0 for
    /// a shape), as [`Self::surface_of`] a hit on it.
    #[inline]
    pub fn surface_of_primitive(&self, object: u32, primitive: u32) -> SurfaceKind<'_> {
        match self.surfaces[object as usize] {
            Surface::Material(m) => SurfaceKind::Material(&self.materials[m as usize]),
            Surface::Emitter(l) => SurfaceKind::Emitter(&self.lights[l as usize]),
            Surface::Mesh(k) => {
                let m = self.mesh_materials[k as usize][primitive as usize];
                SurfaceKind::Material(&self.materials[m as usize])
            }
        }
    }

    /// Reads image textures at `level` (the command line's
    /// `--texture-level`); at the report's level, trilinearly.
    pub fn set_texture_level(&mut self, level: TextureLevel) {
        self.texture_level = level;
        if level == TextureLevel::Report {
            self.override_texture_filter(TextureFilter::Trilinear);
        }
    }

    /// Sets the filter of every image texture the materials use (the command
    /// line's `--texture-filter`). Procedural textures keep their own filtering.
    pub fn override_texture_filter(&mut self, filter: TextureFilter) {
        for material in &mut self.materials {
            let textures = std::iter::once(&mut material.diffuse).chain(material.specular.as_mut());
            for texture in textures {
                if let Texture::Image(image) = texture {
                    image.filter = filter;
                }
            }
        }
    }

    /// Evaluates every image rasterised from a checkerboard (a `checker_image`
    /// texture) as the procedural checkerboard, box-filtered exactly over the
    /// footprint ([`glint_texture::Checkerboard`]'s analytic filter), and filters
    /// the other images with `others`. Only repeating images of an even number of
    /// checks are replaced: only they repeat exactly as the pattern does outside
    /// the uv square.
    pub fn use_analytic_checkerboards(&mut self, others: TextureFilter) {
        for material in &mut self.materials {
            let textures = std::iter::once(&mut material.diffuse).chain(material.specular.as_mut());
            for texture in textures {
                let Texture::Image(image) = texture else {
                    continue;
                };
                match image.image.pattern() {
                    Some(pattern)
                        if image.wrap == glint_texture::WrapMode::Repeat
                            && pattern.checks % 2 == 0 =>
                    {
                        *texture = Texture::Checkerboard(glint_texture::Checkerboard {
                            analytic: true,
                            ..pattern.clone()
                        });
                    }
                    _ => image.filter = others,
                }
            }
        }
    }
}

/// Why a scene could not be assembled.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SceneError {
    #[error("shape {shape} refers to material {material}, but only {count} materials exist")]
    UnknownMaterial {
        shape: usize,
        material: u32,
        count: usize,
    },
}

/// Assembles a [`Scene`] piece by piece; area lights add their emitting surface
/// to the shape list themselves.
#[derive(Clone, Debug, Default)]
pub struct SceneBuilder {
    shapes: ShapeList,
    surfaces: Vec<Surface>,
    materials: Vec<PhongMaterial>,
    lights: Vec<Light>,
    ambient: Vec3,
    environment: Option<EnvironmentLight>,
    mesh_materials: Vec<Vec<u32>>,
    shading: ShadingModel,
}

impl SceneBuilder {
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a material and returns the index shapes refer to it by.
    pub fn material(&mut self, material: PhongMaterial) -> u32 {
        self.materials.push(material);
        (self.materials.len() - 1) as u32
    }

    /// Adds a shape made of material `material`.
    pub fn shape(&mut self, shape: impl Into<Shape>, material: u32) -> &mut Self {
        self.shapes.push(shape);
        self.surfaces.push(Surface::Material(material));
        self
    }

    /// Adds a triangle mesh whose triangle `i` is made of material
    /// `triangle_materials[i]` (one entry per triangle).
    pub fn mesh(&mut self, mesh: TriangleMesh, triangle_materials: Vec<u32>) -> &mut Self {
        assert_eq!(
            mesh.triangle_count(),
            triangle_materials.len(),
            "one material per triangle"
        );
        self.shapes.push_mesh(mesh);
        self.surfaces
            .push(Surface::Mesh(self.mesh_materials.len() as u32));
        self.mesh_materials.push(triangle_materials);
        self
    }

    pub fn point_light(&mut self, light: PointLight) -> &mut Self {
        self.lights.push(Light::Point(light));
        self
    }

    /// Adds an area light, visible to camera rays through its emitting surface.
    pub fn area_light(&mut self, light: AreaLight) -> &mut Self {
        self.shapes.push(*light.surface());
        self.surfaces
            .push(Surface::Emitter(self.lights.len() as u32));
        self.lights.push(Light::Area(light));
        self
    }

    /// How lights and materials are read (default: the course's Phong model).
    pub fn shading(&mut self, shading: ShadingModel) -> &mut Self {
        self.shading = shading;
        self
    }

    /// Adds a spherical light (physical shading only), visible to camera rays
    /// through its surface.
    pub fn sphere_light(&mut self, light: SphereLight) -> &mut Self {
        self.shapes.push(*light.surface());
        self.surfaces
            .push(Surface::Emitter(self.lights.len() as u32));
        self.lights.push(Light::Sphere(light));
        self
    }

    pub fn ambient(&mut self, ambient: Vec3) -> &mut Self {
        self.ambient = ambient;
        self
    }

    pub fn environment(&mut self, environment: EnvironmentLight) -> &mut Self {
        self.environment = Some(environment);
        self
    }

    /// The scene, with its BVH built.
    pub fn build(mut self, camera: Camera) -> Result<Scene, SceneError> {
        for (shape, surface) in self.surfaces.iter().enumerate() {
            let used: &[u32] = match surface {
                Surface::Material(m) => std::slice::from_ref(m),
                Surface::Mesh(k) => &self.mesh_materials[*k as usize],
                Surface::Emitter(_) => &[],
            };
            if let Some(&material) = used.iter().find(|&&m| m as usize >= self.materials.len()) {
                return Err(SceneError::UnknownMaterial {
                    shape,
                    material,
                    count: self.materials.len(),
                });
            }
        }
        self.shapes.build_acceleration();
        let mut light_objects = vec![u32::MAX; self.lights.len()];
        for (object, surface) in self.surfaces.iter().enumerate() {
            if let Surface::Emitter(light) = *surface {
                light_objects[light as usize] = object as u32;
            }
        }
        Ok(Scene {
            light_objects,
            camera,
            shapes: self.shapes,
            surfaces: self.surfaces,
            materials: self.materials,
            lights: self.lights,
            ambient: self.ambient,
            environment: self.environment,
            mesh_materials: self.mesh_materials,
            shading: self.shading,
            texture_level: TextureLevel::Footprint,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glint_texture::{Checkerboard, ImageTexture, TextureImage, WrapMode};

    fn image_texture(image: std::sync::Arc<TextureImage>, wrap: WrapMode) -> Texture {
        Texture::Image(ImageTexture::new(image, wrap, TextureFilter::Trilinear))
    }

    #[test]
    fn checker_images_become_analytic_checkerboards_and_photos_take_the_filter() {
        let even = Checkerboard::new(Vec3::ONE, Vec3::ZERO, 8);
        let odd = Checkerboard::new(Vec3::ONE, Vec3::ZERO, 3);
        let photo = TextureImage::new(odd.to_image(4));
        let mut builder = SceneBuilder::new();
        let textures = [
            image_texture(
                TextureImage::from_checkerboard(even.clone(), 4),
                WrapMode::Repeat,
            ),
            image_texture(
                TextureImage::from_checkerboard(even.clone(), 4),
                WrapMode::Clamp,
            ),
            image_texture(TextureImage::from_checkerboard(odd, 4), WrapMode::Repeat),
            image_texture(photo, WrapMode::Repeat),
        ];
        for t in &textures {
            builder.material(PhongMaterial {
                diffuse: t.clone(),
                ..PhongMaterial::new(Vec3::ONE, 1.0)
            });
        }
        let camera =
            Camera::new(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0, 1.0, glam::UVec2::ONE).unwrap();
        let mut scene = builder.build(camera).unwrap();
        scene.use_analytic_checkerboards(TextureFilter::Ewa);
        let kinds: Vec<String> = scene
            .materials
            .iter()
            .map(|m| match &m.diffuse {
                Texture::Checkerboard(c) => format!("analytic {} checks: {}", c.checks, c.analytic),
                Texture::Image(i) => format!("image {:?}", i.filter),
                Texture::Constant(_) => "constant".into(),
            })
            .collect();
        assert_eq!(
            kinds,
            [
                "analytic 8 checks: true",
                "image Ewa",
                "image Ewa",
                "image Ewa"
            ]
        );
    }
}
