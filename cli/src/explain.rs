//! `glint explain`: every stage's numbers for one pixel.

use crate::render::SceneArgs;
use crate::Failure;
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::Args;
use glint_explain::against::{self, Node};
use glint_explain::{Explanation, MistakenPixel, Stage};
use glint_grade::mistakes::{FilmMistake, How, Mistake};
use glint_integrator::mistakes::{pixel_with_mistakes, Mistakes};
use glint_integrator::trace::SampleSelection;
use glint_integrator::ExplainError;
use std::path::{Path, PathBuf};

#[derive(Args)]
pub(crate) struct ExplainArgs {
    #[command(flatten)]
    scene: SceneArgs,

    /// The pixel to explain: column X and row Y from the top left, e.g. 256,300
    #[arg(long, value_name = "X,Y", value_parser = parse_pixel)]
    pixel: (u32, u32),

    /// The camera sample to follow (0 to spp − 1)
    #[arg(
        long,
        value_name = "K",
        default_value_t = 0,
        conflicts_with = "all_samples"
    )]
    sample: u64,

    /// Follow every camera sample of the pixel
    #[arg(long)]
    all_samples: bool,

    /// Print only this stage: camera, intersect, texture, light or film
    /// (intersection and lighting, the text's headings, are accepted too);
    /// with --against, compare only this stage
    #[arg(long, value_name = "STAGE", value_parser = stage_parser())]
    stage: Option<Stage>,

    /// Print a JSON document instead of text (its schema:
    /// docs/checking-your-ray-tracer.md); with --against, the comparison as JSON
    #[arg(long)]
    json: bool,

    /// Compare a student's document (schema glint-explain/1, any subset of its
    /// keys) with Glint's for this pixel and these flags, and report the first
    /// stage, in pipeline order, where they part: exit status 0 if every value
    /// given agrees within the tolerances, 1 if not (tolerances:
    /// docs/checking-your-ray-tracer.md)
    #[arg(long, value_name = "STUDENT.json")]
    against: Option<PathBuf>,

    /// Explain the pixel as a ray tracer with this classic mistake renders
    /// it (an id of glint grade --mistakes): a change to the scene is traced,
    /// so that the first number that goes wrong shows; for a stage the
    /// one-ray integrator swaps or a mistake in the file, the right stages
    /// are shown, then the pixel as the mistake writes it
    #[arg(long, value_name = "ID")]
    mistake: Option<String>,
}

/// `--stage`'s parser: the names in pipeline order, each with the heading
/// the text prints for it as an alias (`intersection`, `lighting`); help and
/// errors list the names.
fn stage_parser() -> impl TypedValueParser<Value = Stage> {
    let values = Stage::ALL.map(|stage| {
        let value = PossibleValue::new(stage.name());
        match stage.heading() {
            heading if heading != stage.name() => value.alias(heading),
            _ => value,
        }
    });
    PossibleValuesParser::new(values)
        .map(|name: String| Stage::from_name(&name).expect("clap accepted only listed names"))
}

fn parse_pixel(text: &str) -> Result<(u32, u32), String> {
    let (x, y) = text
        .split_once(',')
        .ok_or_else(|| format!("expected X,Y (two whole numbers), got \"{text}\""))?;
    let coordinate = |name: &str, s: &str| {
        s.trim()
            .parse::<u32>()
            .map_err(|_| format!("{name} is \"{}\", not a whole number from 0", s.trim()))
    };
    Ok((coordinate("X", x)?, coordinate("Y", y)?))
}

pub(crate) fn explain(args: &ExplainArgs) -> Result<(), Failure> {
    let (description, untraced) = match &args.mistake {
        Some(id) => with_mistake(args, id)?,
        None => (args.scene.load()?, None),
    };
    let Explained { text, parted } = explained(args, &description, untraced)?;
    print(&text);
    match parted {
        None => Ok(()),
        Some(message) => Err(Failure::Verdict(Some(message))),
    }
}

/// A mistake the trace does not follow, shown after the right stages: a
/// stage the one-ray integrator swaps, or what the file stores.
#[derive(Clone, Copy)]
pub(crate) struct Untraced {
    mistake: &'static Mistake,
    swaps: Mistakes,
    film: Option<FilmMistake>,
}

impl Untraced {
    /// The radiance the file holds at `(x, y)` for a tracer with the
    /// mistake: the swapped render's pixel; for a mistake in the file, the
    /// right `radiance` as the file reads back (rows flipped: another pixel's).
    fn radiance(
        &self,
        description: &glint_scene::SceneDescription,
        (x, y): (u32, u32),
        radiance: glam::Vec3,
    ) -> Result<glam::Vec3, Failure> {
        let (scene, settings) = (&description.scene, &description.settings);
        let from = match self.film {
            Some(FilmMistake::FlipVertical) => (x, scene.camera.resolution().y - 1 - y),
            Some(film) => return Ok(film.decoded_rgb(radiance)),
            None => (x, y),
        };
        pixel_with_mistakes(scene, settings, from, self.swaps)
            .map_err(|e| Failure::Input(format!("render settings: {e}")))
    }
}

