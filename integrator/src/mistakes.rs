//! Classic mistakes of a student's ray tracer, switched on in the one-ray
//! reference integrator ([`crate::reference`]) so that `glint grade` can
//! render what a mistaken tracer renders. Built only with the `mistakes`
//! feature: the render's lanes never read them, so the shipped render path
//! has no branch for any of them.
//!
//! Each mistake swaps one step of the course's Phong integrator for the
//! wrong one, as the course's report would be misread: the camera's sample
//! positions, the hit's texture coordinates or normal, the shading terms,
//! the shadow rays, what camera rays see, how the cube map is read.

use crate::context::SampleContext;
use crate::render::{camera_ray, footprint_scale, pixel_positions};
use crate::settings::{RenderSettings, SettingsError};
use crate::shading_point::ShadingPoint;
use crate::{DirectIntegrator, Scene, ShadingModel, SurfaceKind};
use glam::{Vec2, Vec3};
use glint_camera::Film;
use glint_geometry::{Hit, ObjectRef, Ray, RayDifferential, Shape};
use glint_lighting::{EnvironmentLight, Light, PhongMaterial};
use glint_texture::{Environment, TexCoord};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// The revision of how the mistakes render, for caches of their renders
/// (`glint grade`'s references): raised whenever one renders differently.
pub const REVISION: u32 = 4;

/// One mistake the reference integrator can make.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mistake {
    /// Camera rays through the pixels' corners: every sample position half a
    /// pixel up and left (`x + ξ` for `x + 0.5 + ξ − 0.5`).
    PixelCorner,
    /// Shadow rays start at the computed hit point and test every shape,
    /// their own too, for `t > 0`: the point's own surface blocks about half
    /// of them (acne).
    NoShadowOffset,
    /// A sphere's shading normal is `p − c`, of length `r`, in every dot
    /// product of the shading.
    NormalNotNormalised,
    /// A sphere's `u` from `atan2(z, x)` for `atan2(−z, x)`: `u → 1 − u`.
    SphereUSign,
    /// `u` and `v` swapped before every texture lookup.
    UvSwapped,
    /// The trilinear MIP level `ln(w·m)` for `log2(w·m)` (footprint `w`,
    /// texture side `m`): `ln 2` times the right level, too sharp.
    MipLevelLn,
    /// `ambient` for `ambient · kd`.
    AmbientWithoutKd,
    /// Every light sample counts as visible.
    NoShadows,
    /// An area light's own surface blocks its shadow rays: it lights nothing.
    LightBlocksItself,
    /// Camera (and mirror) rays pass through area lights to what is behind.
    LightInvisible,
    /// The view vector's sign flipped in the specular term.
    ViewSign,
    /// The specular term multiplied by `n·l` too.
    SpecularCosine,
    /// The diffuse term `kd` without `n·l` (still only where `n·l > 0`).
    NoLambertCosine,
    /// The cube map's `+z` and `−z` faces swapped.
    CubeFaceSwapped,
    /// Every cube-map face read mirrored left to right.
    CubeFaceMirrored,
}

impl Mistake {
    /// Every mistake, in the order of its bit.
    pub const ALL: [Mistake; 15] = [
        Mistake::PixelCorner,
        Mistake::NoShadowOffset,
        Mistake::NormalNotNormalised,
        Mistake::SphereUSign,
        Mistake::UvSwapped,
        Mistake::MipLevelLn,
        Mistake::AmbientWithoutKd,
        Mistake::NoShadows,
        Mistake::LightBlocksItself,
        Mistake::LightInvisible,
        Mistake::ViewSign,
        Mistake::SpecularCosine,
        Mistake::NoLambertCosine,
        Mistake::CubeFaceSwapped,
        Mistake::CubeFaceMirrored,
    ];

    fn bit(self) -> u32 {
        1 << self as u32
    }

