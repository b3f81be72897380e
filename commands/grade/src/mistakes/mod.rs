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

use crate::jpeg::JpegEncoding;
use crate::reference::{references, samples_through, with_jpeg, Estimate, GradeScene};
use crate::test::{self, Bands, NoiseFit, Region, TestOptions};
use crate::{Cache, GradeError, References, StatedSettings, Submission};
use glam::Vec3;
use glint_camera::SampleEncoding;
use glint_integrator::mistakes::{Mistake as Swap, Mistakes};
use rayon::prelude::*;
use serde::Serialize;
use std::path::Path;

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

/// The scene text `text` with `edits` applied in turn, or `None` when one
/// of them changes nothing.
pub fn edited_text(
    text: &str,
    edits: &[edit::Edit],
    context: &edit::Context,
) -> Result<Option<String>, String> {
    let mut table: toml::Table = text.parse().map_err(|e: toml::de::Error| e.to_string())?;
    for edit in edits {
        if !edit(&mut table, context) {
            return Ok(None);
        }
    }
    toml::to_string(&table).map(Some).map_err(|e| e.to_string())
}

/// `scene` with `mistakes` in it: the edits of those that are scene edits
/// applied to its file, those the one-ray integrator makes switched on in
/// it; or `None` when one changes nothing, is neither, or is an edit of a
/// scene with no file to edit (it came from memory).
pub fn edited_scene(
    scene: &GradeScene,
    mistakes: &[&Mistake],
    context: &edit::Context,
) -> Result<Option<GradeScene>, GradeError> {
    let edits: Vec<edit::Edit> = mistakes.iter().filter_map(|m| m.how.edit()).collect();
    let swaps: Vec<Swap> = mistakes.iter().filter_map(|m| m.how.swap()).collect();
    if edits.len() + swaps.len() != mistakes.len() {
        return Ok(None);
    }
    let Some(edited) = scene_edited(scene, mistakes, &edits, context)? else {
        return Ok(None);
    };
    if swaps.is_empty() {
        return Ok(Some(edited));
    }
    let rendered = &edited.description.scene;
    if !swaps.iter().all(|s| s.applies_to(rendered)) {
        return Ok(None);
    }
    let name = format!(
        "{} with {}",
        scene.path.display(),
        joined(mistakes, |m| m.id, "+")
    );
    Ok(Some(
        edited.with_mistakes(&name, swaps.into_iter().collect()),
    ))
}

/// `scene` with `edits` (those of `mistakes`) applied to its file or, from
/// memory, its text: a new scene with the settings that replaced the
/// text's, or the same (`None` when an edit changes nothing, or there are
/// edits and no text).
fn scene_edited(
    scene: &GradeScene,
    mistakes: &[&Mistake],
    edits: &[edit::Edit],
    context: &edit::Context,
) -> Result<Option<GradeScene>, GradeError> {
    if edits.is_empty() {
        return Ok(Some(
            scene.with_mistakes(&scene.path.to_string_lossy(), Mistakes::NONE),
        ));
    }
    let path = &scene.path;
    let (text, base) = match (&scene.source, &scene.text_hash) {
        (Some(source), _) => (source.text.clone(), source.base.clone()),
        (None, Some(_)) => return Ok(None),
        (None, None) => {
            let text = std::fs::read_to_string(path)
                .map_err(|e| GradeError::Input(format!("{}: {e}", path.display())))?;
            (text, path.parent().unwrap_or(Path::new("")).to_owned())
        }
    };
    let Some(edited) = edited_text(&text, edits, context)
        .map_err(|e| GradeError::Input(format!("{}: {e}", path.display())))?
    else {
        return Ok(None);
    };
    let ids = joined(mistakes, |m| m.id, "+");
    let name = format!("{} with {ids}", path.display());
    let mut description = glint_scene::parse_in(&edited, &name, &base)
        .map_err(|e| GradeError::Internal(format!("{ids} edited: {e}")))?;
    // No edit touches [render]: the settings are the scene's, replaced or not.
    description.settings = scene.description.settings.clone();
    // Keyed by the edited text and, from memory, by what the original's key
    // hashed (its text and the settings that replaced the text's).
    let key = match &scene.text_hash {
        Some(hash) => format!("{edited}\nreplaced as in {hash}"),
        None => edited,
    };
    Ok(Some(GradeScene::from_text(&name, &key, description)))
}

