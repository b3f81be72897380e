//! What every test of the `glint` binary needs: running it as a user does, the
//! shipped scenes, its output as text, and the rule for bad input.

#![allow(dead_code)] // each test file uses its own part of this

pub mod browser;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Flags that make a shipped scene render in milliseconds: 24 × 24 pixels, 4
/// camera samples and 4 light samples each.
pub const SMALL: [&str; 6] = [
    "--resolution",
    "24x24",
    "--spp",
    "4",
    "--light-samples",
    "4",
];

/// A correct submission: 4 random camera samples and 4 random light
/// samples, seed 7.
pub const CORRECT: [&str; 10] = [
    "--spp",
    "4",
    "--sampler",
    "random",
    "--light-samples",
    "4",
    "--light-sampler",
    "random",
    "--seed",
    "7",
];

/// Runs the built `glint` with `args` in `dir`.
pub fn glint(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_glint"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("glint runs")
}

/// The absolute path of a shipped scene, `scenes/NAME.toml`.
pub fn scene(name: &str) -> String {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../scenes/{name}.toml"));
    p.to_str().unwrap().to_owned()
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Bad input: exit status 2, one line on stderr, `glint: error: …` containing
/// `expected`, no panic, nothing on stdout.
pub fn assert_input_error(o: &Output, expected: &str) {
    if let Some(problem) = input_error_problem(o, expected) {
        panic!("{problem}");
    }
}

/// What makes `o` not the answer to bad input [`assert_input_error`] expects,
/// if anything.
pub fn input_error_problem(o: &Output, expected: &str) -> Option<String> {
    let err = stderr(o);
    if o.status.code() != Some(2) {
        Some(format!("status {:?}, not 2: {err}", o.status.code()))
    } else if err.lines().count() != 1 {
        Some(format!("not one line: {err}"))
    } else if !err.starts_with("glint: error: ") {
        Some(format!("not `glint: error: …`: {err}"))
    } else if !err.contains(expected) {
        Some(format!("expected {expected:?} in {err}"))
    } else if err.contains("panicked") || err.contains("backtrace") {
        Some(format!("a panic: {err}"))
    } else if !o.stdout.is_empty() {
        Some(format!("stdout: {}", stdout(o)))
    } else {
        None
    }
}

/// The repository's root.
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The Python of a virtual environment where `import mitsuba` works
/// (`GLINT_MITSUBA_VENV`, or `target/mitsuba-venv` as `.ci/run` and
/// `measure/mitsuba/compare.sh` make it), a real part ([`real_part`]):
/// `None` where there is none, after saying so; under `CI=true` a missing
/// one fails the test.
pub fn python_with_mitsuba() -> Option<PathBuf> {
    let install = "then pip install mitsuba; measure/mitsuba/README.md";
    python_in_venv(
        ("GLINT_MITSUBA_VENV", "target/mitsuba-venv"),
        "mitsuba",
        install,
    )
}

/// The Python of the virtual environment `$VAR` (or `default` in the
/// repository) where `import MODULES` works, a real part ([`real_part`]);
/// where there is none, `install` says how to make it.
pub fn python_in_venv(
    (var, default): (&str, &str),
    modules: &str,
    install: &str,
) -> Option<PathBuf> {
    let venv = std::env::var_os(var)
        .map(PathBuf::from)
        .unwrap_or_else(|| repo().join(default));
    let python = venv.join("bin/python");
    let imports = Command::new(&python)
        .args(["-c", &format!("import {modules}")])
        .output()
        .is_ok_and(|o| o.status.success());
    let missing = (!imports).then(|| {
        format!(
            "no Python that imports {modules} in {} (python3 -m venv it, {install})",
            venv.display()
        )
    });
    real_part(missing).then_some(python)
}

/// A small class in `dir`: `scenes/` with Set 1 and Set 2, and
/// `class.csv` listing three students' 32 × 32 renders of both ([`CORRECT`]'s
/// settings, a seed each), one of them of the wrong scene, and a fourth
/// student's file that is not there. Returns the manifest.
pub fn small_class(dir: &Path) -> PathBuf {
    let scenes = dir.join("scenes");
    std::fs::create_dir_all(&scenes).unwrap();
    for set in ["set1", "set2"] {
        std::fs::copy(
            scene(&format!("cornell-{set}")),
            scenes.join(format!("{set}.toml")),
        )
        .unwrap();
    }
    let mut manifest = String::from("student,scene,file\n");
    for (k, student) in ["ada", "bo", "cy"].into_iter().enumerate() {
        std::fs::create_dir_all(dir.join("class").join(student)).unwrap();
        for set in ["set1", "set2"] {
            // Bo renders Set 1 for both.
            let rendered = if student == "bo" { "set1" } else { set };
            let file = format!("class/{student}/{set}.png");
            let seed = (7 + k).to_string();
            let scene_file = scenes.join(format!("{rendered}.toml"));
            let scene_file = scene_file.to_str().unwrap();
            let mut args = vec!["render", scene_file, "--resolution", "32x32", "-o", &file];
            // CORRECT's settings, with each student's own seed.
            args.extend_from_slice(&CORRECT[..8]);
            args.extend(["--seed", &seed]);
            let o = glint(&args, dir);
            assert!(o.status.success(), "{}", stderr(&o));
            manifest += &format!("{student},{set},{file}\n");
        }
    }
    manifest += "dee,set1,class/dee/set1.png\n";
    let path = dir.join("class.csv");
    std::fs::write(&path, manifest).unwrap();
    path
}

/// Asserts that folders `a` and `b` hold the same files, byte for byte.
pub fn assert_same_folders(a: &Path, b: &Path) {
    fn files(root: &Path, dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            match path.is_dir() {
                true => files(root, &path, out),
                false => out.push(path.strip_prefix(root).unwrap().to_owned()),
            }
        }
    }
    let (mut left, mut right) = (Vec::new(), Vec::new());
    files(a, a, &mut left);
    files(b, b, &mut right);
    left.sort();
    right.sort();
    assert_eq!(
        left,
        right,
        "{} and {} hold other files",
        a.display(),
        b.display()
    );
    for file in &left {
        assert!(
            std::fs::read(a.join(file)).unwrap() == std::fs::read(b.join(file)).unwrap(),
            "{} differs",
            file.display()
        );
    }
}

/// Whether a test may use a real part it needs (a program from a Debian
/// package, a daemon): `missing` says why it cannot, or is `None`. Where the
/// part is missing, the test says so and skips that part; under `CI=true`,
/// where `.ci/run` has installed every part, a missing one fails the test.
pub fn real_part(missing: Option<String>) -> bool {
    let Some(why) = missing else {
        return true;
    };
    assert!(
        std::env::var("CI").as_deref() != Ok("true"),
        "{why} (CI=true: .ci/run installs every part the tests need)"
    );
    eprintln!("skipped: {why}");
    false
}

/// Why a program cannot be run with `--version`, if it cannot, with the
/// Debian package that has it.
pub fn program_missing(program: &str, package: &str) -> Option<String> {
    let runs = Command::new(program)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    (!runs).then(|| format!("no {program} (apt-get install {package})"))
}
