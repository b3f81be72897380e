//! `glint render`: a scene file to an image.

use crate::interrupt::Interrupts;
use crate::stats::StatsReport;
use crate::{named, progress_bar, Failure};
use clap::Args;
use glam::UVec2;
use glint_camera::{Film, ImageFormat, PartialFilm, Placement, Tile};
use glint_grade::mistakes::FilmMistake;
use glint_integrator::mistakes::{render_with_mistakes, Mistakes};
use glint_integrator::{
    Aov, AreaSampling, Crop, EnvironmentSampling, RenderControl, RenderOutput, RenderSettings,
    RenderStats, SamplePattern, TextureLevel,
};
use glint_scene::{OverrideError, Overrides, SceneDescription};
use glint_texture::TextureFilter;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

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
    /// size, and its pixels are the same pixels of the whole render, bit for
    /// bit; an .exr output also records where the window belongs and the
    /// render's fingerprint, for `glint assemble`
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = parse_crop)]
    crop: Option<Crop>,

    /// Render only tile I of N (counted from 0): rows I, I+N, I+2N, ... of the
    /// image, dealt out in turn so that the tiles cost about the same. The
    /// output is an .exr that records where its pixels belong (its data
    /// window in the image's display window, alpha marking its rows) and the
    /// render's fingerprint; `glint assemble` puts the N tiles together into
    /// the whole render, bit for bit
    #[arg(long, value_name = "I/N", value_parser = Tile::parse, conflicts_with = "crop")]
    tile: Option<Tile>,

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

    /// Render the scene as a ray tracer with this classic mistake renders it
    /// (`glint grade --mistakes` lists them): what a student's image with it
    /// looks like. A mistake in what the file stores needs a .png output
    #[arg(long, value_name = "ID", conflicts_with_all = ["crop", "tile", "resume", "aov"])]
    mistake: Option<String>,
}

/// The scene file and the settings that change its pixels, shared by the
/// commands that render it (`render`, `explain`).
#[derive(Args)]
pub(crate) struct SceneArgs {
    /// The scene file (TOML; every key is described in docs/scene-format.md)
    pub(crate) scene: PathBuf,

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

    /// The MIP level image textures are read at: footprint (Glint's, from the
    /// ray differentials) or report (the course report's log2(L/W) at each
    /// camera ray's hit, read trilinearly, as a ray tracer that follows the
    /// report reads it)
    /// [default: footprint]
    #[arg(long, value_name = "LEVEL", value_parser = named(&TextureLevel::NAMES, TextureLevel::from_name))]
    texture_level: Option<TextureLevel>,
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
    let (description, swaps, film_mistake, lights_from) = match &args.mistake {
        Some(id) => {
            let m = crate::mistake::load(&args.scene, crate::mistake::find(id)?)?;
            check_film_mistake(id, m.film, &output)?;
            (m.description, m.swaps, m.film, m.lights_from)
        }
        None => (args.scene.load()?, Mistakes::NONE, None, None),
    };
    let SceneDescription {
        scene,
        mut settings,
        timings,
        assets,
        ..
    } = description;
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
    let image = scene.camera.resolution();
    if let Some(crop) = args.crop {
        if crop.x1 > image.x || crop.y1 > image.y {
            return Err(Failure::Input(format!(
                "--crop: the window {},{},{},{} reaches past the {}x{} image",
                crop.x0, crop.y0, crop.x1, crop.y1, image.x, image.y
            )));
        }
    }
    if let Some(tile) = args.tile {
        if tile.row_span(image.y).is_none() {
            return Err(Failure::Input(format!(
                "--tile {tile}: the image has {} rows, one per tile at most, so tile {} would be empty; use at most {} tiles",
                image.y, tile.index, image.y
            )));
        }
    }