fn joined(mistakes: &[&Mistake], part: fn(&Mistake) -> &str, by: &str) -> String {
    let parts: Vec<&str> = mistakes.iter().map(|m| part(m)).collect();
    parts.join(by)
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
            How::Scene(_) | How::Lights(_) | How::Integrator(_) => {
                let edited = match edited_scene(scene, &[mistake], &context) {
                    Ok(Some(edited)) => edited,
                    Ok(None) => continue,
                    // A scene the edit made invalid is one mistake fewer,
                    // not a grade that fails.
                    Err(e) => {
                        progress(&format!("{}: left out: {e}", mistake.id));
                        continue;
                    }
                };
                let references = references(&edited, refs.resolution, &refs.plan, cache, progress)?;
                MutantRender::Scene {
                    scene: Box::new(edited),
                    references: Box::new(references),
                    keep_lights: matches!(mistake.how, How::Lights(_)),
                }
            }
            How::Film(FilmMistake::FlipVertical) => MutantRender::Flip,
            How::Film(film) => MutantRender::Encoding {
                mistake: film,
                samples: through_film(scene, refs, film, mistake.id, cache, progress)?,
            },
            How::NoiseOnly => continue,
        };
        mutants.push(Mutant { mistake, render });
    }
    Ok(Mutants { mutants })
}

impl Mutants {
    /// Each mutant rendered as a scene, its references also through
    /// `encoding` ([`with_jpeg`]): for diagnosing a JPEG submission, whose
    /// mutants are judged as it is, through its encoding.
    pub fn through_jpeg(
        &mut self,
        encoding: &JpegEncoding,
        cache: &Cache,
        progress: &(dyn Fn(&str) + Sync),
    ) -> Result<(), GradeError> {
        for mutant in &mut self.mutants {
            if let MutantRender::Scene {
                scene, references, ..
            } = &mut mutant.render
            {
                with_jpeg(references, scene, encoding, cache, progress)?;
            }
        }
        Ok(())
    }
}

/// `submission`'s bands under `refs`: through its encoding for a JPEG
/// (`None` where `refs` were not passed through it, [`Mutants::through_jpeg`]).
fn bands_of(submission: &Submission, refs: &References) -> Option<Bands> {
    let jpeg = match &submission.jpeg {
        Some(Ok(encoding)) => Some(refs.through_jpeg(encoding)?),
        _ => None,
    };
    Some(Bands::new(submission, refs, jpeg))
}

/// Whether `submission`'s file stores what an encoding mistake changes:
/// 8-bit codes, not floats and not a JPEG's coefficients.
fn stores_codes(submission: &Submission) -> bool {
    let float = matches!(submission.encoding, SampleEncoding::Float { .. });
    !float && !matches!(submission.jpeg, Some(Ok(_)))
}

/// The sample reference of `scene` (`refs`) through the encoding mistake
/// `film` (named `id`), round by round.
fn through_film(
    scene: &GradeScene,
    refs: &References,
    film: FilmMistake,
    id: &str,
    cache: &Cache,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<Estimate, GradeError> {
    let tag = format!(" with {id}");
    let f = move |p: Vec3| film.decoded_rgb(p);
    samples_through(scene, refs, &tag, &f, cache, progress)
}

/// What a submission's mistakes are tested against: the correct render of
/// its scene and its mistakes, with what rendering a combination needs.
pub struct Against<'a> {
    pub scene: &'a GradeScene,
    pub references: &'a References,
    pub stated: &'a StatedSettings,
    pub mutants: &'a Mutants,
    pub cache: &'a Cache,
    pub progress: &'a (dyn Fn(&str) + Sync),
}

