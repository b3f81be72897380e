//! `glint bench`: run time against error (the work is glint-bench's; this file
//! turns flags into its configuration and its progress into a bar).

use crate::{named, progress_bar, Failure};
use clap::Args;
use glam::UVec2;
use glint_bench::budget::{parse_counts, parse_durations, sample_ladder, Ladder};
use glint_bench::strategy::{
    combine, parse_environment_samplings, parse_light_strategies, parse_samplers,
    parse_texture_filters, Choices,
};
use glint_bench::{BenchConfig, BenchError, Progress, ReferenceChoice, RegionChoice};
use glint_metrics::Region;
use glint_texture::TextureFilter;
use std::path::{Path, PathBuf};

#[derive(Args)]
pub(crate) struct BenchArgs {
    /// The scene file (TOML; every key is described in docs/scene-format.md)
    scene: PathBuf,

    /// Directory for the results (results.csv, results.json, relmse-vs-time.png
    /// and .svg, heat maps) and the cached reference; created if missing
    /// [default: SCENE-NAME-bench]
    #[arg(short, long, value_name = "DIR")]
    output: Option<PathBuf>,

    /// Sampler strategies to compare, comma-separated: a pattern (grid, random,
    /// stratified, sobol) for every sample, pixel, light and environment alike
    /// (unlike render's --sampler, which sets only the pixel's), or PIXEL/LIGHT
    /// (the environment following the light), or PIXEL/LIGHT/ENVIRONMENT
    #[arg(
        long,
        value_name = "LIST",
        default_value = "random,stratified,sobol,grid"
    )]
    samplers: String,

    /// Texture filters to compare (each with every sampler), comma-separated:
    /// nearest, bilinear, trilinear, ewa, or analytic (checker images evaluated as
    /// the procedural checkerboard, box-filtered exactly; other images ewa)
    /// [default: each texture's own]
    #[arg(long, value_name = "LIST")]
    texture_filters: Option<String>,

    /// Physical shading: light strategies to compare (each with every sampler
    /// and filter), comma-separated: auto, solid-angle or area, each optionally
    /// with +mis (multiple importance sampling of glossy lobes), e.g.
    /// solid-angle+mis,solid-angle,area+mis,area [default: the scene's]
    #[arg(long, value_name = "LIST")]
    light_strategies: Option<String>,

    /// Environment samplings to compare (each with every other choice),
    /// comma-separated: luminance (the map's luminance) or cosine (the cosine
    /// about the shading normal) [default: the scene's]
    #[arg(long, value_name = "LIST")]
    environment_samplings: Option<String>,

    /// Camera samples per pixel at each step of the ladder, comma-separated
    #[arg(long, value_name = "LIST", default_value = "1,4,16,64,256")]
    spp: String,

    /// Samples per area light per camera sample: one value for every step, or
    /// one per step
    #[arg(long, value_name = "LIST", default_value = "1")]
    light_samples: String,

    /// Environment directions per shading point: one value, or one per step
    /// [default: 1, or 0 when the scene has no environment or it lights nothing]
    #[arg(long, value_name = "LIST")]
    environment_samples: Option<String>,

    /// Time budgets instead of sample counts, e.g. 0.1s,0.3s,1s,3s: each strategy
    /// renders with the spp that takes about that long here
    #[arg(long, value_name = "LIST", conflicts_with = "spp")]
    time: Option<String>,

    /// Runs per budget; times are their median (images are identical: renders are
    /// deterministic)
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=100))]
    repeat: u32,

    /// Measure errors over part of the image: x0,y0,x1,y1 in pixels (x1, y1
    /// excluded), or the name of a region in the scene's `[regions]` table
    #[arg(long, value_name = "REGION")]
    region: Option<String>,

    /// Reference image (EXR, PFM, PNG or JPEG) of the bench's resolution, e.g. from
    /// another renderer, instead of rendering one
    #[arg(long, value_name = "FILE", conflicts_with_all = ["reference_spp", "reference_texture_filter"])]
    reference: Option<PathBuf>,

    /// Samples per pixel of the rendered reference [default: enough for its noise
    /// to be 10x below the smallest error measured]
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(2..=1_048_576))]
    reference_spp: Option<u32>,

    /// Texture filter of the reference [default: bilinear when --texture-filters
    /// is given (full resolution, supersampled), else each texture's own]
    #[arg(long, value_name = "FILTER", value_parser = named(&TextureFilter::NAMES, TextureFilter::from_name))]
    reference_texture_filter: Option<TextureFilter>,

    /// Where the rendered reference samples each pixel: over its area (the
    /// pixel's box filter), or at its centre only, its samples then going to the
    /// lights and the environment; `centre` measures light sampling alone, for
    /// strategies that also sample pixel centres (--samplers grid/PATTERN --spp 1
    /// --light-samples LIST)
    #[arg(long, value_name = "WHERE", value_enum, default_value_t = ReferencePixel::Area, conflicts_with = "reference")]
    reference_pixel: ReferencePixel,

    /// The ladder step (1 = the first) whose error heat maps are drawn
    /// [default: the last]
    #[arg(long, value_name = "STEP", value_parser = clap::value_parser!(u32).range(1..=1000))]
    heatmap_step: Option<u32>,

    /// Film size in pixels, e.g. 256x256 (overrides render.resolution)
    #[arg(long, value_name = "WxH", value_parser = crate::render::parse_resolution)]
    resolution: Option<UVec2>,

    /// Seed of every random stream (overrides render.seed)
    #[arg(long, value_name = "N")]
    seed: Option<u64>,

    /// Worker threads [default: one per core]
    #[arg(long, value_name = "N")]
    threads: Option<usize>,

    /// Most mirror reflections followed per camera ray (overrides render.max_depth)
    #[arg(long, value_name = "N")]
    max_depth: Option<u32>,

    /// Render nothing: put together the results of benches of this scene run
    /// apart (each TASK-DIR holding the results.json of a `glint bench` with
    /// some of the strategies and budgets, against one reference, as the
    /// tasks of `glint farm ... bench` write them): one table, CSV, JSON and
    /// plot over all their rows, with the fits and speed-ups (no heat maps:
    /// each task's are on its own scale)
    #[arg(long, value_name = "TASK-DIR", num_args = 1.., conflicts_with_all = ["time", "reference", "reference_spp", "texture_filters", "light_strategies", "environment_samplings", "region", "resolution", "heatmap_step"])]
    merge: Vec<PathBuf>,
}

