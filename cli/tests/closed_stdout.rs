//! A reader that stops early (`glint diff a b | head -1`) is not an error of
//! Glint's: every command whose standard output is closed ends as it would
//! have, with its own exit status, and neither panics nor complains.

mod common;

use common::{scene, stderr};
use std::path::Path;
use std::process::{Command, Output};

/// `glint ARGS | true` in `dir` (bash, so that glint's own exit status is
/// kept): `true` exits at once, so glint's writes to stdout fail (EPIPE).
fn into_a_closed_pipe(args: &[&str], dir: &Path) -> Output {
    Command::new("bash")
        .arg("-c")
        .arg("\"$0\" \"$@\" | true; exit ${PIPESTATUS[0]}")
        .arg(env!("CARGO_BIN_EXE_glint"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("bash runs")
}

#[test]
fn every_command_survives_a_closed_standard_output() {
    let dir = tempfile::tempdir().unwrap();
    let set1 = scene("cornell-set1");
    let small = [
        "--resolution",
        "16x16",
        "--spp",
        "1",
        "--light-samples",
        "1",
    ];
    let mut render = vec!["render", set1.as_str(), "-o", "a.pfm", "--stats"];
    render.extend(small);
    let mut other = vec!["render", set1.as_str(), "-o", "b.pfm", "--seed", "2"];
    other.extend(small);
    let mut bench = vec!["bench", set1.as_str(), "-o", "bench", "--spp", "1,4"];
    bench.extend([
        "--samplers",
        "random",
        "--resolution",
        "8x8",
        "--reference-spp",
        "16",
    ]);
    let mut explain = vec!["explain", set1.as_str(), "--pixel", "8,8"];
    explain.extend(small);
    let commands: Vec<(Vec<&str>, i32)> = vec![
        (render, 0),
        (other, 0),
        (vec!["diff", "a.pfm", "b.pfm"], 1), // they differ: status 1, as always
        (vec!["diff", "a.pfm", "a.pfm", "--json"], 0),
        (bench, 0),
        (vec!["stress", "--grid", "2"], 0),
        (
            vec!["export", "--mitsuba", set1.as_str(), "-o", "set1.xml"],
            0,
        ),
        (explain, 0),
        (vec!["grade", set1.as_str(), "a.pfm", "--no-cache"], 0),
        (vec!["--help"], 0),
    ];
    for (args, status) in commands {
        let o = into_a_closed_pipe(&args, dir.path());
        let err = stderr(&o);
        assert!(
            !err.contains("panicked")
                && !err.contains("Broken pipe")
                && !err.contains("internal error"),
            "{args:?}: {err}"
        );
        assert_eq!(o.status.code(), Some(status), "{args:?}: {err}");
    }
}
