//! `glint`: the command-line front end. It only wires the stage crates together:
//! load a scene (scene crate), apply command-line overrides, render (integrator
//! crate) and write the film (camera crate).
//!
//! Exit status: 0 on success, 2 for bad input (usage, scene file, settings,
//! output path), 1 for anything else. Errors are one line on stderr, prefixed
//! `glint: error: `.
//!
//! # Entry points
//! The command line is the clap parser [`Cli`] with one subcommand, `render`
//! ([`RenderArgs`]). [`main`] maps every failure to its exit status; [`render`] runs
//! the pipeline: [`output_path`] checks the output before any work,
//! [`glint_scene::load`] reads the scene, [`apply_overrides`] applies the flags,
//! [`glint_integrator::render`] renders, and [`glint_camera::Film::save`] writes.

use clap::builder::TypedValueParser;
use clap::{Args, Parser, Subcommand, ValueEnum};
use glam::UVec2;
use glint_camera::ImageFormat;
use glint_integrator::{Aov, RenderSettings, SamplePattern};
use glint_scene::SceneDescription;
use glint_texture::TextureFilter;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "glint",
    version,
    about = "Glint: a ray tracer for direct lighting and texturing",
    long_about = "Glint: a ray tracer for direct lighting and texturing.\n\n\
                  Exit status: 0 on success, 2 for bad input (usage, scene or asset errors), 1 otherwise."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene file to an image
    Render(RenderArgs),
}

#[derive(Args)]
struct RenderArgs {
    /// The scene file (TOML; every key is described in docs/scene-format.md)
    scene: PathBuf,

    /// Output image; the extension picks the format: .png (8-bit sRGB),
    /// .exr or .pfm (linear 32-bit float). Default: SCENE-NAME.png in the
    /// current directory. Written atomically: a failed run leaves any existing file untouched.
    #[arg(short, long, value_name = "OUT")]
    output: Option<PathBuf>,

    /// Camera samples per pixel (overrides render.spp)
    #[arg(long, value_name = "N")]
    spp: Option<u32>,

    /// Samples per area light per camera sample (overrides render.light_samples)
    #[arg(long, value_name = "N")]
    light_samples: Option<u32>,

    /// Pixel sample pattern (overrides render.pixel_sampler); grid needs a square spp
    #[arg(long, value_name = "PATTERN")]
    sampler: Option<Pattern>,

    /// Light sample pattern (overrides render.light_sampler); grid needs a square count
    #[arg(long, value_name = "PATTERN")]
    light_sampler: Option<Pattern>,

    /// Worker threads [default: one per core]; the image is identical for any count
    #[arg(long, value_name = "N")]
    threads: Option<usize>,

    /// Most mirror reflections followed per camera ray (overrides render.max_depth)
    #[arg(long, value_name = "N")]
    max_depth: Option<u32>,

    /// Environment directions sampled per shading point (overrides
    /// render.environment_samples; 0: the environment lights nothing)
    #[arg(long, value_name = "N")]
    environment_samples: Option<u32>,

    /// Seed of every random stream (overrides render.seed)
    #[arg(long, value_name = "N")]
    seed: Option<u64>,

    /// Film size in pixels, e.g. 640x480 (overrides render.resolution)
    #[arg(long, value_name = "WxH", value_parser = parse_resolution)]
    resolution: Option<UVec2>,

    /// Filter for every image texture (overrides each texture's `filter`):
    /// nearest or bilinear (full resolution), trilinear (the two MIP levels around
    /// the footprint), ewa (elliptically weighted average, anisotropic)
    #[arg(long, value_name = "FILTER", value_parser = named(&TextureFilter::NAMES, TextureFilter::from_name))]
    texture_filter: Option<TextureFilter>,

