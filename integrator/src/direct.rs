use crate::camera_lanes::LaneOccluders;
use crate::counters::{ShadingCounters, TextureCounters};
use crate::light_samples::LANES_FROM_SAMPLES;
use crate::sampling::Pcg32;
use crate::sampling::{
    DimensionPair, PixelSample, PointChunk, PointLanes, SamplePattern, SamplePoints, SequenceCache,
    MAX_JOINT,
};
use crate::settings::RenderSettings;
use crate::texture_lookup::texture_footprint;
use crate::trace::{Event, Shadow, Tracer};
use crate::{Scene, SurfaceKind};
use glam::{Vec2, Vec3};
use glint_geometry::lanes::{self, F32Lanes, Vec3Lanes, LANES};
use glint_geometry::{
    offset_ray_origin, reflect_differential, spawn_ray, spawn_ray_to, Hit, Occluders, Ray,
    RayDifferential, RayLanes, RayTarget,
};
use glint_lighting::{
    AreaLight, AreaSampling, EnvironmentLight, EnvironmentSample, EnvironmentSampling, Light,
    PhongMaterial, ShadingModel,
};
use glint_texture::TexCoord;

/// From this many samples per area light on, each shading point first culls the
/// shapes that cannot block its shadow rays to the light
/// ([`glint_geometry::ShapeList::occluders_towards`]).
pub(crate) const CULL_FROM_SAMPLES: u32 = 4;

/// How far from the point it was found for a culling serves, as a fraction of
/// the point's distance to the light: a pixel's samples on one surface then
/// share one (a pixel spans about a thousandth of its distance from the camera
/// at 512², so a hundredth covers it with room), at the price of faces
/// widened by that much.
pub(crate) const CULL_REACH: f32 = 0.01;

/// The direct-lighting integrator of the course report (section 2.5), with the
/// environment and mirror reflections of section 2.7.
///
/// For a ray: a miss sees the environment (black without one); a first hit on a
/// light's front face is the light's color; otherwise the hit point reflects
/// `ambient · kd`, plus for each light the Phong reflection of every unoccluded light
/// sample (one shadow ray per sample, the N samples of an area light averaged), plus
/// the environment's light through shadow rays towards importance-sampled directions;
/// a material with reflectivity `r` blends in `r` times the mirror reflection, traced
/// recursively up to `max_depth` reflections (beyond that, black).
#[derive(Clone, Copy, Debug)]
pub struct DirectIntegrator {
    pub light_samples: u32,
    pub light_pattern: SamplePattern,
    pub environment_samples: u32,
    pub environment_pattern: SamplePattern,
    pub environment_sampling: EnvironmentSampling,
    pub max_depth: u32,
    /// Physical shading: how area lights are sampled.
    pub area_sampling: AreaSampling,
    /// Physical shading: multiple importance sampling of glossy lobes.
    pub mis: bool,
}

/// Reusable per-thread state: the current camera sample and its random stream,
/// buffers for sample positions, ray counters, and the [`Tracer`] that sees
/// each step (`()`, which sees nothing at no cost, for renders).
pub struct SampleContext<T: Tracer = ()> {
    /// The camera sample being traced; names its points of the Sobol sequences.
    pub sample: PixelSample,
    /// Its PCG stream (for the patterns other than Sobol).
    pub rng: Pcg32,
    pub light_points: SamplePoints,
    pub environment_points: SamplePoints,
    /// What the integrator did so far.
    pub counters: ShadingCounters,
    /// Texture lookups by kind and level, counted when `detailed` is set.
    pub textures: TextureCounters,
    /// Whether to gather [`Self::textures`] (`--stats`).
    pub detailed: bool,
    /// Sees every step of the integrator ([`crate::trace`]).
    pub tracer: T,
    /// The last culling of shadow-ray occluders, for the next points near it.
    occluders: Option<CachedOccluders>,
    /// The last culling in the camera-sample lanes, for the next chunks near it.
    pub(crate) lane_occluders: Option<LaneOccluders>,
    /// The Sobol sequences of the pixel's pairs, hashed once for its samples.
    pub(crate) sequences: SequenceCache,
    /// Each lane's points, drawn up front, in the camera-sample lanes.
    pub(crate) lane_points: Vec<Vec2>,
    /// The camera-sample lanes' Sobol points, hashed up front.
    pub(crate) sobol_lanes: Vec<PointLanes>,
}