/// Pairs are tried only when the best single mistake's mean z² is at most
/// this share of the correct render's.
const PAIRING_SHARE: f64 = 0.5;

/// Single mistakes tried in pairs with each other when none fits alone:
/// the best fits.
const PAIRED: usize = 4;

/// The single mistakes the best fit is tried with in a slow pair, in an
/// image of more than [`ALL_SLOW_PAIRS`] pixels: the next best fits.
const PAIRED_WITH_BEST: usize = 10;

/// The most pixels an image may have for the best fit to be tried with
/// every other mistake in slow pairs too (256², where a one-ray pair takes
/// a few seconds).
const ALL_SLOW_PAIRS: u32 = 256 * 256;

/// The pairs of `ranked` (mutants, best fit first) that are tried: the best
/// with each other one, and every pair of the first [`PAIRED`]. A second
/// mistake hides behind the first's larger error, so its own rank says
/// little; the best fit is most likely one of the two. A pair with a stage
/// the one-ray integrator swaps (`slow`) is a slow render (at 512², tens of
/// seconds): above [`ALL_SLOW_PAIRS`] pixels the best is tried in those
/// only with the next [`PAIRED_WITH_BEST`].
fn pairs(ranked: &[(usize, f64)], slow: impl Fn(usize) -> bool) -> Vec<(usize, usize)> {
    let mut pairs: Vec<(usize, usize)> = Vec::new();
    for (k, &(a, _)) in ranked.iter().enumerate() {
        for (l, &(b, _)) in ranked.iter().enumerate().skip(k + 1) {
            let with_best = l <= PAIRED_WITH_BEST || !(slow(a) || slow(b));
            if (k == 0 && with_best) || l < PAIRED {
                pairs.push((a, b));
            }
        }
    }
    pairs
}

/// The mistakes `submission` was tested against, ranked, the consistent
/// first: each single mistake; when none fits, each with the image upside
/// down, then, where the best single mistake explains at least half of
/// what is wrong (by mean z², [`PAIRING_SHARE`]), pairs ([`pairs`];
/// rendered, or read from the cache).
pub fn diagnose(
    against: &Against,
    submission: &Submission,
    options: &TestOptions,
) -> Result<Vec<LikelyMistake>, GradeError> {
    let refs = against.references;
    let size = refs.resolution;
    let block = options
        .block
        .unwrap_or_else(|| test::block_side(size.x, size.y));
    let regions = test::regions(size.x, size.y, block, &refs.objects);
    let test = (submission, regions.as_slice(), options);
    let Some(correct) = bands_of(submission, refs) else {
        return Ok(Vec::new());
    };
    let lights = lights_by_object(&against.scene.description.scene);
    let mutants = &against.mutants.mutants;
    // Each test is independent of the others: in parallel, in order.
    let singles: Vec<(usize, Bands)> = (0..mutants.len())
        .into_par_iter()
        .filter_map(|i| Some((i, bands(&mutants[i], &correct, refs, &lights, submission)?)))
        .collect();
    let mut found: Vec<LikelyMistake> = singles
        .par_iter()
        .map(|(i, b)| judged(&[mutants[*i].mistake], b, test))
        .collect();
    if !found.iter().any(|f| f.consistent) {
        let flip = find("flip-vertical").expect("in the catalogue");
        let upside_down: Vec<LikelyMistake> = (singles.par_iter())
            .filter(|(i, _)| mutants[*i].mistake.id != flip.id)
            .map(|(i, b)| {
                let flipped = flipped(b, size.x, size.y);
                judged(&[mutants[*i].mistake, flip], &flipped, test)
            })
            .collect();
        found.extend(upside_down);
    }
    let mut best: Vec<(usize, f64)> = (singles.iter().zip(&found))
        .filter(|((i, _), _)| !matches!(mutants[*i].render, MutantRender::Flip))
        .map(|((i, _), f)| (*i, f.score))
        .collect();
    best.sort_by(|a, b| a.1.total_cmp(&b.1));
    // Pairs are rendered: only where one mistake explains most of what is
    // wrong, so that a second may explain the rest.
    let unexplained = judged(&[], &correct, test).score;
    let half_explained = best
        .first()
        .is_some_and(|&(_, score)| score <= PAIRING_SHARE * unexplained);
    if !found.iter().any(|f| f.consistent) && half_explained {
        let by_index: Vec<Option<&Bands>> = (0..mutants.len())
            .map(|i| singles.iter().find(|(j, _)| *j == i).map(|(_, b)| b))
            .collect();
        let pair = Pair {
            against,
            submission,
            lights: &lights,
            singles: &by_index,
        };
        let large = size.x * size.y > ALL_SLOW_PAIRS;
        let slow = |i: usize| large && mutants[i].mistake.how.swap().is_some();
        let tried: Vec<Option<LikelyMistake>> = (pairs(&best, slow).into_par_iter())
            .map(|(a, b)| {
                let both = [mutants[a].mistake, mutants[b].mistake];
                Ok(pair.bands(a, b)?.map(|bands| judged(&both, &bands, test)))
            })
            .collect::<Result<_, GradeError>>()?;
        found.extend(tried.into_iter().flatten());
    }
    found.sort_by(|a, b| {
        b.consistent
            .cmp(&a.consistent)
            .then(a.score.total_cmp(&b.score))
            .then(a.id.cmp(&b.id))
    });
    Ok(found)
}