    /// Write this buffer instead of the shaded image: uv (surface coordinates),
    /// mip-level (the level the diffuse texture is read at), normal, depth
    /// (distance from the camera), albedo (filtered diffuse color),
    /// reflection-depth (mirror reflections taken). Raw values in .exr/.pfm, false
    /// color in .png (normals as 0.5·n + 0.5, uv as its fractional part, depth as
    /// gray from near to far, MIP level and reflection depth as a blue-green-red ramp)
    #[arg(long, value_name = "BUFFER", value_parser = named(&Aov::NAMES, Aov::from_name))]
    aov: Option<Aov>,
}

/// A clap parser for one of the library's named values: the names are its own
/// list (so help and errors show them), the value its own `from_name`.
fn named<T: Clone + Send + Sync + 'static>(
    names: &'static [&'static str],
    from_name: fn(&str) -> Option<T>,
) -> impl TypedValueParser<Value = T> {
    clap::builder::PossibleValuesParser::new(names)
        .map(move |name: String| from_name(&name).expect("clap accepted only listed names"))
}

#[derive(Clone, Copy, ValueEnum)]
enum Pattern {
    /// The course's uniform grid (needs a perfect-square count)
    Grid,
    /// Independent uniform samples
    Random,
    /// Jittered grid (Latin hypercube when the count is not a square)
    Stratified,
}

impl From<Pattern> for SamplePattern {
    fn from(p: Pattern) -> Self {
        match p {
            Pattern::Grid => SamplePattern::Grid,
            Pattern::Random => SamplePattern::Random,
            Pattern::Stratified => SamplePattern::Stratified,
        }
    }
}

fn parse_resolution(text: &str) -> Result<UVec2, String> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, e.g. 640x480, got \"{text}\""))?;
    let side = |s: &str| {
        s.trim()
            .parse::<u32>()
            .map_err(|_| format!("expected WIDTHxHEIGHT with whole numbers, got \"{text}\""))
    };
    glint_scene::parse_resolution_parts(side(w)?, side(h)?)
}

/// A failure and the exit status it maps to.
enum Failure {
    /// Bad input: usage, scene file, settings, output path. Exit status 2.
    Input(String),
    /// Anything else (I/O while writing, thread start-up). Exit status 1.
    Other(String),
    /// A bug; the panic hook has already printed it. Exit status 1.
    Panicked,
}

fn main() -> ExitCode {
    // A panic is a bug, never a reaction to input: report it on one line and
    // exit with status 1 (caught below) instead of Rust's 101 and a backtrace hint.
    std::panic::set_hook(Box::new(|info| {
        let message = info.to_string().replace('\n', " ");
        eprintln!("glint: internal error (please report): {message}");
    }));
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return usage_error(e),
    };
    let result = std::panic::catch_unwind(|| match &cli.command {
        Command::Render(args) => render(args),
    })
    .unwrap_or(Err(Failure::Panicked));
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Input(message)) => {
            eprintln!("glint: error: {message}");
            ExitCode::from(2)
        }
        Err(Failure::Other(message)) => {
            eprintln!("glint: error: {message}");
            ExitCode::from(1)
        }
        Err(Failure::Panicked) => ExitCode::from(1),
    }
}

/// Help and version go to stdout in full; a usage error is one line on stderr
/// (clap's first line, which names the problem) with exit status 2.
fn usage_error(e: clap::Error) -> ExitCode {
    if !e.use_stderr() {
        let _ = e.print();
        return ExitCode::SUCCESS;
    }
    let rendered = e.render().to_string();
    let first = rendered.lines().next().unwrap_or("invalid usage");
    let problem = first.strip_prefix("error: ").unwrap_or(first);
    eprintln!("glint: error: {problem} (see glint --help)");
    ExitCode::from(2)
}

