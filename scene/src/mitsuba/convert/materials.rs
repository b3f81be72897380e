//! Glint's materials as Mitsuba BSDFs: `diffuse`, a `conductor` for a
//! mirror, a `blendbsdf` of the two for a partial mirror, in `twosided` where
//! Glint shades both sides.

use super::Converter;
use crate::mitsuba::xml::{number, vector, Xml};
use glam::{Affine2, Vec3};
use glint_lighting::{PhongMaterial, SpecularLobe};
use glint_texture::Texture;

impl Converter<'_> {
    /// The id of the BSDF of `material` on a shape whose Mitsuba uv maps to
    /// Glint's by `uv`, written on first use.
    pub(super) fn bsdf(&mut self, material: u32, uv: Affine2, two_sided: bool) -> String {
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

    pub(super) fn write_bsdf(
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

    pub(super) fn diffuse(
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

    /// The warnings a material earns once: its dropped specular term, its mirror.
    pub(super) fn note_material(&mut self, material: u32) {
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
}

pub(super) fn open_bsdf(xml: &mut Xml, kind: &str, id: Option<&str>) {
    match id {
        Some(id) => xml.open("bsdf", &[("type", kind), ("id", id)]),
        None => xml.open("bsdf", &[("type", kind)]),
    }
}

/// A perfect mirror whose reflection is multiplied by `tint`.
pub(super) fn mirror(xml: &mut Xml, tint: Vec3, id: Option<&str>) {
    open_bsdf(xml, "conductor", id);
    xml.string("material", "none");
    xml.rgb("specular_reflectance", tint);
    xml.close("bsdf");
}
