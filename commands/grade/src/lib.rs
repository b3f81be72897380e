//! `glint grade`: whether a submitted image is an unbiased render of a scene,
//! whatever its noise, with where and by how much it is not; for one image or
//! a whole class.
//!
//! The verdict is a statistical test, not a threshold on an error metric
//! ([`test`](mod@test)): the submission's mean over each block of pixels and over each
//! object is compared with the band its expected value must lie in, given
//! Glint's references at the submission's resolution ([`reference`](mod@reference)), the
//! settings the submission is stated to use ([`hypothesis`]) and what its file
//! format did to it ([`submission`]); the noise is estimated from the
//! submission itself, and Holm's procedure keeps the chance of failing a
//! correct image at `α`. `docs/grading.md` writes the test down with its
//! assumptions and measures it on a corpus of correct and wrong renders.
//!
//! # Conventions
//! - Images are compared in linear RGB: 8- and 16-bit files are decoded with
//!   the exact sRGB curve. Pixels are counted from the top left, regions are
//!   half-open rectangles `x0..x1 × y0..y1`.
//! - Objects are the scene's shape-list entries, named by their `name` key or
//!   their table and index (`sphere[2]`); a pixel belongs to the object its
//!   centre sees.
//!
//! # Entry points
//! [`GradeScene::load`], [`references`] (rendered or cached), then
//! [`grade_image`] for each [`Submission`]: an [`ImageGrade`] with the verdict,
//! the rejected regions ([`RegionFinding`]) and a [`heatmap`].

pub mod class;
pub mod course;
pub mod document;
pub mod heatmap;
pub mod html;
pub mod hypothesis;
pub mod jpeg;
pub mod mistakes;
pub mod output;
pub mod parts;
pub mod reference;
pub mod report;
pub mod stages;
pub mod submission;
pub mod test;
pub mod text;

pub use hypothesis::{ReferencePlan, StatedSettings};
pub use reference::{references, with_jpeg, Cache, GradeScene, References};
pub use submission::Submission;
pub use test::{Outcome, Place, TestOptions};

use glam::Vec3;
use serde::Serialize;

/// Why grading could not be done: bad input (exit status 2 on the command
/// line) or a failure of Glint's own (3).
#[derive(Debug, thiserror::Error)]
pub enum GradeError {
    #[error("{0}")]
    Input(String),
    #[error("{0}")]
    Internal(String),
}

/// The channels, by index.
pub const CHANNELS: [&str; 3] = ["R", "G", "B"];

/// A submission's grade.
#[derive(Clone, Debug, Serialize)]
pub struct ImageGrade {
    pub file: String,
    pub passed: bool,
    /// Why the file cannot be graded, where its format lost what the test
    /// needs (a JPEG below quality 50, a palette of fewer colours than the
    /// render, a gray image of a colour scene): neither a pass nor a fail.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unreadable: Option<String>,
    /// What the file was read as ("JPEG, quality 75, 4:2:0").
    pub format: String,
    /// What the grade should be read with (an alpha channel that was not
    /// opaque, ignored).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    pub resolution: [u32; 2],
    /// The settings the submission was judged under.
    pub settings: String,
    /// Regions × channels tested.
    pub tests: usize,
    pub alpha: f64,
    /// The rejected regions and channels, the strongest evidence first.
    pub rejected: Vec<RegionFinding>,
    /// The largest |z| the test accepted.
    pub largest_accepted_z: f64,
    /// The submission's per-pixel noise (standard deviation, linear).
    pub noise: f64,
    /// For a failing submission, the classic mistakes it was tested
    /// against, ranked, the consistent first ([`mistakes`]); empty for a
    /// pass, or when they were not asked for.
    pub likely_mistakes: Vec<mistakes::LikelyMistake>,
    /// The full outcome, for heat maps (not serialised).
    #[serde(skip)]
    pub outcome: Outcome,
    #[serde(skip)]
    pub regions: Vec<Place>,
}

/// A rejected region, named, with its rejected channels.
#[derive(Clone, Debug, Serialize)]
pub struct RegionFinding {
    /// "left wall", or "pixels 256–272 × 400–416 (floor 75%, sphere 4 25%)".
    pub region: String,
    pub place: Place,
    pub pixels: usize,
    /// The strongest evidence first.
    pub channels: Vec<ChannelFinding>,
}

/// One rejected channel of a region.
#[derive(Clone, Debug, Serialize)]
pub struct ChannelFinding {
    pub channel: &'static str,
    /// The submission's mean over the region.
    pub observed: f64,
    /// The band its expected value must lie in.
    pub expected: [f64; 2],
    /// How far the mean lies outside the band (negative: too dark).
    pub difference: f64,
    pub z: f64,
    pub p: f64,
}

impl RegionFinding {
    /// The strongest channel's evidence.
    pub fn strongest(&self) -> &ChannelFinding {
        &self.channels[0]
    }
}