    // Taken now, of the bytes just loaded: a scene edited during the render
    // must not label its partial image.
    let window = args.crop.map_or(image, |crop| crop.size());
    let placement = Placement {
        image,
        origin: args
            .crop
            .map_or(glam::UVec2::ZERO, |c| glam::UVec2::new(c.x0, c.y0)),
    };
    let render_id = fingerprint(args, &assets, &settings, image)?;
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
            check_same_render(&partial_file, &partial, (window, placement), &render_id)?;
            check_same_piece(&partial_file, &partial, args.tile)?;
            Some(partial)
        }
        // A tile's other rows count as finished from the start.
        false => args.tile.map(|tile| other_rows_finished(tile, image)),
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
    let rendered = match swaps.is_empty() {
        true => glint_integrator::render_with(&scene, &settings, &on_tile, control),
        false => one_ray(&scene, &settings, swaps, interrupts.stop()),
    }
    .map_err(|e| Failure::Other(e.to_string()))?;
    if let Some(bar) = progress {
        bar.finish_and_clear();
    }
    if let (false, Some(status)) = (swaps.is_empty(), interrupts.exit_status()) {
        return Err(Failure::Interrupted {
            message: format!("stopped; {} was not written", output.display()),
            status,
        });
    }
    let film = match settings.aov {
        Some(aov) if ImageFormat::from_path(&output).ok() == Some(ImageFormat::Png) => {
            aov.false_color(&rendered.film)
        }
        _ => rendered.film,
    };
    let film = match film_mistake {
        Some(mistake) => with_film_mistake(film, mistake),
        None => film,
    };
    let film = match &lights_from {
        Some(correct) => {
            crate::mistake::with_correct_lights(film, (&correct.scene, &scene), &settings)?
        }
        None => film,
    };
    let finished = rendered.finished.iter().filter(|&&f| f).count();
    if finished < rendered.finished.len() {
        let status = interrupts
            .exit_status()
            .expect("only a signal stops a render early");
        let _writing = interrupts.writing();
        let partial = PartialFilm {
            fingerprint: Some(render_id),
            placement,
            tile: args.tile,
            interrupted: true,
            ..PartialFilm::new(film, rendered.finished)
        };
        // A tile's other rows were never its to render.
        let others = args.tile.map_or(0, |tile| {
            (image.y - tile.row_count(image.y)) as usize * image.x as usize
        });
        return Err(write_partial(
            &output,
            &partial_file,
            (partial, others),
            status,
        ));
    }
    let write_start = std::time::Instant::now();
    let piece = match (args.tile, args.crop) {
        (Some(tile), _) => Some(tile_piece(&film, tile, render_id)),
        (None, Some(_)) if ImageFormat::from_path(&output).ok() == Some(ImageFormat::Exr) => {
            let held = vec![true; film.pixels().len()];
            Some(PartialFilm {
                fingerprint: Some(render_id),
                placement,
                ..PartialFilm::new(film.clone(), held)
            })
        }
        _ => None,
    };
    // Every output is written beside its place first and put there only when
    // all are written: a failure in the last leaves the first as it was.
    let staged_image = match &piece {
        Some(piece) => piece.stage(&output),
        None => film.stage(&output),
    }
    .map_err(|e| Failure::Other(e.to_string()))?;
    let write = write_start.elapsed();

    let stats = rendered.stats;
    let report = StatsReport {
        stats: &stats,
        scene: &scene,
        load: timings,
        write,
    };
    let staged_json = match &args.stats_json {
        Some(path) => {
            let text = serde_json::to_string_pretty(&report.to_json()).expect("JSON of numbers");
            Some(crate::output::stage_text(path, &(text + "\n"))?)
        }
        None => None,
    };
    {
        let _writing = interrupts.writing();
        let persist = |staged: glint_camera::StagedFile, path: &Path| {
            staged
                .persist()
                .map_err(|e| Failure::Other(format!("{}: {e}", path.display())))
        };
        persist(staged_image, &output)?;
        if let (Some(staged), Some(path)) = (staged_json, &args.stats_json) {
            persist(staged, path)?;
        }
        if partial.is_some() {
            // Finished: the partial render has served.
            let _ = std::fs::remove_file(&partial_file);
        }
    }

    let resolution = film.resolution();
    let environment_samples = match scene.environment {
        Some(_) => format!(", {} environment samples", settings.environment_samples),
        None => String::new(),
    };
    let size = match args.tile {
        Some(tile) => format!(
            "tile {tile} of {}x{} ({} rows)",
            image.x,
            image.y,
            tile.row_count(image.y)
        ),
        None => format!("{}x{}", resolution.x, resolution.y),
    };
    crate::output::say(&format!(
        "wrote {}: {size}, {} spp, {} light samples{environment_samples}, {:.3} s wall ({:.3} s rendering), {}\n",
        output.display(),
        settings.spp,
        settings.light_samples,
        start.elapsed().as_secs_f64(),
        stats.elapsed.as_secs_f64(),
        match (&args.mistake, swaps.is_empty()) {
            (Some(id), false) => format!("the one-ray integrator with {id}"),
            (Some(id), true) => format!("{} rays, with {id}", stats.rays()),
            (None, _) => format!("{} rays ({:.2} M rays/s)", stats.rays(), stats.rays_per_second() / 1e6),
        },
    ));
    if args.stats {
        crate::output::say(&format!("{}\n", report.to_text()));
    }
    if stats.shading.nonfinite_samples > 0 {
        crate::output::tell(&format!("glint: warning: {} camera samples were NaN or infinite and were left out of their pixels",
            stats.shading.nonfinite_samples));
    }
    Ok(())
}

