//! `glint farm ENGINE bench`: a `glint bench` sweep as a farm job, one task
//! per strategy and budget (`bench-task.sh K`), each measuring against the
//! same reference file, then `merge-bench.sh`, which fits and plots from the
//! tasks' JSON (`glint bench --merge`).

use super::script::{check_managed, or_default, parse_command, quote, quote_str, Farm};
use crate::{Command, Failure};
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Args)]
pub(crate) struct FarmBench {
    /// The scene file
    scene: PathBuf,

    /// The merged results: table, CSV, JSON and plot [default:
    /// SCENE-NAME-bench in the current directory]
    #[arg(short, long, value_name = "DIR")]
    output: Option<PathBuf>,

    /// Where the scripts, the tasks' results (tasks/) and logs (logs/) go
    /// [default: SCENE-NAME.bench-farm in the current directory]
    #[arg(long, value_name = "DIR")]
    dir: Option<PathBuf>,

    /// Options for every task's glint bench (after --): --reference FILE is
    /// required; --samplers and the budgets (--spp or --time, with
    /// --light-samples and --environment-samples) are split, one task per
    /// strategy and budget
    #[arg(last = true, value_name = "BENCH-OPTIONS")]
    bench_options: Vec<String>,
}

/// Options `glint farm` sets for every task itself.
const MANAGED: [&str; 4] = ["-o", "--output", "--merge", "--threads"];
/// Options split into the tasks (each with its value).
const SPLIT: [&str; 5] = [
    "--samplers",
    "--spp",
    "--time",
    "--light-samples",
    "--environment-samples",
];

/// A sweep in tasks, checked, with every path absolute.
pub(crate) struct Sweep {
    glint: PathBuf,
    scene: PathBuf,
    output: PathBuf,
    dir: PathBuf,
    samplers: Vec<String>,
    steps: Vec<Vec<String>>,
    /// The options every task takes, the split ones taken out.
    common: Vec<String>,
}

impl Sweep {
    /// Checks everything before any file is written: the options (as `glint
    /// bench` parses and checks them) and the paths.
    pub(crate) fn new(args: &FarmBench) -> Result<Sweep, Failure> {
        check_managed("bench", &args.bench_options, &MANAGED)?;
        let stem = glint_bench::scene_name(&args.scene);
        let dir = or_default(&args.dir, format!("{stem}.bench-farm"));
        let output = or_default(&args.output, format!("{stem}-bench"));
        for (flag, folder) in [("--dir", &dir), ("-o", &output)] {
            glint_camera::check_output_folder(folder)
                .map_err(|e| Failure::Input(format!("{flag} {}: {e}", folder.display())))?;
        }
        let bench = parse_bench(&args.scene, &dir, &args.bench_options)?;
        let split = crate::bench::sweep_split(&bench)?;
        let absolute = |path: &Path| std::path::absolute(path).unwrap_or_else(|_| path.to_owned());
        let glint = crate::program()
            .map_err(|e| Failure::Other(format!("cannot find the glint executable: {e}")))?;
        Ok(Sweep {
            glint,
            scene: absolute(&args.scene),
            output: absolute(&output),
            dir: absolute(&dir),
            samplers: split.samplers,
            steps: split.steps,
            common: with_absolute_reference(&without_split(&args.bench_options))?,
        })
    }

    fn tasks(&self) -> u32 {
        (self.samplers.len() * self.steps.len()) as u32
    }

    fn task_dir(&self, task: &str) -> String {
        format!("{}/task-{task}", quote(&self.dir.join("tasks")))
    }

    /// The job: a task per strategy and budget (`bench-task.sh`), then
    /// `merge-bench.sh`.
    pub(crate) fn farm(&self) -> Farm {
        let output_folder = self.output.parent().map(Path::to_owned);
        let folders = [
            self.dir.clone(),
            self.dir.join("tasks"),
            self.dir.join("logs"),
        ];
        Farm {
            first: None,
            kind: "bench",
            merge_kind: "merge",
            task_script: "bench-task.sh",
            merge_script: "merge-bench.sh",
            scene: self.scene.clone(),
            dir: self.dir.clone(),
            tasks: self.tasks(),
            what: format!(
                "{} tasks ({} strategies × {} budgets) of the bench of {}",
                self.tasks(),
                self.samplers.len(),
                self.steps.len(),
                self.scene.display()
            ),
            folders: folders.into_iter().chain(output_folder).collect(),
            task_text: self.task_script(),
            merge_text: self.merge_script(),
        }
    }

