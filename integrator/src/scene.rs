use glam::Vec3;
use glint_camera::Camera;
use glint_geometry::{Hit, Shape, ShapeList, TriangleMesh};
use glint_lighting::{AreaLight, EnvironmentLight, Light, PhongMaterial, PointLight};
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
}

impl Scene {
    /// The material or light at `hit`.
    #[inline]
    pub fn surface_of(&self, hit: &Hit) -> SurfaceKind<'_> {
        match self.surfaces[hit.shape as usize] {
            Surface::Material(m) => SurfaceKind::Material(&self.materials[m as usize]),
            Surface::Emitter(l) => SurfaceKind::Emitter(&self.lights[l as usize]),
            Surface::Mesh(k) => {
                let m = self.mesh_materials[k as usize][hit.primitive as usize];
                SurfaceKind::Material(&self.materials[m as usize])
            }
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
        Ok(Scene {
            camera,
            shapes: self.shapes,
            surfaces: self.surfaces,
            materials: self.materials,
            lights: self.lights,
            ambient: self.ambient,
            environment: self.environment,
            mesh_materials: self.mesh_materials,
        })
    }
}
