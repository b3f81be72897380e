//! The document around the converted parts: the integrator, the sensor with
//! its sampler and film.

use super::Converter;
use crate::mitsuba::xml::{vector, Xml};
use glint_integrator::ShadingModel;
use glint_lighting::Light;

impl Converter<'_> {
    /// The `direct` integrator's emitter and BSDF samples: Glint's light
    /// samples for both, except with point lights, which Mitsuba 3's `direct`
    /// counts once per emitter sample without dividing by their number
    /// (mitsuba3 issue #1861): then one emitter sample, which is exact for
    /// them. [`Options::bsdf_samples`](super::Options) replaces the BSDF
    /// samples.
    pub(super) fn integrator_samples(&mut self) -> (u32, u32) {
        let n = self.description.settings.light_samples;
        let bsdf = self.options.bsdf_samples.unwrap_or(n);
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
                 {bsdf}, not {n} and {bsdf}: exact for point lights, noisier for area lights and the \
                 environment"
            ));
            (1, bsdf)
        } else {
            (n, bsdf)
        }
    }

    /// The whole document: integrator, sensor, BSDFs, shapes and emitters.
    pub(super) fn document(&self, emitter_samples: u32, bsdf_samples: u32) -> String {
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
        xml.comment(match self.options.bsdf_samples {
            None => {
                "Glint's light samples per camera sample become emitter and BSDF samples, \
                 which Mitsuba combines by multiple importance sampling."
            }
            Some(0) => {
                "Glint's light samples per camera sample become emitter samples, and no BSDF \
                 samples are taken (glint export --bsdf-samples 0): one shadow ray per light \
                 sample, as in Glint."
            }
            Some(_) => {
                "Glint's light samples per camera sample become emitter samples; the BSDF \
                 samples are as asked (glint export --bsdf-samples), combined with them by \
                 multiple importance sampling."
            }
        });
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
}
