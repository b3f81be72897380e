//! A class graded in parts: `glint grade --references-only` fills the
//! cache, `--part I/N` grades every N-th submission into a part folder, and
//! `--merge` gives what a single run prints and writes, byte for byte; the
//! merge refuses missing, repeated and foreign parts. `glint farm ENGINE
//! grade` writes those steps as scripts, which give the same report run by
//! hand and through GNU parallel (where it is installed).

mod common;

use common::{assert_input_error, assert_same_folders, glint, small_class, stderr, stdout};
use std::path::Path;

fn grade(args: &[&str], dir: &Path) -> std::process::Output {
    let mut all = vec!["grade", "--class", "class.csv", "--scenes", "scenes"];
    all.extend_from_slice(args);
    glint(&all, dir)
}

/// The single run's report (`single/`) and JSON, with its exit status.
fn single_run(d: &Path) -> (Option<i32>, String) {
    let o = grade(
        &["--cache", "cache", "--report", "single", "--format", "json"],
        d,
    );
    (o.status.code(), stdout(&o))
}

#[test]
fn a_class_graded_in_parts_and_merged_is_the_single_run_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    small_class(d);
    let (status, json) = single_run(d);
    assert_eq!(status, Some(1), "bo's wrong scene fails");
    assert!(
        json.contains("\"fail\": 1") && json.contains("\"error\": 1"),
        "{json}"
    );

    // The references in two tasks, one set each, then the parts read them.
    let cached = || std::fs::read_dir(d.join("shared")).map_or(0, |files| files.count());
    let mut counts = vec![cached()];
    for task in ["0/2", "1/2"] {
        let o = grade(
            &["--cache", "shared", "--references-only", "--part", task],
            d,
        );
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let said = format!("1 of the 2 reference sets (part {task}) for 7 submissions");
        assert!(stdout(&o).contains(&said), "{}", stdout(&o));
        counts.push(cached());
    }
    assert!(counts[0] < counts[1] && counts[1] < counts[2], "{counts:?}");
    for part in 0..3 {
        let (tile, folder) = (format!("{part}/3"), format!("part-{part}"));
        let o = grade(
            &[
                "--cache",
                "shared",
                "--part",
                &tile,
                "--report",
                &folder,
                "--threads",
                "1",
            ],
            d,
        );
        // A part's failed submissions are the merge's to report.
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    let merged = glint(
        &[
            "grade", "--merge", "part-2", "part-0", "part-1", "--report", "merged", "--format",
            "json",
        ],
        d,
    );
    assert_eq!(merged.status.code(), Some(1), "{}", stderr(&merged));
    assert!(
        stdout(&merged) == json,
        "the merge prints the single run's JSON"
    );
    assert_same_folders(&d.join("single"), &d.join("merged"));
    for format in ["table", "csv"] {
        let single = grade(&["--cache", "shared", "--format", format], d);
        let merged = glint(
            &[
                "grade", "--merge", "part-0", "part-1", "part-2", "--format", format,
            ],
            d,
        );
        assert!(
            stdout(&single) == stdout(&merged),
            "{format}: {}",
            stdout(&merged)
        );
    }
}

#[test]
fn the_merge_refuses_missing_repeated_and_foreign_parts_and_bad_parts_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    small_class(d);
    for (part, options) in [
        ("0/3", &[][..]),
        ("1/3", &[][..]),
        ("2/3", &[][..]),
        ("1/3", &["--alpha", "0.05"][..]),
    ] {
        let folder = match options.is_empty() {
            true => format!("part-{}", &part[..1]),
            false => "other-1".to_owned(),
        };
        let mut args = vec!["--cache", "cache", "--part", part, "--report", &folder];
        args.extend_from_slice(options);
        let o = grade(&args, d);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    let merge = |parts: &[&str]| {
        glint(
            &[&["grade", "--merge"], parts, &["--report", "out"]].concat(),
            d,
        )
    };
    assert_input_error(&merge(&["part-0", "part-2"]), "missing parts 1/3");
    assert_input_error(
        &merge(&["part-0", "part-1", "part-1", "part-2"]),
        "part 1/3 is given twice",
    );
    assert_input_error(
        &merge(&["part-0", "other-1", "part-2"]),
        "graded with other options",
    );
    assert_input_error(&merge(&["part-0", "class"]), "not a part folder");
    assert!(!d.join("out").exists(), "a refused merge writes nothing");

    let o = grade(&["--cache", "fresh", "--part", "0/9", "--report", "p"], d);
    assert_input_error(&o, "--part 0/9: the class has 7 submissions");
    assert!(
        !d.join("fresh").exists(),
        "refused before the cache is made"
    );
    assert_input_error(
        &grade(&["--part", "3/3", "--report", "p"], d),
        "expected I/N with 0 ≤ I < N",
    );
    assert_input_error(&grade(&["--part", "0/3"], d), "--report");
    assert_input_error(
        &grade(&["--no-cache", "--references-only"], d),
        "--references-only",
    );
    assert_input_error(
        &glint(&["grade", "--merge", "part-0", "--spp", "4"], d),
        "--spp",
    );
    assert!(!d.join("p").exists());
}

