//! Glint from Python: the extension module `glint._glint` behind the `glint`
//! package (`python/glint`), a thin layer over the crates.
//!
//! # Conventions
//! - Images cross as numpy arrays of shape `(height, width, 3)`, `float32`,
//!   C-contiguous, linear RGB radiance, row 0 at the top (the film's order).
//! - Scenes load through [`glint_scene::Overrides`], the code `glint render`'s
//!   flags go through, so a keyword and a flag of the same name do the same.
//! - Errors are the package's exception types (`glint/errors.py`): a bad
//!   scene is `SceneError` (also a `ValueError`) with its file, line, column
//!   and field; a missing scene file is `FileNotFoundError`. Nothing panics
//!   into Python.
//! - Renders release the GIL and run on Glint's own threads; the calling
//!   thread waits in slices of 50 ms, checking for signals, so Ctrl-C stops
//!   the render and raises `KeyboardInterrupt` at once.

mod convert;
mod errors;
mod grade;
mod render;

use convert::{array_of, film_of, overrides_of, toml_of};
use errors::{glint_error, not_found, scene_error};
use glint_camera::{Film, ImageFormat};
use glint_integrator::{Crop, RenderSettings};
use glint_metrics::ImageView;
use glint_scene::SceneDescription;
use numpy::{PyArray3, PyReadonlyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};

/// A loaded scene with its render settings (`glint.Scene` wraps it), and
/// where it came from, which grading's reference cache is keyed by.
#[pyclass(module = "glint._glint", frozen)]
struct Scene {
    description: SceneDescription,
    origin: Origin,
    overrides: glint_scene::Overrides,
}

/// Where a scene was read from.
enum Origin {
    File(PathBuf),
    /// TOML text (a dict's, as written), and the name errors call it by.
    Text {
        name: String,
        text: String,
        base: PathBuf,
    },
}

impl Scene {
    /// The scene as grading takes it: a file read as it is keys the cache as
    /// `glint grade` does (by the file); otherwise by its text and the
    /// settings that replaced the text's.
    fn grade_scene(&self) -> PyResult<glint_grade::GradeScene> {
        use glint_grade::GradeScene;
        let description = self.description.clone();
        let replaced = format!("\nreplaced: {:?}", self.overrides);
        Ok(match &self.origin {
            Origin::File(path) if self.overrides == Default::default() => {
                GradeScene::from_file(path, description)
            }
            Origin::File(path) => {
                let text = std::fs::read_to_string(path).map_err(|e| {
                    pyo3::exceptions::PyOSError::new_err(format!("{}: {e}", path.display()))
                })?;
                let base = path.parent().unwrap_or(Path::new("")).to_owned();
                GradeScene::from_text(
                    &path.display().to_string(),
                    &(text.clone() + &replaced),
                    description,
                )
                .with_source(text, base)
            }
            Origin::Text { name, text, base } => {
                GradeScene::from_text(name, &format!("{text}{replaced}"), description)
                    .with_source(text.clone(), base.clone())
            }
        })
    }
}

#[pymethods]
impl Scene {
    /// The film's size, `(width, height)`.
    #[getter]
    fn resolution(&self) -> (u32, u32) {
        let r = self.description.scene.camera.resolution();
        (r.x, r.y)
    }