/// Where the rendered reference samples each pixel.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum ReferencePixel {
    /// Over the pixel's area, as the renders do
    Area,
    /// At the pixel's centre only
    Centre,
}

pub(crate) fn bench(args: &BenchArgs) -> Result<(), Failure> {
    if !args.merge.is_empty() {
        return merge(args);
    }
    let config = config(args)?;
    check_output_dir(&config.output_dir)?;
    // A bar over the current render's tiles, with the render's name.
    let bar = progress_bar("{spinner} [{elapsed_precise}] {wide_bar} {msg}");
    let on_progress = |p: Progress| {
        let Some(bar) = &bar else { return };
        match p {
            Progress::Render {
                number,
                planned,
                what,
            } => {
                bar.set_message(format!("render {number}/{planned}: {what}"));
                bar.set_position(0);
            }
            Progress::Tiles { done, total } => {
                bar.set_length(total as u64);
                bar.set_position(done as u64);
            }
            Progress::Step(what) => bar.set_message(what.to_owned()),
        }
    };
    let result = glint_bench::run(&config, &on_progress);
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    let bench = result.map_err(|e| match e {
        BenchError::Input(m) => Failure::Input(m),
        BenchError::Other(m) => Failure::Other(m),
    })?;
    std::fs::create_dir_all(&config.output_dir)
        .map_err(|e| Failure::Other(format!("{}: {e}", config.output_dir.display())))?;
    let written = bench.write(&config.output_dir).map_err(Failure::Other)?;
    crate::output::say(&bench.report.table());
    crate::output::say(&format!(
        "wrote {} files to {}\n",
        written.len(),
        config.output_dir.display()
    ));
    Ok(())
}

