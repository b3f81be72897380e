//! The routes: the page, the session, images, the render, explain, heat
//! maps and grading. Each answers a [`Reply`], a refusal being a 4xx reply
//! with its reason.

use crate::http::{Reply, Request};
use crate::progressive::{Renders, Step};
use crate::query::{self, get, Flags};
use crate::{Backend, ViewError};
use glint_camera::{Film, ImageFormat};
use glint_grade::document::Graded;
use glint_integrator::SamplePattern;
use serde_json::{json, Value};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// The page: HTML, CSS and script in one file, built into the program.
const PAGE: &str = include_str!("page.html");
/// The routes, for a 404's message.
const ROUTES: &str = "/api/session, /api/image, /api/render, /api/explain, /api/against, \
                      /api/heatmap, /api/grade, /api/grade/heatmap";
/// Graded submissions kept, for their heat maps.
const GRADES_KEPT: usize = 16;

type Answer = Result<Reply, Reply>;

fn bad(message: String) -> Reply {
    Reply::error(400, &message)
}

/// An image named on the command line, read once.
pub(crate) struct Image {
    path: PathBuf,
    film: Arc<Film>,
    format: String,
}

/// The command line's images, numbered from 0 in the order given.
pub(crate) struct Images(Vec<Image>);

impl Images {
    pub fn read(paths: &[PathBuf]) -> Result<Images, ViewError> {
        let read = |path: &PathBuf| {
            let file = Film::read(path).map_err(|e| ViewError::Image {
                path: path.clone(),
                message: e.to_string(),
            })?;
            Ok(Image {
                path: path.clone(),
                format: file.description(),
                film: Arc::new(file.film),
            })
        };
        paths.iter().map(read).collect::<Result<_, _>>().map(Images)
    }
}

/// Everything a request may read or start.
pub(crate) struct State {
    images: Images,
    scene: Option<PathBuf>,
    against: bool,
    backend: Arc<dyn Backend>,
    renders: Renders,
    grades: Mutex<HashMap<String, Arc<Graded>>>,
}

impl State {
    pub fn new(
        images: Images,
        scene: Option<PathBuf>,
        against: bool,
        backend: Arc<dyn Backend>,
    ) -> State {
        State {
            images,
            scene,
            against,
            backend,
            renders: Renders::default(),
            grades: Mutex::default(),
        }
    }

    pub fn answer(&self, request: &Request) -> Reply {
        let answer = match request.path.as_str() {
            "/" => Ok(Reply::bytes(
                "text/html; charset=utf-8",
                PAGE.as_bytes().to_vec(),
            )),
            "/api/session" => self.session(),
            "/api/image" => self.image(request),
            "/api/render" => self.render(request),
            "/api/explain" => self.explain(request, false),
            "/api/against" => self.explain(request, true),
            "/api/heatmap" => self.heatmap(request),
            "/api/grade" => self
                .grade(request)
                .map(|g| Reply::json(pretty(&g.document))),
            "/api/grade/heatmap" => self.grade_heatmap(request),
            other => Err(Reply::error(
                404,
                &format!("no page {}: the API is {ROUTES}", query::shorten(other)),
            )),
        };
        answer.unwrap_or_else(|refusal| refusal)
    }

    /// What there is to look at: the scene (its size, settings, lights and
    /// objects), the images, whether a student's document was given.
    fn session(&self) -> Answer {
        let scene = match &self.scene {
            None => Value::Null,
            Some(path) => {
                let scene = self.backend.scene(&Flags::new()).map_err(bad)?;
                scene_json(path, &scene)
            }
        };
        let images: Vec<Value> = (self.images.0.iter().enumerate())
            .map(|(id, image)| {
                let size = image.film.resolution();
                json!({
                    "id": id,
                    "name": image.path.display().to_string(),
                    "format": image.format,
                    "width": size.x,
                    "height": size.y,
                })
            })
            .collect();
        let document = json!({
            "schema": "glint-view/1",
            "scene": scene,
            "images": images,
            "against": self.against,
            "aovs": glint_integrator::Aov::NAMES,
            "samplers": SamplePattern::NAMES,
        });
        Ok(Reply::json(pretty(&document)))
    }

