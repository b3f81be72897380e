//! `glint export`: a scene file as another renderer's scene (Mitsuba 3's XML).

use crate::Failure;
use clap::Args;
use glam::UVec2;
use glint_scene::mitsuba;
use std::path::{Path, PathBuf};

#[derive(Args)]
pub(crate) struct ExportArgs {
    /// The scene file (TOML; every key is described in docs/scene-format.md)
    scene: PathBuf,

    /// Write a Mitsuba 3 scene (XML, version 3.0.0) and, beside it in
    /// OUT-assets/, the meshes (PLY), images and environment map (EXR) it
    /// refers to. The only format so far, and required
    #[arg(long)]
    mitsuba: bool,

    /// The XML file to write. Default: SCENE-NAME.xml in the current directory.
    /// Written atomically with its assets folder: a failed run leaves what was
    /// there untouched
    #[arg(short, long, value_name = "OUT.xml")]
    output: Option<PathBuf>,

    /// Samples per pixel (overrides render.spp)
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1_048_576))]
    spp: Option<u32>,

    /// Light samples per camera sample, written as the direct integrator's
    /// emitter and BSDF samples (overrides render.light_samples)
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1_048_576))]
    light_samples: Option<u32>,

    /// The direct integrator's BSDF samples (default: the light samples). 0
    /// samples the emitters only, one shadow ray per light sample, the work
    /// Glint's light sampling does
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(0..=1_048_576))]
    bsdf_samples: Option<u32>,

    /// The sampler's seed (overrides render.seed)
    #[arg(long, value_name = "N")]
    seed: Option<u64>,

    /// Film size in pixels, e.g. 640x480 (overrides render.resolution)
    #[arg(long, value_name = "WxH", value_parser = crate::render::parse_resolution)]
    resolution: Option<UVec2>,
}

pub(crate) fn export(args: &ExportArgs) -> Result<(), Failure> {
    if !args.mitsuba {
        return Err(Failure::Input(
            "choose the format to export: --mitsuba (Mitsuba 3's XML, the only one so far)".into(),
        ));
    }
    let output = match &args.output {
        Some(p) => p.clone(),
        None => {
            let stem = args.scene.file_stem().unwrap_or("scene".as_ref());
            Path::new(stem).with_extension("xml")
        }
    };
    let failure = |e: mitsuba::ExportError| match e.is_bad_input() {
        true => Failure::Input(e.to_string()),
        false => Failure::Other(e.to_string()),
    };
    mitsuba::check_output(&output).map_err(failure)?;
    let mut description =
        glint_scene::load(&args.scene).map_err(|e| Failure::Input(e.to_string()))?;
    let inputs: Vec<&Path> = std::iter::once(args.scene.as_path())
        .chain(description.assets.iter().map(|p| p.as_path()))
        .collect();
    crate::output::check_outputs_apart(&[("-o", &output)], &inputs)?;
    let settings = &mut description.settings;
    if let Some(spp) = args.spp {
        settings.spp = spp;
    }
    if let Some(n) = args.light_samples {
        settings.light_samples = n;
    }
    if let Some(seed) = args.seed {
        settings.seed = seed;
    }
    if let Some(resolution) = args.resolution {
        let scene = &mut description.scene;
        scene.camera = scene
            .camera
            .with_resolution(resolution)
            .map_err(|e| Failure::Input(format!("--resolution: {e}")))?;
    }
    let options = mitsuba::Options {
        bsdf_samples: args.bsdf_samples,
    };
    let exported = mitsuba::export_with(&description, &output, options).map_err(failure)?;
    for warning in &exported.warnings {
        crate::output::tell(&format!("glint: warning: {warning}"));
    }
    let (settings, resolution) = (&description.settings, description.scene.camera.resolution());
    let assets = match &exported.assets {
        Some((folder, n)) => format!(
            " and {n} file{} in {}",
            if *n == 1 { "" } else { "s" },
            folder.display()
        ),
        None => String::new(),
    };
    crate::output::say(&format!(
        "wrote {}{assets} (Mitsuba 3): {}x{}, {} spp, direct integrator with {} emitter and {} BSDF samples, {} warning{}\n",
        output.display(),
        resolution.x,
        resolution.y,
        settings.spp,
        exported.emitter_samples,
        exported.bsdf_samples,
        exported.warnings.len(),
        if exported.warnings.len() == 1 { "" } else { "s" },
    ));
    Ok(())
}
