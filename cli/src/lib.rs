//! `glint`: the command-line front end, as a library ([`run`]) for the
//! `glint` program and the Python package's `glint` command. It only wires the stage crates together:
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
//! [`run`] maps every
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
mod mistake;
mod output;
mod render;
mod stats;
mod stress;
mod view;

use clap::builder::TypedValueParser;
use clap::error::{ContextKind, ContextValue};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use std::ffi::OsString;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::OnceLock;

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
    /// A local web inspector: images with exposure, A/B flips and heat maps,
    /// a scene rendered progressively, and every stage of a clicked pixel
    View(view::ViewArgs),
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

/// Runs the command line `args` (its first item the program's name, as
/// `std::env::args_os` gives it) and returns the exit status. `program` is
/// the path job scripts and `glint bench`'s runs call this program by (its
/// own executable where `None`).
pub fn run(program: Option<PathBuf>, args: Vec<OsString>) -> u8 {
    if let Some(program) = program {
        let _ = PROGRAM.set(program);
    }
    // A panic is a bug, never a reaction to input: report it on one line and
    // exit with status 1 (caught below) instead of Rust's 101 and a backtrace hint.
    std::panic::set_hook(Box::new(|info| {
        let message = info.to_string().replace('\n', " ");
        output::tell(&format!("glint: internal error (please report): {message}"));
    }));
    let cli = match Cli::try_parse_from(&args) {
        Ok(cli) => cli,
        Err(e) => return usage_error(e, &args),
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
        Command::View(args) => view::view(args),
    })
    .unwrap_or(Err(Failure::Panicked));
    // A command that judges must tell Glint's own failures from its verdict.
    let judging = matches!(cli.command, Command::Grade(_) | Command::Diff(_));
    match result {
        Ok(()) => 0,
        Err(Failure::Input(message)) => {
            output::tell(&format!("glint: error: {}", output::readable(&message)));
            2
        }
        Err(Failure::Other(message)) => {
            output::tell(&format!("glint: error: {}", output::readable(&message)));
            if judging {
                3
            } else {
                1
            }
        }
        Err(Failure::Panicked) => {
            if judging {
                3
            } else {
                1
            }
        }
        Err(Failure::Verdict(message)) => {
            // A verdict is the answer asked for, not an error.
            if let Some(message) = message {
                output::tell(&format!("glint: {}", output::readable(&message)));
            }
            1
        }
        Err(Failure::Internal(message)) => {
            output::tell(&format!("glint: internal error: {message}"));
            3
        }
        Err(Failure::Interrupted { message, status }) => {
            output::tell(&format!("glint: interrupted: {message}"));
            status
        }
    }
}

/// The path this program is called by from job scripts and `glint bench`'s
/// runs: the one [`run`] was given, else its own executable.
pub(crate) fn program() -> std::io::Result<PathBuf> {
    match PROGRAM.get() {
        Some(program) => Ok(program.clone()),
        None => std::env::current_exe(),
    }
}

static PROGRAM: OnceLock<PathBuf> = OnceLock::new();

/// Help and version go to stdout in full; a usage error is one line on stderr
/// (clap's first line, which names the problem, and the allowed values when
/// the value must be one of a list) with exit status 2.
fn usage_error(e: clap::Error, args: &[OsString]) -> u8 {
    if !e.use_stderr() {
        let _ = e.print();
        return 0;
    }
    use clap::error::ErrorKind;
    if matches!(
        e.kind(),
        ErrorKind::MissingSubcommand | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    ) && args.len() <= 1
    {
        let commands: Vec<String> = <Cli as clap::CommandFactory>::command()
            .get_subcommands()
            .map(|c| c.get_name().to_owned())
            .collect();
        output::tell(&format!(
            "glint: error: no command given; give one of {} (see glint --help)",
            commands.join(", ")
        ));
        return 2;
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
        let args: Vec<String> = args
            .iter()
            .skip(1)
            .map(|a| a.to_string_lossy().into_owned())
            .collect();
        if let Some(hint) = farm::misplaced_option(&args, flag) {
            output::tell(&format!("glint: error: {}", output::readable(&hint)));
            return 2;
        }
    }
    output::tell(&format!(
        "glint: error: {} (see glint --help)",
        output::readable(&problem)
    ));
    2
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
