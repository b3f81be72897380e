//! `glint`: the command-line front end. It only wires the stage crates together:
//! load a scene (scene crate), apply command-line overrides, render (integrator
//! crate) and write the film (camera crate).
//!
//! Exit status: 0 on success, 2 for bad input (usage, scene file, settings,
//! output path), 130 or 143 for a render stopped by Ctrl-C or SIGTERM (after
//! writing the pixels it finished), 1 for anything else. Errors are one line on stderr, prefixed
//! `glint: error: `.
//!
//! # Entry points
//! The command line is the clap parser [`Cli`]; each subcommand has a file of its
//! own: `render` ([`render::RenderArgs`], [`render::render`]), `assemble`
//! ([`assemble::AssembleArgs`], [`assemble::assemble`]), `farm`
//! ([`farm::FarmArgs`], [`farm::farm`]), `diff`
//! ([`diff::DiffArgs`], [`diff::diff`]), `bench` ([`bench::BenchArgs`],
//! [`bench::bench`]), `stress` ([`stress::StressArgs`], [`stress::stress`]),
//! `export` ([`export::ExportArgs`], [`export::export`]).
//! [`main`] maps every
//! failure to its exit status; [`output`] checks output paths before any work.

mod assemble;
mod bench;
mod diff;
mod explain;
mod export;
mod farm;
mod grade;
mod grade_stages;
mod interrupt;
mod output;
mod render;
mod stats;
mod stress;

use clap::builder::TypedValueParser;
use clap::error::{ContextKind, ContextValue};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "glint",
    version,
    about = "Glint: a ray tracer for direct lighting and texturing",
    long_about = "Glint: a ray tracer for direct lighting and texturing.\n\n\
                  Exit status: 0 on success, 2 for bad input (usage, scene or asset errors), \
                  130 (Ctrl-C) or 143 (SIGTERM) for an interrupted render, 1 otherwise."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene file to an image
    Render(render::RenderArgs),
    /// Put the tiles or windows of one render (glint render --tile or --crop)
    /// together into the whole image, checking they cover it exactly once
    Assemble(assemble::AssembleArgs),
    /// Write a render in tiles as a job for Slurm (a job array and a merge
    /// job) or GNU parallel (local cores or machines over ssh)
    Farm(farm::FarmArgs),
    /// Compare two images (metrics, heat map); exit status 1 beyond a tolerance
    Diff(diff::DiffArgs),
    /// Run time against error: sample patterns and filters over a ladder of
    /// budgets, measured against a reference (table, CSV, JSON, plot, heat maps)
    Bench(bench::BenchArgs),
    /// Numerical stress: generated configurations at scales 1e-4 to 1e6,
    /// counting shadow acne, light leaks and self-hits; exit status 1 if any
    Stress(stress::StressArgs),
    /// Write a scene for another renderer: --mitsuba, Mitsuba 3's XML with
    /// its meshes, images and environment map beside it
    Export(export::ExportArgs),
    /// Every stage's numbers for one pixel: camera, intersection, texture,
    /// lighting, film (text, or JSON with --json)
    Explain(explain::ExplainArgs),
    /// Whether submitted images are unbiased renders of their scenes, by a
    /// statistical test that tells a bug from noise: one scene's images or a
    /// whole class (table, CSV, JSON, HTML report with heat maps)
    Grade(grade::GradeArgs),
}

/// A failure and the exit status it maps to.
pub(crate) enum Failure {
    /// Bad input: usage, scene file, settings, output path. Exit status 2.
    Input(String),
    /// Anything else (I/O while writing, thread start-up). Exit status 1.
    Other(String),
    /// A bug; the panic hook has already printed it. Exit status 1.
    Panicked,
    /// Stopped by a signal after writing what was finished, which the message
    /// says; the exit status is the signal's (130 for Ctrl-C, 143 for SIGTERM).
    Interrupted { message: String, status: u8 },
    /// A negative verdict of a command that judges (`diff`: beyond the
    /// tolerance; `grade`: a submission failed or could not be read), said on
    /// stdout, and on stderr when there is a message. Exit status 1.
    Verdict(Option<String>),
    /// A failure of Glint's own in a command that judges (`diff`, `grade`),
    /// told apart from a negative verdict. Exit status 3.
    Internal(String),
}

/// Makes glibc's malloc give every block of 128 KiB or more its own mapping,
/// returned to the system when freed. By default glibc raises that threshold
/// to the size of each such block freed, up to 32 MiB: a BVH build's
/// thousands of per-subtree node lists then stay in the threads' heaps when
/// freed, and a 4M-triangle mesh's peak was 618 MiB where it is 498 with
/// this (Intel Xeon; `docs/speed.md`).
fn return_large_blocks_at_once() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: `mallopt` takes two integers and touches no memory of ours;
    // glibc documents it as safe to call before other threads exist
    // (MT-Unsafe init), and it runs first thing in `main`, before this
    // process starts any thread.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 128 * 1024);
    }
}

