//! The Glint renders a submission is judged against, at the submission's
//! resolution: the mean reference `M` and the clamp-gap reference `G` (see
//! [`hypothesis`](crate::hypothesis)), each the mean of independent rounds
//! with the variance of that mean; and the object seen at each pixel's
//! centre, which names the regions of a report; and, for a JPEG submission,
//! both passed through its encoding ([`with_jpeg`]). Rendered references are
//! cached (the same files and key as `glint bench`'s), so that a class's
//! submissions of one scene pay for them once.

use crate::hypothesis::ReferencePlan;
use crate::jpeg::{DcRounding, JpegEncoding};
use crate::GradeError;
use glam::{UVec2, Vec3};
use glint_bench::reference::{cache_key, round_seed, CachePaths, Origin, RoundSums};
use glint_integrator::mistakes::{render_with_mistakes, Mistakes};
use glint_integrator::RenderSettings;
use glint_scene::SceneDescription;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The object index of a pixel whose centre sees no object.
pub const BACKGROUND: u32 = u32::MAX;

/// A scene to grade against: its description and what the reference
/// cache's key hashes, which is every file it was read from or, for a scene
/// from memory, its text and its assets.
#[derive(Debug)]
pub struct GradeScene {
    /// The scene file, or what names a scene from memory in reports.
    pub path: PathBuf,
    pub description: SceneDescription,
    /// The scene file (unless from memory) and its assets.
    pub inputs: Vec<PathBuf>,
    /// A scene from memory: the BLAKE3 hash of its text, hashed by the
    /// cache's key in place of a scene file.
    pub text_hash: Option<String>,
    /// The mistakes its references are rendered with (by the one-ray
    /// integrator; none for the correct references).
    pub mistakes: Mistakes,
    /// A scene from memory: the TOML text it was read from and the folder
    /// its assets are relative to, for the mistakes made as edits of the
    /// text ([`GradeScene::with_source`]).
    pub source: Option<SceneSource>,
}

/// The text a scene from memory was read from.
#[derive(Clone, Debug)]
pub struct SceneSource {
    pub text: String,
    pub base: PathBuf,
}

impl GradeScene {
    /// A scene from memory, named `name`, read as `description` from `text`:
    /// everything that made the description beside its assets (the scene's
    /// text and whatever replaced its settings), so that equal texts share
    /// cached references and any change in them does not.
    pub fn from_text(name: &str, text: &str, description: SceneDescription) -> GradeScene {
        GradeScene {
            path: PathBuf::from(name),
            inputs: description.assets.clone(),
            text_hash: Some(blake3::hash(text.as_bytes()).to_hex().to_string()),
            description,
            mistakes: Mistakes::NONE,
            source: None,
        }
    }

    /// The scene, read from the TOML `text` with its assets relative to
    /// `base` (and its settings then replaced or not): what its mistakes
    /// are edits of.
    pub fn with_source(self, text: String, base: PathBuf) -> GradeScene {
        GradeScene {
            source: Some(SceneSource { text, base }),
            ..self
        }
    }

    pub fn load(path: &Path) -> Result<GradeScene, GradeError> {
        let description = glint_scene::load(path).map_err(|e| GradeError::Input(e.to_string()))?;
        Ok(GradeScene::from_file(path, description))
    }

    /// The scene file at `path`, already read as `description` (nothing
    /// replaced in it: the cache's key hashes the file as it is).
    pub fn from_file(path: &Path, description: SceneDescription) -> GradeScene {
        let inputs = std::iter::once(path.to_owned())
            .chain(description.assets.iter().cloned())
            .collect();
        GradeScene {
            path: path.to_owned(),
            description,
            inputs,
            text_hash: None,
            mistakes: Mistakes::NONE,
            source: None,
        }
    }