/// What Glint renders for the finding `id` (one mistake, or two joined by
/// `+`, as [`diagnose`] names them) as `submission` would store it: the
/// middle of its bands, for the report to show beside the submission.
/// `None` for an id the mutants do not have.
pub fn fit_image(
    against: &Against,
    submission: &Submission,
    id: &str,
) -> Result<Option<Vec<Vec3>>, GradeError> {
    let refs = against.references;
    let Some(correct) = bands_of(submission, refs) else {
        return Ok(None);
    };
    let lights = lights_by_object(&against.scene.description.scene);
    let mutants = &against.mutants.mutants;
    let index = |id: &str| mutants.iter().position(|m| m.mistake.id == id);
    let single = |i: usize| bands(&mutants[i], &correct, refs, &lights, submission);
    let parts: Vec<&str> = id.split('+').collect();
    let found = match parts[..] {
        [one] => index(one).and_then(single),
        [a, b] => match (index(a), index(b)) {
            (Some(i), Some(j)) if matches!(mutants[j].render, MutantRender::Flip) => {
                let size = refs.resolution;
                single(i).map(|b| flipped(&b, size.x, size.y))
            }
            (Some(i), Some(j)) => {
                let singles: Vec<Option<Bands>> = (0..mutants.len())
                    .map(|k| [i, j].contains(&k).then(|| single(k)).flatten())
                    .collect();
                let singles: Vec<Option<&Bands>> = singles.iter().map(Option::as_ref).collect();
                let pair = Pair {
                    against,
                    submission,
                    lights: &lights,
                    singles: &singles,
                };
                pair.bands(i, j)?
            }
            _ => None,
        },
        _ => None,
    };
    Ok(found.map(|b| {
        (b.lo.iter().zip(&b.hi))
            .map(|(lo, hi)| (*lo + *hi) / 2.0)
            .collect()
    }))
}

/// Two mistakes rendered together.
struct Pair<'a> {
    against: &'a Against<'a>,
    submission: &'a Submission,
    lights: &'a [bool],
    /// Each mutant's bands alone, by its index (`None` where it does not
    /// apply).
    singles: &'a [Option<&'a Bands>],
}