/// The shapes that may block shadow rays to one area light from anywhere
/// within `reach` of `center`, on one surface, found for one pixel.
#[derive(Clone, Copy, Debug)]
struct CachedOccluders {
    pixel: u64,
    light: usize,
    shape: u32,
    center: Vec3,
    reach: f32,
    occluders: Occluders,
}

impl SampleContext {
    pub fn new(light_samples: u32, environment_samples: u32) -> Self {
        Self::with_tracer(light_samples, environment_samples, ())
    }
}

impl<T: Tracer> SampleContext<T> {
    /// [`SampleContext::new`] with `tracer` seeing every step.
    pub fn with_tracer(light_samples: u32, environment_samples: u32, tracer: T) -> Self {
        Self {
            sample: PixelSample::default(),
            rng: PixelSample::default().rng(),
            light_points: SamplePoints::new(light_samples as usize),
            environment_points: SamplePoints::new(environment_samples as usize),
            counters: ShadingCounters::default(),
            textures: TextureCounters::default(),
            detailed: false,
            tracer,
            occluders: None,
            lane_occluders: None,
            sequences: SequenceCache::default(),
            lane_points: Vec::new(),
            sobol_lanes: Vec::new(),
        }
    }

    /// Starts camera sample `sample` of pixel `pixel` (index `y · width + x`):
    /// sets [`Self::sample`] and its stream [`Self::rng`].
    pub fn begin_sample(&mut self, seed: u64, pixel: u64, sample: u64) {
        self.sample = PixelSample {
            seed,
            pixel,
            sample,
        };
        self.rng = self.sample.rng();
    }

    /// Fills `out` with this camera sample's points of `pair` in `pattern`, as
    /// [`SamplePattern::fill`] does with [`PixelSample::sobol_points`]`(pair,
    /// out.len())`.
    #[inline]
    pub(crate) fn fill_points(
        &mut self,
        pattern: SamplePattern,
        pair: DimensionPair,
        out: &mut SamplePoints,
    ) {
        let sobol = self.sample.sobol_points(pair, out.len() as u32);
        pattern.fill_lanes(&mut self.rng, sobol, &mut self.sequences, out);
    }
}

impl DirectIntegrator {
    /// The integrator `settings` describe (their sample counts, patterns and
    /// depth; the rest is the render loop's).
    pub fn new(settings: &RenderSettings) -> Self {
        Self {
            light_samples: settings.light_samples,
            light_pattern: settings.light_pattern,
            environment_samples: settings.environment_samples,
            environment_pattern: settings.environment_pattern,
            environment_sampling: settings.environment_sampling,
            max_depth: settings.max_depth,
            area_sampling: settings.area_sampling,
            mis: settings.mis,
        }
    }

    /// Radiance arriving along `ray` (a camera ray, or a reflection ray `depth`
    /// reflections deep), whose footprint is given by the ray differentials `diff`.
    /// Light and environment samples come from the camera sample `ctx` was
    /// started on ([`SampleContext::begin_sample`]).
    pub fn li<T: Tracer>(
        &self,
        scene: &Scene,
        ray: &Ray,
        diff: &RayDifferential,
        depth: u32,
        ctx: &mut SampleContext<T>,
    ) -> Vec3 {
        let hit = scene.shapes.closest_hit(ray, f32::INFINITY);
        self.li_at(scene, ray, diff, hit, depth, ctx)
    }

    /// [`Self::li`] for a ray whose closest hit is already found: `hit`, or
    /// `None` for a miss.
    pub fn li_at<T: Tracer>(
        &self,
        scene: &Scene,
        ray: &Ray,
        diff: &RayDifferential,
        hit: Option<Hit>,
        depth: u32,
        ctx: &mut SampleContext<T>,
    ) -> Vec3 {
        let Some(hit) = hit else {
            return self.environment_seen(scene, ray, diff, ctx);
        };
        let material = match scene.surface_of(&hit) {
            SurfaceKind::Emitter(light) => return light.emitted(),
            SurfaceKind::Material(m) => m,
        };
        let r = material.reflectivity;
        let at = SurfaceHit {
            hit: &hit,
            material,
            ray,
            diff,
        };
        let local = if material.has_local_shading() {
            self.local_shading(scene, &at, depth, ctx)
        } else {
            Vec3::ZERO
        };
        let mirror = if r > 0.0 && depth < self.max_depth {
            self.mirror_reflection(scene, &at, depth, ctx)
        } else {
            Vec3::ZERO
        };
        (1.0 - r) * local + r * mirror
    }