    fn image(&self, request: &Request) -> Answer {
        let (own, flags) = query::split(request, &["id", "as"]).map_err(bad)?;
        refuse_flags(&flags)?;
        let image = self.numbered(get(&own, "id"))?;
        encoded(&image.film, get(&own, "as"))
    }

    /// The newest step of the render these flags ask for (202 while none).
    fn render(&self, request: &Request) -> Answer {
        let (own, flags) = query::split(request, &["as"]).map_err(bad)?;
        self.scene_path()?;
        match self
            .renders
            .latest(&flags, self.backend.as_ref())
            .map_err(bad)?
        {
            None => Ok(Reply {
                status: 202,
                ..Reply::json("{\"pending\": true}\n".into())
            }),
            Some(Step { film, spp, target }) => Ok(encoded(
                &as_written(film, &flags, get(&own, "as")),
                get(&own, "as"),
            )?
            .with_header("X-Spp", spp.to_string())
            .with_header("X-Target-Spp", target.to_string())),
        }
    }

    /// `glint explain SCENE --json` (with `--against` where asked) with the
    /// request's flags: the command's bytes.
    fn explain(&self, request: &Request, against: bool) -> Answer {
        let (_, flags) = query::split(request, &[]).map_err(bad)?;
        self.scene_path()?;
        if against && !self.against {
            return Err(bad("glint view was not given --against STUDENT.json".into()));
        }
        if get(&flags, "pixel").is_none() {
            return Err(bad("pixel: give the pixel as pixel=X,Y".into()));
        }
        let text = self.backend.explain(&flags, against).map_err(bad)?;
        Ok(Reply::json(text))
    }

    /// `glint diff --heatmap`'s picture of image `a` against image `b`
    /// (`render` for the newest render): FLIP, or relative MSE per pixel.
    fn heatmap(&self, request: &Request) -> Answer {
        let (own, flags) = query::split(request, &["a", "b", "metric", "scale"]).map_err(bad)?;
        refuse_flags(&flags)?;
        let (a, b) = (self.film(get(&own, "a"))?, self.film(get(&own, "b"))?);
        let (t, r) = (
            glint_metrics::ImageView::from(&*a),
            glint_metrics::ImageView::from(&*b),
        );
        let unmeasurable = |e: glint_metrics::MetricsError| bad(e.to_string());
        let (map, default_scale) = match get(&own, "metric").unwrap_or("flip") {
            "flip" => (glint_metrics::flip(t, r).map_err(unmeasurable)?, None),
            "relmse" => {
                let map = glint_metrics::rel_mse_map(t, r).map_err(unmeasurable)?;
                let scale = glint_metrics::heatmap_scale(map.values.iter().copied());
                (map, Some(scale))
            }
            other => {
                let other = query::shorten(other);
                return Err(bad(format!("metric: \"{other}\"; expected flip or relmse")));
            }
        };
        let scale = match get(&own, "scale") {
            Some(text) => text
                .parse::<f32>()
                .ok()
                .filter(|s| s.is_finite() && *s > 0.0)
                .ok_or_else(|| {
                    bad(format!(
                        "scale: \"{}\" is not a positive number",
                        query::shorten(text)
                    ))
                })?,
            None => default_scale.unwrap_or(1.0),
        };
        let colors = glint_metrics::heatmap(&map, scale).map_err(unmeasurable)?;
        let png = glint_metrics::heatmap_png(map.width, map.height, &colors)
            .map_err(|e| Reply::error(500, &e))?;
        Ok(Reply::bytes("image/png", png).with_header("X-Scale", scale.to_string()))
    }