/// Grades `submission` against `refs` of `scene`. A JPEG submission's
/// references must have been passed through its encoding first
/// ([`with_jpeg`]).
pub fn grade_image(
    scene: &GradeScene,
    refs: &References,
    submission: &Submission,
    stated: &StatedSettings,
    options: &TestOptions,
) -> ImageGrade {
    let size = refs.resolution;
    let mut grade = ImageGrade {
        file: submission.path.display().to_string(),
        passed: false,
        unreadable: None,
        format: submission.format.clone(),
        notes: notes(submission),
        resolution: [size.x, size.y],
        settings: stated.describe(),
        tests: 0,
        alpha: options.alpha,
        rejected: Vec::new(),
        largest_accepted_z: 0.0,
        noise: 0.0,
        likely_mistakes: Vec::new(),
        outcome: Outcome {
            findings: Vec::new(),
            alpha: options.alpha,
            largest_accepted_z: 0.0,
            noise: 0.0,
        },
        regions: Vec::new(),
    };
    if let Some(reason) = unreadable_for_grading(submission, refs) {
        grade.unreadable = Some(reason);
        return grade;
    }
    let jpeg = match &submission.jpeg {
        Some(Ok(encoding)) => Some(refs.through_jpeg(encoding).expect(
            "the references of a JPEG submission are passed through its encoding (with_jpeg) before grading",
        )),
        _ => None,
    };
    let block = options
        .block
        .unwrap_or_else(|| test::block_side(size.x, size.y));
    let regions = test::regions(size.x, size.y, block, &refs.objects);
    let bands = test::Bands::new(submission, refs, jpeg);
    let outcome = test::test(submission, &bands, &regions, options);
    let mut rejected: Vec<RegionFinding> = Vec::new();
    for f in outcome.rejections() {
        let channel = ChannelFinding {
            channel: CHANNELS[f.channel],
            observed: f.observed,
            expected: f.expected,
            difference: f.difference,
            z: f.z,
            p: f.p,
        };
        let region = &regions[f.region];
        match rejected.iter_mut().find(|r| r.place == region.place) {
            Some(known) => known.channels.push(channel),
            None => rejected.push(RegionFinding {
                region: describe(scene, region, &refs.objects),
                place: region.place.clone(),
                pixels: f.pixels,
                channels: vec![channel],
            }),
        }
    }
    ImageGrade {
        passed: outcome.passed(),
        tests: outcome.findings.len(),
        rejected,
        largest_accepted_z: outcome.largest_accepted_z,
        noise: outcome.noise,
        regions: regions.into_iter().map(|r| r.place).collect(),
        outcome,
        ..grade
    }
}

/// What a grade of `submission` should be read with.
fn notes(submission: &Submission) -> Vec<String> {
    match submission.alpha {
        glint_camera::AlphaChannel::Translucent { pixels } => vec![format!(
            "its alpha channel is below 1 in {pixels} pixels; alpha is not graded, the colour channels are, as stored"
        )],
        _ => Vec::new(),
    }
}

/// Why the file of `submission` cannot be graded against `refs`, if its
/// format lost what the test needs: then it neither passes nor fails.
fn unreadable_for_grading(submission: &Submission, refs: &References) -> Option<String> {
    if let Some(jpeg) = &submission.jpeg {
        match jpeg {
            Err(reason) => return Some(reason.clone()),
            Ok(encoding) => {
                if let Some(reason) = encoding.too_lossy() {
                    return Some(reason);
                }
            }
        }
    }
    if submission.gray && colourful(&refs.mean.mean) {
        return Some(
            "a gray image of a scene in colour: its format kept one channel of three".into(),
        );
    }
    if let Some(colours) = submission.palette {
        let rendered = eight_bit_colours(&refs.mean.mean);
        if colours < rendered {
            return Some(format!(
                "a palette image of {colours} colours, where Glint's render of the scene has {rendered}: the palette merged colours the test needs"
            ));
        }
    }
    None
}

/// Whether at least 1% of the pixels differ between channels by more than
/// 0.01 (linear).
fn colourful(pixels: &[Vec3]) -> bool {
    let coloured = pixels
        .iter()
        .filter(|p| {
            let p = p.min(Vec3::ONE);
            p.max_element() - p.min_element() > 0.01
        })
        .count();
    coloured * 100 > pixels.len()
}

/// The number of distinct 8-bit sRGB colours of `pixels`: the fewest a
/// lossless palette of the render needs (noise only adds more).
fn eight_bit_colours(pixels: &[Vec3]) -> usize {
    let colours: std::collections::HashSet<[u8; 3]> = pixels
        .iter()
        .map(|p| p.to_array().map(glint_camera::linear_to_srgb8))
        .collect();
    colours.len()
}

/// A region's name: its object's, or a block's pixels and the objects its
/// pixels' centres see (the largest shares, up to three).
fn describe(scene: &GradeScene, region: &test::Region, objects: &[u32]) -> String {
    match &region.place {
        Place::Object { object } => scene
            .object_name(object.unwrap_or(reference::BACKGROUND))
            .to_owned(),
        Place::Block { x0, y0, x1, y1 } => {
            let mut counts: std::collections::BTreeMap<u32, usize> = Default::default();
            for &i in &region.pixels {
                *counts.entry(objects[i as usize]).or_default() += 1;
            }
            let mut shares: Vec<(u32, usize)> = counts.into_iter().collect();
            shares.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
            let n = region.pixels.len();
            let seen: Vec<String> = shares
                .iter()
                .take(3)
                .map(|&(object, count)| {
                    format!(
                        "{} {}%",
                        scene.object_name(object),
                        (100 * count + n / 2) / n
                    )
                })
                .collect();
            format!("pixels {x0}–{x1} × {y0}–{y1} ({})", seen.join(", "))
        }
    }
}

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