/// The one-ray integrator's render with `swaps` on, as a whole render (an
/// interrupted one is not written), its time its only count.
fn one_ray(
    scene: &glint_integrator::Scene,
    settings: &RenderSettings,
    swaps: Mistakes,
    stop: &AtomicBool,
) -> Result<RenderOutput, glint_integrator::SettingsError> {
    let start = std::time::Instant::now();
    let film = render_with_mistakes(scene, settings, swaps, Some(stop))?;
    Ok(RenderOutput {
        finished: vec![true; film.pixels().len()],
        film,
        stats: RenderStats {
            elapsed: start.elapsed(),
            ..RenderStats::default()
        },
    })
}

/// Refuses a mistake in the file's encoding for an output that is not an
/// 8-bit PNG: a float file has no curve to get wrong.
fn check_film_mistake(id: &str, film: Option<FilmMistake>, output: &Path) -> Result<(), Failure> {
    let encoding = matches!(film, Some(FilmMistake::NoSrgb | FilmMistake::Gamma22));
    if encoding && ImageFormat::from_path(output).ok() != Some(ImageFormat::Png) {
        return Err(Failure::Input(format!(
            "--mistake {id}: a mistake in the 8-bit encoding needs a .png output, not {}",
            output.display()
        )));
    }
    Ok(())
}

