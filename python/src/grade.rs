//! `glint grade` for one scene's images from Python: the class path the
//! command takes, its JSON document as text.

use glint_grade::class::{self, ClassOptions, Progress};
use glint_grade::course::Scenes;
use glint_grade::{Cache, GradeError, GradeScene, StatedSettings, TestOptions};
use glint_integrator::SamplePattern;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The settings a class's submissions state, by `glint grade`'s flag names.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub(crate) struct Stated {
    spp: Option<u32>,
    pixel_sampler: Option<String>,
    light_samples: Option<u32>,
    light_sampler: Option<String>,
}

/// No progress shown.
struct Quiet;

impl Progress for Quiet {
    fn rendering(&self, _: &str) {}
    fn graded(&self, _: usize, _: usize) {}
}

/// What one scene's submissions are graded against.
pub(crate) enum Against {
    /// A scene file, loaded as `glint grade SCENE` loads it.
    File(PathBuf),
    /// A scene already loaded.
    Loaded(Box<GradeScene>),
}

/// The test's `alpha`, `block`, reference cache folder (none without) and
/// whether failing submissions are tested against the classic mistakes.
pub(crate) type Test = (f64, Option<u32>, Option<PathBuf>, bool);

/// `glint grade SCENE FILE... --format json` with the stated settings and
/// the [`Test`]'s.
pub(crate) fn grade_json(
    scene: Against,
    files: Vec<PathBuf>,
    stated: Stated,
    test: Test,
) -> PyResult<Graded> {
    let stated = stated_settings(stated)?;
    let scene = match scene {
        Against::File(path) => GradeScene::load(&path).map_err(input)?,
        Against::Loaded(scene) => *scene,
    };
    let entries = class::entries_of_scene(&scene.path, &files, &stated);
    let scenes = Scenes::Loaded(Arc::new(scene));
    for entry in &entries {
        glint_grade::Submission::load(&entry.file).map_err(PyValueError::new_err)?;
    }
    report_json(&entries, (&scenes, &PathBuf::new()), test)
}

/// `glint grade --class CLASS [--scenes DIR] --format json`: a class folder
/// (`CLASS/STUDENT/SCENE.EXT`) or manifest (CSV), its scenes in `scenes`
/// (else beside it).
pub(crate) fn grade_class_json(
    class: PathBuf,
    scenes: Option<PathBuf>,
    stated: Stated,
    test: Test,
) -> PyResult<Graded> {
    let stated = stated_settings(stated)?;
    let base = class
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
        .to_owned();
    let entries = match class.is_dir() {
        true => class::entries_from_folder(&class, &stated),
        false => class::entries_from_manifest(&class, &stated),
    }
    .map_err(input)?;
    let scenes = Scenes::Folder(scenes.unwrap_or_else(|| base.clone()));
    report_json(&entries, (&scenes, &base), test)
}

/// The stated settings, their sampler names read and checked.
fn stated_settings(stated: Stated) -> PyResult<StatedSettings> {
    let pattern = |name: Option<String>| -> PyResult<Option<SamplePattern>> {
        name.map(|n| {
            SamplePattern::from_name(&n).ok_or_else(|| {
                let names = SamplePattern::NAMES.join(", ");
                PyValueError::new_err(format!("unknown sampler \"{n}\"; expected one of {names}"))
            })
        })
        .transpose()
    };
    let stated = StatedSettings {
        spp: stated.spp,
        pixel_pattern: pattern(stated.pixel_sampler)?,
        light_samples: stated.light_samples,
        light_pattern: pattern(stated.light_sampler)?,
    };
    stated
        .validate()
        .map_err(|e| PyValueError::new_err(format!("the submissions' settings: {e}")))?;
    Ok(stated)
}

/// A graded class: `glint grade --format json`'s document as text, and each
/// submission's heat map (`--heatmap`'s RGB8 pixels and its size) where it
/// was graded.
pub(crate) struct Graded {
    pub(crate) json: String,
    pub(crate) heatmaps: Vec<Option<glint_grade::document::Heatmap>>,
}

/// The class path for `entries`: its document and heat maps.
fn report_json(
    entries: &[class::Entry],
    (scenes, base): (&Scenes, &Path),
    (alpha, block, cache, mistakes): Test,
) -> PyResult<Graded> {
    if !(alpha > 0.0 && alpha < 1.0) {
        return Err(PyValueError::new_err(format!(
            "alpha is {alpha}; expected 0 < alpha < 1"
        )));
    }
    let options = ClassOptions {
        test: TestOptions { alpha, block },
        cache: Cache { dir: cache },
        mistakes,
    };
    let graded =
        glint_grade::document::grade_with_heatmaps(entries, (scenes, base), &options, &Quiet)
            .map_err(input)?;
    let json = serde_json::to_string_pretty(&graded.document)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(Graded {
        json: json + "\n",
        heatmaps: graded.heatmaps,
    })
}

fn input(e: GradeError) -> PyErr {
    PyValueError::new_err(e.to_string())
}