fn main() -> ExitCode {
    return_large_blocks_at_once();
    // A panic is a bug, never a reaction to input: report it on one line and
    // exit with status 1 (caught below) instead of Rust's 101 and a backtrace hint.
    std::panic::set_hook(Box::new(|info| {
        let message = info.to_string().replace('\n', " ");
        output::tell(&format!("glint: internal error (please report): {message}"));
    }));
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return usage_error(e),
    };
    let result = std::panic::catch_unwind(|| match &cli.command {
        Command::Render(args) => render::render(args),
        Command::Assemble(args) => assemble::assemble(args),
        Command::Farm(args) => farm::farm(args),
        Command::Diff(args) => diff::diff(args),
        Command::Bench(args) => bench::bench(args),
        Command::Stress(args) => stress::stress(args),
        Command::Export(args) => export::export(args),
        Command::Explain(args) => explain::explain(args),
        Command::Grade(args) => grade::grade(args),
    })
    .unwrap_or(Err(Failure::Panicked));
    // A command that judges must tell Glint's own failures from its verdict.
    let judging = matches!(cli.command, Command::Grade(_) | Command::Diff(_));
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Input(message)) => {
            output::tell(&format!("glint: error: {}", output::readable(&message)));
            ExitCode::from(2)
        }
        Err(Failure::Other(message)) => {
            output::tell(&format!("glint: error: {}", output::readable(&message)));
            ExitCode::from(if judging { 3 } else { 1 })
        }
        Err(Failure::Panicked) => ExitCode::from(if judging { 3 } else { 1 }),
        Err(Failure::Verdict(message)) => {
            // A verdict is the answer asked for, not an error.
            if let Some(message) = message {
                output::tell(&format!("glint: {}", output::readable(&message)));
            }
            ExitCode::from(1)
        }
        Err(Failure::Internal(message)) => {
            output::tell(&format!("glint: internal error: {message}"));
            ExitCode::from(3)
        }
        Err(Failure::Interrupted { message, status }) => {
            output::tell(&format!("glint: interrupted: {message}"));
            ExitCode::from(status)
        }
    }
}

/// Help and version go to stdout in full; a usage error is one line on stderr
/// (clap's first line, which names the problem, and the allowed values when
/// the value must be one of a list) with exit status 2.
fn usage_error(e: clap::Error) -> ExitCode {
    if !e.use_stderr() {
        let _ = e.print();
        return ExitCode::SUCCESS;
    }
    use clap::error::ErrorKind;
    if matches!(
        e.kind(),
        ErrorKind::MissingSubcommand | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    ) && std::env::args_os().len() <= 1
    {
        let commands: Vec<String> = <Cli as clap::CommandFactory>::command()
            .get_subcommands()
            .map(|c| c.get_name().to_owned())
            .collect();
        output::tell(&format!(
            "glint: error: no command given; give one of {} (see glint --help)",
            commands.join(", ")
        ));
        return ExitCode::from(2);
    }
    let rendered = e.render().to_string();
    let mut lines = rendered.lines();
    let first = lines.next().unwrap_or("invalid usage");
    let mut problem = first.strip_prefix("error: ").unwrap_or(first).to_owned();
    // "the following required arguments were not provided:" names them on
    // the next line.
    if problem.ends_with(':') {
        if let Some(next) = lines.next() {
            problem = format!("{problem} {}", next.trim());
        }
    }
    // Clap lists the allowed values on a line of their own, which the one
    // line would drop.
    if let Some(ContextValue::Strings(values)) = e.get(ContextKind::ValidValue) {
        problem = format!("{problem} [possible values: {}]", values.join(", "));
    }
    if let Some(ContextValue::String(flag)) = e.get(ContextKind::InvalidArg) {
        let args: Vec<String> = std::env::args().skip(1).collect();
        if let Some(hint) = farm::misplaced_option(&args, flag) {
            output::tell(&format!("glint: error: {}", output::readable(&hint)));
            return ExitCode::from(2);
        }
    }
    output::tell(&format!(
        "glint: error: {} (see glint --help)",
        output::readable(&problem)
    ));
    ExitCode::from(2)
}

/// A clap parser for one of the library's named values: the names are its own
/// list (so help and errors show them), the value its own `from_name`.
pub(crate) fn named<T: Clone + Send + Sync + 'static>(
    names: &'static [&'static str],
    from_name: fn(&str) -> Option<T>,
) -> impl TypedValueParser<Value = T> {
    clap::builder::PossibleValuesParser::new(names)
        .map(move |name: String| from_name(&name).expect("clap accepted only listed names"))
}

/// A progress bar drawn with `template` on stderr, only when stderr is a terminal.
pub(crate) fn progress_bar(template: &str) -> Option<ProgressBar> {
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = ProgressBar::new(0);
    bar.set_style(ProgressStyle::with_template(template).expect("valid template"));
    Some(bar)
}
