//! `glint farm`: a render split into tiles, written as a job for an engine
//! that already runs work across machines, not run by a scheduler of
//! Glint's own: a Slurm job array (`sbatch`) with a merge job that waits for
//! it, or a GNU parallel command over local cores or machines reached by ssh.
//!
//! Both engines drive one script per tile (`render-tile.sh I`): it renders
//! tile I with `glint render --tile I/N`, continuing the tile's partial
//! render with `--resume` when an earlier run was stopped (Slurm's requeue,
//! a time limit's SIGTERM, GNU parallel's `--resume-failed`). A tile rendered
//! again gives the same bytes. `assemble.sh` then puts the tiles together
//! (`glint assemble`), which refuses an incomplete set and names the tiles
//! to render again. A render in tiles ([`tiles`]), a bench sweep ([`sweep`])
//! and a class's grading ([`class`]) each fill one [`Farm`]
//! ([`script`]): its task and merge scripts; this module writes it for an
//! engine and submits it.
//! docs/cluster.md walks through both engines.

mod class;
mod script;
mod sweep;
mod tiles;

pub(crate) use script::misplaced_option;
use script::{quote, Farm, FirstStep};
use tiles::{FarmRender, Plan};

use crate::Failure;
use clap::{Args, Subcommand};
use std::path::{Path, PathBuf};

#[derive(Args)]
pub(crate) struct FarmArgs {
    #[command(subcommand)]
    engine: Engine,
}

#[derive(Subcommand)]
enum Engine {
    /// A Slurm job array, one task per tile, bench task or part (with, for a
    /// class, an array of reference tasks before it), and a merge job that
    /// runs once every task has succeeded
    Slurm {
        #[command(flatten)]
        options: SlurmOptions,
        #[command(subcommand)]
        job: Job,
    },
    /// A GNU parallel command, one job per tile, bench task or part, on this
    /// machine's cores or on machines reached by ssh (run-parallel.sh), then
    /// the merge
    Parallel {
        #[command(flatten)]
        options: ParallelOptions,
        #[command(subcommand)]
        job: Job,
    },
}

#[derive(Subcommand)]
enum Job {
    /// One frame in tiles: glint render --tile I/N for each I, then glint assemble
    Render(FarmRender),
    /// A glint bench sweep: one task per strategy and budget against one
    /// reference file, then glint bench --merge (the fits and the plot)
    Bench(sweep::FarmBench),
    /// A class's grading: its references rendered into a shared cache, then
    /// one task per part of the submissions (glint grade --part I/N), then
    /// glint grade --merge (the report)
    Grade(class::FarmGrade),
}

#[derive(Args)]
struct SlurmOptions {
    /// Tasks of the array running at once (sbatch --array=0-N%M)
    #[arg(long, value_name = "M", global = true, value_parser = clap::value_parser!(u32).range(1..))]
    max_running: Option<u32>,

    /// Time limit of each task, as sbatch takes it (MM, HH:MM:SS or D-HH:MM:SS)
    #[arg(long, value_name = "TIME", global = true, value_parser = parse_slurm_time)]
    time: Option<String>,

    /// Memory of each task, as sbatch takes it (e.g. 2G, 500M)
    #[arg(long, value_name = "SIZE", global = true, value_parser = parse_slurm_memory)]
    mem: Option<String>,

    /// CPUs of each task; glint renders with as many threads
    #[arg(long, value_name = "N", global = true, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1024))]
    cpus: u32,

    /// The partition (queue) to submit to
    #[arg(long, value_name = "NAME", global = true, value_parser = parse_slurm_name)]
    partition: Option<String>,

    /// Submit the jobs (sbatch) instead of printing the commands
    #[arg(long, global = true)]
    submit: bool,
}

#[derive(Args)]
struct ParallelOptions {
    /// Jobs at once on each machine, as GNU parallel takes it (e.g. 2, 100%)
    /// [default: one per core]; each renders on one thread
    #[arg(long, value_name = "N", global = true, value_parser = parse_jobs)]
    jobs: Option<String>,

    /// Machines to run on, one ssh login per line (GNU parallel's
    /// --sshloginfile; ":" for this machine). They must see the scene, glint
    /// and the farm directory at the same paths (a shared file system)
    #[arg(long, value_name = "FILE", global = true)]
    sshloginfile: Option<PathBuf>,

    /// Run the command now instead of printing it
    #[arg(long, global = true)]
    run: bool,
}

pub(crate) fn farm(args: &FarmArgs) -> Result<(), Failure> {
    match &args.engine {
        Engine::Slurm { options, job } => slurm(options, &job_of(job)?),
        Engine::Parallel { options, job } => parallel(options, &job_of(job)?),
    }
}