/// A bench split into tasks for `glint farm ... bench`: the `--samplers`
/// entries, and per ladder step the budget flags a task takes for it.
pub(crate) struct SweepSplit {
    pub(crate) samplers: Vec<String>,
    pub(crate) steps: Vec<Vec<String>>,
}

/// Checks `args` as a bench would (everything but the scene's assets and
/// the reference's size, which each task checks) and splits it into one
/// task per strategy and budget. Every task must measure against one
/// reference: `--reference FILE` is required.
pub(crate) fn sweep_split(args: &BenchArgs) -> Result<SweepSplit, Failure> {
    config(args)?;
    if args.reference.is_none() {
        return Err(Failure::Input(
            "glint farm bench: give --reference FILE (after --), one reference for every task; \
             render one with glint farm ... render at many samples and another --seed"
                .into(),
        ));
    }
    let samplers: Vec<String> = args
        .samplers
        .split(',')
        .map(|s| s.trim().to_owned())
        .collect();
    let light: Vec<&str> = args.light_samples.split(',').map(str::trim).collect();
    let environment: Option<Vec<&str>> = args
        .environment_samples
        .as_ref()
        .map(|list| list.split(',').map(str::trim).collect());
    let (flag, budgets): (&str, Vec<&str>) = match &args.time {
        Some(list) => ("--time", list.split(',').map(str::trim).collect()),
        None => ("--spp", args.spp.split(',').map(str::trim).collect()),
    };
    let per_step =
        |values: &[&str], i: usize| values[if values.len() == 1 { 0 } else { i }].to_owned();
    let steps = (0..budgets.len())
        .map(|i| {
            let mut step = vec![flag.to_owned(), budgets[i].to_owned()];
            step.extend(["--light-samples".to_owned(), per_step(&light, i)]);
            if let Some(environment) = &environment {
                step.extend(["--environment-samples".to_owned(), per_step(environment, i)]);
            }
            step
        })
        .collect();
    Ok(SweepSplit { samplers, steps })
}

/// `--merge`: the tasks' results, read and put together, written as a
/// bench's.
fn merge(args: &BenchArgs) -> Result<(), Failure> {
    let dir = output_dir(args);
    check_output_dir(&dir)?;
    let scene = glint_bench::scene_name(&args.scene);
    let mut reports = Vec::new();
    let mut names = Vec::new();
    for task in &args.merge {
        let path = task.join("results.json");
        let text = std::fs::read_to_string(&path)
            .map_err(|e| Failure::Input(format!("--merge: {}: {e}", path.display())))?;
        let report: glint_bench::Report = serde_json::from_str(&text).map_err(|e| {
            Failure::Input(format!(
                "--merge: {}: not a glint bench results.json ({e})",
                path.display()
            ))
        })?;
        if report.scene_name != scene {
            return Err(Failure::Input(format!(
                "--merge: {}: results of scene \"{}\", not {}",
                path.display(),
                report.scene_name,
                args.scene.display()
            )));
        }
        reports.push(report);
        names.push(task.display().to_string());
    }
    let bench =
        glint_bench::merge(reports, &names).map_err(|e| Failure::Input(format!("--merge: {e}")))?;
    std::fs::create_dir_all(&dir).map_err(|e| Failure::Other(format!("{}: {e}", dir.display())))?;
    let written = bench.write(&dir).map_err(Failure::Other)?;
    crate::output::say(&bench.report.table());
    crate::output::say(&format!(
        "wrote {} files to {} from {} tasks\n",
        written.len(),
        dir.display(),
        args.merge.len()
    ));
    Ok(())
}

/// Where the results go: `-o`, or SCENE-NAME-bench.
fn output_dir(args: &BenchArgs) -> PathBuf {
    args.output
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{}-bench", glint_bench::scene_name(&args.scene))))
}

/// The output directory, before any work: an existing directory we may write
/// in, or one we may create ([`glint_camera::check_output_folder`]). It is
/// created only when there is something to put in it.
fn check_output_dir(dir: &Path) -> Result<(), Failure> {
    glint_camera::check_output_folder(dir)
        .map_err(|e| Failure::Input(format!("{}: the results directory {e}", dir.display())))
}

