//! Tracing one pixel's computation, stage by stage, for `glint explain`.
//!
//! The integrator takes a [`Tracer`] as a type parameter of its
//! [`SampleContext`](crate::SampleContext). A render uses `()`, whose
//! [`Tracer::ON`] is `false` and whose hooks are empty and inlined: the events'
//! closures are never called, and the compiler removes them, so a render does
//! exactly what it did before tracing existed. [`PixelTrace`] records the
//! events of the samples it is asked for.
//!
//! A traced pixel takes the render's own route: its camera samples in the
//! SIMD lanes of one chunk, each lane one camera sample. Every hook names the
//! lanes its event happens in, and the tracer keeps the events of the lanes
//! whose samples it records, each sample's in its own order. The hooks only
//! read what the integrator computed (or recompute, for display, numbers it
//! does not keep: `n·l`, the reflection vector, the diffuse and specular
//! parts, the nearest blocker of a blocked shadow ray): nothing a hook
//! computes flows back into the radiance, and [`crate::explain_pixel`]
//! checks the traced pixel against the untraced one bit for bit.

use glam::{Vec2, Vec3};
use glint_geometry::lanes::{self, LANES};
use glint_geometry::{Hit, Ray, RayDifferential};
use glint_texture::TexCoord;

/// Receives the integrator's events. `()` ignores them at no cost.
pub trait Tracer {
    /// Whether events are recorded at all: with `false`, no event closure is
    /// ever called.
    const ON: bool;
    /// A chunk of camera samples begins: lane k, for `k < used`, holds camera
    /// sample `sample(k)` of the pixel.
    fn start_chunk(&mut self, used: usize, sample: impl Fn(usize) -> u64);
    /// An event in each lane of `lanes` (bit k for lane k), built only for the
    /// lanes recorded.
    fn record(&mut self, lanes: u32, event: impl FnMut(usize) -> Event);
    /// The surfaces the lanes of `lanes` shade next, kept for the events of
    /// their shading ([`Self::record_on`]).
    fn keep_surfaces(&mut self, lanes: u32, surface: impl FnMut(usize) -> Option<TracedSurface>);
    /// An event, or none, in each lane of `lanes` recorded, made from the
    /// lane's kept surface.
    fn record_on(&mut self, lanes: u32, event: impl FnMut(usize, &TracedSurface) -> Option<Event>);
}

impl Tracer for () {
    const ON: bool = false;
    #[inline(always)]
    fn start_chunk(&mut self, _: usize, _: impl Fn(usize) -> u64) {}
    #[inline(always)]
    fn record(&mut self, _: u32, _: impl FnMut(usize) -> Event) {}
    #[inline(always)]
    fn keep_surfaces(&mut self, _: u32, _: impl FnMut(usize) -> Option<TracedSurface>) {}
    #[inline(always)]
    fn record_on(&mut self, _: u32, _: impl FnMut(usize, &TracedSurface) -> Option<Event>) {}
}

/// A lane's surface point as its events describe it: the hit's full record,
/// the ray that found it and the texture lookup made there.
#[derive(Clone, Debug)]
pub struct TracedSurface {
    pub hit: Hit,
    pub ray: Ray,
    pub tc: TexCoord,
}

/// Why a light or environment sample adds nothing without a shadow ray.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Skip {
    /// The direction is below the geometric surface.
    BehindSurface,
    /// The sample point sees the light's back (lights emit from the front).
    BehindLight,
    /// The BRDF times the cosine is zero.
    ZeroBrdf,
    /// The sample's density is zero or not finite.
    ZeroPdf,
}

/// What a shadow ray found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shadow {
    /// No ray was traced.
    Skipped(Skip),
    /// Nothing blocks the light.
    Unoccluded,
    /// The nearest blocker: its object index and the distance along the
    /// shadow ray (in multiples of its direction, which ends at the light).
    Blocked { object: u32, t: f32 },
    /// A ray along a direction drawn from the specular lobe did not reach the
    /// light it was drawn for: it hit `object` first (at `t`), or left the
    /// scene (`None`).
    MissedLight { object: Option<u32>, t: f32 },
}

/// How a physical-shading sample was drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Technique {
    /// A point light: one exact sample.
    PointLight,
    /// A point on the light (by area or solid angle).
    Light,
    /// A direction from the specular lobe.
    Lobe,
}

