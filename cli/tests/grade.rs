//! `glint grade`: correct renders pass and wrong ones fail, with where and by
//! how much, for one scene's images and for a class (folder or manifest);
//! the exit status tells a failed submission from bad input; every output is
//! written where asked and nowhere else.
//!
//! Renders are deterministic (fixed seeds, references rendered with fixed
//! seeds), so every verdict here is too.

mod common;

use common::{assert_input_error, glint, scene, stderr, stdout, CORRECT};
use std::path::{Path, PathBuf};

/// Renders the Cornell box Set 1 at 32 × 32 into `dir/name` with `flags`.
fn render(dir: &Path, scene_file: &str, name: &str, flags: &[&str]) -> PathBuf {
    let out = dir.join(name);
    let mut args = vec!["render", scene_file, "--resolution", "32x32", "-o"];
    args.push(out.to_str().unwrap());
    args.extend_from_slice(flags);
    let o = glint(&args, dir);
    assert!(o.status.success(), "{}", stderr(&o));
    out
}

/// Set 1 without its ambient light: the classic "no ambient" mistake.
fn no_ambient_scene(dir: &Path) -> String {
    let text = std::fs::read_to_string(scene("cornell-set1")).unwrap();
    let changed = text.replace("ambient = [0.1, 0.1, 0.1]", "ambient = [0, 0, 0]");
    assert_ne!(text, changed);
    let path = dir.join("no-ambient.toml");
    std::fs::write(&path, changed).unwrap();
    path.to_str().unwrap().to_owned()
}

fn grade(args: &[&str], dir: &Path) -> std::process::Output {
    let cache = dir.join("cache");
    let mut all = vec!["grade", "--cache", cache.to_str().unwrap()];
    all.extend_from_slice(args);
    glint(&all, dir)
}

#[test]
fn a_correct_render_passes_and_a_wrong_one_fails_with_where_and_how_much() {
    let dir = tempfile::tempdir().unwrap();
    let set1 = scene("cornell-set1");
    let good = render(dir.path(), &set1, "good.png", &CORRECT);
    let o = grade(&[&set1, good.to_str().unwrap()], dir.path());
    assert_eq!(o.status.code(), Some(0), "{}{}", stdout(&o), stderr(&o));
    let text = stdout(&o);
    assert!(
        text.contains("good.png: pass (32x32, PNG, 8-bit RGB, settings spp unknown, light unknown"),
        "{text}"
    );

    let wrong = render(
        dir.path(),
        &no_ambient_scene(dir.path()),
        "wrong.png",
        &CORRECT,
    );
    let o = grade(&[&set1, wrong.to_str().unwrap()], dir.path());
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.contains("wrong.png: FAIL"), "{text}");
    // Named regions, the direction and size of the difference, its z.
    assert!(text.contains("too dark by"), "{text}");
    for wall in ["back wall", "ceiling", "left wall"] {
        assert!(text.contains(wall), "{wall} missing from:\n{text}");
    }
    assert!(stderr(&o).is_empty(), "{}", stderr(&o));
}

#[test]
fn the_first_step_passes_when_its_settings_are_stated() {
    // One ray through each pixel's centre, no anti-aliasing: its expected
    // value is not the anti-aliased image's, but it is right as stated.
    let dir = tempfile::tempdir().unwrap();
    let set1 = scene("cornell-set1");
    let first = [
        "--spp",
        "1",
        "--sampler",
        "grid",
        "--light-samples",
        "16",
        "--seed",
        "3",
    ];
    let image = render(dir.path(), &set1, "first.png", &first);
    let stated = ["--spp", "1", "--sampler", "grid"];
    let mut args = vec![set1.as_str(), image.to_str().unwrap()];
    args.extend_from_slice(&stated);
    let o = grade(&args, dir.path());
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    assert!(stdout(&o).contains("settings spp 1 grid, light unknown"));
}