    /// Whether the mistake can change a render of `scene`: the course's
    /// Phong shading, and what the mistake spoils in it (spheres, textures,
    /// ambient light, area lights, a cube map).
    pub fn applies_to(self, scene: &Scene) -> bool {
        use Mistake::*;
        if scene.shading != ShadingModel::Phong {
            return false;
        }
        let spheres = || {
            (0..scene.shapes.len() as u32)
                .any(|i| matches!(scene.shapes.object(i), ObjectRef::Shape(Shape::Sphere(_))))
        };
        let area_lights = || scene.lights.iter().any(|l| matches!(l, Light::Area(_)));
        let cube_map = || {
            (scene.environment.as_ref())
                .is_some_and(|e| matches!(e.environment(), Environment::CubeMap(_)))
        };
        match self {
            PixelCorner | NoShadowOffset | NoShadows => true,
            NormalNotNormalised => spheres(),
            SphereUSign => spheres() && scene.materials.iter().any(|m| m.reads_uv()),
            UvSwapped => scene.materials.iter().any(|m| m.reads_uv()),
            MipLevelLn => scene.materials.iter().any(|m| m.uses_footprint()),
            AmbientWithoutKd => scene.ambient != Vec3::ZERO,
            LightBlocksItself | LightInvisible => area_lights(),
            ViewSign | SpecularCosine | NoLambertCosine => true,
            CubeFaceSwapped | CubeFaceMirrored => cube_map(),
        }
    }
}

/// A set of [`Mistake`]s.
#[derive(Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct Mistakes(u32);

impl std::fmt::Debug for Mistakes {
    /// The mistakes by name (`[NoShadows, ViewSign]`): what `glint grade`'s
    /// reference cache keys hash.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

impl Mistakes {
    /// No mistake: the reference integrator as it is.
    pub const NONE: Mistakes = Mistakes(0);

    pub fn with(self, mistake: Mistake) -> Mistakes {
        Mistakes(self.0 | mistake.bit())
    }

    pub fn has(self, mistake: Mistake) -> bool {
        self.0 & mistake.bit() != 0
    }

    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    pub fn union(self, other: Mistakes) -> Mistakes {
        Mistakes(self.0 | other.0)
    }

    /// The mistakes in the set.
    pub fn iter(self) -> impl Iterator<Item = Mistake> {
        Mistake::ALL.into_iter().filter(move |&m| self.has(m))
    }

    /// Whether any of them changes a shading point's reflection of a light
    /// (an unnormalised normal, by a lobe that can overflow `f32`).
    fn in_reflection(self) -> bool {
        self.has(Mistake::SpecularCosine)
            || self.has(Mistake::NoLambertCosine)
            || self.has(Mistake::NormalNotNormalised)
    }
}

impl FromIterator<Mistake> for Mistakes {
    fn from_iter<I: IntoIterator<Item = Mistake>>(iter: I) -> Self {
        iter.into_iter().fold(Mistakes::NONE, Mistakes::with)
    }
}

/// `scene` rendered with `settings` by the one-ray reference integrator
/// with `mistakes` switched on. With none, every pixel is [`crate::render`]'s
/// bit for bit (the same sample positions, streams and rays; the AOV and
/// crop settings are not read): the one-ray integrator is tested against
/// the lanes bit for bit. About ten times slower than `render`. Once `stop`
/// is set, rows not yet begun are left black.
pub fn render_with_mistakes(
    scene: &Scene,
    settings: &RenderSettings,
    mistakes: Mistakes,
    stop: Option<&AtomicBool>,
) -> Result<Film, SettingsError> {
    settings.validate()?;
    scene.prepare(settings);
    let integrator = DirectIntegrator::new(settings);
    let size = scene.camera.resolution();
    let mut film = Film::new(size);
    let run = |pixels: &mut [Vec3]| {
        let rows = pixels.par_chunks_mut(size.x as usize);
        rows.enumerate().for_each(|(y, row)| {
            if stop.is_some_and(|stop| stop.load(Ordering::Relaxed)) {
                return;
            }
            let (mut ctx, mut positions) = mistaken_context(settings, mistakes);
            for (x, pixel) in row.iter_mut().enumerate() {
                let at = (x as u32, y as u32);
                *pixel = integrator.mistaken_pixel(scene, settings, at, &mut positions, &mut ctx);
            }
        })
    };
    match settings.threads {
        None => run(film.pixels_mut()),
        Some(threads) => rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| SettingsError::ThreadPool(e.to_string()))?
            .install(|| run(film.pixels_mut())),
    }
    Ok(film)
}