    /// The shapes that may block `point`'s shadow rays to area light `index`:
    /// every shape but its own and the light's flat surfaces
    /// ([`ShapeList::occluders_but`](glint_geometry::ShapeList::occluders_but))
    /// below [`CULL_FROM_SAMPLES`] samples per light, where culling costs more
    /// than it saves; else the culling found for an earlier sample of the pixel
    /// on the same surface within its reach, or a new one.
    pub(crate) fn occluders<T: Tracer>(
        &self,
        scene: &Scene,
        point: &ShadingPoint,
        index: usize,
        light: &AreaLight,
        ctx: &mut SampleContext<T>,
    ) -> Occluders {
        let (p, shape, pixel) = (point.hit.point, point.hit.shape, ctx.sample.pixel);
        if self.light_samples < CULL_FROM_SAMPLES {
            return scene
                .shapes
                .occluders_but([shape, scene.light_objects[index]]);
        }
        if let Some(cached) = &ctx.occluders {
            let same = (cached.pixel, cached.light, cached.shape) == (pixel, index, shape);
            if same && p.distance(cached.center) <= cached.reach {
                return cached.occluders;
            }
        }
        let reach = CULL_REACH * p.distance(light.surface().center());
        let occluders = scene.shapes.occluders_towards(
            p,
            reach,
            &light.surface().corners(),
            [shape, scene.light_objects[index]],
        );
        ctx.occluders = Some(CachedOccluders {
            pixel,
            light: index,
            shape,
            center: p,
            reach,
            occluders,
        });
        occluders
    }

    /// The environment's radiance along a ray that hits nothing (black without one).
    fn environment_seen<T: Tracer>(
        &self,
        scene: &Scene,
        ray: &Ray,
        diff: &RayDifferential,
        ctx: &mut SampleContext<T>,
    ) -> Vec3 {
        let Some(env) = &scene.environment else {
            return Vec3::ZERO;
        };
        ctx.counters.environment_lookups += 1;
        // Physical shading reads the map unfiltered: the mean of a
        // pixel's samples is then an unbiased estimate of the
        // radiance over its footprint, where a map prefiltered over
        // each ray's footprint is blurred twice (measured against
        // Mitsuba 3: a chrome sphere's rim came out 16% too bright
        // under the studio map's small, bright lamps).
        let width = match scene.shading {
            ShadingModel::Phong => diff.angular_width(ray.direction),
            ShadingModel::Physical => 0.0,
        };
        env.radiance(ray.direction.normalize(), width)
    }

    /// The light reflected at `hit` by its material (ambient, lights and
    /// environment), its textures read over the ray's footprint.
    fn local_shading<T: Tracer>(
        &self,
        scene: &Scene,
        at: &SurfaceHit,
        depth: u32,
        ctx: &mut SampleContext<T>,
    ) -> Vec3 {
        if at.material.uses_footprint() {
            ctx.counters.footprints += 1;
        }
        let tc = texture_footprint(at.material, at.hit, at.diff);
        if ctx.detailed {
            ctx.textures.record(at.material, &tc);
        }
        let point = ShadingPoint::new(at.hit, at.material, at.ray, &tc);
        match scene.shading {
            ShadingModel::Phong => self.shade(scene, &point, depth, ctx),
            ShadingModel::Physical => self.shade_physical(scene, &point, depth, ctx),
        }
    }

    /// The radiance a mirror at `hit` reflects towards the ray, tinted: the
    /// reflected ray followed one level deeper, with its differentials.
    fn mirror_reflection<T: Tracer>(
        &self,
        scene: &Scene,
        at: &SurfaceHit,
        depth: u32,
        ctx: &mut SampleContext<T>,
    ) -> Vec3 {
        let (reflected, reflected_diff) = mirror_ray(at.hit, at.ray, at.diff);
        ctx.counters.reflection_rays += 1;
        at.material.mirror_tint * self.li(scene, &reflected, &reflected_diff, depth + 1, ctx)
    }

