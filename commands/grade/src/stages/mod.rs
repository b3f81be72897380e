//! `glint grade --stages`: test vectors for each stage of a student's ray
//! tracer (camera, intersection, texture, lighting, film), and the check of
//! a student's answers to them, in any language.
//!
//! [`write_vectors`] writes, per stage, the cases' inputs with Glint's
//! outputs (`STAGE.json`, schema [`SCHEMA`], and `STAGE.csv`) and the inputs
//! alone (`STAGE-inputs.csv`, what a student is handed). Each stage's inputs
//! are Glint's outputs of the stage before, where that makes sense, so a
//! stage can be tested alone. [`check_answers`] reads the student's
//! `STAGE.csv` or `STAGE.json`, checks each value within its documented
//! tolerance ([`Check`]), and scores each stage, explaining its first
//! failing case with `glint explain`'s text for the pixel and camera sample
//! the case came from. `docs/grading-stages.md` documents the files, their
//! columns and the tolerances.
//!
//! # Conventions
//! - World space, right-handed, y up; linear RGB; the field of view in
//!   degrees; pixels counted from the image's top left.
//! - Cases are deterministic: the same scene and case count give the same
//!   files, byte for byte.
//! - Every case comes from one camera sample of one pixel on the grid
//!   patterns (`stages/probe.rs`), so `glint explain` shows it in full.

mod answers;
mod camera;
mod check;
mod files;
mod film;
mod intersection;
mod lighting;
mod probe;
mod report;
mod survey;
mod table;
#[cfg(test)]
mod tests;
mod texture;

pub use answers::{Answer, Answers};
pub use check::{CaseFailure, Difference, StageCheck, StagesCheck};
pub use probe::{explain_flags, LIGHT_GRID};
pub use table::{Case, Check, Field, Kind, Layout, Origin, Value};

use crate::{GradeError, GradeScene};
use glint_integrator::{RenderSettings, Scene};
use std::path::{Path, PathBuf};

/// The schema of the test-vector documents.
pub const SCHEMA: &str = "glint-stages/1";

/// The schema of `--format json`'s report of a check.
pub const CHECK_SCHEMA: &str = "glint-stages-check/1";

/// Cases per stage unless told.
pub const DEFAULT_CASES: u32 = 64;

/// The most cases per stage.
pub const MAX_CASES: u32 = 10_000;

/// A stage of the pipeline, in pipeline order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Stage {
    Camera,
    Intersection,
    Texture,
    Lighting,
    Film,
}

impl Stage {
    pub const ALL: [Stage; 5] = [
        Stage::Camera,
        Stage::Intersection,
        Stage::Texture,
        Stage::Lighting,
        Stage::Film,
    ];

    /// The name files and reports use.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Camera => "camera",
            Stage::Intersection => "intersection",
            Stage::Texture => "texture",
            Stage::Lighting => "lighting",
            Stage::Film => "film",
        }
    }

    /// The stage `glint explain --stage` prints for this one.
    pub fn explain_stage(self) -> glint_explain::Stage {
        match self {
            Stage::Camera => glint_explain::Stage::Camera,
            Stage::Intersection => glint_explain::Stage::Intersect,
            Stage::Texture => glint_explain::Stage::Texture,
            Stage::Lighting => glint_explain::Stage::Light,
            Stage::Film => glint_explain::Stage::Film,
        }
    }

    /// The stage's columns for `scene`.
    pub fn layout(self, scene: &Scene) -> Layout {
        match self {
            Stage::Camera => camera::layout(),
            Stage::Intersection => intersection::layout(scene),
            Stage::Texture => texture::layout(),
            Stage::Lighting => lighting::layout(scene),
            Stage::Film => film::layout(),
        }
    }

    /// What the stage's numbers mean, for the documents' `conventions`.
    pub fn conventions(self) -> &'static [&'static str] {
        match self {
            Stage::Camera => &CAMERA_CONVENTIONS,
            Stage::Intersection => &INTERSECTION_CONVENTIONS,
            Stage::Texture => &TEXTURE_CONVENTIONS,
            Stage::Lighting => &LIGHTING_CONVENTIONS,
            Stage::Film => &FILM_CONVENTIONS,
        }
    }
}