    /// The scene rendered by the one-ray integrator with `mistakes` (on top
    /// of its own), named `name`.
    pub fn with_mistakes(&self, name: &str, mistakes: Mistakes) -> GradeScene {
        GradeScene {
            path: PathBuf::from(name),
            description: self.description.clone(),
            inputs: self.inputs.clone(),
            text_hash: self.text_hash.clone(),
            mistakes: mistakes.union(self.mistakes),
            source: self.source.clone(),
        }
    }

    /// The scene's own render settings (its `[render]` table).
    pub fn settings(&self) -> &RenderSettings {
        &self.description.settings
    }

    /// What reports call object `i` (or the background).
    pub fn object_name(&self, object: u32) -> &str {
        match object {
            BACKGROUND => "background",
            i => &self.description.object_names[i as usize],
        }
    }
}

/// One reference: per pixel, a mean and the variance of that mean.
#[derive(Clone, Debug, PartialEq)]
pub struct Estimate {
    pub mean: Vec<Vec3>,
    pub variance: Vec<Vec3>,
    pub rounds: u32,
    /// Whether it was read from the cache rather than rendered.
    pub cached: bool,
}

impl Estimate {
    /// The variance of one round, per pixel: `rounds` times that of the mean.
    pub fn round_variance(&self, pixel: usize) -> Vec3 {
        self.variance[pixel] * self.rounds as f32
    }
}

/// The sample reference: the submission's own estimator, rendered in rounds.
#[derive(Clone, Debug, PartialEq)]
pub struct SampleEstimates {
    /// Its radiance `X_s`.
    pub radiance: Estimate,
    /// `min(X_s, 1)`: what a clamped image stores.
    pub clamped: Estimate,
    /// The clamp gap `(X_s − 1)⁺`.
    pub gap: Estimate,
}

/// Everything a submission of one resolution is judged against.
#[derive(Clone, Debug)]
pub struct References {
    pub resolution: UVec2,
    pub plan: ReferencePlan,
    /// `M`, the expected value of the submission's renderer.
    pub mean: Estimate,
    /// The submission's own estimator: its noise and clamp gap.
    pub samples: SampleEstimates,
    /// Per pixel, the object its centre sees ([`BACKGROUND`] for none).
    pub objects: Vec<u32>,
    /// Time spent rendering (zero when everything came from the cache).
    pub render_time: Duration,
    /// The references through each JPEG encoding a submission judged
    /// against them has ([`with_jpeg`]).
    pub jpeg: Vec<JpegReference>,
}

impl References {
    /// The references through `encoding`, if they were made.
    pub fn through_jpeg(&self, encoding: &JpegEncoding) -> Option<&JpegReference> {
        self.jpeg.iter().find(|j| &j.encoding == encoding)
    }
}

/// Glint's renders as a JPEG submission's file would hold them: each passed
/// through its encoding ([`JpegEncoding::round_trip`]).
#[derive(Clone, Debug, PartialEq)]
pub struct JpegReference {
    pub encoding: JpegEncoding,
    /// Each round of the sample reference through the encoding: `E[J(X_s)]`,
    /// what a file of the submission's own estimator holds, noise included.
    pub samples: Estimate,
    /// The mean reference through the encoding: `J(M)`, the noiseless end.
    pub mean: Vec<Vec3>,
    /// What the rounding of `M`'s DC coefficients may do, under the sample
    /// reference's noise ([`JpegEncoding::dc_rounding`]).
    pub dc: DcRounding,
}

/// Where rendered references are kept; `None` renders them every time.
#[derive(Clone, Debug, Default)]
pub struct Cache {
    pub dir: Option<PathBuf>,
}