    /// The render settings, as the scene file's `[render]` keys name them.
    #[getter]
    fn settings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s: &RenderSettings = &self.description.settings;
        let d = PyDict::new(py);
        d.set_item("spp", s.spp)?;
        d.set_item("light_samples", s.light_samples)?;
        d.set_item("pixel_sampler", s.pixel_pattern.name())?;
        d.set_item("light_sampler", s.light_pattern.name())?;
        d.set_item("max_depth", s.max_depth)?;
        d.set_item("environment_samples", s.environment_samples)?;
        d.set_item("environment_sampler", s.environment_pattern.name())?;
        d.set_item("environment_sampling", s.environment_sampling.name())?;
        d.set_item("area_sampling", s.area_sampling.name())?;
        d.set_item("mis", s.mis)?;
        d.set_item("seed", s.seed)?;
        Ok(d)
    }

    /// The file's `[regions]`: name to `(x0, y0, x1, y1)`.
    #[getter]
    fn regions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (name, [x0, y0, x1, y1]) in &self.description.regions {
            d.set_item(name, (x0, y0, x1, y1))?;
        }
        Ok(d)
    }

    /// The linear radiance, or an AOV, of the whole film or of the window
    /// `crop = (x0, y0, x1, y1)`; `progress(done, total)` is called from
    /// the calling thread as tiles finish.
    #[pyo3(signature = (*, crop=None, aov=None, threads=None, progress=None))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        crop: Option<(u32, u32, u32, u32)>,
        aov: Option<&str>,
        threads: Option<usize>,
        progress: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let mut settings = self.description.settings.clone();
        if let Some(name) = aov {
            let aov = glint_integrator::Aov::from_name(name).ok_or_else(|| {
                let names = glint_integrator::Aov::NAMES.join(", ");
                pyo3::exceptions::PyValueError::new_err(format!(
                    "aov: unknown buffer \"{name}\"; expected one of {names}"
                ))
            })?;
            settings.aov = Some(aov);
        }
        settings.threads = threads.or(settings.threads);
        let crop = crop.map(|(x0, y0, x1, y1)| Crop { x0, y0, x1, y1 });
        let scene = &self.description.scene;
        let film = render::render(py, scene, &settings, crop, progress.as_ref())?;
        Ok(array_of(py, film))
    }

    /// `glint explain SCENE --pixel X,Y --json` with the same settings: the
    /// `glint-explain/1` document as JSON text, ending in a newline; with
    /// `against` (a student's document as JSON text), `--against`'s
    /// comparison instead.
    #[pyo3(signature = (x, y, *, sample=0, all_samples=false, stage=None, against=None))]
    #[allow(clippy::too_many_arguments)]
    fn explain_json(
        &self,
        py: Python<'_>,
        x: u32,
        y: u32,
        sample: u64,
        all_samples: bool,
        stage: Option<&str>,
        against: Option<&str>,
    ) -> PyResult<String> {
        use glint_integrator::trace::SampleSelection;
        let stage = stage
            .map(|name| {
                glint_explain::Stage::from_name(name).ok_or_else(|| {
                    let names = glint_explain::Stage::ALL.map(|s| s.name()).join(", ");
                    pyo3::exceptions::PyValueError::new_err(format!(
                        "stage: unknown stage \"{name}\"; expected one of {names}"
                    ))
                })
            })
            .transpose()?;
        let selection = match all_samples {
            true => SampleSelection::All,
            false => SampleSelection::One(sample),
        };
        let (scene, settings) = (&self.description.scene, &self.description.settings);
        let explained = py
            .detach(|| glint_explain::explain(scene, settings, x, y, selection))
            .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
        let document = match against {
            None => explained.json(stage),
            Some(student) => compare(&explained, student, stage)?,
        };
        let json =
            serde_json::to_string_pretty(&document).map_err(|e| glint_error(py, &e.to_string()))?;
        Ok(json + "\n")
    }
}

/// A student's document (JSON text) against Glint's explanation, limited
/// to `stage`: `glint explain --against`'s comparison document.
fn compare(
    explained: &glint_explain::Explanation,
    student: &str,
    stage: Option<glint_explain::Stage>,
) -> PyResult<serde_json::Value> {
    use glint_explain::against::{self, Node};
    let student = Node::parse(student).map_err(|e| {
        let at = against::located(&e);
        pyo3::exceptions::PyValueError::new_err(format!("the student's document{at}"))
    })?;
    let comparison = against::compare(&student, &explained.json(None), stage).map_err(|e| {
        pyo3::exceptions::PyValueError::new_err(format!("the student's document: {e}"))
    })?;
    Ok(comparison.json())
}

/// Loads the scene file at `path` with `overrides` (a dict of setting names).
#[pyfunction]
fn load(py: Python<'_>, path: PathBuf, overrides: &Bound<'_, PyDict>) -> PyResult<Scene> {
    let overrides = overrides_of(overrides)?;
    if !path.exists() {
        return Err(not_found(&path));
    }
    let description = py
        .detach(|| glint_scene::load(&path))
        .map_err(|e| scene_error(py, e))?;
    prepared(py, description, Origin::File(path), overrides)
}