    /// The local shading of `point`, `depth` reflections deep: ambient, the
    /// lights and the environment.
    fn shade<T: Tracer>(
        &self,
        scene: &Scene,
        point: &ShadingPoint,
        depth: u32,
        ctx: &mut SampleContext<T>,
    ) -> Vec3 {
        self.shade_with(
            scene,
            point,
            depth,
            ctx,
            |index, light, pairs, ctx| match light {
                Light::Point(p) => {
                    ctx.counters.point_light_samples += 1;
                    let target = RayTarget::exact(p.position);
                    let reflected =
                        point.unoccluded_reflection(scene, &target, &Occluders::ALL, ctx);
                    p.color * reflected
                }
                Light::Area(area) => {
                    let pair = self.light_pair(pairs, index, depth);
                    self.area_light(scene, point, index, area, pair, ctx)
                }
                // The course's model has no sphere lights: the scene file
                // accepts them under physical shading only.
                Light::Sphere(_) => Vec3::ZERO,
            },
        )
    }

    /// What both shading models share: `ambient · kd`, plus what each light
    /// adds (`light_term(index, light, pairs, ctx)`, in scene order, taking
    /// its dimension pair from `pairs` if it samples), plus the environment.
    pub(crate) fn shade_with<T: Tracer>(
        &self,
        scene: &Scene,
        point: &ShadingPoint,
        depth: u32,
        ctx: &mut SampleContext<T>,
        mut light_term: impl FnMut(usize, &Light, &mut PairAllocation, &mut SampleContext<T>) -> Vec3,
    ) -> Vec3 {
        let mut radiance = scene.ambient * point.kd;
        let mut pairs = PairAllocation::new(depth);
        for (index, light) in scene.lights.iter().enumerate() {
            radiance += light_term(index, light, &mut pairs, ctx);
        }
        radiance += self.environment_term(scene, point, &mut pairs, depth, ctx);
        radiance
    }

    /// The dimension pair of light `index`'s samples at a point `depth`
    /// reflections deep.
    #[inline]
    pub(crate) fn light_pair(
        &self,
        pairs: &mut PairAllocation,
        index: usize,
        depth: u32,
    ) -> DimensionPair {
        let own = DimensionPair::Light {
            light: index as u32,
            depth,
        };
        pairs.take(own, self.light_samples)
    }

    /// Light `pair`'s points for this camera sample, in the buffer taken from
    /// `ctx.light_points` (the caller puts it back).
    #[inline]
    pub(crate) fn draw_light_points<T: Tracer>(
        &self,
        pair: DimensionPair,
        ctx: &mut SampleContext<T>,
    ) -> SamplePoints {
        let mut samples = std::mem::take(&mut ctx.light_points);
        ctx.fill_points(self.light_pattern, pair, &mut samples);
        samples
    }

    /// The environment's light at `point` (zero without environment samples),
    /// its sample points taken from `pairs`.
    pub(crate) fn environment_term<T: Tracer>(
        &self,
        scene: &Scene,
        point: &ShadingPoint,
        pairs: &mut PairAllocation,
        depth: u32,
        ctx: &mut SampleContext<T>,
    ) -> Vec3 {
        if self.environment_samples == 0 || scene.environment.is_none() {
            return Vec3::ZERO;
        }
        let pair = pairs.take(
            DimensionPair::Environment { depth },
            self.environment_samples,
        );
        self.environment_light(scene, point, pair, ctx)
    }

    /// The average over the light's samples (the dimension pair `pair` of the
    /// Sobol pattern) of the Phong reflection of each visible sample, times the
    /// light's color.
    fn area_light<T: Tracer>(
        &self,
        scene: &Scene,
        point: &ShadingPoint,
        index: usize,
        light: &AreaLight,
        pair: DimensionPair,
        ctx: &mut SampleContext<T>,
    ) -> Vec3 {
        let samples = self.draw_light_points(pair, ctx);
        let occluders = self.occluders(scene, point, index, light, ctx);
        ctx.counters.light_samples += samples.len() as u64;
        let sum = point.area_light_sum(scene, light, &samples, &occluders, ctx);
        ctx.light_points = samples;
        light.color * sum / self.light_samples as f32
    }

