//! The bad-input corpus (`tests/bad-inputs/`, its README says how a case is
//! laid out): every case, run as a user would, gives one clear error line
//! containing its `expected` text, exit status 2, no panic, within a bounded
//! time and address space, and leaves the folder it ran in as it was: no
//! output file, an existing output untouched, no temporary file behind.

mod common;

use common::{assert_input_error, stderr};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Longest a case may take: a bad input is refused, not rendered.
const TIME_LIMIT: Duration = Duration::from_secs(20);

/// The address space a case runs in (`ulimit -v`, KiB): an input that would
/// exhaust memory must be refused before allocating, not abort.
const ADDRESS_SPACE_KIB: u64 = 4 << 20;

/// What a user had in the folder before the run: `out.png`, the default
/// output of every case, must be there after it unchanged.
const PRECIOUS: &[u8] = b"an image the user wants to keep";

fn corpus() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/bad-inputs")
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), target).unwrap();
        }
    }
}

/// Every file under `dir` with its contents, by path relative to `dir`.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<PathBuf, Vec<u8>>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(root, &path, out);
            } else {
                let bytes = std::fs::read(&path).unwrap();
                out.insert(path.strip_prefix(root).unwrap().to_owned(), bytes);
            }
        }
    }
    let mut files = BTreeMap::new();
    walk(dir, dir, &mut files);
    files
}

/// `glint render scene.toml ARGS` in `dir`, under the address-space limit,
/// killed past the time limit (which fails the case).
fn render(dir: &Path, args: &[String]) -> (Output, Duration) {
    let start = Instant::now();
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {ADDRESS_SPACE_KIB} && exec \"$0\" \"$@\""
        ))
        .arg(env!("CARGO_BIN_EXE_glint"))
        .arg("render")
        .arg("scene.toml")
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("sh runs");
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > TIME_LIMIT {
            child.kill().unwrap();
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    (child.wait_with_output().unwrap(), start.elapsed())
}

#[test]
fn every_bad_input_gives_one_clear_error_and_changes_nothing() {
    let mut cases: Vec<PathBuf> = std::fs::read_dir(corpus())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    cases.sort();
    assert!(cases.len() >= 40, "the corpus has {} cases", cases.len());
    for case in &cases {
        let name = case.file_name().unwrap().to_string_lossy();
        let expected = std::fs::read_to_string(case.join("expected"))
            .unwrap_or_else(|_| panic!("{name}: no `expected` file"));
        let args: Vec<String> = std::fs::read_to_string(case.join("args"))
            .map(|a| a.lines().map(str::to_owned).collect())
            .unwrap_or_default();
        let dir = tempfile::tempdir().unwrap();
        copy_dir(case, dir.path());
        std::fs::remove_file(dir.path().join("expected")).unwrap();
        let _ = std::fs::remove_file(dir.path().join("args"));
        std::fs::write(dir.path().join("out.png"), PRECIOUS).unwrap();
        let before = snapshot(dir.path());
        let mut args = args;
        if !args.iter().any(|a| a == "-o") {
            args.extend(["-o".to_owned(), "out.png".to_owned()]);
        }
        let (output, took) = render(dir.path(), &args);
        assert!(took < TIME_LIMIT, "{name}: still running after {took:?}");
        assert!(
            std::panic::catch_unwind(|| assert_input_error(&output, expected.trim())).is_ok(),
            "{name}: status {:?}, stderr {:?}, expected {:?}",
            output.status.code(),
            stderr(&output),
            expected.trim()
        );
        assert_eq!(snapshot(dir.path()), before, "{name}: the folder changed");
    }
}