/// Parses scene text, or a dict of the file's tables, whose asset paths are
/// relative to `base_dir`; `name` names it in error messages.
#[pyfunction]
fn parse(
    py: Python<'_>,
    scene: &Bound<'_, PyAny>,
    name: &str,
    base_dir: PathBuf,
    overrides: &Bound<'_, PyDict>,
) -> PyResult<Scene> {
    let overrides = overrides_of(overrides)?;
    let text = match scene.extract::<String>() {
        Ok(text) => text,
        Err(_) => toml_of(scene)?,
    };
    let description = py
        .detach(|| glint_scene::parse_in(&text, name, &base_dir))
        .map_err(|e| scene_error(py, e))?;
    let name = name.to_owned();
    let base = base_dir;
    prepared(
        py,
        description,
        Origin::Text { name, text, base },
        overrides,
    )
}

/// The scene with `overrides` applied (prepared for them, checked).
fn prepared(
    py: Python<'_>,
    mut description: SceneDescription,
    origin: Origin,
    overrides: glint_scene::Overrides,
) -> PyResult<Scene> {
    py.detach(|| overrides.apply(&mut description))
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
    Ok(Scene {
        description,
        origin,
        overrides,
    })
}

/// Reads an image file of any format Glint reads: its linear pixels and
/// what it was read as ("PNG, 8-bit RGB", ...).
#[pyfunction]
fn imread<'py>(py: Python<'py>, path: PathBuf) -> PyResult<(Bound<'py, PyArray3<f32>>, String)> {
    if !path.exists() {
        return Err(not_found(&path));
    }
    let file = py
        .detach(|| Film::read(&path))
        .map_err(|e| glint_error(py, &e.to_string()))?;
    let description = file.description();
    Ok((array_of(py, file.film), description))
}

/// Writes `image` to `path` in the format its extension names (.png as
/// 8-bit sRGB, .exr or .pfm as linear 32-bit float), atomically.
#[pyfunction]
fn imwrite(py: Python<'_>, path: PathBuf, image: PyReadonlyArray3<'_, f32>) -> PyResult<()> {
    let film = film_of(&image)?;
    py.detach(|| film.save(&path))
        .map_err(|e| glint_error(py, &e.to_string()))
}

/// `image` encoded as a file of `format` ("png", "exr", "pfm") would hold it.
#[pyfunction]
fn encode(py: Python<'_>, image: PyReadonlyArray3<'_, f32>, format: &str) -> PyResult<Vec<u8>> {
    let film = film_of(&image)?;
    let format = ImageFormat::from_path(Path::new(&format!("image.{format}")))
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
    py.detach(|| film.to_bytes(format))
        .map_err(|e| glint_error(py, &e.to_string()))
}

/// `glint diff`'s measures of `test` against `reference` over the whole
/// image: RMSE, relMSE, mean FLIP, the largest difference and each image's
/// channel means.
#[pyfunction]
fn diff<'py>(
    py: Python<'py>,
    test: PyReadonlyArray3<'_, f32>,
    reference: PyReadonlyArray3<'_, f32>,
) -> PyResult<Bound<'py, PyDict>> {
    let (test, reference) = (film_of(&test)?, film_of(&reference)?);
    let size = test.resolution();
    let c = py
        .detach(|| {
            let (test, reference) = (ImageView::from(&test), ImageView::from(&reference));
            glint_metrics::compare(test, reference, glint_metrics::Region::full(size.x, size.y))
        })
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
    let d = PyDict::new(py);
    d.set_item("rmse", c.rmse)?;
    d.set_item("rel_mse", c.rel_mse)?;
    d.set_item("flip", c.flip)?;
    d.set_item("max_difference", c.max_difference.value)?;
    let (x, y) = (c.max_difference.x, c.max_difference.y);
    d.set_item("max_difference_pixel", (x, y))?;
    d.set_item("means_test", c.means_test.to_array())?;
    d.set_item("means_reference", c.means_reference.to_array())?;
    Ok(d)
}

/// What `glint.grade` grades against: a scene file or a loaded scene.
#[derive(FromPyObject)]
enum SceneArg<'py> {
    Loaded(Bound<'py, Scene>),
    File(PathBuf),
}

