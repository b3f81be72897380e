//! Warnings about what Mitsuba does not reproduce like for like, beyond those
//! written as each part is converted.

use super::placement::seen_from_behind;
use super::Converter;
use crate::mitsuba::xml::vector;
use glam::Vec3;
use glint_geometry::{ObjectRef, Parallelogram, Shape};
use glint_integrator::{ShadingModel, Surface};
use glint_lighting::Light;

impl Converter<'_> {
    /// What the whole scene's model lacks in Mitsuba: the Phong model's
    /// units, ambient light.
    pub(super) fn model_warnings(&mut self) {
        let scene = self.scene;
        if scene.shading == ShadingModel::Phong {
            self.warn(
                "the scene uses the course's Phong model (shading = \"phong\"), which has no \
                 physical counterpart (no distance falloff, no normalisation): its lights' colors \
                 are written as Mitsuba's point-light intensities and area-light radiances, so \
                 the images will differ in value (shading = \"physical\" makes them comparable)"
                    .into(),
            );
        }
        if scene.ambient != Vec3::ZERO {
            self.warn(format!(
                "ambient [{}] is dropped: Mitsuba 3 has no ambient term",
                vector(scene.ambient)
            ));
        }
    }

    pub(super) fn late_warnings(&mut self) {
        if !self.mirrors.is_empty() {
            let names = quoted(&self.mirrors);
            self.warn(format!(
                "Mitsuba 3's `direct` integrator does not follow mirror reflections: the mirrors \
                 of {names} show only what emits (area lights, the environment), and surfaces seen \
                 in them are black, where Glint follows up to {} reflections",
                self.description.settings.max_depth
            ));
        }
        if !self.blends.is_empty() {
            let names = quoted(&self.blends);
            let verb = if self.blends.len() == 1 {
                "blends"
            } else {
                "blend"
            };
            self.warn(format!(
                "{names} {verb} a perfect mirror into a diffuse BSDF (`blendbsdf`), which \
                 Mitsuba 3.9 renders biased with multiple importance sampling (its sampling \
                 reports the chosen lobe's density, not the blend's; a sphere of reflectivity 0.3 \
                 under a uniform sky came out 6-37% too dark per channel)"
            ));
        }
        if !self.unfiltered.is_empty() {
            let names: Vec<String> = self.unfiltered.iter().cloned().collect();
            self.warn(format!(
                "Mitsuba 3's bitmap textures have no MIP maps: the trilinear or EWA-filtered \
                 textures of {} are looked up bilinearly at full resolution (minified, they \
                 come out a little sharper and noisier than in Glint)",
                quoted(&names)
            ));
        }
        if self.description.settings.seed > u32::MAX as u64 {
            let seed = self.description.settings.seed;
            self.warn(format!(
                "seed {seed} does not fit Mitsuba's 32-bit sampler seed: written as {}",
                seed as u32
            ));
        }
    }

    /// Flat shapes and area lights that turn their backs to the camera: Glint
    /// sees through them from behind, Mitsuba sees them black.
    pub(super) fn facing_warnings(&mut self) {
        let camera = self.scene.camera.position();
        let behind = |p: &Parallelogram| (camera - p.center()).dot(p.normal()) < 0.0;
        let mut shapes = Vec::new();
        let mut n = 0;
        for object in 0..self.scene.shapes.len() as u32 {
            let (ObjectRef::Shape(Shape::Parallelogram(p)), Surface::Material(_)) = (
                self.scene.shapes.object(object),
                self.scene.surfaces[object as usize],
            ) else {
                continue;
            };
            let one_sided =
                !seen_from_behind(p.center(), p.normal(), |r| p.hit_distance(r, f32::INFINITY));
            if one_sided && behind(p) {
                shapes.push(format!("parallelogram {n}"));
            }
            n += 1;
        }
        for (i, light) in self.scene.lights.iter().enumerate() {
            if let Light::Area(a) = light {
                if behind(a.surface()) {
                    shapes.push(format!("area light {i}"));
                }
            }
        }
        if !shapes.is_empty() {
            let (turn, it) = match shapes.len() {
                1 => ("turns its back", "it is"),
                _ => ("turn their backs", "they are"),
            };
            self.warn(format!(
                "{} {turn} to the camera: where {it} in view, Glint sees through (one-sided \
                 surfaces and lights are invisible from behind) and Mitsuba sees black",
                shapes.join(", ")
            ));
        }
    }
}

pub(super) fn quoted(names: &[String]) -> String {
    let quoted: Vec<String> = names.iter().map(|n| format!("\"{n}\"")).collect();
    match quoted.len() {
        1 => format!("material {}", quoted[0]),
        _ => format!("materials {}", quoted.join(", ")),
    }
}