impl Pair<'_> {
    /// The bands of mutants `a` and `b` together: two scene edits as one
    /// edited scene, an edit and an encoding as the edited scene's sample
    /// reference through it; `None` for two encodings. Where a lights'
    /// mistake keeps the pixels near a light, they come from the other
    /// mistake alone (or the correct render, when both are the lights').
    fn bands(&self, a: usize, b: usize) -> Result<Option<Bands>, GradeError> {
        let against = self.against;
        let (refs, mutants) = (against.references, &against.mutants.mutants);
        let (s, o) = match (&mutants[a].render, &mutants[b].render) {
            (MutantRender::Scene { .. }, _) => (a, b),
            (_, MutantRender::Scene { .. }) => (b, a),
            _ => return Ok(None),
        };
        let MutantRender::Scene {
            scene: edited,
            references: edited_refs,
            keep_lights,
        } = &mutants[s].render
        else {
            unreachable!("matched above")
        };
        let (bands, objects, light_source) = match &mutants[o].render {
            MutantRender::Scene {
                keep_lights: also, ..
            } => {
                let context = context(refs, against.stated);
                let both = [mutants[s].mistake, mutants[o].mistake];
                // An edit the other made invalid: a pair fewer.
                let Ok(Some(both)) = edited_scene(against.scene, &both, &context) else {
                    return Ok(None);
                };
                let mut both_refs = references(
                    &both,
                    refs.resolution,
                    &refs.plan,
                    against.cache,
                    against.progress,
                )?;
                if let Some(Ok(encoding)) = &self.submission.jpeg {
                    with_jpeg(
                        &mut both_refs,
                        &both,
                        encoding,
                        against.cache,
                        against.progress,
                    )?;
                }
                let Some(bands) = bands_of(self.submission, &both_refs) else {
                    return Ok(None);
                };
                let source = match (*keep_lights, *also) {
                    (true, true) => bands_of(self.submission, refs),
                    (true, false) => self.singles[o].cloned(),
                    (false, true) => self.singles[s].cloned(),
                    (false, false) => None,
                };
                (bands, both_refs.objects, source)
            }
            MutantRender::Encoding { mistake, .. } => {
                if !stores_codes(self.submission) {
                    return Ok(None);
                }
                let id = mutants[o].mistake.id;
                let samples = through_film(
                    edited,
                    edited_refs,
                    *mistake,
                    id,
                    against.cache,
                    against.progress,
                )?;
                let bands = through_encoding(*mistake, &samples, edited_refs);
                let source = keep_lights.then(|| self.singles[o].cloned()).flatten();
                (bands, edited_refs.objects.clone(), source)
            }
            MutantRender::Flip => return Ok(None),
        };
        let mut bands = bands;
        if let Some(source) = light_source {
            let mask = near_objects(self.lights, &refs.objects, &objects, refs.resolution.x);
            keep(&mut bands, &source, &mask);
        }
        // A mistake whose amount varies is fitted on top of the other alone.
        let varies = |i: usize| mutants[i].mistake.amount_varies();
        let base = [(s, o), (o, s)].into_iter().find(|&(v, _)| varies(v));
        if let Some(other) = base.and_then(|(_, other)| self.singles[other]) {
            scaled_per_object(&mut bands, other, self.submission, &refs.objects);
        }
        Ok(Some(bands))
    }
}

/// The test of `submission` against `bands`, as a finding about
/// `mistakes` (one, or a combination).
fn judged(
    mistakes: &[&Mistake],
    bands: &Bands,
    (submission, regions, options): (&Submission, &[Region], &TestOptions),
) -> LikelyMistake {
    let outcome = test::test(submission, bands, regions, options);
    let n = outcome.findings.len().max(1) as f64;
    LikelyMistake {
        id: joined(mistakes, |m| m.id, "+"),
        description: joined(mistakes, |m| m.description, "; "),
        stage: mistakes.first().map_or("", |m| m.stage.name()),
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
            let mut bands = bands_of(submission, references)?;
            if *keep_lights {
                let near = near_objects(lights, &refs.objects, &references.objects, size.x);
                keep(&mut bands, correct, &near);
            }
            if mutant.mistake.amount_varies() {
                scaled_per_object(&mut bands, correct, submission, &refs.objects);
            }
            Some(bands)
        }
        MutantRender::Flip => Some(flipped(correct, size.x, size.y)),
        MutantRender::Encoding { mistake, samples } => {
            if !stores_codes(submission) {
                return None;
            }
            Some(through_encoding(*mistake, samples, refs))
        }
    }
}

