//! `glint render`: a scene file to an image.

use crate::interrupt::Interrupts;
use crate::stats::StatsReport;
use crate::{named, progress_bar, Failure};
use clap::Args;
use glam::UVec2;
use glint_camera::{ImageFormat, PartialFilm};
use glint_integrator::{
    Aov, AreaSampling, Crop, EnvironmentSampling, RenderControl, RenderSettings, SamplePattern,
};
use glint_scene::SceneDescription;
use glint_texture::TextureFilter;
use std::path::{Path, PathBuf};

#[derive(Args)]
pub(crate) struct RenderArgs {
    #[command(flatten)]
    pub(crate) scene: SceneArgs,

    /// Output image; the extension picks the format: .png (8-bit sRGB),
    /// .exr or .pfm (linear 32-bit float). Default: SCENE-NAME.png in the
    /// current directory. Written atomically: a failed run leaves any existing file untouched.
    #[arg(short, long, value_name = "OUT")]
    output: Option<PathBuf>,

    /// Render only this window of the image, half-open: columns x0..x1, rows
    /// y0..y1 from the top (e.g. 100,50,164,114). The output is the window's
    /// size, and its pixels are the same pixels of the whole render, bit for bit
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = parse_crop)]
    crop: Option<Crop>,

    /// Worker threads [default: one per core]; the image is identical for any count
    #[arg(long, value_name = "N")]
    threads: Option<usize>,

    /// Write this buffer instead of the shaded image: uv (surface coordinates),
    /// mip-level (the level Glint reads the diffuse texture at),
    /// report-mip-level (the course report's level log2(L/W), from a whole
    /// pixel's footprint), normal, depth (distance from the camera), albedo
    /// (filtered diffuse color), reflection-depth (mirror reflections taken),
    /// object (the object hit first: its index in the shape list plus one; use
    /// --spp 1 --sampler grid for the object at each pixel's centre). Raw
    /// values in .exr/.pfm, false color in .png (normals as 0.5·n + 0.5, uv as its
    /// fractional part, depth as gray from near to far, MIP levels and reflection
    /// depth as a blue-green-red ramp)
    #[arg(long, value_name = "BUFFER", value_parser = named(&Aov::NAMES, Aov::from_name))]
    aov: Option<Aov>,

    /// At the end, print what the render did: rays by kind, intersection tests by
    /// shape, BVH nodes and leaves visited, shadow rays skipped and why, texture
    /// lookups by filter and MIP level, NaN/Inf samples dropped, time by phase, peak
    /// memory. The image is the same with or without it
    #[arg(long)]
    stats: bool,

    /// Write the same statistics as JSON to FILE (atomically); implies gathering
    /// them (the schema is in docs/command-line.md)
    #[arg(long, value_name = "FILE")]
    stats_json: Option<PathBuf>,

    /// Continue the interrupted render in OUT (an .exr whose alpha channel marks
    /// the pixels finished): only the others are rendered, and with the same
    /// scene and settings the image is the uninterrupted render's, bit for bit
    #[arg(long)]
    resume: bool,
}

/// The scene file and the settings that change its pixels, shared by the
/// commands that render it (`render`, `explain`).
#[derive(Args)]
pub(crate) struct SceneArgs {
    /// The scene file (TOML; every key is described in docs/scene-format.md)
    scene: PathBuf,

    /// Camera samples per pixel (overrides render.spp)
    #[arg(long, value_name = "N")]
    spp: Option<u32>,

    /// Samples per area light per camera sample (overrides render.light_samples)
    #[arg(long, value_name = "N")]
    light_samples: Option<u32>,

    /// Pixel sample pattern: where the camera samples fall in the pixel, and
    /// nothing else (overrides render.pixel_sampler; the light samples' pattern
    /// is --light-sampler's): grid (the course's uniform grid; needs a square
    /// spp), random (independent uniform points), stratified (jittered grid;
    /// Latin hypercube when spp is not a square), sobol (Owen-scrambled Sobol
    /// points, one sequence per pixel; best at powers of two)
    #[arg(long, value_name = "PATTERN", value_parser = named(&SamplePattern::NAMES, SamplePattern::from_name))]
    sampler: Option<SamplePattern>,

    /// Light sample pattern: where the samples fall on each area light
    /// (overrides render.light_sampler; --sampler sets only the pixel's); the
    /// same patterns, grid needing a square count
    #[arg(long, value_name = "PATTERN", value_parser = named(&SamplePattern::NAMES, SamplePattern::from_name))]
    light_sampler: Option<SamplePattern>,

    /// Most mirror reflections followed per camera ray (overrides render.max_depth)
    #[arg(long, value_name = "N")]
    max_depth: Option<u32>,

    /// Environment directions sampled per shading point (overrides
    /// render.environment_samples; 0: the environment lights nothing)
    #[arg(long, value_name = "N")]
    environment_samples: Option<u32>,