fn config(args: &BenchArgs) -> Result<BenchConfig, Failure> {
    let input = Failure::Input;
    let samplers = parse_samplers(&args.samplers).map_err(|e| input(format!("--samplers: {e}")))?;
    let filters = match &args.texture_filters {
        Some(list) => {
            parse_texture_filters(list).map_err(|e| input(format!("--texture-filters: {e}")))?
        }
        None => Vec::new(),
    };
    let lights = match &args.light_strategies {
        Some(list) => {
            parse_light_strategies(list).map_err(|e| input(format!("--light-strategies: {e}")))?
        }
        None => Vec::new(),
    };
    let environments = match &args.environment_samplings {
        Some(list) => parse_environment_samplings(list)
            .map_err(|e| input(format!("--environment-samplings: {e}")))?,
        None => Vec::new(),
    };
    let light = parse_counts("--light-samples", &args.light_samples, 1).map_err(input)?;
    let environment = match &args.environment_samples {
        Some(list) => parse_counts("--environment-samples", list, 0).map_err(input)?,
        None => vec![default_environment_samples(&args.scene)],
    };
    let ladder = match &args.time {
        Some(list) => {
            let budgets = parse_durations(list).map_err(input)?;
            let single = |flag: &str, values: &[u32]| match values {
                [one] => Ok(*one),
                _ => Err(Failure::Input(format!(
                    "{flag}: with --time give one value, got {}",
                    values.len()
                ))),
            };
            Ladder::Time {
                budgets,
                light_samples: single("--light-samples", &light)?,
                environment_samples: single("--environment-samples", &environment)?,
            }
        }
        None => {
            let spp = parse_counts("--spp", &args.spp, 1).map_err(input)?;
            Ladder::Samples(sample_ladder(&spp, &light, &environment).map_err(input)?)
        }
    };
    let region = match &args.region {
        None => RegionChoice::Whole,
        Some(text) if text.contains(',') => {
            RegionChoice::Pixels(Region::parse(text).map_err(|e| input(format!("--region: {e}")))?)
        }
        Some(name) => RegionChoice::Named(name.clone()),
    };
    let reference = match &args.reference {
        Some(path) => ReferenceChoice::File(path.clone()),
        None => ReferenceChoice::Render {
            pixel_centre: args.reference_pixel == ReferencePixel::Centre,
            spp: args.reference_spp,
            texture_filter: args
                .reference_texture_filter
                .or((!filters.is_empty()).then_some(TextureFilter::Bilinear)),
        },
    };
    Ok(BenchConfig {
        scene: args.scene.clone(),
        strategies: combine(
            &samplers,
            &Choices {
                filters,
                lights,
                environments,
            },
        ),
        ladder,
        repeat: args.repeat as usize,
        region,
        reference,
        heatmap_step: args.heatmap_step.map(|s| s as usize - 1),
        resolution: args.resolution,
        seed: args.seed,
        threads: args.threads,
        max_depth: args.max_depth,
        output_dir: output_dir(args),
        version: version(),
    })
}

/// One environment direction per shading point, or none when the scene has no
/// environment or its own settings sample none (its environment is then only
/// seen, not a light). An unreadable scene gets 0 here; loading it reports the
/// real error.
fn default_environment_samples(scene: &Path) -> u32 {
    glint_scene::load(scene).map_or(0, |d| {
        u32::from(d.scene.environment.is_some() && d.settings.environment_samples > 0)
    })
}

/// This build's identity for the reference cache: the package version and a
/// hash of the running executable, so that a rebuilt Glint renders anew.
fn version() -> String {
    let exe = crate::program()
        .ok()
        .and_then(|p| std::fs::read(p).ok())
        .map_or_else(
            || "unknown".into(),
            |b| blake3::hash(&b).to_hex()[..16].to_owned(),
        );
    format!("{} {exe}", env!("CARGO_PKG_VERSION"))
}
