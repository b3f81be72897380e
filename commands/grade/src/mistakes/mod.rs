//! Naming the mistake behind a failing image: the submission tested, with
//! the test that failed it, against Glint's renders of the scene with each
//! classic mistake switched on ([`catalogue`]).
//!
//! A mistake is rendered without touching the renderer: as the correct
//! render of an edited scene ([`edit`]: no ambient, a doubled fov, white
//! lights...), those of the lights' mistakes with the pixels that see a
//! light kept from the correct render, or as a change to what the file
//! stores, applied to the references (rows upside down; linear values
//! written without the sRGB curve, applied to each round of the sample
//! reference, so that its noise goes through the curve as the student's
//! did). Each mutant's references are made and cached as the correct ones
//! are, once per scene, resolution and stated settings.
//!
//! A mistake is **consistent** with a submission when the test passes it
//! against the mutant (Holm's procedure at the grade's α over the same
//! regions); mistakes are ranked by the mean z² over every region and
//! channel, the consistent first. When no single mistake is consistent,
//! a mistake with the image also upside down is tried. No consistent
//! mistake is reported as such: never a guess.

pub mod catalogue;
pub mod edit;

pub use catalogue::{find, FilmMistake, How, Mistake, Stage, CATALOGUE};

use crate::reference::{references, samples_through, Estimate, GradeScene};
use crate::test::{self, Bands, NoiseFit, Region, TestOptions};
use crate::{Cache, GradeError, References, StatedSettings, Submission};
use glam::Vec3;
use glint_camera::SampleEncoding;
use serde::Serialize;

/// A mistake as a finding about one submission.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct LikelyMistake {
    /// Its id, or two ids joined by `+` for a combination.
    pub id: String,
    pub description: String,
    pub stage: &'static str,
    /// Whether the test passes the submission against its render.
    pub consistent: bool,
    /// The largest |z| over the regions and channels.
    pub largest_z: f64,
    /// The mean z² over them: what the ranking orders by.
    #[serde(skip)]
    pub score: f64,
}

/// A scene's mistakes rendered at one resolution under one set of stated
/// settings.
pub struct Mutants {
    pub mutants: Vec<Mutant>,
}

pub struct Mutant {
    pub mistake: &'static Mistake,
    pub render: MutantRender,
}

/// What a mutant's bands are made from.
pub enum MutantRender {
    /// The references of the edited scene; `keep_lights`: the pixels near
    /// a light are the correct render's.
    Scene {
        scene: Box<GradeScene>,
        references: Box<References>,
        keep_lights: bool,
    },
    /// The correct bands upside down.
    Flip,
    /// Each round of the sample reference through the encoding, `E[f(X_s)]`.
    Encoding {
        mistake: FilmMistake,
        samples: Estimate,
    },
}

/// The context the scene's edits are made in, for submissions of `refs`.
fn context(refs: &References, stated: &StatedSettings) -> edit::Context {
    let size = refs.resolution;
    edit::Context {
        aspect: f64::from(size.x) / f64::from(size.y),
        light_samples: stated.light_samples,
    }
}

/// `scene` with `edit` applied to its file, or `None` when the edit changes
/// nothing (or the scene has no file to edit: it came from memory).
pub fn edited_scene(
    scene: &GradeScene,
    mistake: &Mistake,
    edit: edit::Edit,
    context: &edit::Context,
) -> Result<Option<GradeScene>, GradeError> {
    if scene.text_hash.is_some() {
        return Ok(None);
    }
    let path = &scene.path;
    let text = std::fs::read_to_string(path)
        .map_err(|e| GradeError::Input(format!("{}: {e}", path.display())))?;
    let mut table: toml::Table = text
        .parse()
        .map_err(|e| GradeError::Input(format!("{}: {e}", path.display())))?;
    if !edit(&mut table, context) {
        return Ok(None);
    }
    let edited = toml::to_string(&table)
        .map_err(|e| GradeError::Internal(format!("{} edited: {e}", mistake.id)))?;
    let name = format!("{} with {}", path.display(), mistake.id);
    let base = path.parent().unwrap_or(std::path::Path::new(""));
    let description = glint_scene::parse_in(&edited, &name, base)
        .map_err(|e| GradeError::Internal(format!("{} edited: {e}", mistake.id)))?;
    Ok(Some(GradeScene::from_text(&name, &edited, description)))
}