/// The job, checked and planned; nothing written yet.
fn job_of(job: &Job) -> Result<Farm, Failure> {
    match job {
        Job::Render(render) => Ok(Plan::new(render)?.farm()),
        Job::Bench(bench) => Ok(sweep::Sweep::new(bench)?.farm()),
        Job::Grade(grade) => Ok(class::ClassPlan::new(grade)?.farm()),
    }
}

/// Writes the job array and the merge job, and submits them or says how.
fn slurm(options: &SlurmOptions, farm: &Farm) -> Result<(), Failure> {
    if farm.dir.to_string_lossy().chars().any(char::is_whitespace) {
        return Err(Failure::Input(format!(
            "--dir {}: Slurm's #SBATCH lines cannot hold a path with spaces; choose another folder",
            farm.dir.display()
        )));
    }
    if options.submit {
        needs("sbatch", "--version", "Slurm's sbatch")?;
    }
    farm.write()?;
    let (array, merge) = (
        farm.dir.join(format!("{}.sbatch", farm.kind)),
        farm.dir.join(format!("{}.sbatch", farm.merge_kind)),
    );
    let first = match &farm.first {
        Some(step) => {
            let path = farm.dir.join(format!("{}.sbatch", step.kind));
            write_script(&path, &farm.slurm_first(step, options))?;
            Some(path)
        }
        None => None,
    };
    write_script(&array, &farm.slurm_array(options))?;
    write_script(&merge, &farm.slurm_merge(options))?;
    if options.submit {
        return submit(farm, first.as_deref(), &array, &merge);
    }
    let array_command = match &first {
        Some(first) => format!(
            "first=$(sbatch --parsable {})\njob=$(sbatch --parsable --dependency=afterok:${{first%%;*}} {})",
            quote(first),
            quote(&array)
        ),
        None => format!("job=$(sbatch --parsable {})", quote(&array)),
    };
    crate::output::say(&format!(
        "wrote {}: {}; submit with\n{array_command}\nsbatch --dependency=afterok:${{job%%;*}} {}\n",
        farm.dir.display(),
        farm.what,
        quote(&merge)
    ));
    Ok(())
}

/// Writes the GNU parallel script, and runs it or says how.
fn parallel(options: &ParallelOptions, farm: &Farm) -> Result<(), Failure> {
    if options.run {
        needs("parallel", "--version", "GNU parallel")?;
    }
    farm.write()?;
    let script = farm.dir.join("run-parallel.sh");
    write_script(&script, &farm.parallel(options))?;
    if options.run {
        return run_parallel(&script);
    }
    crate::output::say(&format!(
        "wrote {}: {}; run with\n{}\n",
        farm.dir.display(),
        farm.what,
        quote(&script)
    ));
    Ok(())
}

impl Farm {
    /// Makes the folders and writes the job's scripts.
    fn write(&self) -> Result<(), Failure> {
        for dir in &self.folders {
            std::fs::create_dir_all(dir)
                .map_err(|e| Failure::Other(format!("{}: cannot make it: {e}", dir.display())))?;
        }
        if let Some(step) = &self.first {
            write_script(&self.dir.join(step.script), &step.text)?;
        }
        write_script(&self.dir.join(self.task_script), &self.task_text)?;
        write_script(&self.dir.join(self.merge_script), &self.merge_text)
    }

    /// `KIND.sbatch`: the job array, task I running `TASK_SCRIPT I`.
    fn slurm_array(&self, options: &SlurmOptions) -> String {
        self.slurm_tasks(
            (self.kind, self.task_script, self.tasks),
            &self.what,
            options,
        )
    }

    /// The first step's `KIND.sbatch`, an array as the tasks'.
    fn slurm_first(&self, step: &FirstStep, options: &SlurmOptions) -> String {
        let what = format!("{} {}, before the {}", step.tasks, step.kind, self.what);
        self.slurm_tasks((step.kind, step.script, step.tasks), &what, options)
    }

    /// A job array named `kind` of `tasks` tasks, task I running `script I`
    /// (of `what`).
    fn slurm_tasks(
        &self,
        (kind, script, tasks): (&str, &str, u32),
        what: &str,
        options: &SlurmOptions,
    ) -> String {
        let throttle = options
            .max_running
            .map_or(String::new(), |m| format!("%{m}"));
        let mut lines = vec![
            "#!/bin/bash".to_owned(),
            format!("#SBATCH --job-name=glint-{kind}-{}", self.name()),
            format!("#SBATCH --array=0-{}{throttle}", tasks - 1),
            format!(
                "#SBATCH --output={}/logs/{kind}_%A_%a.log",
                self.dir.display(),
            ),
            // A requeued task adds to its log instead of replacing it.
            "#SBATCH --open-mode=append".to_owned(),
            format!("#SBATCH --cpus-per-task={}", options.cpus),
            // Requeued after a node failure or preemption; a tile then
            // continues from its partial render.
            "#SBATCH --requeue".to_owned(),
        ];
        lines.extend(self.slurm_limits(options));
        lines.push(format!(
            "# Task $SLURM_ARRAY_TASK_ID of {what} (written by glint farm)."
        ));
        lines.push(format!(
            "exec {} \"$SLURM_ARRAY_TASK_ID\"",
            quote(&self.dir.join(script))
        ));
        lines.join("\n") + "\n"
    }