/// Pixel `(x, y)` of [`render_with_mistakes`]'s film, alone.
pub fn pixel_with_mistakes(
    scene: &Scene,
    settings: &RenderSettings,
    (x, y): (u32, u32),
    mistakes: Mistakes,
) -> Result<Vec3, SettingsError> {
    settings.validate()?;
    scene.prepare(settings);
    let integrator = DirectIntegrator::new(settings);
    let (mut ctx, mut positions) = mistaken_context(settings, mistakes);
    Ok(integrator.mistaken_pixel(scene, settings, (x, y), &mut positions, &mut ctx))
}

/// A sample context with `mistakes` on, and room for a pixel's sample
/// positions: what [`DirectIntegrator::mistaken_pixel`] reuses pixel to pixel.
fn mistaken_context(settings: &RenderSettings, mistakes: Mistakes) -> (SampleContext, Vec<Vec2>) {
    let mut ctx = SampleContext::new(settings.light_samples, settings.environment_samples);
    ctx.mistakes = mistakes;
    (ctx, vec![Vec2::ZERO; settings.spp as usize])
}

/// The most a mistaken sample's radiance counts for. A mistake can overflow
/// `f32` (an unnormalised normal of radius `r` raises `r²` to the
/// shininess): where the render leaves an infinite sample out, a tracer in
/// doubles has a huge finite one and writes white; capped far above 1, the
/// sample still makes its pixel white, and the clamp gap stays exact in
/// `f32`. A NaN is still left out.
const MISTAKEN_CAP: f32 = 1e3;

/// The most a mistaken specular lobe counts for: `(r·v)ⁿ` of an unnormalised
/// normal overflows `f32` where a tracer in doubles has a huge finite lobe,
/// and a zero channel of `ks` or of the light's colour times an infinite one
/// is NaN, a sample left out (a black crescent in the highlight) where the
/// tracer's channel is 0. Finite, the channel stays 0; the rest of the
/// sample's factors are far below `f32::MAX / 1e30`.
const MISTAKEN_LOBE_CAP: f32 = 1e30;

impl DirectIntegrator {
    /// Pixel `(x, y)`: the mean of its finite camera samples, each traced by
    /// [`Self::li_one_ray`] with `ctx`'s mistakes.
    fn mistaken_pixel(
        &self,
        scene: &Scene,
        settings: &RenderSettings,
        (x, y): (u32, u32),
        positions: &mut [Vec2],
        ctx: &mut SampleContext,
    ) -> Vec3 {
        let pixel = y as u64 * scene.camera.resolution().x as u64 + x as u64;
        pixel_positions(settings, pixel, positions);
        let corner = match ctx.mistakes.has(Mistake::PixelCorner) {
            true => Vec2::splat(0.5),
            false => Vec2::ZERO,
        };
        let scale = footprint_scale(settings.spp);
        let differentials = scene.needs_differentials();
        let mut sum = Vec3::ZERO;
        for (sample, &jitter) in positions.iter().enumerate() {
            let raster = Vec2::new(x as f32, y as f32) + jitter - corner;
            let (ray, diff) = match differentials {
                true => camera_ray(&scene.camera, raster, scale),
                false => {
                    let c = scene.camera.generate_ray(raster.x, raster.y);
                    let ray = Ray::new(c.origin, c.direction);
                    (ray, RayDifferential::none(&ray))
                }
            };
            ctx.begin_sample(settings.seed, pixel, sample as u64);
            let value = self.li_one_ray(scene, &ray, &diff, 0, ctx);
            let value = match ctx.mistakes.is_empty() || value.is_nan() {
                true => value,
                false => value.min(Vec3::splat(MISTAKEN_CAP)),
            };
            if value.is_finite() {
                sum += value;
            }
        }
        sum / settings.spp as f32
    }
}

/// The hit of `ray` as a mistaken tracer has it: its texture coordinates,
/// and, without a shadow offset, its point where `o + t d` puts it (the
/// shapes put it back on their surface; shadow rays starting there hit
/// their own surface as often as a student's do).
pub(crate) fn mistaken_hit(scene: &Scene, hit: &Hit, ray: &Ray, mistakes: Mistakes) -> Hit {
    let mut hit = *hit;
    if mistakes.has(Mistake::NoShadowOffset) {
        hit.point = ray.origin + hit.t * ray.direction;
    }
    if mistakes.has(Mistake::SphereUSign) && sphere_radius(scene, &hit).is_some() {
        hit.uv.x = (1.0 - hit.uv.x).fract();
        (hit.dpdu, hit.dndu) = (-hit.dpdu, -hit.dndu);
    }
    if mistakes.has(Mistake::UvSwapped) {
        hit.uv = Vec2::new(hit.uv.y, hit.uv.x);
        (hit.dpdu, hit.dpdv) = (hit.dpdv, hit.dpdu);
        (hit.dndu, hit.dndv) = (hit.dndv, hit.dndu);
    }
    hit
}