/// Renders (or reads from `cache`) every mistake of the catalogue that
/// changes the image of `scene` at the resolution of `refs`.
pub fn render_mutants(
    scene: &GradeScene,
    refs: &References,
    stated: &StatedSettings,
    cache: &Cache,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<Mutants, GradeError> {
    let context = context(refs, stated);
    let mut mutants = Vec::new();
    for mistake in CATALOGUE {
        let render = match mistake.how {
            How::Scene(edit) | How::Lights(edit) => {
                let Some(edited) = edited_scene(scene, mistake, edit, &context)? else {
                    continue;
                };
                let references = references(&edited, refs.resolution, &refs.plan, cache, progress)?;
                MutantRender::Scene {
                    scene: Box::new(edited),
                    references: Box::new(references),
                    keep_lights: matches!(mistake.how, How::Lights(_)),
                }
            }
            How::Film(FilmMistake::FlipVertical) => MutantRender::Flip,
            How::Film(film) => {
                let tag = format!(" with {}", mistake.id);
                let f = move |p: Vec3| Vec3::from_array(p.to_array().map(|c| film.decoded(c)));
                MutantRender::Encoding {
                    mistake: film,
                    samples: samples_through(scene, refs, &tag, &f, cache, progress)?,
                }
            }
            How::NotRendered | How::NoiseOnly => continue,
        };
        mutants.push(Mutant { mistake, render });
    }
    Ok(Mutants { mutants })
}

/// The mistakes `submission` was tested against, ranked; the consistent
/// first. `correct` are its bands under the correct render (`refs`, of
/// `scene`).
pub fn diagnose(
    scene: &GradeScene,
    refs: &References,
    mutants: &Mutants,
    submission: &Submission,
    options: &TestOptions,
) -> Vec<LikelyMistake> {
    let size = refs.resolution;
    let block = options
        .block
        .unwrap_or_else(|| test::block_side(size.x, size.y));
    let regions = test::regions(size.x, size.y, block, &refs.objects);
    let correct = Bands::new(submission, refs, None);
    let lights = near_lights(scene, refs);
    let singles: Vec<(&Mistake, Bands)> = mutants
        .mutants
        .iter()
        .filter_map(|m| Some((m.mistake, bands(m, &correct, refs, &lights, submission)?)))
        .collect();
    let mut found: Vec<LikelyMistake> = singles
        .iter()
        .map(|(m, b)| {
            judged(
                m.id.into(),
                m.description.into(),
                m.stage,
                b,
                (submission, &regions, options),
            )
        })
        .collect();
    if !found.iter().any(|f| f.consistent) {
        let flip = find("flip-vertical").expect("in the catalogue");
        for (m, b) in singles.iter().filter(|(m, _)| m.id != flip.id) {
            let flipped = flipped(b, size.x, size.y);
            found.push(judged(
                format!("{}+{}", m.id, flip.id),
                format!("{}; {}", m.description, flip.description),
                m.stage,
                &flipped,
                (submission, &regions, options),
            ));
        }
    }
    found.sort_by(|a, b| {
        b.consistent
            .cmp(&a.consistent)
            .then(a.score.total_cmp(&b.score))
            .then(a.id.cmp(&b.id))
    });
    found
}

/// The test of `submission` against `bands`, as a finding about mistake `id`.
fn judged(
    id: String,
    description: String,
    stage: Stage,
    bands: &Bands,
    (submission, regions, options): (&Submission, &[Region], &TestOptions),
) -> LikelyMistake {
    let outcome = test::test(submission, bands, regions, options);
    let n = outcome.findings.len().max(1) as f64;
    LikelyMistake {
        id,
        description,
        stage: stage.name(),
        consistent: outcome.passed(),
        largest_z: outcome
            .findings
            .iter()
            .map(|f| f.z.abs())
            .fold(0.0, f64::max),
        score: outcome.findings.iter().map(|f| f.z * f.z).sum::<f64>() / n,
    }
}

/// The bands of `submission` under `mutant`, or `None` where the mutant
/// does not apply to its file (an encoding mistake in a float file).
fn bands(
    mutant: &Mutant,
    correct: &Bands,
    refs: &References,
    lights: &[bool],
    submission: &Submission,
) -> Option<Bands> {
    let size = refs.resolution;
    match &mutant.render {
        MutantRender::Scene {
            references,
            keep_lights,
            ..
        } => {
            let mut bands = Bands::new(submission, references, None);
            if *keep_lights {
                let near = near_objects(lights, &refs.objects, &references.objects, size.x);
                keep(&mut bands, correct, &near);
            }
            Some(bands)
        }
        MutantRender::Flip => Some(flipped(correct, size.x, size.y)),
        MutantRender::Encoding { mistake, samples } => {
            if matches!(submission.encoding, SampleEncoding::Float { .. }) {
                return None;
            }
            Some(through_encoding(*mistake, samples, refs))
        }
    }
}

/// The bands of a file written with `mistake`: between `E[f(X_s)]` (the
/// sample reference's rounds through it) and `f(M)`, as a clamped file's
/// lie between `M − G` and `min(M, 1)`.
fn through_encoding(mistake: FilmMistake, samples: &Estimate, refs: &References) -> Bands {
    let f = |p: Vec3| Vec3::from_array(p.to_array().map(|c| mistake.decoded(c)));
    let (a, m) = (&samples.mean, &refs.mean);
    let b: Vec<Vec3> = m.mean.iter().map(|&p| f(p)).collect();
    // The mean reference's variance through the curve: times its slope².
    let slope = |p: Vec3| {
        let h = 1e-3;
        (f(p + Vec3::splat(h)) - f((p - Vec3::splat(h)).max(Vec3::ZERO))) / (2.0 * h)
    };
    let pixels = a.len();
    Bands {
        lo: (0..pixels).map(|i| a[i].min(b[i])).collect(),
        hi: (0..pixels).map(|i| a[i].max(b[i])).collect(),
        reference_variance: (0..pixels)
            .map(|i| samples.variance[i] + m.variance[i] * slope(m.mean[i]).powf(2.0))
            .collect(),
        noise: (0..pixels).map(|i| samples.round_variance(i)).collect(),
        noise_scale: refs.plan.variance_scale,
        fit: NoiseFit::WithinBlocks,
        precision: None,
    }
}

/// `bands` upside down.
fn flipped(bands: &Bands, width: u32, height: u32) -> Bands {
    let (w, h) = (width as usize, height as usize);
    let flip = |v: &[Vec3]| -> Vec<Vec3> {
        (0..h)
            .rev()
            .flat_map(|y| v[y * w..(y + 1) * w].iter().copied())
            .collect()
    };
    Bands {
        lo: flip(&bands.lo),
        hi: flip(&bands.hi),
        reference_variance: flip(&bands.reference_variance),
        noise: flip(&bands.noise),
        noise_scale: bands.noise_scale,
        fit: bands.fit,
        precision: bands.precision.as_deref().map(flip),
    }
}

/// Which objects are the scene's lights, by object index.
fn near_lights(scene: &GradeScene, refs: &References) -> Vec<bool> {
    let objects = refs.objects.iter().copied().max().map_or(0, |m| m as usize);
    let mut lights = vec![false; scene.description.object_names.len().max(objects)];
    for &i in &scene.description.scene.light_objects {
        if let Some(l) = lights.get_mut(i as usize) {
            *l = true;
        }
    }
    lights
}

/// The pixels that see a light at their centre in either object map, or
/// next to one that does: where a mistake in the lights' size or colour
/// would change the light as seen, which the student's tracer did not.
fn near_objects(lights: &[bool], a: &[u32], b: &[u32], width: u32) -> Vec<bool> {
    let w = width as i64;
    let h = a.len() as i64 / w;
    let is_light = |map: &[u32], i: usize| lights.get(map[i] as usize).copied().unwrap_or(false);
    let seen: Vec<bool> = (0..a.len())
        .map(|i| is_light(a, i) || is_light(b, i))
        .collect();
    (0..a.len() as i64)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            (-1..=1).any(|dy| {
                (-1..=1).any(|dx| {
                    let (nx, ny) = (x + dx, y + dy);
                    (0..w).contains(&nx) && (0..h).contains(&ny) && seen[(ny * w + nx) as usize]
                })
            })
        })
        .collect()
}

/// `bands` with the pixels in `mask` taken from `correct`.
fn keep(bands: &mut Bands, correct: &Bands, mask: &[bool]) {
    for (i, _) in mask.iter().enumerate().filter(|(_, &m)| m) {
        bands.lo[i] = correct.lo[i];
        bands.hi[i] = correct.hi[i];
        bands.reference_variance[i] = correct.reference_variance[i];
        bands.noise[i] = correct.noise[i];
    }
}
