//! Glint's lights as Mitsuba emitters: point emitters, and rectangles and
//! spheres with area emitters.

use super::placement::rectangle;
use super::Converter;
use crate::mitsuba::xml::vector;
use glam::Vec3;
use glint_lighting::Light;

impl Converter<'_> {
    pub(super) fn lights(&mut self) {
        let scene = self.scene;
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
    }

    /// Closes an open light `shape` with a black `diffuse` BSDF (Glint does
    /// not shade a light's surface) and an `area` emitter of `radiance`.
    pub(super) fn black_emitter(&mut self, radiance: Vec3) {
        self.shapes.open("bsdf", &[("type", "diffuse")]);
        self.shapes.rgb("reflectance", Vec3::ZERO);
        self.shapes.close("bsdf");
        self.shapes.open("emitter", &[("type", "area")]);
        self.shapes.rgb("radiance", radiance);
        self.shapes.close("emitter");
        self.shapes.close("shape");
    }
}