#[test]
fn glint_farm_grade_scripts_give_the_single_report_by_hand_and_through_gnu_parallel() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let class = small_class(d);
    let class = class.to_str().unwrap();
    // The farm's paths are absolute: so is the single run's class.
    let o = glint(
        &[
            "grade", "--class", class, "--scenes", "scenes", "--cache", "cache", "--report",
            "single",
        ],
        d,
    );
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));

    let farm = |engine: &str, name: &str| {
        let report = format!("{name}-report");
        let o = glint(
            &[
                "farm", engine, "grade", "--class", class, "--parts", "3", "--dir", name, "-o",
                &report, "--", "--scenes", "scenes",
            ],
            d,
        );
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        d.join(name)
    };
    let run = |script: &Path, args: &[&str]| {
        let o = std::process::Command::new(script)
            .args(args)
            .current_dir("/")
            .output()
            .unwrap();
        assert!(o.status.success(), "{}: {}", script.display(), stderr(&o));
    };
    let by_hand = farm("slurm", "by-hand");
    let sbatch = std::fs::read_to_string(by_hand.join("grade.sbatch")).unwrap();
    assert!(
        sbatch.contains("#SBATCH --array=0-2") && sbatch.contains("grade-part.sh"),
        "{sbatch}"
    );
    let references = std::fs::read_to_string(by_hand.join("references.sbatch")).unwrap();
    assert!(
        references.contains("#SBATCH --array=0-1"),
        "a task per scene: {references}"
    );
    assert!(by_hand.join("merge.sbatch").is_file());
    for task in ["0", "1"] {
        run(&by_hand.join("references.sh"), &[task]);
    }
    for part in ["0", "1", "2"] {
        run(&by_hand.join("grade-part.sh"), &[part]);
    }
    run(&by_hand.join("merge-grades.sh"), &[]);
    assert_same_folders(&d.join("single"), &d.join("by-hand-report"));

    let managed = glint(
        &[
            "farm", "parallel", "grade", "--class", class, "--parts", "3", "--", "--part", "0/3",
        ],
        d,
    );
    assert_input_error(&managed, "--part is set by glint farm");
    let too_many = glint(
        &[
            "farm", "parallel", "grade", "--class", class, "--parts", "8",
        ],
        d,
    );
    assert_input_error(&too_many, "--parts 8: the class has 7 submissions");

    if !common::real_part(common::program_missing("parallel", "parallel")) {
        return;
    }
    let parallel = farm("parallel", "parallel");
    run(&parallel.join("run-parallel.sh"), &[]);
    assert_same_folders(&d.join("single"), &d.join("parallel-report"));
}

/// A part stopped by SIGTERM (a Slurm requeue, a time limit) ends with the
/// signal's status, leaves the part folder of an earlier run as it was, and
/// leaves nothing beside it.
#[test]
fn a_stopped_part_leaves_the_earlier_part_as_it_was_and_nothing_beside_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    small_class(d);
    let part = ["--no-cache", "--part", "0/2", "--report", "part-0"];
    let o = grade(&part, d);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let before = std::fs::read(d.join("part-0/part.json")).unwrap();
    let staging = || {
        std::fs::read_dir(d)
            .unwrap()
            .filter_map(|e| e.ok())
            .any(|e| e.file_name().to_string_lossy().starts_with(".glint"))
    };
    // Without the cache the part renders its references first: time to stop
    // it once its folder is being made. A run that finishes first is tried again.
    let stopped = (0..20).find_map(|_| {
        let mut args = vec!["grade", "--class", "class.csv", "--scenes", "scenes"];
        args.extend_from_slice(&part);
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_glint"))
            .args(&args)
            .current_dir(d)
            .stdout(std::process::Stdio::null())
            .spawn()
            .unwrap();
        while !staging() && child.try_wait().unwrap().is_none() {
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
        let _ = std::process::Command::new("kill")
            .args(["-TERM", &child.id().to_string()])
            .status();
        let status = child.wait().unwrap();
        (status.code() != Some(0)).then_some(status)
    });
    let stopped = stopped.expect("no run was stopped mid-way in 20 tries");
    assert_eq!(stopped.code(), Some(128 + 15), "{stopped:?}");
    assert!(!staging(), "a stopped part leaves its folder being made");
    assert!(std::fs::read(d.join("part-0/part.json")).unwrap() == before);
}
