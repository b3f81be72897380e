//! The docs' recipes followed literally: `tools/student/tracer.py`, a ray
//! tracer written from Glint's docs alone (no Glint source), answers every
//! stage of `glint grade --stages` and writes `glint-explain/1` documents,
//! and must agree with Glint on every shipped course scene, at both ends of
//! the shadow-ray offsets the docs allow, at the render's texture level and
//! at the report's. A recipe that cannot be followed literally fails here.
//!
//! The pixels compared are `tools/student/pixels.txt`: a wall, a penumbra, a
//! sphere's u seam, the light, a textured sphere, mirrors and the
//! background. They leave out the grazes where a fixed-offset shadow ray
//! decides otherwise than Glint's at an allowed offset (docs/scene-format.md,
//! step 9, "A graze"), as `grade --stages` leaves them out of its cases.
//! Needs `python3` (standard library only).

mod common;

use common::{glint, scene, stderr, stdout};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Both ends of the offsets the docs allow, as fractions of the scene's
/// size (`glint_explain::rules::SHADOW_EPSILON`).
const FRACTIONS: [&str; 2] = ["1e-5", "1e-4"];

/// The deterministic recipe, with one camera sample and with the third of
/// four.
const RECIPE: [&str; 8] = [
    "--sampler",
    "grid",
    "--light-samples",
    "16",
    "--light-sampler",
    "grid",
    "--environment-samples",
    "0",
];
const SAMPLES: [&[&str]; 2] = [&["--spp", "1"], &["--spp", "4", "--sample", "2"]];

fn tracer() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tools/student/tracer.py")
}

/// Whether `python3` runs ([`common::real_part`]).
fn python_runs() -> bool {
    common::real_part(common::program_missing("python3", "python3"))
}

/// Runs the tracer with `args` in `dir`; it prints nothing when it succeeds.
fn run_tracer(args: &[&str], dir: &Path) {
    let o = Command::new("python3")
        .arg(tracer())
        .args(args)
        .current_dir(dir)
        .output()
        .expect("python3 runs");
    assert!(
        o.status.success(),
        "tracer.py {}: {}",
        args.join(" "),
        stderr(&o)
    );
}

/// The pixels of `name` in `tools/student/pixels.txt`.
fn pixels(name: &str) -> Vec<String> {
    let list = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tools/student/pixels.txt");
    let text = std::fs::read_to_string(list).unwrap();
    let pixels: Vec<String> = text
        .lines()
        .filter_map(
            |line| match line.split_whitespace().collect::<Vec<_>>()[..] {
                [scene, x, y] if scene == name => Some(format!("{x},{y}")),
                _ => None,
            },
        )
        .collect();
    assert!(pixels.len() >= 5, "{name}: {} pixels", pixels.len());
    pixels
}

/// Every stage of `name`'s vectors answered by the tracer at each offset:
/// full marks.
fn stages_pass(name: &str) {
    let dir = tempfile::tempdir().unwrap();
    let s = scene(name);
    let o = glint(&["grade", "--stages", &s, "--write", "v"], dir.path());
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for fraction in FRACTIONS {
        let answers = format!("a{fraction}");
        let args = ["stages", &s, "v", &answers, "--epsilon-fraction", fraction];
        run_tracer(&args, dir.path());
        let o = glint(
            &["grade", "--stages", &s, "--answers", &answers],
            dir.path(),
        );
        let out = stdout(&o);
        assert_eq!(
            o.status.code(),
            Some(0),
            "ε {fraction}:\n{out}{}",
            stderr(&o)
        );
        assert!(out.ends_with("every answered case passes\n"), "{out}");
        for stage in ["camera", "intersection", "texture", "lighting", "film"] {
            let row = out
                .lines()
                .find(|l| l.split_whitespace().next() == Some(stage))
                .unwrap();
            let words: Vec<&str> = row.split_whitespace().collect();
            assert_eq!(words[1], words[2], "{stage} not full marks: {row}");
            assert_ne!(words[1], "-", "{stage} not answered: {row}");
        }
    }
}

/// Each pixel of `name`, at each offset, each texture level and each
/// sample: the tracer's document agrees with Glint's everywhere.
fn documents_agree(name: &str, levels: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let s = scene(name);
    for pixel in pixels(name) {
        for fraction in FRACTIONS {
            for level in levels {
                for samples in SAMPLES {
                    let mut flags: Vec<&str> = vec!["--pixel", &pixel];
                    flags.extend(samples);
                    flags.extend(RECIPE);
                    flags.extend(["--texture-level", level]);
                    let mut args = vec!["explain", s.as_str()];
                    args.extend(&flags);
                    args.extend(["--epsilon-fraction", fraction, "-o", "doc.json"]);
                    run_tracer(&args, dir.path());
                    let mut args = vec!["explain", s.as_str()];
                    args.extend(&flags);
                    args.extend(["--against", "doc.json"]);
                    let o = glint(&args, dir.path());
                    assert_eq!(
                        o.status.code(),
                        Some(0),
                        "glint {} (ε {fraction}):\n{}{}",
                        args.join(" "),
                        stdout(&o),
                        stderr(&o)
                    );
                    assert!(
                        stdout(&o).ends_with("agrees with Glint's everywhere it gives a value\n"),
                        "{}",
                        stdout(&o)
                    );
                }
            }
        }
    }
}

const BOTH_LEVELS: [&str; 2] = ["footprint", "report"];

#[test]
fn set1_stages_and_documents() {
    if python_runs() {
        stages_pass("cornell-set1");
        documents_agree("cornell-set1", &BOTH_LEVELS);
    }
}

#[test]
fn set2_stages_and_documents() {
    if python_runs() {
        stages_pass("cornell-set2");
        documents_agree("cornell-set2", &BOTH_LEVELS);
    }
}

#[test]
fn set3_stages_and_documents() {
    if python_runs() {
        stages_pass("cornell-set3");
        documents_agree("cornell-set3", &BOTH_LEVELS);
    }
}

#[test]
fn textured_spheres_stages_and_documents() {
    if python_runs() {
        stages_pass("textured-spheres");
        documents_agree("textured-spheres", &BOTH_LEVELS);
    }
}

#[test]
fn environment_stages_and_documents() {
    if python_runs() {
        stages_pass("environment");
        documents_agree("environment", &BOTH_LEVELS);
    }
}