/// The scene of `args` as a tracer with mistake `id` sees it: edited for a
/// mistake Glint renders as a change to the scene; as it is, with what the
/// trace does not follow, for the others.
fn with_mistake(
    args: &ExplainArgs,
    id: &str,
) -> Result<(glint_scene::SceneDescription, Option<Untraced>), Failure> {
    let mistake = crate::mistake::find(id)?;
    let untraced = matches!(mistake.how, How::Integrator(_) | How::Film(_));
    if untraced && args.against.is_some() {
        return Err(Failure::Input(format!(
            "--mistake {id}: the trace does not follow it (glint grade --mistakes says how it is rendered), so there is nothing to compare --against; without --against, the pixel with it is shown after the right stages"
        )));
    }
    let mistaken = crate::mistake::load(&args.scene, mistake)?;
    let untraced = untraced.then_some(Untraced {
        mistake,
        swaps: mistaken.swaps,
        film: mistaken.film,
    });
    Ok((mistaken.description, untraced))
}

/// What `glint explain` prints, and with `--against`, where the student's
/// document parts from Glint's, if it does.
pub(crate) struct Explained {
    pub(crate) text: String,
    pub(crate) parted: Option<String>,
}

/// `args` answered for the scene `description` (its file loaded with
/// `args`' settings): the text, JSON or comparison the command prints.
pub(crate) fn explained(
    args: &ExplainArgs,
    description: &glint_scene::SceneDescription,
    untraced: Option<Untraced>,
) -> Result<Explained, Failure> {
    let selection = match args.all_samples {
        true => SampleSelection::All,
        false => SampleSelection::One(args.sample),
    };
    let (x, y) = args.pixel;
    let mut explanation =
        glint_explain::explain(&description.scene, &description.settings, x, y, selection)
            .map_err(|e| match e {
                ExplainError::Outside { .. } => Failure::Input(format!("--pixel: {e}")),
                ExplainError::NoSuchSample { .. } => Failure::Input(format!("--sample: {e}")),
                ExplainError::Settings(e) => Failure::Input(format!("render settings: {e}")),
                ExplainError::Diverged { .. } => Failure::Other(e.to_string()),
            })?;
    if let Some(path) = &args.against {
        return compare(&explanation, path, args);
    }
    if let Some(untraced) = untraced {
        let radiance = untraced.radiance(description, (x, y), explanation.radiance)?;
        let mistake = untraced.mistake;
        let shown = MistakenPixel {
            id: mistake.id,
            stage: mistake.stage.name(),
            description: mistake.description,
        };
        explanation.with_mistake(&shown, radiance);
    }
    let text = match args.json {
        true => {
            serde_json::to_string_pretty(&explanation.json(args.stage))
                .expect("JSON of numbers and strings")
                + "\n"
        }
        false => explanation.text(args.stage),
    };
    Ok(Explained { text, parted: None })
}

impl ExplainArgs {
    /// The scene and the settings the flags replace.
    pub(crate) fn scene(&self) -> &SceneArgs {
        &self.scene
    }
}

/// Prints `text` on stdout; a reader that stops early (`| head`) is not an
/// error.
fn print(text: &str) {
    crate::output::say(text);
}

/// `--against`: the student's document at `path` against Glint's: the
/// report, and where they part.
fn compare(
    explanation: &Explanation,
    path: &Path,
    args: &ExplainArgs,
) -> Result<Explained, Failure> {
    let name = path.display();
    let text = glint_scene::read_text(path, glint_scene::MAX_DOCUMENT_BYTES, "a document")
        .map_err(|e| Failure::Input(format!("{name}: cannot read the document: {e}")))?;
    let student = Node::parse(&text)
        .map_err(|e| Failure::Input(format!("{name}{}", against::located(&e))))?;
    let comparison = against::compare(&student, &explanation.json(None), args.stage)
        .map_err(|e| Failure::Input(format!("{name}: {e}")))?;
    let text = match args.json {
        true => {
            serde_json::to_string_pretty(&comparison.json()).expect("JSON of numbers and strings")
                + "\n"
        }
        false => comparison.text(&name.to_string()),
    };
    let parted = comparison.first().map(|d| {
        format!(
            "{name} parts from Glint in the {} stage, at {}",
            d.stage.heading(),
            d.path
        )
    });
    Ok(Explained { text, parted })
}
