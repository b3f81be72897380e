//! Materials: each file material as a Phong material, and the names shapes
//! refer to them by.

use super::Assembly;
use crate::error::Problem;
use crate::format::{ColorOrTexture, MaterialTable};
use glint_lighting::{PhongMaterial, UvTransform};
use glint_texture::Texture;
use std::collections::BTreeMap;
use toml::Spanned;

/// The builder's id of each file material, by its name in the file.
pub(super) struct MaterialIds<'a> {
    ids: BTreeMap<&'a str, u32>,
}

impl MaterialIds<'_> {
    /// The id of the material `name`, which the file's `field` names; the
    /// problem lists the names defined.
    pub(super) fn get(&self, field: String, name: &Spanned<String>) -> Result<u32, Problem> {
        self.ids
            .get(name.get_ref().as_str())
            .copied()
            .ok_or_else(|| {
                Problem::new(
                    name.span(),
                    field,
                    format!(
                        "no material named \"{}\" (defined: {})",
                        name.get_ref(),
                        known_names(self.ids.keys())
                    ),
                )
            })
    }
}

/// `"a", "b"` for a problem's list of defined names, or `none`.
pub(super) fn known_names(names: impl Iterator<Item = impl std::fmt::Display>) -> String {
    let known: Vec<_> = names.map(|k| format!("\"{k}\"")).collect();
    if known.is_empty() {
        "none".into()
    } else {
        known.join(", ")
    }
}

impl Assembly<'_> {
    /// Adds every file material, in name order.
    pub(super) fn materials<'m>(
        &mut self,
        tables: &'m BTreeMap<String, Spanned<MaterialTable>>,
        textures: &BTreeMap<&str, Texture>,
    ) -> Result<MaterialIds<'m>, Problem> {
        let mut ids = BTreeMap::new();
        for (name, table) in tables {
            let material = material(name, table, textures)?;
            ids.insert(name.as_str(), self.builder.material(material));
        }
        Ok(MaterialIds { ids })
    }
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
            Problem::new(
                value.span(),
                format!("materials.{name}.{key}"),
                format!(
                    "no texture named \"{t}\" (defined: {})",
                    known_names(textures.keys())
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