    /// `MERGE_KIND.sbatch`: the merge, submitted to wait for the array.
    fn slurm_merge(&self, options: &SlurmOptions) -> String {
        let mut lines = vec![
            "#!/bin/bash".to_owned(),
            format!(
                "#SBATCH --job-name=glint-{}-{}",
                self.merge_kind,
                self.name()
            ),
            format!(
                "#SBATCH --output={}/logs/{}_%j.log",
                self.dir.display(),
                self.merge_kind
            ),
            "#SBATCH --cpus-per-task=1".to_owned(),
        ];
        lines.extend(self.slurm_limits(options));
        lines.push(format!("exec {}", quote(&self.dir.join(self.merge_script))));
        lines.join("\n") + "\n"
    }

    fn slurm_limits(&self, options: &SlurmOptions) -> Vec<String> {
        let mut lines = Vec::new();
        if let Some(time) = &options.time {
            lines.push(format!("#SBATCH --time={time}"));
        }
        if let Some(mem) = &options.mem {
            lines.push(format!("#SBATCH --mem={mem}"));
        }
        if let Some(partition) = &options.partition {
            lines.push(format!("#SBATCH --partition={partition}"));
        }
        lines
    }

    /// `run-parallel.sh`: every task through GNU parallel, then the merge.
    /// Run again, it runs only the tasks whose job failed (the job log and
    /// `--resume-failed`), a tile continuing its partial render.
    fn parallel(&self, options: &ParallelOptions) -> String {
        let mut flags = vec!["--resume-failed".to_owned(), "--halt never".to_owned()];
        if let Some(jobs) = &options.jobs {
            flags.push(format!("--jobs {jobs}"));
        }
        if let Some(logins) = &options.sshloginfile {
            let logins = std::path::absolute(logins).unwrap_or_else(|_| logins.clone());
            flags.push(format!("--sshloginfile {}", quote(&logins)));
        }
        // Each step's jobs, then a stop if any failed.
        let step = |joblog: &str, script: &str, tasks: u32| {
            let joblog = self.dir.join(joblog);
            format!(
                r#"parallel --joblog {log} {flags} {script} {{}} ::: $(seq 0 {last})
status=$?
if [ $status -ne 0 ]; then
  echo "glint farm: $status job(s) failed (see {log_text}); run this script again to run them" >&2
  exit $status
fi
"#,
                log = quote(&joblog),
                flags = flags.join(" "),
                script = quote(&self.dir.join(script)),
                last = tasks - 1,
                log_text = joblog.display(),
            )
        };
        let first = match &self.first {
            Some(first) => format!(
                "# First: {kind}.\n{jobs}# Then the tasks.\n",
                kind = first.kind,
                jobs = step(&format!("{}.joblog", first.kind), first.script, first.tasks)
            ),
            None => String::new(),
        };
        format!(
            r#"#!/bin/bash
# Runs the {what} with GNU parallel, then the merge (written by glint farm).
# Run again after a failure: only the failed tasks run again.
set -uo pipefail
{first}{tasks}exec {merge}
"#,
            what = self.what,
            tasks = step("parallel.joblog", self.task_script, self.tasks),
            merge = quote(&self.dir.join(self.merge_script)),
        )
    }

    /// A name for the jobs: the scene's.
    fn name(&self) -> String {
        let stem = self.scene.file_stem().unwrap_or_default().to_string_lossy();
        stem.chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                    c
                } else {
                    '_'
                }
            })
            .collect()
    }
}

fn write_script(path: &Path, text: &str) -> Result<(), Failure> {
    crate::output::write_text(path, text)?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755))
            .map_err(|e| Failure::Other(format!("{}: {e}", path.display())))?;
    }
    Ok(())
}

/// Refuses, before anything is written, to start an engine that is not
/// installed: `program` must run with `argument`.
fn needs(program: &str, argument: &str, name: &str) -> Result<(), Failure> {
    let runs = std::process::Command::new(program)
        .arg(argument)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok();
    match runs {
        true => Ok(()),
        false => Err(Failure::Input(format!(
            "{name} ({program}) is not installed here: write the job without starting it, and start it where {program} runs"
        ))),
    }
}