/// Renders (or reads from `cache`) the references of `scene` at `resolution`
/// under `plan`. `progress` hears what is being rendered.
pub fn references(
    scene: &GradeScene,
    resolution: UVec2,
    plan: &ReferencePlan,
    cache: &Cache,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<References, GradeError> {
    let start = Instant::now();
    let rendered = at_resolution(scene, resolution)?;
    let job = Job {
        scene,
        rendered: &rendered,
        resolution,
        cache,
        progress,
    };
    let [radiance, clamped, gap] = job.estimates(
        "sample",
        "",
        [&each(identity), &each(clamp), &each(excess)],
        &plan.samples,
        plan.sample_rounds,
    )?;
    // A mistake rendered by the one-ray integrator (several times slower
    // than the lanes) takes its mean from the sample reference's rounds:
    // the same expected value, known well enough to tell one mistake from
    // another, at a third of the paths.
    let mean = match scene.mistakes.is_empty() {
        true => {
            let [mean] =
                job.estimates("mean", "", [&each(identity)], &plan.mean, plan.mean_rounds)?;
            mean
        }
        false => radiance.clone(),
    };
    let cached = mean.cached && radiance.cached;
    Ok(References {
        resolution,
        plan: plan.clone(),
        mean,
        samples: SampleEstimates {
            radiance,
            clamped,
            gap,
        },
        objects: objects_at_pixel_centres(&rendered)?,
        render_time: if cached {
            Duration::ZERO
        } else {
            start.elapsed()
        },
        jpeg: Vec::new(),
    })
}

/// Adds to `refs` (of `scene`) the references through `encoding`, unless
/// they are there: the sample reference's rounds rendered again (the same
/// seeds, so the same rounds) and each passed through the encoding, or read
/// from the cache; and the mean reference through it.
pub fn with_jpeg(
    refs: &mut References,
    scene: &GradeScene,
    encoding: &JpegEncoding,
    cache: &Cache,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<(), GradeError> {
    if refs.through_jpeg(encoding).is_some() {
        return Ok(());
    }
    let (w, h) = (refs.resolution.x, refs.resolution.y);
    let rendered = at_resolution(scene, refs.resolution)?;
    let job = Job {
        scene,
        rendered: &rendered,
        resolution: refs.resolution,
        cache,
        progress,
    };
    let through = |pixels: &[Vec3], out: &mut Vec<Vec3>| {
        out.extend(encoding.round_trip(pixels, w, h)?);
        Ok(())
    };
    let tag = format!(
        " through JPEG {} ({})",
        encoding.key(),
        crate::jpeg::ROUND_TRIP
    );
    let [samples] = job.estimates(
        "sample",
        &tag,
        [&through],
        &refs.plan.samples,
        refs.plan.sample_rounds,
    )?;
    let mean = encoding
        .round_trip(&refs.mean.mean, w, h)
        .map_err(GradeError::Internal)?;
    let dc = dc_rounding(refs, encoding);
    refs.jpeg.push(JpegReference {
        encoding: encoding.clone(),
        samples,
        mean,
        dc,
    });
    Ok(())
}

/// The sample reference's rounds rendered again (the same seeds, so the
/// same rounds), each pixel passed through `f`: `E[f(X_s)]` and the variance
/// of that mean, cached apart under `tag`.
pub fn samples_through(
    scene: &GradeScene,
    refs: &References,
    tag: &str,
    f: &(dyn Fn(Vec3) -> Vec3 + Sync),
    cache: &Cache,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<Estimate, GradeError> {
    let rendered = at_resolution(scene, refs.resolution)?;
    let job = Job {
        scene,
        rendered: &rendered,
        resolution: refs.resolution,
        cache,
        progress,
    };
    let through = |pixels: &[Vec3], out: &mut Vec<Vec3>| {
        out.extend(pixels.iter().map(|&p| f(p)));
        Ok(())
    };
    let [samples] = job.estimates(
        "sample",
        tag,
        [&through],
        &refs.plan.samples,
        refs.plan.sample_rounds,
    )?;
    Ok(samples)
}

/// [`JpegEncoding::dc_rounding`] of the mean reference `M` under the sample
/// reference's noise (clamped, as an 8-bit file stores it) and `M`'s own,
/// in codes.
pub fn dc_rounding(refs: &References, encoding: &JpegEncoding) -> DcRounding {
    let m = &refs.mean.mean;
    let codes: Vec<u8> = m
        .iter()
        .flat_map(|p| p.to_array())
        .map(glint_camera::linear_to_srgb8)
        .collect();
    let noise: Vec<Vec3> = (0..m.len())
        .map(|i| {
            let variance = refs.samples.clamped.round_variance(i) + refs.mean.variance[i];
            Vec3::from_array(std::array::from_fn(|c| {
                variance[c] / crate::submission::code_step(m[i][c]).powi(2)
            }))
        })
        .collect();
    let size = refs.resolution;
    encoding.dc_rounding(&codes, &noise, size.x, size.y)
}

/// `scene`'s scene with its camera's film at `resolution`.
fn at_resolution(
    scene: &GradeScene,
    resolution: UVec2,
) -> Result<glint_integrator::Scene, GradeError> {
    let mut rendered = scene.description.scene.clone();
    rendered.camera = rendered
        .camera
        .with_resolution(resolution)
        .map_err(|e| GradeError::Input(format!("{}: {e}", scene.path.display())))?;
    Ok(rendered)
}

/// What a reference keeps of each round's film: its pixels transformed
/// (clamped, say), or the whole image passed through a file format.
type Transform<'a> = &'a (dyn Fn(&[Vec3], &mut Vec<Vec3>) -> Result<(), String> + Sync);

/// The transform that applies `f` to each pixel.
fn each(f: fn(Vec3) -> Vec3) -> impl Fn(&[Vec3], &mut Vec<Vec3>) -> Result<(), String> + Sync {
    move |pixels, out| {
        out.extend(pixels.iter().map(|&p| f(p)));
        Ok(())
    }
}

fn identity(x: Vec3) -> Vec3 {
    x
}

fn clamp(x: Vec3) -> Vec3 {
    x.min(Vec3::ONE)
}

fn excess(x: Vec3) -> Vec3 {
    (x - Vec3::ONE).max(Vec3::ZERO)
}

/// Seeds of a reference's rounds, apart from each other's, from the other
/// reference's and from any seed a user renders with.
fn seed_of(name: &str) -> u64 {
    name.bytes().fold(0x47_5241_4445_u64, |h, b| {
        glint_integrator::sampling::mix64(h ^ b as u64)
    })
}

struct Job<'a> {
    scene: &'a GradeScene,
    rendered: &'a glint_integrator::Scene,
    resolution: UVec2,
    cache: &'a Cache,
    progress: &'a (dyn Fn(&str) + Sync),
}

impl Job<'_> {
    /// The mean and variance of the mean of each of `transforms` of the
    /// radiance, over `rounds` renders with `settings` (seeded by `name`):
    /// from the cache when all are there, else rendered (and stored). `tag`
    /// tells transforms of the same name apart in the cache (a JPEG
    /// encoding's tables).
    fn estimates<const K: usize>(
        &self,
        name: &str,
        tag: &str,
        transforms: [Transform; K],
        settings: &RenderSettings,
        rounds: u32,
    ) -> Result<[Estimate; K], GradeError> {
        let (w, h) = (self.resolution.x, self.resolution.y);
        let fingerprint = |k: usize| {
            let text = match &self.scene.text_hash {
                Some(hash) => format!(", scene text {hash}"),
                None => String::new(),
            };
            let mistakes = match self.scene.mistakes.is_empty() {
                true => String::new(),
                false => format!(
                    ", one-ray integrator with {:?} (revision {})",
                    self.scene.mistakes,
                    glint_integrator::mistakes::REVISION
                ),
            };
            format!(
                "glint-grade {name} reference{tag}, transform {k} of {K}, rounds={rounds}{text}{mistakes} {}",
                glint_bench::reference::settings_fingerprint(settings, w, h)
            )
        };
        let keys = (0..K)
            .map(|k| {
                cache_key(
                    env!("CARGO_PKG_VERSION"),
                    &fingerprint(k),
                    &self.scene.inputs,
                )
            })
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| GradeError::Input(format!("{}: {e}", self.scene.path.display())))?;
        let paths: Option<Vec<CachePaths>> = self
            .cache
            .dir
            .as_ref()
            .map(|d| keys.iter().map(|k| CachePaths::new(d, k)).collect());
        if let Some(paths) = &paths {
            let cached: Vec<Estimate> = paths
                .iter()
                .zip(&keys)
                .filter_map(|(p, key)| p.load_rounds(key, w, h, rounds))
                .map(|r| Estimate {
                    mean: r.mean,
                    variance: r.variance_of_mean.expect("cached with a variance"),
                    rounds,
                    cached: true,
                })
                .collect();
            if let Ok(all) = <[Estimate; K]>::try_from(cached) {
                return Ok(all);
            }
        }
        let mut sums: Vec<RoundSums> = (0..K).map(|_| RoundSums::new(w, h, settings.spp)).collect();
        let mut buffer = Vec::new();
        for round in 0..rounds {
            (self.progress)(&format!(
                "rendering the {name} reference of {} at {w}x{h}: round {} of {rounds} ({} spp × {} light samples)",
                self.scene.path.display(),
                round + 1,
                settings.spp,
                settings.light_samples,
            ));
            let mut round_settings = settings.clone();
            round_settings.seed = round_seed(seed_of(name), round);
            let film = self.render(&round_settings)?;
            for (sum, transform) in sums.iter_mut().zip(transforms) {
                buffer.clear();
                transform(film.pixels(), &mut buffer).map_err(GradeError::Internal)?;
                sum.add(&buffer);
            }
        }
        let mut estimates = Vec::with_capacity(K);
        for (k, sum) in sums.iter().enumerate() {
            let origin = Origin::Rendered {
                cached: false,
                key: keys[k].clone(),
            };
            let mut reference = sum.reference(origin, Duration::ZERO);
            let variance = reference
                .variance_of_mean
                .get_or_insert_with(|| vec![Vec3::ZERO; (w * h) as usize])
                .clone();
            if let Some(paths) = &paths {
                paths[k]
                    .store(&keys[k], &fingerprint(k), &reference)
                    .map_err(|e| GradeError::Internal(format!("reference cache: {e}")))?;
            }
            estimates.push(Estimate {
                mean: reference.mean,
                variance,
                rounds,
                cached: false,
            });
        }
        Ok(estimates.try_into().expect("K estimates"))
    }

    /// One round's film: the render's, or the one-ray integrator's with
    /// the scene's mistakes.
    fn render(&self, settings: &RenderSettings) -> Result<glint_camera::Film, GradeError> {
        let mistakes = self.scene.mistakes;
        match mistakes.is_empty() {
            true => glint_integrator::render(self.rendered, settings, &|_, _| {}).map(|o| o.film),
            false => render_with_mistakes(self.rendered, settings, mistakes, None),
        }
        .map_err(|e| GradeError::Internal(format!("reference render: {e}")))
    }
}

/// Per pixel, the object the ray through its centre hits first: the
/// `object` AOV of a render with one sample at each pixel's centre.
pub fn objects_at_pixel_centres(scene: &glint_integrator::Scene) -> Result<Vec<u32>, GradeError> {
    let settings = RenderSettings {
        spp: 1,
        pixel_pattern: glint_integrator::SamplePattern::Grid,
        aov: Some(glint_integrator::Aov::Object),
        ..RenderSettings::default()
    };
    let output = glint_integrator::render(scene, &settings, &|_, _| {})
        .map_err(|e| GradeError::Internal(format!("object ids: {e}")))?;
    Ok(output
        .film
        .pixels()
        .iter()
        .map(|p| match p.x as u32 {
            0 => BACKGROUND,
            id => id - 1,
        })
        .collect())
}