/// `glint grade SCENE FILE... --format json` with these settings: the
/// document as text.
#[pyfunction]
#[pyo3(signature = (scene, files, stated, alpha=0.01, block=None, cache=None, mistakes=false))]
#[allow(clippy::too_many_arguments)]
fn grade_json<'py>(
    py: Python<'py>,
    scene: SceneArg<'py>,
    files: Vec<PathBuf>,
    stated: grade::Stated,
    alpha: f64,
    block: Option<u32>,
    cache: Option<PathBuf>,
    mistakes: bool,
) -> PyResult<GradedPy<'py>> {
    let scene = match scene {
        SceneArg::File(path) => grade::Against::File(path),
        SceneArg::Loaded(scene) => grade::Against::Loaded(Box::new(scene.get().grade_scene()?)),
    };
    let test = (alpha, block, cache, mistakes);
    let graded = py.detach(|| grade::grade_json(scene, files, stated, test))?;
    Ok(graded_py(py, graded))
}

/// `glint grade --class CLASS [--scenes DIR] --format json` with these
/// settings: the document as text.
#[pyfunction]
#[pyo3(signature = (class, scenes, stated, alpha=0.01, block=None, cache=None, mistakes=false))]
#[allow(clippy::too_many_arguments)]
fn grade_class_json(
    py: Python<'_>,
    class: PathBuf,
    scenes: Option<PathBuf>,
    stated: grade::Stated,
    alpha: f64,
    block: Option<u32>,
    cache: Option<PathBuf>,
    mistakes: bool,
) -> PyResult<GradedPy<'_>> {
    let test = (alpha, block, cache, mistakes);
    let graded = py.detach(|| grade::grade_class_json(class, scenes, stated, test))?;
    Ok(graded_py(py, graded))
}

/// A graded class for Python: the document's text and each submission's
/// heat map as a `(height, width, 3)` uint8 array (None where not graded).
type GradedPy<'py> = (String, Vec<Option<Bound<'py, numpy::PyArray3<u8>>>>);

fn graded_py(py: Python<'_>, graded: grade::Graded) -> GradedPy<'_> {
    use numpy::IntoPyArray;
    let heatmaps = graded
        .heatmaps
        .into_iter()
        .map(|map| {
            map.map(
                |glint_grade::document::Heatmap {
                     resolution: size,
                     rgb,
                 }| {
                    numpy::ndarray::Array3::from_shape_vec(
                        (size.y as usize, size.x as usize, 3),
                        rgb,
                    )
                    .expect("a heat map fills its image")
                    .into_pyarray(py)
                },
            )
        })
        .collect();
    (graded.json, heatmaps)
}

/// The `glint` command line `args` (the first the program's name), run in
/// this process as the `glint` program runs it; `program` is the path job
/// scripts call it by. Returns the exit status.
#[pyfunction]
fn main(py: Python<'_>, program: PathBuf, args: Vec<String>) -> u8 {
    let args = args.into_iter().map(Into::into).collect();
    py.detach(|| glint_cli::run(Some(program), args))
}

/// The x86-64 instruction sets this build was compiled to use (the CPU
/// level a wheel needs): `target-cpu=native` gives this machine's, a wheel
/// for other machines `x86-64-v3`'s (AVX2, FMA, ...).
fn cpu_features() -> Vec<&'static str> {
    let all = [
        ("sse4.2", cfg!(target_feature = "sse4.2")),
        ("avx", cfg!(target_feature = "avx")),
        ("avx2", cfg!(target_feature = "avx2")),
        ("fma", cfg!(target_feature = "fma")),
        ("avx512f", cfg!(target_feature = "avx512f")),
    ];
    all.into_iter()
        .filter(|(_, on)| *on)
        .map(|(name, _)| name)
        .collect()
}

#[pymodule]
fn _glint(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Scene>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(parse, m)?)?;
    m.add_function(wrap_pyfunction!(imread, m)?)?;
    m.add_function(wrap_pyfunction!(imwrite, m)?)?;
    m.add_function(wrap_pyfunction!(encode, m)?)?;
    m.add_function(wrap_pyfunction!(diff, m)?)?;
    m.add_function(wrap_pyfunction!(main, m)?)?;
    m.add_function(wrap_pyfunction!(grade_json, m)?)?;
    m.add_function(wrap_pyfunction!(grade_class_json, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("cpu_features", cpu_features())?;
    Ok(())
}