/// Submits the array, then the merge with a dependency on it.
fn submit(farm: &Farm, first: Option<&Path>, array: &Path, merge: &Path) -> Result<(), Failure> {
    let sbatch = |args: &[&std::ffi::OsStr]| -> Result<String, Failure> {
        let out = std::process::Command::new("sbatch")
            .arg("--parsable")
            .args(args)
            .output()
            .map_err(|e| Failure::Other(format!("cannot run sbatch: {e} (is Slurm installed?)")))?;
        if !out.status.success() {
            return Err(Failure::Other(format!(
                "sbatch failed: {}",
                String::from_utf8_lossy(&out.stderr).trim()
            )));
        }
        let id = String::from_utf8_lossy(&out.stdout);
        Ok(id.trim().split(';').next().unwrap_or_default().to_owned())
    };
    let after = |job: &str| format!("--dependency=afterok:{job}");
    let mut said = String::from("submitted ");
    let job = match (first, &farm.first) {
        (Some(first), Some(step)) => {
            let first_job = sbatch(&[first.as_os_str()])?;
            said += &format!("job {first_job} ({}), then ", step.kind);
            sbatch(&[after(&first_job).as_ref(), array.as_os_str()])?
        }
        _ => sbatch(&[array.as_os_str()])?,
    };
    let merge_job = sbatch(&[after(&job).as_ref(), merge.as_os_str()])?;
    crate::output::say(&format!(
        "{said}job array {job} ({}) and job {merge_job} ({}, after the array succeeds)\n",
        farm.kind, farm.merge_kind
    ));
    Ok(())
}

fn run_parallel(script: &Path) -> Result<(), Failure> {
    let status = std::process::Command::new(script)
        .status()
        .map_err(|e| Failure::Other(format!("cannot run {}: {e}", script.display())))?;
    match status.code() {
        Some(0) => Ok(()),
        code => Err(Failure::Other(format!(
            "{} failed (exit status {}); run it again to run the failed tasks",
            script.display(),
            code.map_or("none".into(), |c| c.to_string())
        ))),
    }
}

/// A Slurm time limit: minutes, MM:SS, HH:MM:SS, D-HH, D-HH:MM or D-HH:MM:SS.
fn parse_slurm_time(text: &str) -> Result<String, String> {
    let (days, rest) = match text.split_once('-') {
        Some((d, rest)) => (Some(d), rest),
        None => (None, text),
    };
    let parts: Vec<&str> = rest.split(':').collect();
    let numbers = days.into_iter().chain(parts.iter().copied());
    let valid = parts.len() <= 3
        && numbers
            .into_iter()
            .all(|p| !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()));
    match valid {
        true => Ok(text.to_owned()),
        false => Err(format!(
            "expected a Slurm time limit (MM, HH:MM:SS or D-HH:MM:SS), got \"{text}\""
        )),
    }
}

/// A Slurm memory size: a whole number with an optional K, M, G or T.
fn parse_slurm_memory(text: &str) -> Result<String, String> {
    let digits = text.trim_end_matches(['K', 'M', 'G', 'T', 'k', 'm', 'g', 't']);
    let valid = !digits.is_empty()
        && digits.bytes().all(|b| b.is_ascii_digit())
        && text.len() - digits.len() <= 1;
    match valid {
        true => Ok(text.to_owned()),
        false => Err(format!(
            "expected a memory size such as 2G or 500M, got \"{text}\""
        )),
    }
}

/// A partition name: letters, digits, `-`, `_`, `.` and `,` (a list).
fn parse_slurm_name(text: &str) -> Result<String, String> {
    let valid = !text.is_empty()
        && text
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_.,".contains(c));
    match valid {
        true => Ok(text.to_owned()),
        false => Err(format!("expected a partition name, got \"{text}\"")),
    }
}

/// GNU parallel's job count: a whole number, or a percentage of the cores.
fn parse_jobs(text: &str) -> Result<String, String> {
    let digits = text.strip_suffix('%').unwrap_or(text);
    let valid = !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit());
    match valid {
        true => Ok(text.to_owned()),
        false => Err(format!(
            "expected a job count such as 2 or 100%, got \"{text}\""
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slurm_values_are_checked() {
        for good in ["10", "00:10:00", "1-00:00:00", "1-12", "30:00"] {
            assert!(parse_slurm_time(good).is_ok(), "{good}");
        }
        for bad in ["", "ten", "1:2:3:4", "1-", "00:1a:00"] {
            assert!(parse_slurm_time(bad).is_err(), "{bad}");
        }
        assert!(parse_slurm_memory("2G").is_ok() && parse_slurm_memory("500").is_ok());
        for bad in ["", "G", "2GG", "two"] {
            assert!(parse_slurm_memory(bad).is_err(), "{bad}");
        }
        assert!(parse_jobs("100%").is_ok() && parse_jobs("2").is_ok());
        assert!(parse_jobs("x").is_err() && parse_slurm_name("a b").is_err());
    }
}