/// The texture lookup `tc` of `material` as a tracer that takes the MIP
/// level from the natural logarithm makes it: the footprint shrunk by
/// `2^(L·(ln 2 − 1))` so that the right level `L` of its diffuse texture
/// becomes `L·ln 2` (the last level standing for any past it).
pub(crate) fn mistaken_footprint(
    material: &PhongMaterial,
    tc: TexCoord,
    mistakes: Mistakes,
) -> TexCoord {
    if !mistakes.has(Mistake::MipLevelLn) {
        return tc;
    }
    let level = material.diffuse_mip_level(&tc);
    let shrink = (level * (std::f32::consts::LN_2 - 1.0)).exp2();
    TexCoord {
        duvdx: tc.duvdx * shrink,
        duvdy: tc.duvdy * shrink,
        ..tc
    }
}

/// The radius of the sphere `hit` is on, if it is on one.
fn sphere_radius(scene: &Scene, hit: &Hit) -> Option<f32> {
    match scene.shapes.object(hit.shape) {
        ObjectRef::Shape(Shape::Sphere(s)) => Some(s.radius()),
        _ => None,
    }
}

/// Whether `hit` is on an area light's surface, for [`Mistake::LightInvisible`].
pub(crate) fn invisible_light(scene: &Scene, hit: &Hit, mistakes: Mistakes) -> bool {
    mistakes.has(Mistake::LightInvisible)
        && matches!(scene.surface_of(hit), SurfaceKind::Emitter(Light::Area(_)))
}

impl ShadingPoint<'_> {
    /// The shading point's normal and view vector as a mistaken tracer has them.
    pub(crate) fn mistaken(&mut self, scene: &Scene, mistakes: Mistakes) {
        if mistakes.has(Mistake::ViewSign) {
            self.v = -self.v;
        }
        if mistakes.has(Mistake::NormalNotNormalised) {
            if let Some(r) = sphere_radius(scene, self.hit) {
                self.n *= r;
            }
        }
    }

    /// The Phong reflection of a unit light from the unit direction `l`
    /// ([`glint_lighting::PhongMaterial::reflect`]), with the mistakes in its
    /// terms, or `None` when `mistakes` has none.
    pub(crate) fn mistaken_reflection(&self, l: Vec3, mistakes: Mistakes) -> Option<Vec3> {
        if !mistakes.in_reflection() {
            return None;
        }
        let n_dot_l = self.n.dot(l);
        if n_dot_l <= 0.0 {
            return Some(Vec3::ZERO);
        }
        let specular = match self.has_specular {
            true => {
                let lobe = (self.material).specular_lobe(self.n, l, self.v, n_dot_l);
                self.ks * lobe.min(MISTAKEN_LOBE_CAP)
            }
            false => Vec3::ZERO,
        };
        let diffuse = match mistakes.has(Mistake::NoLambertCosine) {
            true => self.kd,
            false => self.kd * n_dot_l,
        };
        let specular = match mistakes.has(Mistake::SpecularCosine) {
            true => specular * n_dot_l,
            false => specular,
        };
        Some(diffuse + specular)
    }
}

