//! `glint explain`: every stage's numbers for one pixel.

use crate::render::SceneArgs;
use crate::{named, Failure};
use clap::Args;
use glint_explain::Stage;
use glint_integrator::trace::SampleSelection;
use glint_integrator::ExplainError;
use std::io::Write;

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
    #[arg(long, value_name = "STAGE", value_parser = named(&Stage::NAMES, Stage::from_name))]
    stage: Option<Stage>,

    /// Print a JSON document instead of text (its schema:
    /// docs/checking-your-ray-tracer.md)
    #[arg(long)]
    json: bool,
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
    let description = args.scene.load()?;
    let selection = match args.all_samples {
        true => SampleSelection::All,
        false => SampleSelection::One(args.sample),
    };
    let (x, y) = args.pixel;
    let explanation =
        glint_explain::explain(&description.scene, &description.settings, x, y, selection)
            .map_err(|e| match e {
                ExplainError::Outside { .. } => Failure::Input(format!("--pixel: {e}")),
                ExplainError::NoSuchSample { .. } => Failure::Input(format!("--sample: {e}")),
                ExplainError::Settings(e) => Failure::Input(format!("render settings: {e}")),
                ExplainError::Diverged { .. } => Failure::Other(e.to_string()),
            })?;
    let text = match args.json {
        true => {
            serde_json::to_string_pretty(&explanation.json(args.stage))
                .expect("JSON of numbers and strings")
                + "\n"
        }
        false => explanation.text(args.stage),
    };
    // A reader that stops early (`| head`) is not an error.
    let _ = std::io::stdout().write_all(text.as_bytes());
    Ok(())
}
