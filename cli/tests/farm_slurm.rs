//! `glint farm slurm` on a real Slurm cluster: a tiled render submitted with
//! `sbatch` (a job array and a merge job that waits for it) gives the single
//! render's bytes, also when one task is stopped mid-render and requeued
//! (`scontrol requeue`: SIGTERM, then the task runs again and resumes its
//! tile); a bench sweep (a task per strategy and budget, then the merge)
//! gives the single bench's errors; a class's grading (the references, a
//! task per part, then the merge) gives the single run's report, byte for
//! byte. Runs where `sinfo` answers, or where Slurm is installed and the test
//! runs as root: then it starts a one-node cluster itself
//! (`tools/cluster/slurm-one-node.sh`, docs/testing.md). Elsewhere it is
//! skipped with a message, and fails under `CI=true`.

mod common;

use common::{assert_same_folders, glint, scene, small_class, stderr, stdout};
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// Whether a Slurm cluster answers, else why not.
fn slurm_answers() -> Result<(), String> {
    let out = Command::new("sinfo")
        .args(["--noheader", "--format=%T"])
        .output()
        .map_err(|e| format!("sinfo does not run ({e})"))?;
    let states = String::from_utf8_lossy(&out.stdout);
    let up = ["idle", "mixed", "allocated"];
    match out.status.success()
        && states
            .lines()
            .any(|s| up.contains(&s.trim_end_matches('*')))
    {
        true => Ok(()),
        false => Err(format!("no Slurm node is up ({})", stderr(&out).trim())),
    }
}

/// A Slurm cluster that answers: one that is up, else the one-node cluster
/// this machine's Slurm starts as root, else why there is none.
fn slurm_cluster() -> Result<(), String> {
    let Err(why) = slurm_answers() else {
        return Ok(());
    };
    let installed =
        Path::new("/usr/sbin/slurmctld").exists() && Path::new("/usr/sbin/munged").exists();
    let root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| stdout(&o).trim() == "0");
    if !installed || !root {
        return Err(format!(
            "{why}; start a one-node cluster with `sudo tools/cluster/slurm-one-node.sh` (apt-get install slurm-wlm munge), then `cargo test -p glint-cli --test farm_slurm` (docs/testing.md)"
        ));
    }
    let script = common::repo().join("tools/cluster/slurm-one-node.sh");
    let started = Command::new(&script)
        .output()
        .map_err(|e| format!("{}: {e}", script.display()))?;
    match started.status.success() {
        true => slurm_answers(),
        false => Err(format!(
            "{} could not start a cluster: {}",
            script.display(),
            stderr(&started).trim()
        )),
    }
}

/// Samples per pixel of the render stopped mid-way: a few seconds a tile.
const LONG_SPP: &str = "32768";

fn render_options(spp: &str) -> Vec<String> {
    [
        "--resolution",
        "64x64",
        "--spp",
        spp,
        "--light-samples",
        "1",
    ]
    .map(str::to_owned)
    .to_vec()
}

/// Submits the farm of `tiles` tiles into `dir/NAME`; returns the job ids
/// (the array, the merge).
fn submit(d: &Path, name: &str, tiles: u32, spp: &str) -> (String, String) {
    let cornell = scene("cornell-set1");
    let tiles = tiles.to_string();
    let output = format!("{name}.exr");
    let mut args = vec!["farm", "slurm", "render", &cornell, "--tiles", &tiles];
    args.extend([
        "--dir", name, "-o", &output, "--cpus", "1", "--submit", "--",
    ]);
    let options = render_options(spp);
    args.extend(options.iter().map(String::as_str));
    let out = glint(&args, d);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let said = stdout(&out);
    (job_id(&said, "array", 1), job_id(&said, "and", 2))
}

/// The job id `skip` words after `word` in what `glint farm slurm --submit`
/// said: "submitted [job F (references), then ]job array A (render) and job
/// M (assemble, ...)".
fn job_id(said: &str, word: &str, skip: usize) -> String {
    let words: Vec<&str> = said.split_whitespace().collect();
    let k = words.iter().position(|w| *w == word).expect(word);
    words[k + skip].to_owned()
}