    /// Whether the scene's environment samples are drawn from its map, by
    /// luminance, so that they do not depend on the shading normal.
    pub(crate) fn samples_environment_by_map(&self, scene: &Scene) -> bool {
        self.environment_sampling == EnvironmentSampling::Luminance
            && (scene.environment.as_ref()).is_some_and(EnvironmentLight::is_sampled_by_map)
    }

    /// The dimension pair of the environment's samples at a point `depth`
    /// reflections deep: the one `shade_with` gives it after the lights that
    /// sample take theirs.
    pub(crate) fn environment_pair(&self, scene: &Scene, depth: u32) -> DimensionPair {
        let mut pairs = PairAllocation::new(depth);
        for (index, light) in scene.lights.iter().enumerate() {
            let samples = match light {
                Light::Area(_) => true,
                Light::Sphere(_) => scene.shading == ShadingModel::Physical,
                Light::Point(_) => false,
            };
            if samples {
                self.light_pair(&mut pairs, index, depth);
            }
        }
        let own = DimensionPair::Environment { depth };
        pairs.take(own, self.environment_samples)
    }

    /// Monte Carlo estimate of `∫ L_env(ω)·V(ω)·f(ω)·cos θ dω` with directions
    /// importance-sampled from the environment (the points of
    /// `environment_pattern` over [0, 1)² mapped to directions), for a shading
    /// point `depth` reflections deep.
    pub(crate) fn environment_light<T: Tracer>(
        &self,
        scene: &Scene,
        point: &ShadingPoint,
        pair: DimensionPair,
        ctx: &mut SampleContext<T>,
    ) -> Vec3 {
        let Some(env) = &scene.environment else {
            return Vec3::ZERO;
        };
        let n = self.environment_samples as usize;
        ctx.counters.environment_samples += n as u64;
        let one_by_one = n < LANES_FROM_SAMPLES;
        let mut sum = Vec3::ZERO;
        let mut samples = std::mem::take(&mut ctx.environment_points);
        ctx.fill_points(self.environment_pattern, pair, &mut samples);
        for chunk in samples.chunks() {
            let drawn = drawn_together(env, self.environment_sampling, point.n, &chunk);
            let drawn = &drawn[..chunk.len];
            point.add_environment_samples(scene, drawn, one_by_one, &mut sum, ctx);
        }
        ctx.environment_points = samples;
        sum / self.environment_samples as f32
    }
}