/// `film` as a tracer with the film mistake `mistake` writes it: upside
/// down, or its values such that the sRGB encoding of the PNG writes the
/// mistaken codes (what the grader decodes from them).
fn with_film_mistake(mut film: Film, mistake: FilmMistake) -> Film {
    let width = film.resolution().x as usize;
    let pixels = film.pixels_mut();
    match mistake {
        FilmMistake::FlipVertical => {
            let rows = pixels.len() / width;
            for y in 0..rows / 2 {
                let (top, bottom) = pixels.split_at_mut((rows - 1 - y) * width);
                top[y * width..(y + 1) * width].swap_with_slice(&mut bottom[..width]);
            }
        }
        FilmMistake::NoSrgb | FilmMistake::Gamma22 => {
            for p in pixels.iter_mut() {
                *p = mistake.decoded_rgb(*p);
            }
        }
    }
    film
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

/// Writes the pixels an interrupted render finished (`film`, of whose pixels
/// `others` were not its to render) to `partial` (atomically) and says so;
/// `output` is left as it was.
fn write_partial(
    output: &Path,
    partial: &Path,
    (film, others): (PartialFilm, usize),
    status: u8,
) -> Failure {
    let total = film.finished.len() - others;
    let done = film.finished_count() - others;
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

/// The start of a render of `tile`: the whole image, with every row but the
/// tile's counted as finished (and black), so that only the tile's are
/// rendered.
fn other_rows_finished(tile: Tile, image: glam::UVec2) -> PartialFilm {
    let finished = (0..image.y)
        .flat_map(|y| std::iter::repeat_n(!tile.has_row(y), image.x as usize))
        .collect();
    PartialFilm::new(Film::new(image), finished)
}

/// The rows from the tile's first to its last of the rendered image `film`,
/// with alpha marking the tile's own, placed in the image and named.
fn tile_piece(film: &Film, tile: Tile, fingerprint: String) -> PartialFilm {
    let image = film.resolution();
    let (y0, y1) = tile.row_span(image.y).expect("checked before the render");
    let width = image.x as usize;
    let rows = &film.pixels()[y0 as usize * width..y1 as usize * width];
    let mut piece = Film::new(glam::UVec2::new(image.x, y1 - y0));
    piece.pixels_mut().copy_from_slice(rows);
    let held = (y0..y1)
        .flat_map(|y| std::iter::repeat_n(tile.has_row(y), width))
        .collect();
    PartialFilm {
        fingerprint: Some(fingerprint),
        placement: Placement {
            image,
            origin: glam::UVec2::new(0, y0),
        },
        tile: Some(tile),
        ..PartialFilm::new(piece, held)
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
    let format = ImageFormat::from_path(&path).map_err(|e| Failure::Input(e.to_string()))?;
    if let (Some(tile), false) = (args.tile, format == ImageFormat::Exr) {
        return Err(Failure::Input(format!(
            "{}: --tile {tile} writes OpenEXR (.exr), which records where the tile's pixels belong; name an .exr output",
            path.display()
        )));
    }
    crate::output::check_writable(&path)?;
    // An interrupted render writes beside it: that must be possible too.
    crate::output::check_writable(&partial_path(&path))?;
    Ok(path)
}

/// A name for everything a render's pixels depend on: a BLAKE3 hash of Glint's
/// version, the scene file and every asset it read (their bytes), the render
/// settings that change pixels (not the thread count nor `--stats`), the
/// resolution and the texture filter override: the whole image's, whatever
/// window or tile of it is rendered. An interrupted render stores it in its
/// partial EXR, and `--resume` continues only a render with the same one;
/// tiles and windows store it, and `glint assemble` puts together only pieces
/// with the same one.
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
    let mut settings = format!(
        "{pixels_depend_on:?} {resolution} {:?} {:?}",
        args.scene.texture_filter, args.scene.texture_level
    );
    if let Some(id) = &args.mistake {
        settings += &format!(" mistake {id}");
    }
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
    (resolution, placement): (UVec2, Placement),
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
    let (at, whole) = (partial.placement.origin, partial.placement.image);
    if partial.placement != placement {
        return Err(Failure::Input(format!(
            "--resume: {}: the partial image is the window at {},{} of a {}x{} image, this render the one at {},{} of {}x{}",
            output.display(),
            at.x,
            at.y,
            whole.x,
            whole.y,
            placement.origin.x,
            placement.origin.y,
            placement.image.x,
            placement.image.y
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

/// Refuses to resume as a tile what is not that tile's partial render, or as
/// the whole image (or a window) a tile's.
fn check_same_piece(
    output: &Path,
    partial: &PartialFilm,
    tile: Option<Tile>,
) -> Result<(), Failure> {
    let name = |tile: Option<Tile>| match tile {
        Some(tile) => format!("tile {tile}"),
        None => "no tile".into(),
    };
    if partial.tile != tile {
        return Err(Failure::Input(format!(
            "--resume: {} is a partial render of {}, this command renders {}; run the command that wrote it",
            output.display(),
            name(partial.tile),
            name(tile)
        )));
    }
    if !partial.interrupted {
        return Err(Failure::Input(format!(
            "--resume: {} is not an interrupted render's (it was not written by a stopped glint render); render again without --resume",
            output.display()
        )));
    }
    Ok(())
}

/// The size of the image `args` would render: its scene loaded, with the
/// command's overrides.
pub(crate) fn image_size(args: &RenderArgs) -> Result<UVec2, Failure> {
    Ok(args.scene.load()?.scene.camera.resolution())
}

impl SceneArgs {
    /// The scene file, loaded, with this command's overrides applied and its
    /// settings checked.
    pub(crate) fn load(&self) -> Result<SceneDescription, Failure> {
        let mut description =
            glint_scene::load(&self.scene).map_err(|e| Failure::Input(e.to_string()))?;
        self.overrides().apply(&mut description).map_err(|e| {
            Failure::Input(match e {
                OverrideError::ReportLevelFilter => "--texture-level report reads the report's level trilinearly: leave out --texture-filter, or give trilinear".into(),
                OverrideError::Resolution(e) => format!("--resolution: {e}"),
                OverrideError::Settings(e) => format!("render settings: {e}"),
            })
        })?;
        Ok(description)
    }

    /// The settings this command's flags replace.
    pub(crate) fn overrides(&self) -> Overrides {
        Overrides {
            spp: self.spp,
            light_samples: self.light_samples,
            pixel_sampler: self.sampler,
            light_sampler: self.light_sampler,
            max_depth: self.max_depth,
            environment_samples: self.environment_samples,
            environment_sampler: self.environment_sampler,
            environment_sampling: self.environment_sampling,
            area_sampling: self.area_sampling,
            mis: self.no_mis.then_some(false),
            seed: self.seed,
            resolution: self.resolution,
            texture_filter: self.texture_filter,
            texture_level: self.texture_level,
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