/// Waits until none of `jobs` is queued or running.
fn wait_for(jobs: &[&str], logs: &Path) {
    let start = Instant::now();
    loop {
        let out = Command::new("squeue")
            .args(["--noheader", "--format=%i", "--jobs", &jobs.join(",")])
            .output()
            .unwrap();
        if stdout(&out).trim().is_empty() {
            return;
        }
        if start.elapsed() > Duration::from_secs(300) {
            let listing = std::fs::read_dir(logs).map(|d| d.count()).unwrap_or(0);
            panic!("jobs {jobs:?} still queued after 5 minutes ({listing} logs in {logs:?})");
        }
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// The state of job `id` (`JOBID_TASK` for a task), if queued or running.
fn state(id: &str) -> String {
    let out = Command::new("squeue")
        .args(["--noheader", "--format=%T", "--jobs", id])
        .output()
        .unwrap();
    stdout(&out).trim().to_owned()
}

fn logs_text(dir: &Path) -> String {
    let mut text = String::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        text += &std::fs::read_to_string(entry.unwrap().path()).unwrap_or_default();
    }
    text
}

#[test]
fn a_tiled_render_a_sweep_and_a_class_through_sbatch_are_the_single_runs_also_after_a_requeue() {
    if !common::real_part(slurm_cluster().err()) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (name, spp) in [("quick", "4"), ("long", LONG_SPP)] {
        let mut args = vec!["render".to_owned(), scene("cornell-set1")];
        args.extend(render_options(spp));
        args.extend(["-o".to_owned(), format!("{name}-whole.exr")]);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = glint(&args, d);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    }

    let (array, merge) = submit(d, "quick", 4, "4");
    wait_for(&[&array, &merge], &d.join("quick/logs"));
    let (farmed, whole) = (d.join("quick.exr"), d.join("quick-whole.exr"));
    assert!(
        farmed.exists(),
        "no image; logs:\n{}",
        logs_text(&d.join("quick/logs"))
    );
    assert!(std::fs::read(&farmed).unwrap() == std::fs::read(&whole).unwrap());

    // A sweep: one task per strategy and budget, then the merge.
    let cornell = scene("cornell-set1");
    let measure = [
        "--resolution",
        "16x16",
        "--samplers",
        "random,sobol",
        "--spp",
        "1,4",
    ];
    let reference = glint(
        &[
            "render",
            &cornell,
            "--resolution",
            "16x16",
            "--spp",
            "256",
            "--seed",
            "9",
            "-o",
            "ref16.exr",
        ],
        d,
    );
    assert!(reference.status.success(), "{}", stderr(&reference));
    let single = glint(
        &[
            &["bench", &cornell, "-o", "single"],
            &measure[..],
            &["--reference", "ref16.exr"],
        ]
        .concat(),
        d,
    );
    assert!(single.status.success(), "{}", stderr(&single));
    let out = glint(
        &[
            &[
                "farm", "slurm", "bench", &cornell, "--dir", "sweep", "-o", "swept", "--submit",
                "--",
            ],
            &measure[..],
            &["--reference", "ref16.exr"],
        ]
        .concat(),
        d,
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let said = stdout(&out);
    let (sweep, sweep_merge) = (job_id(&said, "array", 1), job_id(&said, "and", 2));
    wait_for(&[&sweep, &sweep_merge], &d.join("sweep/logs"));
    let rows = |dir: &str| -> Vec<(String, u64, f64)> {
        let path = d.join(dir).join("results.json");
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| {
            panic!(
                "{}: {e}; logs:\n{}",
                path.display(),
                logs_text(&d.join("sweep/logs"))
            )
        });
        let json: serde_json::Value = serde_json::from_str(&text).unwrap();
        let mut rows: Vec<(String, u64, f64)> = json["rows"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| {
                let name = r["strategy"].as_str().unwrap().to_owned();
                (
                    name,
                    r["total_samples"].as_u64().unwrap(),
                    r["rel_mse"].as_f64().unwrap(),
                )
            })
            .collect();
        rows.sort_by(|a, b| (&a.0, a.1).cmp(&(&b.0, b.1)));
        rows
    };
    let (single, swept) = (rows("single"), rows("swept"));
    assert_eq!(single.len(), 4);
    for (a, b) in single.iter().zip(&swept) {
        assert_eq!((&a.0, a.1), (&b.0, b.1));
        assert!((a.2 - b.2).abs() <= 1e-12 * a.2, "{a:?} against {b:?}");
    }

    // A class: its references, then a task per part, then the merge.
    let class = small_class(d);
    let class = class.to_str().unwrap();
    let scenes = ["--scenes", "scenes"];
    let single = glint(
        &[
            &[
                "grade",
                "--class",
                class,
                "--report",
                "class-single",
                "--cache",
                "cache",
            ],
            &scenes[..],
        ]
        .concat(),
        d,
    );
    assert_eq!(single.status.code(), Some(1), "{}", stderr(&single));
    let out = glint(
        &[
            &[
                "farm",
                "slurm",
                "grade",
                "--class",
                class,
                "--parts",
                "3",
                "--dir",
                "class-farm",
            ][..],
            &["-o", "class-report", "--submit", "--"],
            &scenes[..],
        ]
        .concat(),
        d,
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let said = stdout(&out);
    let [references, grading, merge] =
        [("job", 1), ("array", 1), ("and", 2)].map(|(word, skip)| job_id(&said, word, skip));
    wait_for(&[&references, &grading, &merge], &d.join("class-farm/logs"));
    assert!(
        d.join("class-report/grades.json").is_file(),
        "no report; logs:\n{}",
        logs_text(&d.join("class-farm/logs"))
    );
    assert_same_folders(&d.join("class-single"), &d.join("class-report"));

    // One task stopped mid-render: requeued, it resumes its tile.
    let (array, merge) = submit(d, "long", 2, LONG_SPP);
    let task = format!("{array}_1");
    let start = Instant::now();
    while state(&task) != "RUNNING" {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "task {task} never ran"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    std::thread::sleep(Duration::from_millis(1000));
    let requeue = Command::new("scontrol")
        .args(["requeue", &task])
        .output()
        .unwrap();
    assert!(requeue.status.success(), "{}", stderr(&requeue));
    // Slurm holds a requeued job back for a while (its begin time): let it
    // start as soon as it is pending again.
    while state(&task) != "PENDING" {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "task {task} was not requeued"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let release = Command::new("scontrol")
        .args(["update", &format!("JobId={task}"), "StartTime=now"])
        .output()
        .unwrap();
    assert!(release.status.success(), "{}", stderr(&release));
    wait_for(&[&array, &merge], &d.join("long/logs"));
    let logs = logs_text(&d.join("long/logs"));
    assert!(
        logs.contains("glint: interrupted: wrote") && logs.contains("tile-1.partial.exr"),
        "the requeued task was not stopped mid-render:\n{logs}"
    );
    let (farmed, whole) = (d.join("long.exr"), d.join("long-whole.exr"));
    assert!(farmed.exists(), "no image; logs:\n{logs}");
    assert!(std::fs::read(&farmed).unwrap() == std::fs::read(&whole).unwrap());
}
