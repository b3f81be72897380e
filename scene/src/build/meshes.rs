//! Triangle meshes from OBJ files: their materials (the file's, or the OBJ's
//! own from its MTL files), normals and transform.

use super::materials::MaterialIds;
use super::Assembly;
use crate::error::Problem;
use crate::format::MeshTable;
use crate::obj::{load_obj, ObjMesh};
use glam::{Affine3A, EulerRot, Quat, Vec3};
use glint_geometry::TriangleMesh;
use glint_lighting::PhongMaterial;
use glint_texture::Texture;

impl Assembly<'_> {
    /// Adds the file's meshes, in file order.
    pub(super) fn meshes(
        &mut self,
        tables: &[MeshTable],
        materials: &MaterialIds,
    ) -> Result<(), Problem> {
        for (i, m) in tables.iter().enumerate() {
            let field = format!("mesh[{i}]");
            // Names before files: a typo is reported without reading the mesh.
            let material = m
                .material
                .as_ref()
                .map(|name| materials.get(format!("{field}.material"), name))
                .transpose()?;
            let path = self.base_dir.join(m.file.get_ref());
            let obj = self.timed(|_| {
                load_obj(&path, material.is_none())
                    .map_err(|e| Problem::new(m.file.span(), format!("{field}.file"), e))
            })?;
            self.assets.extend(obj.files.iter().cloned());
            let triangle_materials = match material {
                Some(id) => vec![id; obj.indices.len()],
                None => self.obj_materials(m, &obj),
            };
            let mesh = placed_mesh(&field, m, obj)?;
            self.names.add(m.name.as_ref(), field)?;
            self.builder.mesh(mesh, triangle_materials);
        }
        Ok(())
    }

    /// Each triangle's material from the OBJ's own, named FILE:NAME; faces
    /// without one get a light gray diffuse material.
    fn obj_materials(&mut self, m: &MeshTable, obj: &ObjMesh) -> Vec<u32> {
        let ids: Vec<u32> = obj
            .materials
            .iter()
            .map(|(name, material)| {
                self.extra_material_names
                    .push(format!("{}:{name}", m.file.get_ref()));
                self.builder.material(material.clone())
            })
            .collect();
        obj.triangle_materials
            .iter()
            .map(|t| match t {
                Some(k) => ids[*k as usize],
                None => self.default_mesh_material(),
            })
            .collect()
    }

    fn default_mesh_material(&mut self) -> u32 {
        if let Some(id) = self.default_mesh_material {
            return id;
        }
        self.extra_material_names
            .push("(default mesh material)".into());
        let id = self.builder.material(PhongMaterial {
            specular: Some(Texture::Constant(Vec3::ZERO)),
            ..PhongMaterial::new(Vec3::splat(0.8), 1.0)
        });
        self.default_mesh_material = Some(id);
        id
    }
}

/// The OBJ's triangles with normals (angle-weighted where the file has none),
/// scaled, rotated and translated as the table says, and within range.
fn placed_mesh(field: &str, m: &MeshTable, obj: ObjMesh) -> Result<TriangleMesh, Problem> {
    let problem = |message: String| {
        Problem::new(
            m.file.span(),
            format!("{field}.file"),
            format!("{}: {message}", m.file.get_ref()),
        )
    };
    let mesh = TriangleMesh::new(obj.positions, obj.indices, obj.normals, obj.uvs)
        .map_err(|e| problem(e.to_string()))?;
    let mesh = if mesh.has_normals() {
        mesh
    } else {
        mesh.with_angle_weighted_normals()
    };
    // Rotations in degrees, about x, then y, then z.
    let (r, s) = (m.rotate.0 * std::f32::consts::PI / 180.0, m.scale.0);
    let rotation = Quat::from_euler(EulerRot::ZYX, r.z, r.y, r.x);
    let transform = Affine3A::from_scale_rotation_translation(s, rotation, m.translate.0);
    let mesh = mesh.transformed(&transform);
    let extent = mesh.max_coordinate();
    if extent.is_nan() || extent > crate::values::MAX_MAGNITUDE {
        return Err(problem(format!(
            "after the transform a vertex lies beyond {:e} (or is not finite)",
            crate::values::MAX_MAGNITUDE
        )));
    }
    Ok(mesh)
}