impl ShadingPoint<'_> {
    /// The origins of this point's shadow rays, for rays tested in lanes.
    /// Inlined: returned through memory, the lanes cost a store-forwarding stall.
    #[inline(always)]
    pub(crate) fn shadow_origins(&self) -> ShadowOrigins {
        let (point, error, normal) = (self.hit.point, self.hit.error, self.hit.geometric_normal);
        ShadowOrigins {
            front: Vec3Lanes::splat(offset_ray_origin(point, error, normal)),
            back: Vec3Lanes::splat(offset_ray_origin(point, error, -normal)),
            normal,
        }
    }

    /// An environment sample's value `L · f · cos θ / p` if unblocked, short
    /// of its shadow ray, or `None` (counted) where it needs no shadow ray.
    /// Counts the shadow ray it needs.
    fn environment_sample_unshadowed<T: Tracer>(
        &self,
        s: &EnvironmentSample,
        ctx: &mut SampleContext<T>,
    ) -> Option<Vec3> {
        if s.pdf.is_nan() || s.pdf <= 0.0 || s.radiance == Vec3::ZERO {
            ctx.counters.environment_skips.zero_density += 1;
            return None;
        }
        if !self.above_surface(s.direction) {
            ctx.counters.environment_skips.below_surface += 1;
            return None;
        }
        let f = self.brdf_cos(s.direction, ctx);
        if f == Vec3::ZERO {
            ctx.counters.environment_skips.zero_brdf += 1;
            return None;
        }
        ctx.counters.environment_shadow_rays += 1;
        Some(s.radiance * f / s.pdf)
    }

    /// Adds to `sum` the values of the environment samples `drawn` (at most
    /// [`LANES`]) whose shadow rays are unblocked, in order: `one_by_one`,
    /// or each up to its shadow ray one by one and then their shadow rays
    /// tested together (the origins of `spawn_ray`, so the same answers and
    /// the same sum, bit for bit).
    fn add_environment_samples<T: Tracer>(
        &self,
        scene: &Scene,
        drawn: &[EnvironmentSample],
        one_by_one: bool,
        sum: &mut Vec3,
        ctx: &mut SampleContext<T>,
    ) {
        if one_by_one {
            for s in drawn {
                let Some(value) = self.environment_sample_unshadowed(s, ctx) else {
                    continue;
                };
                let shadow_ray = spawn_ray(self.hit, s.direction);
                if !scene.shapes.any_hit(&shadow_ray, f32::INFINITY) {
                    *sum += value;
                }
            }
            return;
        }
        let mut values = [Vec3::ZERO; LANES];
        let mut directions = [self.hit.geometric_normal; LANES];
        let mut traced = 0u32;
        for (k, s) in drawn.iter().enumerate() {
            if let Some(value) = self.environment_sample_unshadowed(s, ctx) {
                (values[k], directions[k]) = (value, s.direction);
                traced |= 1 << k;
            }
        }
        let direction = Vec3Lanes::from_lanes(directions);
        let origin = self.shadow_origins().leaving_towards(&direction);
        let rays = RayLanes { origin, direction };
        let blocked = (scene.shapes).any_hits_among(&Occluders::ALL, &rays, f32::INFINITY, traced);
        for k in lanes::each_set(traced & !blocked) {
            *sum += values[k];
        }
    }
}

/// The origins of a shading point's shadow rays in lanes: its point offset
/// to either side of its surface, made once for all its samples.
pub(crate) struct ShadowOrigins {
    front: Vec3Lanes,
    back: Vec3Lanes,
    normal: Vec3,
}

impl ShadowOrigins {
    /// Each lane's origin on the side of the surface its direction `towards`
    /// leaves on, as `spawn_ray` and `spawn_ray_to` choose it.
    #[inline]
    pub(crate) fn leaving_towards(&self, towards: &Vec3Lanes) -> Vec3Lanes {
        let from_back = lanes::lt(towards.dot_splat(self.normal), F32Lanes::ZERO);
        Vec3Lanes::select(from_back, &self.back, &self.front)
    }
}

/// The environment's samples at a chunk of points, about `normal`: drawn
/// together ([`EnvironmentLight::sample_each`]), each as it is drawn alone.
#[inline]
fn drawn_together(
    env: &EnvironmentLight,
    sampling: EnvironmentSampling,
    normal: Vec3,
    chunk: &PointChunk,
) -> [EnvironmentSample; LANES] {
    let mut points = [Vec2::ZERO; LANES];
    for (point, u) in points.iter_mut().zip(chunk.iter()) {
        *point = u;
    }
    if sampling == EnvironmentSampling::Luminance {
        return env.sample_each(normal, &points, chunk.len);
    }
    let u = (
        lanes::from_fn(|k| points[k].x),
        lanes::from_fn(|k| points[k].y),
    );
    let used = (1 << chunk.len) - 1;
    let (d, radiance, pdf) = env.sample_cosine_each(&Vec3Lanes::splat(normal), u, used);
    let pdf = pdf.to_array();
    lanes::array_from_fn(|k| EnvironmentSample {
        direction: d.lane(k),
        radiance: radiance.lane(k),
        pdf: pdf[k],
    })
}

/// A surface point being shaded: the hit, its material and reflectances, the
/// unit shading normal `n` (on the viewer's side), the geometric normal `ng` on the
/// same side, and the direction `v` towards the viewer.
pub(crate) struct ShadingPoint<'a> {
    pub(crate) hit: &'a Hit,
    pub(crate) material: &'a PhongMaterial,
    pub(crate) kd: Vec3,
    pub(crate) ks: Vec3,
    pub(crate) n: Vec3,
    pub(crate) ng: Vec3,
    pub(crate) v: Vec3,
    /// Whether `ks` is nonzero: without it the specular lobe is never evaluated.
    pub(crate) has_specular: bool,
}