/// The direction the mistaken tracer reads the environment along when the
/// right one reads along `d`: an involution that keeps solid angle, so a
/// sample drawn for the right map and moved by it is one of the mistaken
/// map with the same density.
pub(crate) fn mistaken_direction(env: &EnvironmentLight, d: Vec3, mistakes: Mistakes) -> Vec3 {
    let swapped = mistakes.has(Mistake::CubeFaceSwapped);
    let mirrored = mistakes.has(Mistake::CubeFaceMirrored);
    if !(swapped || mirrored) || !matches!(env.environment(), Environment::CubeMap(_)) {
        return d;
    }
    let mut m = env.to_map(d);
    let a = m.abs();
    let x_major = a.x >= a.y && a.x >= a.z;
    let z_major = !x_major && a.z > a.y;
    if swapped && z_major {
        // Face +z read from −z at the same face coordinates (s = x, t = −y
        // on +z; s = −x, t = −y on −z): a half turn about y.
        m = Vec3::new(-m.x, m.y, -m.z);
    }
    if mirrored {
        // s → −s on each face: s is −z on ±x faces' +x, x elsewhere (up to sign).
        m = match x_major {
            true => Vec3::new(m.x, m.y, -m.z),
            false => Vec3::new(-m.x, m.y, m.z),
        };
    }
    env.to_world(m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{render, SamplePattern, SceneBuilder};
    use glam::UVec2;
    use glint_camera::Camera;
    use glint_geometry::{Parallelogram, Sphere};
    use glint_lighting::{AreaLight, PhongMaterial, UvTransform};
    use glint_texture::{Checkerboard, CubeMap, Image, Texture};

    /// A floor checkered twice as finely in u as in v (u and v swapped
    /// shows), a checkered sphere (an even count of checks: an odd
    /// one is the same turned round), a one-sided light above and
    /// seen by the camera, grey ambient.
    fn scene() -> Scene {
        let mut b = SceneBuilder::new();
        let checks = Checkerboard::new(Vec3::splat(0.9), Vec3::new(0.6, 0.1, 0.1), 3);
        let floor = b.material(PhongMaterial {
            uv_transform: UvTransform {
                scale: Vec2::new(2.0, 1.0),
                offset: Vec2::ZERO,
            },
            ..PhongMaterial::new(Texture::Checkerboard(checks), 8.0)
        });
        let stripes = Checkerboard::new(Vec3::new(0.1, 0.3, 0.8), Vec3::splat(0.7), 4);
        let ball = b.material(PhongMaterial::new(Texture::Checkerboard(stripes), 24.0));
        let ground = Parallelogram::new(
            Vec3::new(-4.0, 0.0, -6.0),
            Vec3::Z * 8.0,
            Vec3::X * 8.0,
            false,
        )
        .unwrap()
        .facing(Vec3::Y);
        b.shape(ground, floor)
            .shape(Sphere::new(Vec3::new(0.3, 0.9, -2.0), 0.8).unwrap(), ball);
        let light = AreaLight::new(
            Vec3::new(-0.5, 2.6, -2.5),
            Vec3::X,
            Vec3::Z,
            Vec3::splat(2.0),
        );
        b.area_light(light.unwrap().facing(-Vec3::Y));
        b.ambient(Vec3::splat(0.15));
        let camera = Camera::new(
            Vec3::new(0.0, 1.2, 3.0),
            Vec3::new(0.0, 1.2, -2.0),
            Vec3::Y,
            60.0,
            1.0,
            UVec2::new(24, 24),
        );
        b.build(camera.unwrap()).unwrap()
    }

    fn settings(spp: u32, pattern: SamplePattern, light_samples: u32) -> RenderSettings {
        RenderSettings {
            spp,
            pixel_pattern: pattern,
            light_samples,
            light_pattern: pattern,
            seed: 5,
            ..RenderSettings::default()
        }
    }

    fn bits(film: &Film) -> Vec<[u32; 3]> {
        film.pixels()
            .iter()
            .map(|p| p.to_array().map(f32::to_bits))
            .collect()
    }

    #[test]
    fn without_mistakes_every_pixel_is_the_renders_bit_for_bit() {
        let scene = scene();
        for (spp, pattern, light) in [
            (1, SamplePattern::Random, 1),
            (4, SamplePattern::Stratified, 4),
            (3, SamplePattern::Sobol, 2),
            (16, SamplePattern::Grid, 1),
        ] {
            let settings = settings(spp, pattern, light);
            let lanes = render(&scene, &settings, &|_, _| {}).unwrap().film;
            let one_ray = render_with_mistakes(&scene, &settings, Mistakes::NONE, None).unwrap();
            assert_eq!(
                bits(&one_ray),
                bits(&lanes),
                "{spp} spp {pattern:?} × {light}"
            );
        }
    }

    /// Each mistake that applies changes the image, the same way for any
    /// thread count; light lost to a blocker never comes back and light
    /// that no shadow ray stops is never less.
    #[test]
    fn each_mistake_that_applies_changes_the_image_as_it_should() {
        let scene = scene();
        let settings = settings(4, SamplePattern::Stratified, 4);
        let right = render_with_mistakes(&scene, &settings, Mistakes::NONE, None).unwrap();
        let (right, mut applied) = (right.pixels(), 0);
        for mistake in Mistake::ALL {
            let cube = matches!(
                mistake,
                Mistake::CubeFaceSwapped | Mistake::CubeFaceMirrored
            );
            // The checkerboards are read at points: no footprint, no level.
            let unread = cube || mistake == Mistake::MipLevelLn;
            assert_eq!(mistake.applies_to(&scene), !unread, "{mistake:?}");
            if unread {
                continue;
            }
            applied += 1;
            let one = Mistakes::NONE.with(mistake);
            let wrong = render_with_mistakes(&scene, &settings, one, None).unwrap();
            let alone = pixel_with_mistakes(&scene, &settings, (5, 17), one).unwrap();
            assert_eq!(alone, wrong.pixels()[17 * 24 + 5], "{mistake:?}");
            let changed = (right.iter().zip(wrong.pixels()))
                .filter(|(a, b)| a != b)
                .count();
            assert!(changed > 0, "{mistake:?} changed no pixel");
            let two_threads = RenderSettings {
                threads: Some(2),
                ..settings.clone()
            };
            let again = render_with_mistakes(&scene, &two_threads, one, None).unwrap();
            assert_eq!(bits(&again), bits(&wrong), "{mistake:?}");
            let pairs = || right.iter().zip(wrong.pixels());
            match mistake {
                Mistake::NoShadows => assert!(pairs().all(|(r, w)| w.cmpge(*r).all())),
                Mistake::LightBlocksItself => assert!(pairs().all(|(r, w)| w.cmple(*r).all())),
                // Shaded at `o + t d`, off the surface by a rounding: darker,
                // or brighter by no more than rounding.
                Mistake::NoShadowOffset => {
                    let within = |r: Vec3, w: Vec3| w.cmple(r * (1.0 + 1e-4) + 1e-6).all();
                    assert!(pairs().all(|(r, w)| within(*r, *w)));
                    assert!(pairs().any(|(r, w)| w.max_element() < 0.9 * r.max_element()));
                }
                _ => {}
            }
        }
        assert_eq!(applied, 12);
    }

    /// A cube map of six flat faces, each its own colour, with a gradient
    /// across the +z face.
    fn cube_environment() -> EnvironmentLight {
        let faces = std::array::from_fn(|face| {
            Image::from_fn(8, 8, |x, _| match face {
                4 => Vec3::new(4.0, x as f32, 0.0),
                _ => Vec3::splat(face as f32),
            })
        });
        EnvironmentLight::new(Environment::CubeMap(CubeMap::new(faces).unwrap()), 0.4, 1.0)
    }

    #[test]
    fn mistaken_cube_map_directions_read_the_swapped_or_mirrored_face() {
        let env = cube_environment();
        let swapped = Mistakes::NONE.with(Mistake::CubeFaceSwapped);
        let mirrored = Mistakes::NONE.with(Mistake::CubeFaceMirrored);
        // Along the map's +z, a little towards +x: the +z face, left of centre.
        let d = env.to_world(Vec3::new(0.3, 0.1, 1.0).normalize());
        let at = |d: Vec3| env.radiance(d, 0.0);
        assert_eq!(at(d).x, 4.0);
        assert_eq!(at(mistaken_direction(&env, d, swapped)), Vec3::splat(5.0));
        let (left, right) = (at(d).y, at(mistaken_direction(&env, d, mirrored)).y);
        assert_eq!(left + right, 7.0, "texel x and 7 − x: {left}, {right}");
        assert_ne!(left, right);
        // Involutions that keep solid angle.
        for m in [swapped, mirrored, swapped.with(Mistake::CubeFaceMirrored)] {
            for d in [
                d,
                Vec3::new(-0.9, 0.2, 0.3).normalize(),
                Vec3::new(0.1, -1.0, 0.2),
            ] {
                let twice = mistaken_direction(&env, mistaken_direction(&env, d, m), m);
                assert!(twice.abs_diff_eq(d, 1e-5), "{m:?}: {d} → {twice}");
            }
        }
        assert_eq!(mistaken_direction(&env, d, Mistakes::NONE), d);
    }
}