/// Conventions every stage shares, first in each document.
pub const COMMON_CONVENTIONS: [&str; 4] = [
    "world space, right-handed, y up; colors and radiance in linear RGB",
    "numbers are Glint's 32-bit floats, written so that they read back exactly",
    "an empty cell (null in JSON) is a value that does not apply and is not checked",
    "each case comes from camera sample `sample` of `spp` on the grid pattern of pixel `pixel`; `from.explain` shows it with glint explain",
];

const CAMERA_CONVENTIONS: [&str; 3] = [
    "x, y: raster position in pixels from the image's top-left corner, y down; pixel (i, j) covers [i, i+1) x [j, j+1) and has its centre at (i + 0.5, j + 0.5)",
    "ndc = (2x/width - 1, 1 - 2y/height); the ray points at f*forward + ndc.x*half_width*right + ndc.y*half_height*up, half_height = f*tan(fov/2), half_width = aspect*half_height",
    "origin: the eye; direction: a unit vector",
];

const INTERSECTION_CONVENTIONS: [&str; 5] = [
    "the ray is origin + t*direction, t > 0, with a unit direction: t is a distance",
    "the closest hit over every object; one-sided flat shapes (and the lights' surfaces) are invisible from behind; ties go to the lower object index",
    "geometric_normal: unit, as the shape defines it (outward on spheres and boxes, the front of flat shapes), whichever side the ray came from; shading_normal: the same except on meshes with interpolated normals",
    "sphere uv: u = atan2(-z, x)/(2 pi) in [0, 1) about the y axis, v = 1 - theta/pi with theta the polar angle from +y; parallelogram uv: the edge coordinates in [0, 1]; plane uv: tile coordinates",
    "objects are numbered as the scene builds them: spheres, parallelograms, planes, boxes, meshes, then the lights' surfaces, each kind in file order; name is the scene's name for it (shown, not checked)",
];

const TEXTURE_CONVENTIONS: [&str; 6] = [
    "uv' = (u*scale_u + offset_u, v*scale_v + offset_v): the material's uv transform, applied before the lookup",
    "l = 2*t*tan(fov/2) / (r*|n_dot_d|): a pixel's height on the surface (report section 2.8)",
    "jacobian = |J_T| = sqrt(|dp/du x dp/dv|) / sqrt(|scale_u*scale_v|): the length one unit of uv' covers on the surface; w = jacobian/m; level = log2(l/w)",
    "value, image: trilinear at the report's level, clamped to [0, levels - 1]: bilinear lookups (texel centres at (i + 0.5)/size, the texture's wrap mode) in levels floor(level) and floor(level) + 1, blended by the fraction; image coordinates st = (u', 1 - v'); each level halves the last (box filter) down to 1 x 1",
    "value, checkerboard: the check's color at uv' (point-sampled): colors[(floor(u'*checks) + floor(v'*checks)) mod 2]; w, level and m are empty (a procedural texture has no texels)",
    "m: the image's larger side in texels",
];

const LIGHTING_CONVENTIONS: [&str; 6] = [
    "n: the unit shading normal facing the viewer; ng: the geometric normal on n's side; v: the unit direction to the viewer; kd and ks: the material's reflectances after texturing",
    "each area light is sampled on its 4 x 4 grid of cell centres, each point light once; a sample's l = normalize(position - point)",
    "diffuse = kd*max(0, n.l); specular = ks*max(0, r.v)^shininess with r = 2(n.l)n - l (blinn-phong: ks*max(0, n.h)^shininess, h = normalize(l + v)), 0 where n.l <= 0; both for a light of color 1, whatever the verdict",
    "verdict: unlit where no shadow ray is traced (the point is behind the light's emitting side, normal.(point - position) <= 0; or ng.l <= 0; or diffuse + specular = 0), else blocked (blocker: the nearest object between the point and the sample) or visible",
    "ambient_term = ambient*kd",
    "total = ambient_term + sum over lights of color * (sum of its visible samples' diffuse + specular) / (its number of samples): the point's local radiance, before mirror reflection, without environment light",
];

const FILM_CONVENTIONS: [&str; 2] = [
    "srgb8 = floor(255*encode(clamp(c, 0, 1)) + 0.5), encode(c) = 12.92*c for c <= 0.0031308, else 1.055*c^(1/2.4) - 0.055 (IEC 61966-2-1)",
    "radiance: a pixel's mean over its samples, as the render writes it, or a chosen value (from is null); no value lies within 0.005 of a code's rounding boundary",
];

