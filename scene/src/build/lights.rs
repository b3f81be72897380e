//! Point, area and sphere lights, read in the units of the scene's shading
//! model.

use super::shapes::{front_side, no_area};
use super::Assembly;
use crate::error::Problem;
use crate::format::{AreaLightTable, PointLightTable, SceneFile, SphereLightTable};
use crate::values::Color;
use glam::Vec3;
use glint_lighting::{AreaLight, PointLight, ShadingModel, SphereLight};
use toml::Spanned;

impl Assembly<'_> {
    /// Sets the shading model and adds the point, area and sphere lights, in
    /// that order.
    pub(super) fn lights(&mut self, file: &SceneFile) -> Result<(), Problem> {
        let shading = file.shading.0;
        self.builder.shading(shading);
        self.point_lights(&file.point_light, shading)?;
        self.area_lights(&file.area_light, shading)?;
        self.sphere_lights(&file.sphere_light, shading)
    }

    fn point_lights(
        &mut self,
        tables: &[Spanned<PointLightTable>],
        shading: ShadingModel,
    ) -> Result<(), Problem> {
        for (i, p) in tables.iter().enumerate() {
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
            self.builder.point_light(PointLight {
                position: p.get_ref().position.0,
                color: power.value(&field)?,
            });
        }
        Ok(())
    }

    fn area_lights(
        &mut self,
        tables: &[Spanned<AreaLightTable>],
        shading: ShadingModel,
    ) -> Result<(), Problem> {
        for (i, a) in tables.iter().enumerate() {
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
            self.names.add(a.name.as_ref(), field)?;
            self.builder.area_light(light.facing(front));
        }
        Ok(())
    }

    /// Sphere lights, which only the physical model has.
    fn sphere_lights(
        &mut self,
        tables: &[Spanned<SphereLightTable>],
        shading: ShadingModel,
    ) -> Result<(), Problem> {
        for (i, s) in tables.iter().enumerate() {
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
            self.names
                .add(s.name.as_ref(), format!("sphere_light[{i}]"))?;
            self.builder.sphere_light(light);
        }
        Ok(())
    }
}

/// A light's strength as the scene's shading model reads it: the course's
/// `color` (default white) under `"phong"`, a radiometric key (`intensity`,
/// `radiance`) under `"physical"`, where it is required. Each key is refused
/// under the other model, so that a light is never read in the wrong units.
struct LightPower<'a> {
    shading: ShadingModel,
    table: std::ops::Range<usize>,
    color: Option<&'a Spanned<Color>>,
    physical: Option<&'a Spanned<Color>>,
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