/// One step of the integrator, in the order it happens.
#[derive(Clone, Debug, PartialEq)]
pub enum Event {
    /// The camera sample: raster position, normalised device coordinates, the
    /// point on the film (relative to the eye, world space), the ray and its
    /// differentials (when the scene needs footprints).
    Camera {
        raster: Vec2,
        ndc: Vec2,
        film_point: Vec3,
        ray: Ray,
        differential: Option<RayDifferential>,
    },
    /// A ray `depth` reflections deep (0: the camera ray) and its closest hit.
    Ray {
        depth: u32,
        ray: Ray,
        hit: Option<Box<Hit>>,
    },
    /// The ray left the scene: the environment's radiance along it, filtered
    /// over `width` radians.
    Environment {
        direction: Vec3,
        width: f32,
        radiance: Vec3,
    },
    /// The ray hit the front of a light: its radiance.
    Emitter { radiance: Vec3 },
    /// The surface point to shade: the texture footprint, the reflectances,
    /// the shading normal `n` and geometric normal `ng` on the viewer's side,
    /// and the direction `v` to the viewer.
    Surface {
        tc: TexCoord,
        kd: Vec3,
        ks: Vec3,
        n: Vec3,
        ng: Vec3,
        v: Vec3,
    },
    /// The ambient term `ambient · kd`.
    Ambient { value: Vec3 },
    /// Light `light` of the scene's lights begins.
    Light { light: usize },
    /// One light sample in the course's model: the point on the light, the
    /// direction `l` to it, `n·l`, the mirror direction of `l`, the diffuse
    /// `kd·n·l` and specular `ks·lobe` parts, the shadow ray's verdict and what
    /// the sample adds (before the light's color and the average).
    LightSample {
        position: Vec3,
        l: Vec3,
        n_dot_l: f32,
        reflection: Vec3,
        diffuse: Vec3,
        specular: Vec3,
        shadow: Shadow,
        value: Vec3,
    },
    /// One sample of physical shading: the direction, the BRDF times the
    /// cosine, the densities of the two techniques (the lobe's is 0 without
    /// MIS), the power-heuristic weight, the shadow ray's verdict and what the
    /// sample adds: `f·cos·w/p` before the light's radiance and the division
    /// by the light sample count (a point light: `f·cos/r²`, before its
    /// intensity). Light and lobe samples of one light add into one sum.
    PhysicalSample {
        technique: Technique,
        l: Vec3,
        f_cos: Vec3,
        light_pdf: f32,
        lobe_pdf: f32,
        weight: f32,
        shadow: Shadow,
        value: Vec3,
    },
    /// What light `light` adds in all: its color times the average.
    LightTotal { light: usize, value: Vec3 },
    /// One environment sample: the direction, its density, the radiance, the
    /// BRDF times the cosine, the shadow ray's verdict and `L·f/p`.
    EnvironmentSample {
        direction: Vec3,
        pdf: f32,
        radiance: Vec3,
        f_cos: Vec3,
        shadow: Shadow,
        value: Vec3,
    },
    /// What the environment adds in all (the average of its samples).
    EnvironmentTotal { value: Vec3 },
    /// A mirror reflection is traced next (its events follow, one deeper).
    Mirror {
        reflectivity: f32,
        tint: Vec3,
        direction: Vec3,
    },
    /// The ray's radiance: `(1 − r)·local + r·tint·reflected`.
    Radiance {
        depth: u32,
        local: Vec3,
        mirror: Vec3,
        value: Vec3,
    },
    /// The camera sample's radiance.
    SampleRadiance { value: Vec3 },
}

/// Which camera samples of a pixel to record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleSelection {
    One(u64),
    All,
}

/// The events of one camera sample.
#[derive(Clone, Debug, PartialEq)]
pub struct SampleTrace {
    pub sample: u64,
    pub events: Vec<Event>,
}

/// A [`Tracer`] that records the events of the selected samples.
#[derive(Clone, Debug)]
pub struct PixelTrace {
    selection: SampleSelection,
    pub samples: Vec<SampleTrace>,
    /// Each lane's sample's place in `samples`, where it is recorded.
    slots: [Option<usize>; LANES],
    /// Each lane's surface being shaded.
    surfaces: [Option<TracedSurface>; LANES],
}

impl PixelTrace {
    pub fn new(selection: SampleSelection) -> Self {
        Self {
            selection,
            samples: Vec::new(),
            slots: [None; LANES],
            surfaces: std::array::from_fn(|_| None),
        }
    }

    /// The recorded lanes of `lanes`, with their places in `samples`.
    fn recorded(&self, lanes: u32) -> impl Iterator<Item = (usize, usize)> {
        let slots = self.slots;
        lanes::each_set(lanes).filter_map(move |k| slots[k].map(|slot| (k, slot)))
    }
}

impl Tracer for PixelTrace {
    const ON: bool = true;

    fn start_chunk(&mut self, used: usize, sample: impl Fn(usize) -> u64) {
        for k in 0..LANES {
            let sample = (k < used).then(|| sample(k));
            let recorded = sample.filter(|&s| match self.selection {
                SampleSelection::All => true,
                SampleSelection::One(one) => one == s,
            });
            self.slots[k] = recorded.map(|sample| {
                self.samples.push(SampleTrace {
                    sample,
                    events: Vec::new(),
                });
                self.samples.len() - 1
            });
            self.surfaces[k] = None;
        }
    }

    fn record(&mut self, lanes: u32, mut event: impl FnMut(usize) -> Event) {
        for (k, slot) in self.recorded(lanes) {
            self.samples[slot].events.push(event(k));
        }
    }

    fn keep_surfaces(
        &mut self,
        lanes: u32,
        mut surface: impl FnMut(usize) -> Option<TracedSurface>,
    ) {
        for (k, _) in self.recorded(lanes) {
            self.surfaces[k] = surface(k);
        }
    }

    fn record_on(
        &mut self,
        lanes: u32,
        mut event: impl FnMut(usize, &TracedSurface) -> Option<Event>,
    ) {
        for (k, slot) in self.recorded(lanes) {
            if let Some(event) = self.surfaces[k].as_ref().and_then(|s| event(k, s)) {
                self.samples[slot].events.push(event);
            }
        }
    }
}