    /// `glint grade SCENE IMAGE --format json` for image `id` under the
    /// settings it states (`spp`, `sampler`, `light-samples`,
    /// `light-sampler`), kept for its heat map.
    fn grade(&self, request: &Request) -> Result<Arc<Graded>, Reply> {
        let (own, flags) = query::split(request, &["id"]).map_err(bad)?;
        let scene = self.scene_path()?;
        let image = self.numbered(get(&own, "id"))?;
        let key = format!("{}{flags:?}", get(&own, "id").unwrap_or_default());
        if let Some(graded) = self.grades.lock().map_err(|_| failed())?.get(&key) {
            return Ok(graded.clone());
        }
        let stated = stated(&flags)?;
        let entries =
            glint_grade::class::entries_of_scene(scene, std::slice::from_ref(&image.path), &stated);
        let scenes = glint_grade::course::Scenes::Folder(PathBuf::new());
        let options = glint_grade::class::ClassOptions {
            test: glint_grade::TestOptions {
                alpha: 0.01,
                block: None,
            },
            cache: glint_grade::Cache { dir: None },
            // The page shows where a submission fails, not why.
            mistakes: false,
        };
        let graded = glint_grade::document::grade_with_heatmaps(
            &entries,
            (&scenes, Path::new("")),
            &options,
            &Quiet,
        )
        .map_err(|e| bad(e.to_string()))?;
        let graded = Arc::new(graded);
        let mut grades = self.grades.lock().map_err(|_| failed())?;
        if grades.len() >= GRADES_KEPT {
            grades.clear();
        }
        grades.insert(key, graded.clone());
        Ok(graded)
    }

    fn grade_heatmap(&self, request: &Request) -> Answer {
        let graded = self.grade(request)?;
        let heatmap = (graded.heatmaps.first().cloned().flatten())
            .ok_or_else(|| bad("the image was not graded (see /api/grade)".into()))?;
        let rgb: Vec<[u8; 3]> = heatmap
            .rgb
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        let size = heatmap.resolution;
        let png =
            glint_metrics::heatmap_png(size.x, size.y, &rgb).map_err(|e| Reply::error(500, &e))?;
        Ok(Reply::bytes("image/png", png))
    }

    fn scene_path(&self) -> Result<&Path, Reply> {
        (self.scene.as_deref()).ok_or_else(|| bad("glint view was given no scene".into()))
    }

    fn numbered(&self, id: Option<&str>) -> Result<&Image, Reply> {
        let id = id.ok_or_else(|| bad("id: give an image's number".into()))?;
        id.parse::<usize>()
            .ok()
            .and_then(|i| self.images.0.get(i))
            .ok_or_else(|| {
                let count = self.images.0.len();
                Reply::error(
                    404,
                    &format!(
                        "id: no image \"{}\" (there are {count}, from 0)",
                        query::shorten(id)
                    ),
                )
            })
    }

    /// Image `id`, or the newest render for `render`.
    fn film(&self, id: Option<&str>) -> Result<Arc<Film>, Reply> {
        match id {
            Some("render") => {
                let latest = self
                    .renders
                    .newest()
                    .ok_or_else(|| bad("no render yet".into()))?;
                Ok(latest.film)
            }
            id => Ok(self.numbered(id)?.film.clone()),
        }
    }
}

/// No progress shown while grading.
struct Quiet;

impl glint_grade::class::Progress for Quiet {
    fn rendering(&self, _: &str) {}
    fn graded(&self, _: usize, _: usize) {}
}

fn failed() -> Reply {
    Reply::error(500, "an earlier request failed")
}

fn pretty(value: &Value) -> String {
    serde_json::to_string_pretty(value).unwrap_or_default() + "\n"
}

fn refuse_flags(flags: &Flags) -> Result<(), Reply> {
    match flags.first() {
        None => Ok(()),
        Some((name, _)) => Err(bad(format!("{name}: not a parameter of this request"))),
    }
}

