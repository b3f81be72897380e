//! `glint farm ENGINE render`: one frame in tiles, each task `glint render
//! --tile I/N` (resuming a stopped tile), then `glint assemble`.

use super::script::{check_managed, file_stem, or_default, parse_command, quote, quote_str, Farm};
use crate::render::RenderArgs;
use crate::{Command, Failure};
use clap::Args;
use std::path::{Path, PathBuf};

/// Options `glint farm` sets for every tile itself.
const MANAGED: [&str; 7] = [
    "-o",
    "--output",
    "--tile",
    "--crop",
    "--resume",
    "--threads",
    "--stats-json",
];

#[derive(Args)]
pub(super) struct FarmRender {
    /// The scene file
    scene: PathBuf,

    /// How many tiles (tasks): tile I renders rows I, I+N, I+2N, ...
    #[arg(long, value_name = "N")]
    tiles: u32,

    /// The assembled image [default: SCENE-NAME.png in the current directory]
    #[arg(short, long, value_name = "OUT")]
    output: Option<PathBuf>,

    /// Where the scripts, tiles (tiles/) and logs (logs/) go [default:
    /// SCENE-NAME.farm in the current directory]
    #[arg(long, value_name = "DIR")]
    dir: Option<PathBuf>,

    /// Options for every tile's glint render (after --, e.g. -- --spp 256)
    #[arg(last = true, value_name = "RENDER-OPTIONS")]
    render_options: Vec<String>,
}

/// A render in tiles, checked, with every path absolute.
pub(super) struct Plan {
    glint: PathBuf,
    scene: PathBuf,
    tiles: u32,
    output: PathBuf,
    dir: PathBuf,
    render_options: Vec<String>,
}

impl Plan {
    /// Checks everything before any file is written: the render options (as
    /// `glint render` parses them), the scene (loaded), the tile count
    /// against the image's rows, and the paths.
    pub(super) fn new(args: &FarmRender) -> Result<Plan, Failure> {
        if args.tiles == 0 {
            return Err(Failure::Input(
                "--tiles: expected at least 1 tile, got 0".into(),
            ));
        }
        check_managed("render", &args.render_options, &MANAGED)?;
        let stem = file_stem(&args.scene, "render");
        let dir = or_default(&args.dir, format!("{stem}.farm"));
        let output = or_default(&args.output, format!("{stem}.png"));
        glint_camera::ImageFormat::from_path(&output).map_err(|e| Failure::Input(e.to_string()))?;
        let output_folder = output.parent().filter(|p| !p.as_os_str().is_empty());
        glint_camera::check_output_folder(output_folder.unwrap_or(Path::new(".")))
            .map_err(|e| Failure::Input(format!("-o {}: its folder {e}", output.display())))?;
        glint_camera::check_output_folder(&dir)
            .map_err(|e| Failure::Input(format!("--dir {}: {e}", dir.display())))?;
        let render = parse_render(&args.scene, &dir, &args.render_options)?;
        let image = crate::render::image_size(&render)?;
        if args.tiles > image.y {
            return Err(Failure::Input(format!(
                "--tiles {}: the image has {} rows, one per tile at most; use at most {} tiles",
                args.tiles, image.y, image.y
            )));
        }
        let absolute = |path: &Path| std::path::absolute(path).unwrap_or_else(|_| path.to_owned());
        let glint = crate::program()
            .map_err(|e| Failure::Other(format!("cannot find the glint executable: {e}")))?;
        Ok(Plan {
            glint,
            scene: absolute(&args.scene),
            tiles: args.tiles,
            output: absolute(&output),
            dir: absolute(&dir),
            render_options: args.render_options.clone(),
        })
    }

    /// The job: a task per tile (`render-tile.sh`), then `assemble.sh`.
    pub(super) fn farm(&self) -> Farm {
        let folders = [self.dir.clone(), self.tiles_dir(), self.dir.join("logs")];
        let output_folder = self.output.parent().map(Path::to_owned);
        Farm {
            first: None,
            kind: "render",
            merge_kind: "assemble",
            task_script: "render-tile.sh",
            merge_script: "assemble.sh",
            scene: self.scene.clone(),
            dir: self.dir.clone(),
            tasks: self.tiles,
            what: format!("{} tiles of {}", self.tiles, self.scene.display()),
            folders: folders.into_iter().chain(output_folder).collect(),
            task_text: self.render_tile(),
            merge_text: self.assemble(),
        }
    }

    fn tiles_dir(&self) -> PathBuf {
        self.dir.join("tiles")
    }

    /// `render-tile.sh I`: tile I, continued where a stopped run left it, on
    /// as many threads as Slurm gave the task CPUs, else one (GNU parallel
    /// runs one job per core).
    fn render_tile(&self) -> String {
        let options: Vec<String> = self.render_options.iter().map(|o| quote_str(o)).collect();
        format!(
            r#"#!/bin/bash
# Renders tile I of {tiles} of {scene} (written by glint farm).
# Usage: render-tile.sh I
set -euo pipefail
tile="$1"
out={tiles_dir}/tile-"$tile".exr
resume=()
# A run stopped earlier (SIGTERM at a time limit, a requeue) left the tile's
# finished pixels here: continue it. The result is the same bytes.
if [ -e {tiles_dir}/tile-"$tile".partial.exr ]; then resume=(--resume); fi
threads="${{SLURM_CPUS_PER_TASK:-1}}"
exec {glint} render {scene} --tile "$tile/{tiles}" -o "$out" --threads "$threads" "${{resume[@]}}"{options}
"#,
            tiles = self.tiles,
            scene = quote(&self.scene),
            tiles_dir = quote(&self.tiles_dir()),
            glint = quote(&self.glint),
            options = options.iter().map(|o| format!(" {o}")).collect::<String>(),
        )
    }

    /// `assemble.sh`: the tiles there are, put together; `glint assemble`
    /// names any missing.
    fn assemble(&self) -> String {
        format!(
            r#"#!/bin/bash
# Puts the {tiles} tiles of {scene} together (written by glint farm).
set -euo pipefail
files=()
for tile in $(seq 0 {last}); do
  f={tiles_dir}/tile-"$tile".exr
  if [ -e "$f" ]; then files+=("$f"); fi
done
if [ ${{#files[@]}} -eq 0 ]; then echo "no tiles in "{tiles_dir} >&2; exit 2; fi
exec {glint} assemble "${{files[@]}}" -o {output}
"#,
            tiles = self.tiles,
            last = self.tiles - 1,
            scene = quote(&self.scene),
            tiles_dir = quote(&self.tiles_dir()),
            glint = quote(&self.glint),
            output = quote(&self.output),
        )
    }
}

/// The tiles' `glint render` command line as `glint render` parses it: the
/// options' errors are caught here, before any job exists.
fn parse_render(scene: &Path, dir: &Path, options: &[String]) -> Result<RenderArgs, Failure> {
    let tile = dir.join("tiles").join("tile-0.exr");
    let fixed = [
        scene.as_os_str().to_owned(),
        "-o".into(),
        tile.into_os_string(),
        "--tile".into(),
        "0/1".into(),
    ];
    match parse_command("render", &fixed, options)? {
        Command::Render(args) => Ok(args),
        _ => unreachable!("parsed as glint render"),
    }
}
