//! What every farm job is made of, whatever it runs: the [`Farm`] its
//! engine writes (a first step, tasks, a merge), and the checks and quoting
//! its scripts share: the flags Glint manages itself, a `glint` command line
//! parsed as the task will run it, paths quoted for bash.

use crate::{Cli, Command, Failure};
use clap::Parser;
use std::path::{Path, PathBuf};

/// What the engines run: the first step if there is one, then tasks
/// `0..tasks`, each `TASK_SCRIPT I`, then the merge script once all have
/// succeeded.
pub(crate) struct Farm {
    /// A step the tasks wait for.
    pub(crate) first: Option<FirstStep>,
    /// Names the jobs, the logs and the Slurm scripts (`render.sbatch`,
    /// `assemble.sbatch`).
    pub(crate) kind: &'static str,
    pub(crate) merge_kind: &'static str,
    pub(crate) task_script: &'static str,
    pub(crate) merge_script: &'static str,
    pub(crate) scene: PathBuf,
    pub(crate) dir: PathBuf,
    pub(crate) tasks: u32,
    /// Said when the job is written: "5 tiles of SCENE".
    pub(crate) what: String,
    /// The folders to make.
    pub(crate) folders: Vec<PathBuf>,
    /// The text of `task_script` and of `merge_script`.
    pub(crate) task_text: String,
    pub(crate) merge_text: String,
}

/// Tasks that the tasks wait for: `KIND.sbatch`, an array of `tasks`
/// tasks, each `SCRIPT I`.
pub(crate) struct FirstStep {
    pub(crate) kind: &'static str,
    pub(crate) script: &'static str,
    pub(crate) tasks: u32,
    pub(crate) text: String,
}

/// `path`'s file name without its extension, or `fallback`.
pub(crate) fn file_stem(path: &Path, fallback: &str) -> String {
    path.file_stem()
        .map_or(fallback.into(), |s| s.to_string_lossy().into_owned())
}

/// A path flag's value, or its default (a name in the current directory).
pub(crate) fn or_default(given: &Option<PathBuf>, default: String) -> PathBuf {
    given.clone().unwrap_or_else(|| PathBuf::from(default))
}

/// `glint COMMAND FIXED... OPTIONS...` as glint parses it; a usage error
/// is bad input in the options after `--`.
/// For `glint farm ENGINE JOB … --flag value …` where `--flag` is not the
/// farm's but the job's command's own (`glint render --resolution`), what to
/// say: that the job's options go after `--`, with the command corrected.
pub(crate) fn misplaced_option(args: &[String], flag: &str) -> Option<String> {
    let farm = args.iter().position(|a| a == "farm")?;
    let (job_at, job) = args
        .iter()
        .enumerate()
        .skip(farm + 2)
        .find(|(_, a)| ["render", "bench", "grade"].contains(&a.as_str()))?;
    let name = flag.split('=').next().unwrap_or(flag);
    let command = <crate::Cli as clap::CommandFactory>::command();
    let takes_value = command
        .find_subcommand(job)?
        .get_arguments()
        .find(|a| a.get_long().is_some_and(|l| format!("--{l}") == name))?
        .get_action()
        .takes_values();
    let joined = format!("{name}=");
    let at = args
        .iter()
        .skip(job_at)
        .position(|a| a == name || a.starts_with(&joined))?
        + job_at;
    let end = args.iter().position(|a| a == "--").unwrap_or(args.len());
    if at > end {
        return None;
    }
    let with_value = takes_value && args[at] == name && at + 1 < end;
    let moved: Vec<&String> = args[at..=at + with_value as usize].iter().collect();
    let mut fixed: Vec<&String> = args[..end]
        .iter()
        .enumerate()
        .filter(|(i, _)| !(at..=at + with_value as usize).contains(i))
        .map(|(_, a)| a)
        .collect();
    let dashes = "--".to_string();
    fixed.push(&dashes);
    fixed.extend(moved);
    fixed.extend(args.iter().skip(end + 1));
    let shown: Vec<String> = fixed.iter().map(|a| quote_str(a)).collect();
    Some(format!(
        "{name} is an option of glint {job}, not of glint farm: the options of every task's glint {job} go after --; try: glint {}",
        shown.join(" ")
    ))
}

pub(crate) fn parse_command(
    command: &str,
    fixed: &[std::ffi::OsString],
    options: &[String],
) -> Result<Command, Failure> {
    let mut words: Vec<std::ffi::OsString> = vec!["glint".into(), command.into()];
    words.extend(fixed.iter().cloned());
    words.extend(options.iter().map(Into::into));
    let parsed = Cli::try_parse_from(words).map_err(|e| {
        let rendered = e.render().to_string();
        let first = rendered.lines().next().unwrap_or("invalid options");
        Failure::Input(format!(
            "{command} options after --: {}",
            first.strip_prefix("error: ").unwrap_or(first)
        ))
    })?;
    Ok(parsed.command)
}

/// Refuses an option among `options` that the farm sets for each task
/// (`managed`).
pub(crate) fn check_managed(
    command: &str,
    options: &[String],
    managed: &[&str],
) -> Result<(), Failure> {
    let name = |o: &String| o.split('=').next().unwrap_or(o).to_owned();
    match options.iter().find(|o| managed.contains(&name(o).as_str())) {
        Some(option) => Err(Failure::Input(format!(
            "{command} options after --: {option} is set by glint farm for each task (managed: {})",
            managed.join(", ")
        ))),
        None => Ok(()),
    }
}

/// `path` quoted for bash.
pub(crate) fn quote(path: &Path) -> String {
    quote_str(&path.to_string_lossy())
}

/// `text` as one bash word: as is where it is plainly safe, else in single quotes.
pub(crate) fn quote_str(text: &str) -> String {
    let plain = !text.is_empty()
        && text
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "/._-+=:,%@".contains(c));
    match plain {
        true => text.to_owned(),
        false => format!("'{}'", text.replace('\'', r"'\''")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_are_quoted_for_bash_only_where_needed() {
        assert_eq!(quote_str("/a/b-c_d.toml"), "/a/b-c_d.toml");
        assert_eq!(quote_str("a b"), "'a b'");
        assert_eq!(quote_str("it's"), r"'it'\''s'");
        assert_eq!(quote_str("$HOME"), "'$HOME'");
        assert_eq!(quote_str(""), "''");
    }
}