    /// Environment sample pattern (overrides render.environment_sampler); the same
    /// patterns, grid needing a square count
    #[arg(long, value_name = "PATTERN", value_parser = named(&SamplePattern::NAMES, SamplePattern::from_name))]
    environment_sampler: Option<SamplePattern>,

    /// How environment directions are drawn (overrides
    /// render.environment_sampling): luminance (in proportion to the map's
    /// luminance; best with small bright sources) or cosine (cosine-weighted
    /// about the shading normal; best under broad skies)
    #[arg(long, value_name = "STRATEGY", value_parser = named(&EnvironmentSampling::NAMES, EnvironmentSampling::from_name))]
    environment_sampling: Option<EnvironmentSampling>,

    /// Physical shading: how area lights are sampled (overrides
    /// render.area_sampling): auto (by solid angle where a light subtends more
    /// than 1 sr or is seen obliquely, else by area), solid-angle (uniform over the solid angle a
    /// rectangular light subtends) or area (uniform over its area)
    #[arg(long, value_name = "STRATEGY", value_parser = named(&AreaSampling::NAMES, AreaSampling::from_name))]
    area_sampling: Option<AreaSampling>,

    /// Physical shading: sample area lights only, without combining them with
    /// samples of glossy lobes by multiple importance sampling (sets render.mis = false)
    #[arg(long)]
    no_mis: bool,

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
}