fn render(args: &RenderArgs) -> Result<(), Failure> {
    let start = std::time::Instant::now();
    let output = output_path(args)?;
    let SceneDescription {
        mut scene,
        mut settings,
        ..
    } = glint_scene::load(&args.scene).map_err(|e| Failure::Input(e.to_string()))?;
    apply_overrides(args, &mut settings);
    if let Some(filter) = args.texture_filter {
        scene.override_texture_filter(filter);
    }
    if let Some(resolution) = args.resolution {
        scene.camera = scene
            .camera
            .with_resolution(resolution)
            .map_err(|e| Failure::Input(format!("--resolution: {e}")))?;
    }
    settings
        .validate()
        .map_err(|e| Failure::Input(format!("render settings: {e}")))?;

    let progress = progress_bar();
    let on_tile = |done: usize, total: usize| {
        if let Some(bar) = &progress {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        }
    };
    let rendered = glint_integrator::render(&scene, &settings, &on_tile)
        .map_err(|e| Failure::Other(e.to_string()))?;
    if let Some(bar) = progress {
        bar.finish_and_clear();
    }
    let film = match settings.aov {
        Some(aov) if ImageFormat::from_path(&output).ok() == Some(ImageFormat::Png) => {
            aov.false_color(&rendered.film)
        }
        _ => rendered.film,
    };
    film.save(&output)
        .map_err(|e| Failure::Other(e.to_string()))?;

    let stats = rendered.stats;
    let resolution = film.resolution();
    let environment_samples = match scene.environment {
        Some(_) => format!(", {} environment samples", settings.environment_samples),
        None => String::new(),
    };
    println!(
        "wrote {}: {}x{}, {} spp, {} light samples{environment_samples}, {:.2} s wall ({:.2} s rendering), {} rays ({:.2} M rays/s)",
        output.display(),
        resolution.x,
        resolution.y,
        settings.spp,
        settings.light_samples,
        start.elapsed().as_secs_f64(),
        stats.elapsed.as_secs_f64(),
        stats.rays(),
        stats.rays_per_second() / 1e6,
    );
    Ok(())
}

/// The output path, checked before any rendering: a known extension, an existing
/// directory, and one we may create files in (probed with a temporary file that
/// is removed at once, so an interrupted render leaves nothing behind).
fn output_path(args: &RenderArgs) -> Result<PathBuf, Failure> {
    let path = match &args.output {
        Some(p) => p.clone(),
        None => {
            let stem = args.scene.file_stem().unwrap_or("render".as_ref());
            Path::new(stem).with_extension("png")
        }
    };
    ImageFormat::from_path(&path).map_err(|e| Failure::Input(e.to_string()))?;
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty());
    if let Some(dir) = dir {
        if !dir.is_dir() {
            return Err(Failure::Input(format!(
                "{}: the output directory {} does not exist",
                path.display(),
                dir.display()
            )));
        }
    }
    if path.is_dir() {
        return Err(Failure::Input(format!(
            "{}: is a directory, expected an image file name",
            path.display()
        )));
    }
    tempfile::Builder::new()
        .prefix(".glint-probe-")
        .tempfile_in(dir.unwrap_or(Path::new(".")))
        .map_err(|e| {
            Failure::Input(format!(
                "{}: cannot write to the output directory: {e}",
                path.display()
            ))
        })?;
    Ok(path)
}

fn apply_overrides(args: &RenderArgs, settings: &mut RenderSettings) {
    if let Some(spp) = args.spp {
        settings.spp = spp;
    }
    if let Some(n) = args.light_samples {
        settings.light_samples = n;
    }
    if let Some(p) = args.sampler {
        settings.pixel_pattern = p.into();
    }
    if let Some(p) = args.light_sampler {
        settings.light_pattern = p.into();
    }
    if let Some(seed) = args.seed {
        settings.seed = seed;
    }
    if let Some(depth) = args.max_depth {
        settings.max_depth = depth;
    }
    if let Some(n) = args.environment_samples {
        settings.environment_samples = n;
    }
    if args.threads.is_some() {
        settings.threads = args.threads;
    }
    if args.aov.is_some() {
        settings.aov = args.aov;
    }
}

/// A progress bar over tiles on stderr, only when stderr is a terminal.
fn progress_bar() -> Option<ProgressBar> {
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {wide_bar} {pos}/{len} tiles (eta {eta})",
        )
        .expect("valid template"),
    );
    Some(bar)
}