/// Greatest amount [`scaled_per_object`] fits: a tracer's acne up to five
/// times Glint's.
const MOST_AMOUNT: f64 = 5.0;

/// `bands` (a mistake whose amount varies, [`Mistake::amount_varies`])
/// moved from `base` (the image without it) by the amount that fits
/// `submission` best on each object: `B + β (M − B)` with `β ∈ [0, 5]`
/// per object, by least squares on the bands' middles over the pixels
/// whose centre sees it. One number per object against thousands of
/// pixels: a fit that cannot make another mistake's pattern.
pub(crate) fn scaled_per_object(
    bands: &mut Bands,
    base: &Bands,
    submission: &Submission,
    objects: &[u32],
) {
    let values = submission.film.pixels();
    let middle = |b: &Bands, i: usize| (b.lo[i] + b.hi[i]).as_dvec3() / 2.0;
    let mut sums: std::collections::BTreeMap<u32, (f64, f64)> = Default::default();
    for (i, object) in objects.iter().enumerate() {
        let (b, m) = (middle(base, i), middle(bands, i));
        let (change, off) = (m - b, values[i].as_dvec3() - b);
        let sum = sums.entry(*object).or_default();
        sum.0 += off.dot(change);
        sum.1 += change.length_squared();
    }
    for (i, object) in objects.iter().enumerate() {
        let (along, norm) = sums[object];
        let beta = match norm > 0.0 {
            true => (along / norm).clamp(0.0, MOST_AMOUNT) as f32,
            false => 0.0,
        };
        let mix = |b: Vec3, m: Vec3| b + beta * (m - b);
        bands.lo[i] = mix(base.lo[i], bands.lo[i]);
        bands.hi[i] = mix(base.hi[i], bands.hi[i]);
        // B + β (M − B) of independent estimates.
        let (vb, vm) = (base.reference_variance[i], bands.reference_variance[i]);
        bands.reference_variance[i] = (1.0 - beta).powi(2) * vb + beta * beta * vm;
        let t = beta.min(1.0);
        bands.noise[i] = (1.0 - t) * base.noise[i] + t * bands.noise[i];
    }
}