pub(crate) fn parse_resolution(text: &str) -> Result<UVec2, String> {
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

pub(crate) fn render(args: &RenderArgs) -> Result<(), Failure> {
    let start = std::time::Instant::now();
    let output = output_path(args)?;
    if let Some(json) = &args.stats_json {
        crate::output::check_writable(json)?;
    }
    let SceneDescription {
        scene,
        mut settings,
        timings,
        assets,
        ..
    } = args.scene.load()?;
    let outputs: Vec<(&str, &Path)> = [
        Some(("-o", output.as_path())),
        args.stats_json.as_deref().map(|p| ("--stats-json", p)),
    ]
    .into_iter()
    .flatten()
    .collect();
    let inputs: Vec<&Path> = std::iter::once(args.scene.scene.as_path())
        .chain(assets.iter().map(PathBuf::as_path))
        .collect();
    crate::output::check_outputs_apart(&outputs, &inputs)?;
    if args.threads.is_some() {
        settings.threads = args.threads;
    }
    if args.aov.is_some() {
        settings.aov = args.aov;
    }
    settings.stats = args.stats || args.stats_json.is_some();
    settings
        .validate()
        .map_err(|e| Failure::Input(format!("render settings: {e}")))?;
    if let Some(crop) = args.crop {
        let size = scene.camera.resolution();
        if crop.x1 > size.x || crop.y1 > size.y {
            return Err(Failure::Input(format!(
                "--crop: the window {},{},{},{} reaches past the {}x{} image",
                crop.x0, crop.y0, crop.x1, crop.y1, size.x, size.y
            )));
        }
    }

    // Taken now, of the bytes just loaded: a scene edited during the render
    // must not label its partial image.
    let window = args
        .crop
        .map_or(scene.camera.resolution(), |crop| crop.size());
    let render_id = fingerprint(args, &assets, &settings, scene.camera.resolution())?;
    let partial_file = partial_path(&output);
    let partial = match args.resume {
        true => {
            if !partial_file.exists() {
                return Err(Failure::Input(format!(
                    "--resume: there is no partial render {} to finish (an interrupted render of {} writes one)",
                    partial_file.display(),
                    output.display()
                )));
            }
            let partial = PartialFilm::load(&partial_file)
                .map_err(|e| Failure::Input(format!("--resume: {e}")))?;
            check_same_render(&partial_file, &partial, window, &render_id)?;
            Some(partial)
        }
        false => None,
    };
    let interrupts =
        Interrupts::install().map_err(|e| Failure::Other(format!("cannot handle Ctrl-C: {e}")))?;
    let progress =
        progress_bar("{spinner} [{elapsed_precise}] {wide_bar} {pos}/{len} tiles (eta {eta})");
    let on_tile = |done: usize, total: usize| {
        if let Some(bar) = &progress {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        }
    };
    let control = RenderControl {
        stop: Some(interrupts.stop()),
        resume: partial.as_ref(),
        crop: args.crop,
    };
    let rendered = glint_integrator::render_with(&scene, &settings, &on_tile, control)
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
    let finished = rendered.finished.iter().filter(|&&f| f).count();
    if finished < rendered.finished.len() {
        let status = interrupts
            .exit_status()
            .expect("only a signal stops a render early");
        let _writing = interrupts.writing();
        return Err(write_partial(
            &output,
            &partial_file,
            film,
            rendered.finished,
            render_id,
            status,
        ));
    }
    let write_start = std::time::Instant::now();
    {
        let _writing = interrupts.writing();
        film.save(&output)
            .map_err(|e| Failure::Other(e.to_string()))?;
        if partial.is_some() {
            // Finished: the partial render has served.
            let _ = std::fs::remove_file(&partial_file);
        }
    }
    let write = write_start.elapsed();

    let stats = rendered.stats;
    let resolution = film.resolution();
    let environment_samples = match scene.environment {
        Some(_) => format!(", {} environment samples", settings.environment_samples),
        None => String::new(),
    };
    crate::output::say(&format!(
        "wrote {}: {}x{}, {} spp, {} light samples{environment_samples}, {:.3} s wall ({:.3} s rendering), {} rays ({:.2} M rays/s)\n",
        output.display(),
        resolution.x,
        resolution.y,
        settings.spp,
        settings.light_samples,
        start.elapsed().as_secs_f64(),
        stats.elapsed.as_secs_f64(),
        stats.rays(),
        stats.rays_per_second() / 1e6,
    ));
    let report = StatsReport {
        stats: &stats,
        scene: &scene,
        load: timings,
        write,
    };
    if args.stats {
        crate::output::say(&format!("{}\n", report.to_text()));
    }
    if let Some(path) = &args.stats_json {
        let text = serde_json::to_string_pretty(&report.to_json()).expect("JSON of numbers");
        let _writing = interrupts.writing();
        crate::output::write_text(path, &(text + "\n"))?;
    }
    if stats.shading.nonfinite_samples > 0 {
        crate::output::tell(&format!("glint: warning: {} camera samples were NaN or infinite and were left out of their pixels",
            stats.shading.nonfinite_samples));
    }
    Ok(())
}

/// Where an interrupted render of `output` keeps the pixels it finished, and
/// where `--resume` finds them: beside it, `NAME.partial.exr` (OpenEXR, whose
/// alpha channel marks the pixels rendered), so that the user's `output`
/// stays as it was.
fn partial_path(output: &Path) -> PathBuf {
    let stem = output
        .file_stem()
        .map_or("render".into(), |s| s.to_string_lossy().into_owned());
    output.with_file_name(format!("{stem}.partial.exr"))
}

/// Writes the pixels an interrupted render finished to `partial` (atomically)
/// and says so; `output` is left as it was.
fn write_partial(
    output: &Path,
    partial: &Path,
    film: glint_camera::Film,
    finished: Vec<bool>,
    fingerprint: String,
    status: u8,
) -> Failure {
    let total = finished.len();
    let film = PartialFilm {
        film,
        finished,
        fingerprint: Some(fingerprint),
    };
    let done = film.finished_count();
    if let Err(e) = film.save(partial) {
        return Failure::Other(format!(
            "interrupted, and could not write the partial image: {e}"
        ));
    }
    let untouched = match output.exists() {
        true => format!("; {} is as it was", output.display()),
        false => String::new(),
    };
    Failure::Interrupted {
        message: format!(
            "wrote {} with {done} of {total} pixels rendered{untouched}; the same command with --resume finishes it",
            partial.display()
        ),
        status,
    }
}

/// The output path: `-o`, or SCENE-NAME.png in the current directory; its
/// extension must name a format, and its directory must be writable.
fn output_path(args: &RenderArgs) -> Result<PathBuf, Failure> {
    let path = match &args.output {
        Some(p) => p.clone(),
        None => {
            let stem = args.scene.scene.file_stem().unwrap_or("render".as_ref());
            Path::new(stem).with_extension("png")
        }
    };
    ImageFormat::from_path(&path).map_err(|e| Failure::Input(e.to_string()))?;
    crate::output::check_writable(&path)?;
    // An interrupted render writes beside it: that must be possible too.
    crate::output::check_writable(&partial_path(&path))?;
    Ok(path)
}

/// A name for everything a render's pixels depend on: a BLAKE3 hash of Glint's
/// version, the scene file and every asset it read (their bytes), the render
/// settings that change pixels (not the thread count nor `--stats`), the
/// resolution and the texture filter override. An interrupted render stores it
/// in its partial EXR; `--resume` continues only a render with the same one.
fn fingerprint(
    args: &RenderArgs,
    assets: &[PathBuf],
    settings: &RenderSettings,
    resolution: UVec2,
) -> Result<String, Failure> {
    let mut hasher = blake3::Hasher::new();
    let add = |hasher: &mut blake3::Hasher, bytes: &[u8]| {
        hasher.update(&(bytes.len() as u64).to_le_bytes());
        hasher.update(bytes);
    };
    add(&mut hasher, env!("CARGO_PKG_VERSION").as_bytes());
    for path in std::iter::once(&args.scene.scene).chain(assets) {
        add_file(&mut hasher, path)?;
    }
    let pixels_depend_on = RenderSettings {
        threads: None,
        stats: false,
        ..settings.clone()
    };
    let settings = format!(
        "{pixels_depend_on:?} {resolution} {:?} {:?}",
        args.scene.texture_filter, args.crop
    );
    add(&mut hasher, settings.as_bytes());
    Ok(format!("blake3 {}", hasher.finalize().to_hex()))
}

/// Adds the file at `path` to `hasher` as `fingerprint` adds bytes (its
/// length, then its bytes), streamed: a mesh's OBJ file can be hundreds of
/// megabytes, beside the scene built from it.
fn add_file(hasher: &mut blake3::Hasher, path: &Path) -> Result<(), Failure> {
    let cannot_read =
        |e: std::io::Error| Failure::Input(format!("{}: cannot read: {e}", path.display()));
    let mut file = std::fs::File::open(path).map_err(cannot_read)?;
    let length = file.metadata().map_err(cannot_read)?.len();
    hasher.update(&length.to_le_bytes());
    let read = std::io::copy(&mut file, hasher).map_err(cannot_read)?;
    if read != length {
        return Err(Failure::Input(format!(
            "{}: changed while being read ({length} bytes long, then {read} bytes read)",
            path.display()
        )));
    }
    Ok(())
}

/// Refuses to resume a partial render of another size, scene or settings
/// (whose finished pixels would not be this render's).
fn check_same_render(
    output: &Path,
    partial: &PartialFilm,
    resolution: UVec2,
    expected: &str,
) -> Result<(), Failure> {
    let film = partial.film.resolution();
    if film != resolution {
        return Err(Failure::Input(format!(
            "--resume: {}: the partial image is {}x{} pixels, this render {}x{}",
            output.display(),
            film.x,
            film.y,
            resolution.x,
            resolution.y
        )));
    }
    match partial.fingerprint.as_deref() {
        Some(f) if f == expected => Ok(()),
        Some(_) => Err(Failure::Input(format!(
            "--resume: {} was rendered from another scene, other assets or other \
             settings than this command's (its fingerprint differs): resuming would mix \
             two images; run the command that wrote it, or render again without --resume",
            output.display()
        ))),
        None => Err(Failure::Input(format!(
            "--resume: {} does not record the scene and settings it was rendered with \
             (it was not written by an interrupted glint render); render again without --resume",
            output.display()
        ))),
    }
}

impl SceneArgs {
    /// The scene file, loaded, with this command's overrides applied and its
    /// settings checked.
    pub(crate) fn load(&self) -> Result<SceneDescription, Failure> {
        let mut description =
            glint_scene::load(&self.scene).map_err(|e| Failure::Input(e.to_string()))?;
        self.apply_overrides(&mut description.settings);
        let scene = &mut description.scene;
        // The map's distribution is part of loading it, not of the render.
        let start = std::time::Instant::now();
        scene.prepare(&description.settings);
        description.timings.assets += start.elapsed();
        if let Some(filter) = self.texture_filter {
            scene.override_texture_filter(filter);
        }
        if let Some(resolution) = self.resolution {
            scene.camera = scene
                .camera
                .with_resolution(resolution)
                .map_err(|e| Failure::Input(format!("--resolution: {e}")))?;
        }
        description
            .settings
            .validate()
            .map_err(|e| Failure::Input(format!("render settings: {e}")))?;
        Ok(description)
    }

    fn apply_overrides(&self, settings: &mut RenderSettings) {
        let args = self;
        if let Some(spp) = args.spp {
            settings.spp = spp;
        }
        if let Some(n) = args.light_samples {
            settings.light_samples = n;
        }
        if let Some(p) = args.sampler {
            settings.pixel_pattern = p;
        }
        if let Some(p) = args.light_sampler {
            settings.light_pattern = p;
        }
        if let Some(seed) = args.seed {
            settings.seed = seed;
        }
        if let Some(strategy) = args.area_sampling {
            settings.area_sampling = strategy;
        }
        if args.no_mis {
            settings.mis = false;
        }
        if let Some(depth) = args.max_depth {
            settings.max_depth = depth;
        }
        if let Some(n) = args.environment_samples {
            settings.environment_samples = n;
        }
        if let Some(p) = args.environment_sampler {
            settings.environment_pattern = p;
        }
        if let Some(s) = args.environment_sampling {
            settings.environment_sampling = s;
        }
    }
}

/// Parses `--crop X0,Y0,X1,Y1` (half-open, non-empty); whether it fits the
/// image is checked once the scene is loaded.
fn parse_crop(text: &str) -> Result<Crop, String> {
    let r = glint_metrics::Region::parse(text)?;
    Ok(Crop {
        x0: r.x0,
        y0: r.y0,
        x1: r.x1,
        y1: r.y1,
    })
}
