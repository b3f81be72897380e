//! One camera sample of one pixel as Glint renders it, and the loop that
//! turns candidate pixels into a stage's cases.
//!
//! Every case comes from camera sample `k` of `spp` on the grid pattern
//! (`--sampler grid`: the centres of a √spp × √spp grid of cells, so the
//! sample at spp 1 is the pixel's centre), with each area light sampled on
//! a [`LIGHT_GRID`] × [`LIGHT_GRID`] grid (`--light-sampler grid`) and no
//! environment samples: settings a student reproduces without Glint's
//! random streams, and the ones `glint explain` is given to explain a case.

use super::table::{Case, Origin};
use crate::GradeError;
use glam::{Vec2, Vec3};
use glint_geometry::{Hit, Ray};
use glint_integrator::trace::{Event, SampleSelection};
use glint_integrator::{explain_pixel, RenderSettings, SamplePattern, Scene};
use std::collections::BTreeSet;

/// Each area light is sampled on a grid of this many points a side.
pub const LIGHT_GRID: u32 = 4;

/// The camera samples cases take, in turn: `(spp, sample)`. The pixel's
/// centre, and sub-pixel offsets of the 2 × 2 and 4 × 4 grids: (¼, ¼),
/// (⅜, ⅜), (¾, ¾), (⅝, ⅝), (¾, ¼) and (⅛, ⅞) of the pixel.
const SAMPLES: [(u32, u32); 7] = [(1, 0), (4, 0), (16, 5), (4, 3), (16, 10), (4, 1), (16, 12)];

/// The render settings of a case taken at `spp` samples per pixel: the
/// scene's own, on the grid patterns, without environment samples.
pub fn settings(scene_settings: &RenderSettings, spp: u32) -> RenderSettings {
    RenderSettings {
        spp,
        pixel_pattern: SamplePattern::Grid,
        light_samples: LIGHT_GRID * LIGHT_GRID,
        light_pattern: SamplePattern::Grid,
        environment_samples: 0,
        aov: None,
        stats: false,
        threads: Some(1),
        ..scene_settings.clone()
    }
}

/// The flags that make `glint explain` (or `glint render`) take a case's
/// settings, after `--pixel`.
pub fn explain_flags(from: &Origin) -> String {
    format!(
        "--pixel {},{} --spp {} --sampler grid --sample {} --light-samples {} \
         --light-sampler grid --environment-samples 0",
        from.pixel[0],
        from.pixel[1],
        from.spp,
        from.sample,
        LIGHT_GRID * LIGHT_GRID
    )
}

/// One camera sample of a pixel, as the render takes it.
pub struct Probe {
    pub from: Origin,
    /// The sample's raster position (pixels from the image's top left).
    pub raster: Vec2,
    /// The camera ray through it ([`glint_camera::Camera::generate_ray`]).
    pub ray: Ray,
    /// That ray's closest hit.
    pub hit: Option<Hit>,
    /// The render's steps for the sample ([`explain_pixel`]).
    pub events: Vec<Event>,
    /// The pixel's radiance: the mean of its samples, as the render writes it.
    pub radiance: Vec3,
}

impl Probe {
    /// Camera sample `from.sample` of pixel `from.pixel` at `from.spp`.
    pub fn new(
        scene: &Scene,
        scene_settings: &RenderSettings,
        from: Origin,
    ) -> Result<Probe, GradeError> {
        let settings = settings(scene_settings, from.spp);
        let [x, y] = from.pixel;
        let explained = explain_pixel(
            scene,
            &settings,
            x,
            y,
            SampleSelection::One(from.sample.into()),
        )
        .map_err(|e| GradeError::Internal(format!("pixel ({x}, {y}): {e}")))?;
        let events = explained
            .samples
            .into_iter()
            .next()
            .map(|s| s.events)
            .unwrap_or_default();
        let raster = events
            .iter()
            .find_map(|e| match e {
                Event::Camera { raster, .. } => Some(*raster),
                _ => None,
            })
            .ok_or_else(|| {
                GradeError::Internal(format!("pixel ({x}, {y}): no camera event was recorded"))
            })?;
        let ray = super::survey::camera_ray(scene, raster.x, raster.y);
        Ok(Probe {
            from,
            raster,
            ray,
            hit: scene.shapes.closest_hit(&ray, f32::INFINITY),
            events,
            radiance: explained.radiance,
        })
    }
}

/// Candidate pixels of one kind, and the share of a stage's cases they get
/// (the stratified pixels, listed first, get what the others leave).
pub struct Plan<'a> {
    pub why: &'static str,
    pub share: f64,
    pub pixels: Box<dyn Iterator<Item = [u32; 2]> + 'a>,
}

impl<'a> Plan<'a> {
    pub fn new(
        why: &'static str,
        share: f64,
        pixels: impl Iterator<Item = [u32; 2]> + 'a,
    ) -> Plan<'a> {
        Plan {
            why,
            share,
            pixels: Box::new(pixels),
        }
    }
}