impl<'a> ShadingPoint<'a> {
    /// The point `hit` of `material`, seen along `ray`, with its texture lookup `tc`.
    pub(crate) fn new(hit: &'a Hit, material: &'a PhongMaterial, ray: &Ray, tc: &TexCoord) -> Self {
        Self::with_reflectances(hit, material, ray, material.reflectances(tc))
    }

    /// [`Self::new`] with the reflectances `(kd, ks)` already looked up.
    pub(crate) fn with_reflectances(
        hit: &'a Hit,
        material: &'a PhongMaterial,
        ray: &Ray,
        (kd, ks): (Vec3, Vec3),
    ) -> Self {
        let n = hit.facing_normal(ray.direction);
        let ng = if hit.geometric_normal.dot(n) < 0.0 {
            -hit.geometric_normal
        } else {
            hit.geometric_normal
        };
        Self {
            hit,
            material,
            kd,
            ks,
            n,
            ng,
            v: -ray.direction.normalize(),
            has_specular: ks != Vec3::ZERO,
        }
    }

    /// Whether light from direction `l` can reach the surface at all: it must be
    /// above the *geometric* surface. With interpolated shading normals a light can
    /// be above the shading normal's horizon but below the triangle's; its shadow
    /// ray would leave into the surface and be blocked by the neighbouring
    /// triangles, leaving dark specks (the "shadow terminator" problem).
    #[inline]
    pub(crate) fn above_surface(&self, l: Vec3) -> bool {
        self.ng.dot(l) > 0.0
    }

    /// The BRDF times the cosine for light from direction `l`: the specular
    /// lobe only where `ks` is nonzero.
    #[inline]
    pub(crate) fn brdf_cos<T: Tracer>(&self, l: Vec3, ctx: &mut SampleContext<T>) -> Vec3 {
        if self.has_specular {
            ctx.counters.specular_lobes += 1;
        }
        self.f_cos(l)
    }

    /// [`Self::brdf_cos`], uncounted.
    #[inline]
    pub(crate) fn f_cos(&self, l: Vec3) -> Vec3 {
        if self.has_specular {
            self.material.brdf_cos(self.kd, self.ks, self.n, l, self.v)
        } else {
            self.material.brdf_cos_diffuse(self.kd, self.n, l)
        }
    }
}

impl ShadingPoint<'_> {
    /// Phong reflection towards `v` of a unit light at `target`, or zero if the
    /// light is behind the surface or a shadow ray finds it occluded (testing only
    /// `occluders`). The shadow ray is only traced when the light could contribute.
    pub(crate) fn unoccluded_reflection<T: Tracer>(
        &self,
        scene: &Scene,
        target: &RayTarget,
        occluders: &Occluders,
        ctx: &mut SampleContext<T>,
    ) -> Vec3 {
        // A direction of no length (the light's point is the shading point)
        // is not above the surface either: `ng · 0 > 0` is false.
        let l = (target.point - self.hit.point).normalize_or_zero();
        if !self.above_surface(l) {
            ctx.counters.light_skips.below_surface += 1;
            return Vec3::ZERO;
        }
        let reflected = if self.has_specular {
            ctx.counters.specular_lobes += 1;
            self.material.reflect(self.kd, self.ks, self.n, l, self.v)
        } else {
            self.material.reflect_diffuse(self.kd, self.n, l)
        };
        if reflected == Vec3::ZERO {
            ctx.counters.light_skips.zero_brdf += 1;
            return Vec3::ZERO;
        }
        let shadow = spawn_ray_to(self.hit, target);
        ctx.counters.light_shadow_rays += 1;
        if scene.shapes.any_hit_among(occluders, &shadow, 1.0) {
            Vec3::ZERO
        } else {
            reflected
        }
    }

    /// A light sample of the course's model at `position` (on the light), the
    /// direction to it `l`, as a tracer shows it: its shadow ray's verdict,
    /// what it adds (`value`), and the diffuse and specular parts recomputed
    /// apart (their sum is the reflection the integrator used, to rounding).
    pub(crate) fn light_sample_event(
        &self,
        (position, l): (Vec3, Vec3),
        shadow: Shadow,
        value: Vec3,
    ) -> Event {
        let n_dot_l = self.n.dot(l);
        let specular = match self.has_specular {
            true => (self.material).reflect(Vec3::ZERO, self.ks, self.n, l, self.v),
            false => Vec3::ZERO,
        };
        Event::LightSample {
            position,
            l,
            n_dot_l,
            reflection: 2.0 * n_dot_l * self.n - l,
            diffuse: self.material.reflect_diffuse(self.kd, self.n, l),
            specular,
            shadow,
            value,
        }
    }
}