/// One stage's test vectors.
#[derive(Clone, Debug, PartialEq)]
pub struct StageVectors {
    pub stage: Stage,
    pub layout: Layout,
    pub cases: Vec<Case>,
}

/// What a stage's cases are made from.
pub struct Context<'a> {
    pub scene: &'a Scene,
    /// The scene's own render settings (the cases change their patterns).
    pub settings: &'a RenderSettings,
    /// The scene's names of its objects, by index.
    pub names: &'a [String],
    pub survey: survey::Survey,
}

/// The test vectors of `stages` for `scene`, `cases` per stage (fewer where
/// the scene has too few pixels of a kind, none for the lighting stage
/// under physical shading).
pub fn vectors(
    scene: &GradeScene,
    stages: &[Stage],
    cases: u32,
) -> Result<Vec<StageVectors>, GradeError> {
    let d = &scene.description;
    let cx = Context {
        scene: &d.scene,
        settings: &d.settings,
        names: &d.object_names,
        survey: survey::Survey::new(&d.scene),
    };
    let n = cases as usize;
    stages
        .iter()
        .map(|&stage| {
            let mut found = match stage {
                Stage::Camera => camera::cases(&cx, n),
                Stage::Intersection => intersection::cases(&cx, n),
                Stage::Texture => texture::cases(&cx, n),
                Stage::Lighting => lighting::cases(&cx, n),
                Stage::Film => film::cases(&cx, n),
            }?;
            table::number(stage.name(), &mut found);
            Ok(StageVectors {
                stage,
                layout: stage.layout(&d.scene),
                cases: found,
            })
        })
        .collect()
}

/// Checks `cases` is a case count `--cases` accepts.
pub fn check_case_count(cases: u32) -> Result<(), GradeError> {
    if (1..=MAX_CASES).contains(&cases) {
        Ok(())
    } else {
        Err(GradeError::Input(format!(
            "--cases: expected a number of cases per stage from 1 to {MAX_CASES}, got {cases}"
        )))
    }
}

/// Checks that `dir` can take the vectors ([`write_vectors`] does too):
/// for a caller that checks its output before loading the scene.
pub fn check_write_dir(dir: &Path) -> Result<(), GradeError> {
    crate::output::check_dir(dir, "--write")
}

/// Writes every stage's vectors for `scene` into `dir` (made if missing;
/// its parent must exist): `STAGE.json`, `STAGE.csv` and `STAGE-inputs.csv`.
/// `dir` is checked before any work, every file is computed before the
/// first is written, and each is written atomically. Returns the files.
pub fn write_vectors(
    scene: &GradeScene,
    cases: u32,
    dir: &Path,
) -> Result<Vec<(PathBuf, usize)>, GradeError> {
    check_case_count(cases)?;
    crate::output::check_dir(dir, "--write")?;
    let all = vectors(scene, &Stage::ALL, cases)?;
    let name = scene_name(scene);
    let documents: Vec<(PathBuf, String, usize)> = all
        .iter()
        .flat_map(|v| files::documents(&name, cases, v, dir))
        .collect();
    crate::output::make_dir(dir)?;
    for (path, text, _) in &documents {
        crate::output::write_text(path, text)?;
    }
    Ok(documents
        .into_iter()
        .map(|(path, _, count)| (path, count))
        .collect())
}

/// Checks the answers in `dir` against the vectors of `scene` at `cases`
/// per stage. A stage without an answer file is not answered; a folder
/// without any is bad input.
pub fn check_answers(
    scene: &GradeScene,
    cases: u32,
    dir: &Path,
) -> Result<StagesCheck, GradeError> {
    check_case_count(cases)?;
    check::check(scene, cases, dir)
}

/// The report of a check as text: a score per stage, then each failing
/// stage's first failing case, explained.
pub fn report_text(check: &StagesCheck) -> String {
    report::text(check)
}

/// The report of a check as JSON (schema [`CHECK_SCHEMA`]).
pub fn report_json(check: &StagesCheck) -> String {
    serde_json::to_string_pretty(&report::json(check)).expect("JSON") + "\n"
}

/// The scene's file name, as the documents and explain commands give it.
pub fn scene_name(scene: &GradeScene) -> String {
    scene.path.file_name().map_or_else(
        || scene.path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}