/// How many cases each plan gets out of `n`: `share · n` rounded, at least
/// one from 8 cases on, never more than `n` in all; the first plan gets the
/// rest.
fn quotas(n: usize, plans: &[Plan]) -> Vec<usize> {
    let mut left = n;
    let mut quotas = vec![0; plans.len()];
    for (q, plan) in quotas.iter_mut().zip(plans).skip(1) {
        let share = (plan.share * n as f64).round() as usize;
        let share = if n >= 8 && plan.share > 0.0 {
            share.max(1)
        } else {
            share
        };
        *q = share.min(left);
        left -= *q;
    }
    if let Some(first) = quotas.first_mut() {
        *first = left;
    }
    quotas
}

/// A stage's cases: from each plan's pixels in turn, a probe at the next
/// camera sample of [`SAMPLES`] (and at the pixel's centre if `make` turns
/// that down), until the plan's quota is met or its pixels run out; what
/// an awkward plan cannot fill goes to the first (stratified) plan. `make`
/// returns `None` for a probe the stage cannot use (a miss where a hit is
/// needed, a case too close to a decision boundary to check exactly).
/// Cases come out in plan order, each pixel at most once.
pub fn collect(
    scene: &Scene,
    scene_settings: &RenderSettings,
    n: usize,
    mut plans: Vec<Plan>,
    mut make: impl FnMut(&Probe) -> Option<Case>,
) -> Result<Vec<Case>, GradeError> {
    let quotas = quotas(n, &plans);
    let mut collector = Collector {
        scene,
        scene_settings,
        used: BTreeSet::new(),
        turn: 0,
    };
    let mut found: Vec<Vec<Case>> = vec![Vec::new(); plans.len()];
    // The awkward plans first, so the stratified one knows what is left.
    for i in (1..plans.len()).chain(0..plans.len().min(1)) {
        let quota = match i {
            0 => n - found.iter().map(Vec::len).sum::<usize>(),
            _ => quotas[i],
        };
        found[i] = collector.fill(&mut plans[i], quota, &mut make)?;
    }
    Ok(found.into_iter().flatten().collect())
}

/// The state of [`collect`]: the pixels used so far, and whose turn it is
/// among the camera samples.
struct Collector<'a> {
    scene: &'a Scene,
    scene_settings: &'a RenderSettings,
    used: BTreeSet<[u32; 2]>,
    turn: usize,
}

impl Collector<'_> {
    /// Up to `quota` cases from `plan`'s pixels, trying at most a few times
    /// the quota (a kind of pixel whose cases all sit on a boundary must not
    /// cost a probe of every pixel).
    fn fill(
        &mut self,
        plan: &mut Plan,
        quota: usize,
        make: &mut impl FnMut(&Probe) -> Option<Case>,
    ) -> Result<Vec<Case>, GradeError> {
        let mut cases = Vec::new();
        let mut tries = 0;
        while cases.len() < quota && tries < 4 * quota + 16 {
            let Some(pixel) = plan.pixels.next() else {
                break;
            };
            if !self.used.insert(pixel) {
                continue;
            }
            tries += 1;
            if let Some(case) = self.case_at(pixel, plan.why, make)? {
                cases.push(case);
            }
        }
        Ok(cases)
    }

    /// A case at `pixel`: at the next camera sample in turn, else at the
    /// pixel's centre.
    fn case_at(
        &mut self,
        pixel: [u32; 2],
        why: &'static str,
        make: &mut impl FnMut(&Probe) -> Option<Case>,
    ) -> Result<Option<Case>, GradeError> {
        let (spp, sample) = SAMPLES[self.turn % SAMPLES.len()];
        self.turn += 1;
        let centre = (spp > 1).then_some((1, 0));
        for (spp, sample) in std::iter::once((spp, sample)).chain(centre) {
            let from = Origin {
                pixel,
                sample,
                spp,
                why,
            };
            if let Some(case) = make(&Probe::new(self.scene, self.scene_settings, from)?) {
                return Ok(Some(case));
            }
        }
        Ok(None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan(share: f64) -> Plan<'static> {
        Plan::new("test", share, std::iter::empty())
    }

    #[test]
    fn quotas_share_the_cases_and_the_first_plan_takes_the_rest() {
        let plans = [plan(0.0), plan(0.25), plan(0.1), plan(0.01)];
        assert_eq!(quotas(64, &plans), [41, 16, 6, 1]);
        assert_eq!(quotas(4, &plans), [3, 1, 0, 0]);
        // Never more than n in all.
        let greedy = [plan(0.0), plan(0.9), plan(0.9)];
        assert_eq!(quotas(10, &greedy), [0, 9, 1]);
    }

    #[test]
    fn the_grid_samples_are_the_pixels_centre_and_sub_pixel_offsets() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../scenes/cornell-set1.toml"
        );
        let d = glint_scene::load(std::path::Path::new(path)).unwrap();
        let at = |spp, sample| {
            let from = Origin {
                pixel: [10, 20],
                sample,
                spp,
                why: "test",
            };
            Probe::new(&d.scene, &d.settings, from).unwrap().raster
        };
        assert_eq!(at(1, 0), Vec2::new(10.5, 20.5));
        assert_eq!(at(4, 3), Vec2::new(10.75, 20.75));
        assert_eq!(at(16, 12), Vec2::new(10.125, 20.875));
    }
}