/// The settings a submission states, by `glint grade`'s flag names.
fn stated(flags: &Flags) -> Result<glint_grade::StatedSettings, Reply> {
    let mut stated = glint_grade::StatedSettings::default();
    let count = |name: &str, text: &str| {
        text.parse::<u32>().map_err(|_| {
            bad(format!(
                "{name}: \"{}\" is not a whole number",
                query::shorten(text)
            ))
        })
    };
    let pattern = |name: &str, text: &str| {
        SamplePattern::from_name(text).ok_or_else(|| {
            let names = SamplePattern::NAMES.join(", ");
            bad(format!(
                "{name}: unknown sampler \"{}\"; expected one of {names}",
                query::shorten(text)
            ))
        })
    };
    for (name, value) in flags {
        match name.as_str() {
            "spp" => stated.spp = Some(count(name, value)?),
            "light-samples" => stated.light_samples = Some(count(name, value)?),
            "sampler" => stated.pixel_pattern = Some(pattern(name, value)?),
            "light-sampler" => stated.light_pattern = Some(pattern(name, value)?),
            other => {
                return Err(bad(format!(
                    "{other}: grading takes spp, sampler, light-samples and light-sampler"
                )))
            }
        }
    }
    stated
        .validate()
        .map_err(|e| bad(format!("the stated settings: {e}")))?;
    Ok(stated)
}

/// The scene's description for the page: its size, settings, lights (area
/// lights with their corner and edges, for drawing samples on them) and
/// objects' names.
fn scene_json(path: &Path, scene: &glint_scene::SceneDescription) -> Value {
    use glint_lighting::Light;
    let size = scene.scene.camera.resolution();
    let s = &scene.settings;
    let lights: Vec<Value> = (scene.scene.lights.iter().enumerate())
        .map(|(i, light)| match light {
            Light::Area(area) => {
                let (e1, e2) = area.surface().edges();
                json!({"light": i, "kind": "area", "origin": area.surface().origin().to_array(),
                       "edges": [e1.to_array(), e2.to_array()]})
            }
            Light::Point(point) => {
                json!({"light": i, "kind": "point", "position": point.position.to_array()})
            }
            Light::Sphere(_) => json!({"light": i, "kind": "sphere"}),
        })
        .collect();
    json!({
        "path": path.display().to_string(),
        "resolution": [size.x, size.y],
        "settings": {
            "spp": s.spp,
            "light-samples": s.light_samples,
            "sampler": s.pixel_pattern.name(),
            "light-sampler": s.light_pattern.name(),
            "max-depth": s.max_depth,
            "seed": s.seed,
        },
        "lights": lights,
        "objects": scene.object_names,
    })
}

/// An AOV's render as `glint render --aov` writes it: its PNG false
/// coloured, its floats as they are.
fn as_written(film: Arc<Film>, flags: &Flags, format: Option<&str>) -> Arc<Film> {
    let aov = get(flags, "aov").and_then(glint_integrator::Aov::from_name);
    match (aov, format) {
        (Some(aov), Some("png")) => Arc::new(aov.false_color(&film)),
        _ => film,
    }
}

/// `film` as the request asks: raw `f32` (its size in headers), PNG or EXR.
fn encoded(film: &Film, format: Option<&str>) -> Answer {
    let size = film.resolution();
    let with_size = |reply: Reply| {
        reply
            .with_header("X-Width", size.x.to_string())
            .with_header("X-Height", size.y.to_string())
    };
    let (content_type, format) = match format {
        None | Some("f32") => {
            let body = film
                .pixels()
                .iter()
                .flat_map(|p| p.to_array())
                .flat_map(f32::to_le_bytes)
                .collect();
            return Ok(with_size(Reply::bytes("application/octet-stream", body)));
        }
        Some("png") => ("image/png", ImageFormat::Png),
        Some("exr") => ("image/x-exr", ImageFormat::Exr),
        Some(other) => {
            let other = query::shorten(other);
            return Err(bad(format!("as: \"{other}\"; expected f32, png or exr")));
        }
    };
    let bytes = film
        .to_bytes(format)
        .map_err(|e| Reply::error(500, &e.to_string()))?;
    Ok(with_size(Reply::bytes(content_type, bytes)))
}