    /// `bench-task.sh K`: strategy K / (budgets), budget K % (budgets).
    fn task_script(&self) -> String {
        let samplers: Vec<String> = self.samplers.iter().map(|s| quote_str(s)).collect();
        let steps: Vec<String> = self.steps.iter().map(|s| quote_str(&s.join(" "))).collect();
        let common: String = self
            .common
            .iter()
            .map(|o| format!(" {}", quote_str(o)))
            .collect();
        format!(
            r#"#!/bin/bash
# Runs task K of the {tasks} of the bench of {scene}: one strategy at one
# budget (written by glint farm).
# Usage: bench-task.sh K
set -euo pipefail
task="$1"
samplers=({samplers})
steps=({steps})
sampler="${{samplers[$((task / {per}))]}}"
read -r -a step <<< "${{steps[$((task % {per}))]}}"
threads="${{SLURM_CPUS_PER_TASK:-1}}"
exec {glint} bench {scene} --samplers "$sampler" "${{step[@]}}" -o {task_dir} --threads "$threads"{common}
"#,
            tasks = self.tasks(),
            scene = quote(&self.scene),
            samplers = samplers.join(" "),
            steps = steps.join(" "),
            per = self.steps.len(),
            glint = quote(&self.glint),
            task_dir = self.task_dir("\"$task\""),
            common = common,
        )
    }

    /// `merge-bench.sh`: the tasks' results put together.
    fn merge_script(&self) -> String {
        let tasks: Vec<String> = (0..self.tasks())
            .map(|k| self.task_dir(&k.to_string()))
            .collect();
        format!(
            r#"#!/bin/bash
# Fits and plots the {count} tasks of the bench of {scene} (written by glint farm).
set -euo pipefail
exec {glint} bench {scene} --merge {tasks} -o {output}
"#,
            count = self.tasks(),
            scene = quote(&self.scene),
            glint = quote(&self.glint),
            tasks = tasks.join(" "),
            output = quote(&self.output),
        )
    }
}

/// The tasks' `glint bench` command line as `glint bench` parses it.
fn parse_bench(
    scene: &Path,
    dir: &Path,
    options: &[String],
) -> Result<crate::bench::BenchArgs, Failure> {
    let task = dir.join("tasks").join("task-0");
    let fixed = [
        scene.as_os_str().to_owned(),
        "-o".into(),
        task.into_os_string(),
    ];
    match parse_command("bench", &fixed, options)? {
        Command::Bench(args) => Ok(args),
        _ => unreachable!("parsed as glint bench"),
    }
}

/// `options` without the split ones and their values (`--spp 1,4` or
/// `--spp=1,4`).
fn without_split(options: &[String]) -> Vec<String> {
    let mut kept = Vec::new();
    let mut skip_value = false;
    for option in options {
        if std::mem::take(&mut skip_value) {
            continue;
        }
        match option.split_once('=') {
            Some((name, _)) if SPLIT.contains(&name) => {}
            _ if SPLIT.contains(&option.as_str()) => skip_value = true,
            _ => kept.push(option.clone()),
        }
    }
    kept
}

/// `options` with `--reference`'s file as an absolute path (the tasks run
/// wherever the engine starts them), checked to be there.
fn with_absolute_reference(options: &[String]) -> Result<Vec<String>, Failure> {
    let absolute = |file: &str| -> Result<String, Failure> {
        let path = Path::new(file);
        if !path.is_file() {
            return Err(Failure::Input(format!(
                "--reference {file}: no such file; every task reads it"
            )));
        }
        let path = std::path::absolute(path).unwrap_or_else(|_| path.to_owned());
        Ok(path.display().to_string())
    };
    let mut out = Vec::with_capacity(options.len());
    let mut next_is_reference = false;
    for option in options {
        if std::mem::take(&mut next_is_reference) {
            out.push(absolute(option)?);
            continue;
        }
        match option.split_once('=') {
            Some(("--reference", file)) => out.push(format!("--reference={}", absolute(file)?)),
            _ => {
                next_is_reference = option == "--reference";
                out.push(option.clone());
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_split_options_leave_the_tasks_common_ones() {
        let options: Vec<String> = [
            "--samplers",
            "random,sobol",
            "--spp=1,4",
            "--reference",
            "ref.exr",
            "--light-samples",
            "2",
            "--repeat",
            "3",
        ]
        .map(str::to_owned)
        .to_vec();
        assert_eq!(
            without_split(&options),
            ["--reference", "ref.exr", "--repeat", "3"]
        );
    }
}