#[test]
fn a_class_folder_and_its_manifest_give_the_same_verdicts_in_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let scenes = dir.path().join("scenes");
    std::fs::create_dir(&scenes).unwrap();
    std::fs::copy(scene("cornell-set1"), scenes.join("set1.toml")).unwrap();
    let set1 = scenes.join("set1.toml");
    let class = dir.path().join("class");
    for student in ["ada", "bo"] {
        std::fs::create_dir_all(class.join(student)).unwrap();
    }
    render(
        &class.join("ada"),
        set1.to_str().unwrap(),
        "set1.png",
        &CORRECT,
    );
    let bad_scene = no_ambient_scene(dir.path());
    render(&class.join("bo"), &bad_scene, "set1.ppm.png", &CORRECT);
    // A PPM, as a first ray tracer writes it: P3 from the PNG's codes.
    let png = image::open(class.join("bo/set1.ppm.png"))
        .unwrap()
        .to_rgb8();
    let mut ppm = format!("P3\n{} {}\n255\n", png.width(), png.height());
    for p in png.pixels() {
        ppm += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    std::fs::remove_file(class.join("bo/set1.ppm.png")).unwrap();
    std::fs::write(class.join("bo/set1.ppm"), ppm).unwrap();
    std::fs::write(class.join("bo/notes.txt"), "not an image").unwrap();

    let class_arg = class.to_str().unwrap();
    let scenes_arg = scenes.to_str().unwrap();
    let o = grade(&["--class", class_arg, "--scenes", scenes_arg], dir.path());
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let table = stdout(&o);
    let lines: Vec<&str> = table.lines().collect();
    assert!(lines[0].starts_with("student  scene  verdict"), "{table}");
    assert!(lines[1].starts_with("ada      set1   pass"), "{table}");
    assert!(lines[2].starts_with("bo       set1   fail"), "{table}");
    assert!(
        table.contains("2 submissions: 1 pass, 1 fail, 0 not graded"),
        "{table}"
    );

    let manifest = dir.path().join("class.csv");
    std::fs::write(
        &manifest,
        "student,scene,file,spp,note\nada,set1,class/ada/set1.png,4,\nbo,set1,class/bo/set1.ppm,,P3\ncy,set1,class/cy/set1.png,,missing\n",
    )
    .unwrap();
    let o = grade(
        &[
            "--class",
            manifest.to_str().unwrap(),
            "--scenes",
            scenes_arg,
            "--format",
            "csv",
        ],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let csv = stdout(&o);
    let rows: Vec<&str> = csv.lines().collect();
    assert!(
        rows[0].starts_with("student,scene,file,format,verdict,rejected,tests"),
        "{csv}"
    );
    assert!(
        rows[1].starts_with("ada,set1,") && rows[1].contains(",pass,0,"),
        "{csv}"
    );
    assert!(
        rows[2].starts_with("bo,set1,") && rows[2].contains(",fail,"),
        "{csv}"
    );
    assert!(
        rows[3].starts_with("cy,set1,") && rows[3].contains(",error,"),
        "{csv}"
    );

    let o = grade(
        &[
            "--class",
            manifest.to_str().unwrap(),
            "--scenes",
            scenes_arg,
            "--format",
            "json",
        ],
        dir.path(),
    );
    let json: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(json["schema"], "glint-grade/2");
    assert_eq!(
        (
            json["pass"].as_u64(),
            json["fail"].as_u64(),
            json["error"].as_u64()
        ),
        (Some(1), Some(1), Some(1))
    );
    let bo = &json["submissions"][1];
    assert_eq!(bo["verdict"], "fail");
    let worst = &bo["rejected"][0];
    assert!(
        worst["channels"][0]["z"].as_f64().unwrap() < -4.0,
        "{worst}"
    );
    assert!(worst["channels"][0]["difference"].as_f64().unwrap() < 0.0);
    assert_eq!(json["submissions"][2]["status"], "unreadable");
}

#[test]
fn a_report_folder_holds_the_page_the_tables_and_the_images() {
    let dir = tempfile::tempdir().unwrap();
    let set1 = scene("cornell-set1");
    let good = render(dir.path(), &set1, "good.png", &CORRECT);
    let report = dir.path().join("report");
    let heat = dir.path().join("heat.png");
    let o = grade(
        &[
            &set1,
            good.to_str().unwrap(),
            "--report",
            report.to_str().unwrap(),
            "--heatmap",
            heat.to_str().unwrap(),
        ],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for file in [
        "index.html",
        "grades.csv",
        "grades.json",
        "images/0-submission.png",
        "images/0-submission-small.png",
        "images/0-heatmap.png",
        "images/reference-0.png",
    ] {
        assert!(report.join(file).is_file(), "{file}");
    }
    let page = std::fs::read_to_string(report.join("index.html")).unwrap();
    assert!(
        page.contains("<th data-column=\"2\">cornell-set1</th>"),
        "{page}"
    );
    assert!(
        !page.contains("http://") && !page.contains("https://"),
        "the page loads nothing from the network"
    );
    let map = image::open(&heat).unwrap();
    assert_eq!((map.width(), map.height()), (32, 32));

    // A second run replaces the report whole: nothing of the old one stays,
    // and nothing is left beside it.
    std::fs::write(report.join("notes.txt"), "the grader's own file").unwrap();
    let o = grade(
        &[
            &set1,
            good.to_str().unwrap(),
            "--report",
            report.to_str().unwrap(),
        ],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(report.join("index.html").is_file() && !report.join("notes.txt").exists());
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(!names.iter().any(|n| n.starts_with(".glint")), "{names:?}");
}

#[test]
fn bad_input_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let set1 = scene("cornell-set1");
    let good = render(dir.path(), &set1, "good.png", &CORRECT);
    let good = good.to_str().unwrap();
    let missing = dir.path().join("missing.png");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec![], "give a scene and the images to grade"),
        (vec![&set1], "no images to grade"),
        (
            vec![good, good],
            "the first argument is the scene, a .toml file",
        ),
        (
            vec![&set1, missing.to_str().unwrap()],
            "missing.png: cannot read the image",
        ),
        (vec![&set1, good, "--sampler", "grid"], "give --spp too"),
        (vec![&set1, good, "--spp", "0"], "spp must be at least 1"),
        (
            vec![&set1, good, "--alpha", "1.5"],
            "expected a probability between 0 and 1",
        ),
        (
            vec![&set1, good, "--heatmap", "heat.jpg"],
            "expected a .png extension",
        ),
        (
            vec![&set1, good, good, "--heatmap", "heat.png"],
            "writes one submission's map, and there are 2",
        ),
        (
            vec![&set1, good, "--report", good],
            "--report: is a file, expected a folder",
        ),
        (
            vec!["--class", "nowhere"],
            "--class: no such folder or manifest",
        ),
        (
            vec![&set1, good, "--report", "."],
            "holds files that are not a report",
        ),
    ];
    for (args, expected) in cases {
        let o = grade(&args, dir.path());
        assert_input_error(&o, expected);
    }
    let o = glint(&["grade", &set1, good, "--cache", good], dir.path());
    assert_input_error(&o, "--cache: not a folder");
    let manifest = dir.path().join("m.csv");
    for (text, expected) in [
        (
            "student,scene,file,colour\n",
            "line 1: unknown column \"colour\"",
        ),
        ("student,file\n", "no \"scene\" column"),
        (
            "student,scene,file,spp\nada,set1,a.png,x\n",
            "line 2: spp is \"x\"; expected a whole number",
        ),
        (
            "student,scene,file,sampler\nada,set1,a.png,grid\n",
            "give --spp too",
        ),
        ("student,scene,file\n", "the manifest lists no submissions"),
    ] {
        std::fs::write(&manifest, text).unwrap();
        let o = grade(&["--class", manifest.to_str().unwrap()], dir.path());
        assert_input_error(&o, expected);
    }
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert!(
        !names.iter().any(|n| n == "heat.png" || n == "heat.jpg"),
        "{names:?}"
    );
}

