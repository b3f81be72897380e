//! `glint grade --stages`: test vectors for each stage of a student's ray
//! tracer (`--write DIR`), and the check of a student's answers to them
//! (`--answers DIR`). The work is in `glint_grade::stages`; this file reads
//! the flags and prints what it returns.

use crate::Failure;
use glint_grade::stages::{self, DEFAULT_CASES};
use glint_grade::{GradeError, GradeScene};
use std::path::{Path, PathBuf};

/// What `glint grade --stages` was asked to do.
pub(crate) struct StageArgs {
    /// The scene the vectors are made from.
    pub(crate) scene: PathBuf,
    /// Write the vectors into this folder.
    pub(crate) write: Option<PathBuf>,
    /// Check the answers in this folder.
    pub(crate) answers: Option<PathBuf>,
    /// Cases per stage ([`DEFAULT_CASES`] if not given).
    pub(crate) cases: Option<u32>,
    /// Print JSON instead of text.
    pub(crate) format_json: bool,
}

/// Writes the vectors or checks the answers. Exit status (through
/// [`Failure`]): 0 when written, or when every answered case passes; 1
/// ([`Failure::Verdict`], with no message) when a case fails; 2 for bad input; 3 for a
/// failure of Glint's own.
pub(crate) fn run(args: &StageArgs) -> Result<(), Failure> {
    let cases = args.cases.unwrap_or(DEFAULT_CASES);
    stages::check_case_count(cases).map_err(failure)?;
    if args.scene.extension().and_then(|e| e.to_str()) != Some("toml") {
        return Err(Failure::Input(format!(
            "{}: --stages: the scene is a .toml file",
            args.scene.display()
        )));
    }
    match (&args.write, &args.answers) {
        (Some(dir), None) => write(args, dir, cases),
        (None, Some(dir)) => check(args, dir, cases),
        (Some(_), Some(_)) => Err(Failure::Input(
            "--stages: give --write DIR or --answers DIR, not both".into(),
        )),
        (None, None) => Err(Failure::Input(
            "--stages: give --write DIR (write the test vectors) or --answers DIR (check a student's answers)".into(),
        )),
    }
}

fn write(args: &StageArgs, dir: &Path, cases: u32) -> Result<(), Failure> {
    // The output folder before the scene: a bad one costs nothing.
    stages::check_write_dir(dir).map_err(failure)?;
    let scene = GradeScene::load(&args.scene).map_err(failure)?;
    let files = stages::write_vectors(&scene, cases, dir).map_err(failure)?;
    let text = match args.format_json {
        true => {
            let list: Vec<serde_json::Value> = files
                .iter()
                .map(
                    |(path, n)| serde_json::json!({"file": path.display().to_string(), "cases": n}),
                )
                .collect();
            serde_json::to_string_pretty(&list).expect("JSON") + "\n"
        }
        false => {
            let mut text = format!(
                "wrote the test vectors of {} ({} cases per stage asked for):\n",
                args.scene.display(),
                cases
            );
            for (path, n) in &files {
                text += &format!("  {} ({n} cases)\n", path.display());
            }
            text
        }
    };
    print(&text);
    Ok(())
}

fn check(args: &StageArgs, dir: &Path, cases: u32) -> Result<(), Failure> {
    let scene = GradeScene::load(&args.scene).map_err(failure)?;
    let checked = stages::check_answers(&scene, cases, dir).map_err(failure)?;
    print(&match args.format_json {
        true => stages::report_json(&checked),
        false => stages::report_text(&checked),
    });
    match checked.passed() {
        true => Ok(()),
        false => Err(Failure::Verdict(None)),
    }
}

/// Prints `text` on stdout; a reader that stops early (`| head`) is not an
/// error.
fn print(text: &str) {
    crate::output::say(text);
}

fn failure(e: GradeError) -> Failure {
    match e {
        GradeError::Input(m) => Failure::Input(m),
        GradeError::Internal(m) => Failure::Internal(m),
    }
}
