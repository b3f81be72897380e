//! Glint's environment as a Mitsuba emitter: `constant`, or an `envmap` of a
//! lat-long EXR on Mitsuba's grid (see [`crate::mitsuba::environment`]).

use super::{Converter, SideContents, SideFile};
use crate::mitsuba::environment as latlong;
use glam::Vec3;
use glint_texture::Environment;

impl Converter<'_> {
    pub(super) fn environment(&mut self) {
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
                let size = latlong::image_size(map).expect("a map has a size");
                let file = "environment.exr".to_owned();
                self.files.push(SideFile {
                    name: file.clone(),
                    contents: SideContents::Exr(latlong::latlong_film(light, size)),
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
                self.shapes.matrix("to_world", latlong::to_world(light));
                self.shapes.close("emitter");
            }
        }
    }
}