/// A fixture of `cli/tests/data/grade/` (renders by the independent tracer).
fn fixture(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/grade")
        .join(name);
    path.to_str().unwrap().to_owned()
}

/// Every submission's verdict, from `--format csv`, by student.
fn verdicts(o: &std::process::Output) -> Vec<(String, String)> {
    csv_rows(&stdout(o))
        .into_iter()
        .map(|row| (row["student"].clone(), row["verdict"].clone()))
        .collect()
}

/// A CSV's rows, each by column name.
fn csv_rows(text: &str) -> Vec<std::collections::HashMap<String, String>> {
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let header = reader.headers().unwrap().clone();
    reader
        .records()
        .map(|r| {
            let r = r.unwrap();
            header
                .iter()
                .zip(r.iter())
                .map(|(k, v)| (k.to_owned(), v.to_owned()))
                .collect()
        })
        .collect()
}

#[test]
fn another_ray_tracer_s_correct_renders_pass_and_its_mistakes_fail() {
    let dir = tempfile::tempdir().unwrap();
    let set1 = scene("cornell-set1");
    let stratified = ["--sampler", "stratified", "--light-sampler", "stratified"];
    let mistakes: Vec<String> = [
        "flipped-view.png",
        "sphere-u-sign.png",
        "no-shadow-offset.png",
        "truncate-8bit.png",
    ]
    .into_iter()
    .map(fixture)
    .collect();
    let mut args = vec![set1.as_str()];
    args.extend(mistakes.iter().map(String::as_str));
    args.extend(["--spp", "16", "--light-samples", "16", "--format", "csv"]);
    args.extend(stratified);
    let o = grade(&args, dir.path());
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let expected = [
        ("flipped-view", "fail"),
        ("sphere-u-sign", "fail"),
        ("no-shadow-offset", "fail"),
        // Half an 8-bit step darker: within what the format may have changed.
        ("truncate-8bit", "pass"),
    ];
    let expected: Vec<(String, String)> = expected
        .iter()
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .collect();
    assert_eq!(verdicts(&o), expected);

    let (correct, first, corners) = (
        fixture("correct.png"),
        fixture("first-step.ppm"),
        fixture("first-step-corners.ppm"),
    );
    let o = grade(
        &[
            &set1,
            &correct,
            "--spp",
            "4",
            "--light-samples",
            "4",
            stratified[0],
            stratified[1],
            stratified[2],
            stratified[3],
        ],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    // The first step, stated: rays through the pixels' centres pass, through
    // their corners fail.
    let first_step = [
        "--spp",
        "1",
        "--sampler",
        "grid",
        "--light-samples",
        "16",
        "--light-sampler",
        "stratified",
        "--format",
        "csv",
    ];
    let mut args = vec![set1.as_str(), &first, &corners];
    args.extend(first_step);
    let o = grade(&args, dir.path());
    let expected: Vec<(String, String)> = [("first-step", "pass"), ("first-step-corners", "fail")]
        .iter()
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .collect();
    assert_eq!(verdicts(&o), expected);
}