/// Which Sobol dimension pair each of a shading point's 2D samples reads. At the
/// camera ray's hit, the first light-like sample (area lights in scene order,
/// then the environment) that takes one sample per camera sample reads the
/// pixel's own sequence, dimensions 2 and 3 ([`DimensionPair::Joint`]):
/// stratified together with the pixel position,
/// which lowers the error of a pixel's soft shadows (measured on the Cornell
/// box's floor: about half the relative MSE at 256 samples, and a steeper
/// convergence slope, than independent pairs). Every other sample keeps its own
/// sequence.
pub(crate) struct PairAllocation {
    depth: u32,
    next_joint: u32,
}

impl PairAllocation {
    pub(crate) fn new(depth: u32) -> Self {
        Self {
            depth,
            next_joint: 1,
        }
    }

    /// The pair for a sample that would otherwise read `own`, taking
    /// `per_sample` points per camera sample.
    #[inline]
    pub(crate) fn take(&mut self, own: DimensionPair, per_sample: u32) -> DimensionPair {
        if self.depth == 0 && per_sample == 1 && self.next_joint <= MAX_JOINT {
            self.next_joint += 1;
            DimensionPair::Joint {
                k: self.next_joint - 1,
            }
        } else {
            own
        }
    }
}

/// A ray's hit on a material, with what shading it reads: the ray and its
/// differentials.
#[derive(Clone, Copy)]
struct SurfaceHit<'a> {
    hit: &'a Hit,
    material: &'a PhongMaterial,
    ray: &'a Ray,
    diff: &'a RayDifferential,
}

/// The ray `ray` reflects into at `hit` by a perfect mirror, and its
/// differentials ([`reflect_differential`]), leaving from an origin offset
/// to its side ([`spawn_ray`]).
pub(crate) fn mirror_ray(hit: &Hit, ray: &Ray, diff: &RayDifferential) -> (Ray, RayDifferential) {
    let surface = hit.differentials(diff);
    let (wi, reflected_diff) = reflect_differential(hit, ray.direction, diff, &surface);
    (spawn_ray(hit, wi), reflected_diff)
}

/// The nearest object blocking `shadow` before `t_max`, as a tracer reports
/// it (the integrator itself only asks whether anything does). A closest-hit
/// query: call it in a tracer's hook only.
pub(crate) fn blocker(scene: &Scene, shadow: &Ray, t_max: f32) -> Shadow {
    match scene.shapes.closest_hit(shadow, t_max) {
        Some(hit) => Shadow::Blocked {
            object: hit.shape,
            t: hit.t,
        },
        // Counted as blocked by a test the closest-hit query rounds differently.
        None => Shadow::Blocked {
            object: u32::MAX,
            t: f32::NAN,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_single_sample_at_the_camera_hit_reads_the_joint_pair() {
        let light = |light| DimensionPair::Light { light, depth: 0 };
        let environment = DimensionPair::Environment { depth: 0 };
        // One sample each at the camera ray's hit: the first light-like one is joint.
        let mut pairs = PairAllocation::new(0);
        assert_eq!(pairs.take(light(1), 1), DimensionPair::Joint { k: 1 });
        assert_eq!(pairs.take(light(2), 1), light(2));
        assert_eq!(pairs.take(environment, 1), environment);
        // Without area lights, the environment takes it.
        assert_eq!(
            PairAllocation::new(0).take(environment, 1),
            DimensionPair::Joint { k: 1 }
        );
        // Several samples per camera sample, or a reflection's hit: their own.
        assert_eq!(PairAllocation::new(0).take(light(0), 4), light(0));
        let deeper = DimensionPair::Light { light: 0, depth: 1 };
        assert_eq!(PairAllocation::new(1).take(deeper, 1), deeper);
    }
}
