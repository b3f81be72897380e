//! A scene as a tracer with one classic mistake renders it (`glint render
//! --mistake`, `glint explain --mistake`): the scene file edited as `glint
//! grade` renders the mistake, then the flags' settings; or the stage the
//! one-ray integrator swaps; or what the file stores changed.

use crate::render::SceneArgs;
use crate::Failure;
use glint_grade::mistakes::{self, FilmMistake, How, Mistake};
use glint_integrator::mistakes::Mistakes;
use glint_scene::SceneDescription;
use std::path::Path;

/// The scene of a mistaken render, and what else the mistake changes.
pub(crate) struct Mistaken {
    pub(crate) description: SceneDescription,
    /// The stages the one-ray integrator swaps (none for a scene edit).
    pub(crate) swaps: Mistakes,
    /// What the file stores changed, after rendering.
    pub(crate) film: Option<FilmMistake>,
    /// For a mistake in how light reaches surfaces: the correct scene,
    /// whose render the pixels that see a light are taken from (the
    /// student's light looks right).
    pub(crate) lights_from: Option<SceneDescription>,
}

/// The catalogue's mistake `id`, or the error that names the list.
pub(crate) fn find(id: &str) -> Result<&'static Mistake, Failure> {
    mistakes::find(id).ok_or_else(|| {
        Failure::Input(format!(
            "--mistake: no mistake is called \"{}\" (glint grade --mistakes lists them)",
            glint_grade::text::shorten(id)
        ))
    })
}

/// The scene of `args` with mistake `mistake` (`id`): edited when it is a
/// scene edit, else as it is, with the swap or the film mistake to apply.
pub(crate) fn load(scene: &SceneArgs, mistake: &Mistake) -> Result<Mistaken, Failure> {
    let id = mistake.id;
    let (swaps, film) = match mistake.how {
        How::Scene(edit) | How::Lights(edit) => {
            let (description, correct) = edited(scene, id, edit)?;
            let lights_from = matches!(mistake.how, How::Lights(_)).then_some(correct);
            return Ok(Mistaken {
                description,
                swaps: Mistakes::NONE,
                film: None,
                lights_from,
            });
        }
        How::Integrator(swap) => (Mistakes::NONE.with(swap), None),
        How::Film(film) => (Mistakes::NONE, Some(film)),
        How::NoiseOnly => {
            return Err(Failure::Input(format!(
                "--mistake {id}: it changes only the noise, which Glint does not render"
            )))
        }
    };
    let description = scene.load()?;
    if let Some(swap) = swaps.iter().find(|s| !s.applies_to(&description.scene)) {
        return Err(Failure::Input(format!(
            "--mistake {id}: it changes nothing in {} ({swap:?} needs what the scene does not have, or Phong shading)",
            scene.scene.display()
        )));
    }
    Ok(Mistaken {
        description,
        swaps,
        film,
        lights_from: None,
    })
}

/// `film`, the render of `mistaken` with a mistake in the lights, with the
/// pixels that see a light (and their neighbours) taken from the correct
/// scene's render with the same `settings`, as `glint grade` keeps them.
pub(crate) fn with_correct_lights(
    mut film: glint_camera::Film,
    (correct, mistaken): (&glint_integrator::Scene, &glint_integrator::Scene),
    settings: &glint_integrator::RenderSettings,
) -> Result<glint_camera::Film, Failure> {
    let internal = |e: String| Failure::Other(format!("the correct lights: {e}"));
    let mask = mistakes::light_pixels(correct, mistaken).map_err(|e| internal(e.to_string()))?;
    let right = glint_integrator::render(correct, settings, &|_, _| {})
        .map_err(|e| internal(e.to_string()))?
        .film;
    for ((pixel, &keep), &right) in film.pixels_mut().iter_mut().zip(&mask).zip(right.pixels()) {
        if keep {
            *pixel = right;
        }
    }
    Ok(film)
}

/// The scene file of `args` with the edit of mistake `id` applied, then the
/// flags' settings; and the scene as it is.
fn edited(
    args: &SceneArgs,
    id: &str,
    edit: mistakes::edit::Edit,
) -> Result<(SceneDescription, SceneDescription), Failure> {
    let correct = args.load()?;
    let path = &args.scene;
    let text = glint_scene::read_text(path, glint_scene::MAX_SCENE_BYTES, "a scene file")
        .map_err(Failure::Input)?;
    let size = correct.scene.camera.resolution();
    let context = mistakes::edit::Context {
        aspect: f64::from(size.x) / f64::from(size.y),
        light_samples: Some(correct.settings.light_samples),
    };
    let edited = mistakes::edited_text(&text, &[edit], &context)
        .map_err(|e| Failure::Input(format!("{}: {e}", path.display())))?
        .ok_or_else(|| {
            Failure::Input(format!(
                "--mistake {id}: it changes nothing in {} at these settings",
                path.display()
            ))
        })?;
    let name = format!("{} with {id}", path.display());
    let base = path.parent().unwrap_or(Path::new(""));
    let mut description = glint_scene::parse_in(&edited, &name, base)
        .map_err(|e| Failure::Other(format!("{id}: the edited scene: {e}")))?;
    args.overrides()
        .apply(&mut description)
        .map_err(|e| Failure::Input(e.to_string()))?;
    Ok((description, correct))
}
