//! Glint's shapes as Mitsuba shapes: spheres, rectangles for parallelograms,
//! boxes and planes, PLY files for meshes.

use super::placement::{
    plane_frame, plane_rectangle, rectangle, scene_points, seen_from_behind, sphere,
};
use super::{Converter, SideContents, SideFile};
use crate::mitsuba::ply;
use glam::Affine2;
use glint_geometry::{AaBox, ObjectRef, Plane, Shape, TriangleMesh};
use glint_integrator::Surface;
use std::collections::BTreeMap;

/// How far a plane's stand-in rectangle reaches, in units of the scene's size:
/// its half side is this many times the largest distance from the point below
/// the camera to anything else in the scene.
const PLANE_REACH: f32 = 10_000.0;

impl Converter<'_> {
    /// Every object of the scene's shape list but area lights' surfaces, in
    /// order.
    pub(super) fn objects(&mut self) {
        let scene = self.scene;
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
    }

    pub(super) fn shape(&mut self, shape: &Shape, material: u32) {
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

    pub(super) fn write_shape(
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

    pub(super) fn plane(&mut self, plane: &Plane, material: u32) {
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

    pub(super) fn aabox(&mut self, aabox: &AaBox, material: u32) {
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

    pub(super) fn mesh(&mut self, mesh: &TriangleMesh, materials: &[u32], k: u32) {
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
}

/// A length or an angle for a message: three significant digits.
pub(super) fn format_size(x: f32) -> String {
    if x == 0.0 {
        "0".into()
    } else if (1e-4..1e5).contains(&x) {
        let digits = (2 - x.log10().floor() as i32).max(0) as usize;
        format!("{x:.digits$}")
    } else {
        format!("{x:.2e}")
    }
}