/// The bands of a file written with `mistake`: between `E[f(X_s)]` (the
/// sample reference's rounds through it) and `f(M)`, as a clamped file's
/// lie between `M − G` and `min(M, 1)`.
fn through_encoding(mistake: FilmMistake, samples: &Estimate, refs: &References) -> Bands {
    let f = |p: Vec3| mistake.decoded_rgb(p);
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

/// The pixels a mistake in the lights leaves as the correct render has
/// them, in renders of `correct` and of `mistaken` (the same scene with
/// that mistake): those that see a light at their centre in either, and
/// their neighbours ([`near_objects`]).
pub fn light_pixels(
    correct: &glint_integrator::Scene,
    mistaken: &glint_integrator::Scene,
) -> Result<Vec<bool>, GradeError> {
    let lights = lights_by_object(correct);
    let a = crate::reference::objects_at_pixel_centres(correct)?;
    let b = crate::reference::objects_at_pixel_centres(mistaken)?;
    Ok(near_objects(&lights, &a, &b, correct.camera.resolution().x))
}

/// Which objects are the scene's lights, by object index.
fn lights_by_object(scene: &glint_integrator::Scene) -> Vec<bool> {
    let mut lights = vec![false; scene.shapes.len()];
    for &i in &scene.light_objects {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_best_fit_is_paired_with_every_other_and_the_first_four_with_each_other() {
        let ranked: Vec<(usize, f64)> = (0..14).map(|i| (10 + i, i as f64)).collect();
        let got = pairs(&ranked, |_| false);
        let mut want: Vec<(usize, usize)> = (11..24).map(|b| (10, b)).collect();
        want.extend([(11, 12), (11, 13), (12, 13)]);
        assert_eq!(got, want);
        assert!(pairs(&ranked[..1], |_| false).is_empty());
        // Slow pairs (mutant 22 is slow) only with the next ten.
        let got = pairs(&ranked, |i| i == 22);
        assert!(
            !got.contains(&(10, 22)) && got.contains(&(10, 23)),
            "{got:?}"
        );
        // A slow best: the next ten only.
        let got = pairs(&ranked, |i| i == 10);
        assert_eq!(got.iter().filter(|p| p.0 == 10).count(), 10);
    }

    #[test]
    fn flipping_twice_gives_the_bands_back_and_the_light_mask_reaches_neighbours() {
        let v = |k: f32| {
            (0..6)
                .map(|i| Vec3::splat(i as f32 + k))
                .collect::<Vec<_>>()
        };
        let bands = Bands {
            lo: v(0.0),
            hi: v(1.0),
            reference_variance: v(2.0),
            noise: v(3.0),
            noise_scale: None,
            fit: NoiseFit::WithinBlocks,
            precision: None,
        };
        let once = flipped(&bands, 3, 2);
        assert_eq!(once.lo[0], bands.lo[3], "row 0 is the last row");
        assert_eq!(flipped(&once, 3, 2).hi, bands.hi);
        // Object 1 is a light, seen at pixel (0, 0) of a 3 × 2 image in the
        // correct render and at (2, 1) in the mutant's.
        let lights = [false, true];
        let a = [1, 0, 0, 0, 0, 0];
        let b = [0, 0, 0, 0, 0, 1];
        let mask = near_objects(&lights, &a, &b, 3);
        assert_eq!(mask, [true, true, true, true, true, true]);
        let mask = near_objects(&lights, &a, &a, 3);
        assert_eq!(mask, [true, true, false, true, true, false]);
    }

    #[test]
    fn an_amount_that_varies_is_fitted_per_object_within_its_bounds() {
        let flat = |values: [f32; 6]| values.map(Vec3::splat).to_vec();
        let bands = |value: f32, variance: f32| Bands {
            lo: flat([value; 6]),
            hi: flat([value; 6]),
            reference_variance: flat([variance; 6]),
            noise: flat([variance; 6]),
            noise_scale: None,
            fit: NoiseFit::WithinBlocks,
            precision: None,
        };
        let base = bands(1.0, 0.01);
        let mut mutant = bands(0.5, 0.02);
        // Object 0 shows half the mutant's change, object 1 twice it,
        // object 2 the opposite of it.
        let pixels = flat([0.75, 0.75, 0.0, 0.0, 1.5, 1.5]);
        let film = glint_camera::Film::from_pixels(glam::UVec2::new(3, 2), pixels).unwrap();
        let submission = Submission::new(
            "a.pfm".into(),
            film,
            SampleEncoding::Float { mantissa_bits: 23 },
        );
        scaled_per_object(&mut mutant, &base, &submission, &[0, 0, 1, 1, 2, 2]);
        let middles: Vec<f32> = mutant.lo.iter().map(|v| v.x).collect();
        assert_eq!(middles, [0.75, 0.75, 0.0, 0.0, 1.0, 1.0]);
        assert_eq!(mutant.hi, mutant.lo);
        // β = ½: ¼ of each variance; β = 2: the base's once, the mutant's four times.
        assert!((mutant.reference_variance[0].x - 0.0075).abs() < 1e-6);
        assert!((mutant.reference_variance[2].x - 0.09).abs() < 1e-6);
        assert_eq!(mutant.reference_variance[4].x, 0.01, "β = 0: the base");
    }

    #[test]
    fn encoding_mistakes_decode_as_the_grader_reads_the_file() {
        assert_eq!(FilmMistake::NoSrgb.decoded(1.0), 1.0);
        assert!((FilmMistake::NoSrgb.decoded(0.5) - 0.214).abs() < 1e-3);
        // pow(1/2.2) is near the sRGB curve: read back, near the value.
        assert!((FilmMistake::Gamma22.decoded(0.5) - 0.5).abs() < 0.02);
        assert_eq!(FilmMistake::NoSrgb.decoded(7.0), 1.0, "clamped");
    }
}
