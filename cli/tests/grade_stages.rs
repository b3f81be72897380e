//! `glint grade --stages`: the test vectors it writes for the Cornell box
//! (Set 1), and its check of answers: Glint's own (exit 0), one with a
//! wrong sign of the sphere's u (exit 1, the intersection stage named with
//! its first failing case), and unreadable ones (exit 2).

mod common;

use common::{assert_input_error, glint, scene, stderr, stdout};
use std::path::{Path, PathBuf};
use std::sync::{LazyLock, OnceLock};

/// Each stage's files.
const STAGES: [&str; 5] = ["camera", "intersection", "texture", "lighting", "film"];

/// The vectors of Set 1 at the default 64 cases per stage (what `--answers`
/// checks against), written once for the tests that answer them.
fn vectors() -> &'static Path {
    static DIR: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    let (_, path) = DIR.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let o = glint(&["grade", "--stages", &SET1, "--write", "v"], dir.path());
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let path = dir.path().join("v");
        (dir, path)
    });
    path
}

/// A folder of answers: `files` copied from the vectors, each through `edit`.
fn answers(files: &[&str], edit: impl Fn(&str, String) -> String) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for name in files {
        let text = std::fs::read_to_string(vectors().join(name)).unwrap();
        std::fs::write(dir.path().join(name), edit(name, text)).unwrap();
    }
    dir
}

/// `glint grade --stages` on Set 1 with the answers in `answers`.
fn check(answers: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "grade",
        "--stages",
        &SET1,
        "--answers",
        answers.to_str().unwrap(),
    ];
    args.extend(extra);
    glint(&args, &std::env::temp_dir())
}

static SET1: LazyLock<String> = LazyLock::new(|| scene("cornell-set1"));

/// The words of the report's line for `stage`.
fn score_row(out: &str, stage: &str) -> Vec<String> {
    let row = out
        .lines()
        .find(|l| l.split_whitespace().next() == Some(stage))
        .unwrap_or_else(|| panic!("no {stage} row in {out}"));
    row.split_whitespace().map(String::from).collect()
}

fn header(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap();
    let first = text.lines().next().unwrap();
    first.split(',').map(String::from).collect()
}

#[test]
fn writes_every_stages_files_with_the_documented_columns() {
    let dir = tempfile::tempdir().unwrap();
    let o = glint(
        &["grade", "--stages", &SET1, "--write", "out", "--cases", "6"],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("out/camera.csv (6 cases)"),
        "{}",
        stdout(&o)
    );
    let out = dir.path().join("out");
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let mut want: Vec<String> = STAGES
        .iter()
        .flat_map(|s| {
            [
                format!("{s}.json"),
                format!("{s}.csv"),
                format!("{s}-inputs.csv"),
            ]
        })
        .collect();
    want.sort();
    assert_eq!(names, want);
    // The columns docs/grading-stages.md lists, in order.
    let documented: [(&str, &[&str], &[&str]); 5] = [
        (
            "camera",
            &["x", "y", "width", "height"],
            &[
                "origin_x",
                "origin_y",
                "origin_z",
                "direction_x",
                "direction_y",
                "direction_z",
            ],
        ),
        (
            "intersection",
            &[
                "origin_x",
                "origin_y",
                "origin_z",
                "direction_x",
                "direction_y",
                "direction_z",
            ],
            &[
                "hit",
                "t",
                "point_x",
                "point_y",
                "point_z",
                "geometric_normal_x",
                "geometric_normal_y",
                "geometric_normal_z",
                "shading_normal_x",
                "shading_normal_y",
                "shading_normal_z",
                "u",
                "v",
                "object",
                "name",
            ],
        ),
        (
            "texture",
            &[
                "object", "texture", "kind", "u", "v", "scale_u", "scale_v", "offset_u",
                "offset_v", "t", "n_dot_d", "r", "fov", "m",
            ],
            &[
                "l", "jacobian", "w", "level", "value_r", "value_g", "value_b",
            ],
        ),
        (
            "lighting",
            &[
                "object",
                "point_x",
                "point_y",
                "point_z",
                "n_x",
                "n_y",
                "n_z",
                "ng_x",
                "ng_y",
                "ng_z",
                "v_x",
                "v_y",
                "v_z",
                "kd_r",
                "kd_g",
                "kd_b",
                "ks_r",
                "ks_g",
                "ks_b",
                "shininess",
                "lobe",
                "ambient_r",
                "ambient_g",
                "ambient_b",
                "light0_kind",
                "light0_r",
                "light0_g",
                "light0_b",
                "light0_normal_x",
                "light0_normal_y",
                "light0_normal_z",
                "s00_light",
                "s00_x",
                "s00_y",
                "s00_z",
                "s01_light",
            ],
            &[
                "ambient_term_r",
                "ambient_term_g",
                "ambient_term_b",
                "s00_verdict",
                "s00_blocker",
                "s00_diffuse_r",
                "s00_diffuse_g",
                "s00_diffuse_b",
                "s00_specular_r",
                "s00_specular_g",
                "s00_specular_b",
                "s01_verdict",
            ],
        ),
        (
            "film",
            &["radiance_r", "radiance_g", "radiance_b"],
            &["srgb8_r", "srgb8_g", "srgb8_b"],
        ),
    ];
    let from = ["pixel_x", "pixel_y", "sample", "spp", "why"];
    for (stage, inputs, expected) in documented {
        let all = header(&out.join(format!("{stage}.csv")));
        let given = header(&out.join(format!("{stage}-inputs.csv")));
        assert_eq!(given[0], "id");
        assert_eq!(&given[1..=inputs.len()], inputs, "{stage}");
        assert_eq!(all[..given.len()], given[..], "{stage}");
        assert_eq!(
            &all[given.len()..given.len() + expected.len()],
            expected,
            "{stage}"
        );
        assert_eq!(&all[all.len() - 5..], from, "{stage}");
        let rows = std::fs::read_to_string(out.join(format!("{stage}.csv"))).unwrap();
        assert_eq!(rows.lines().count(), 7, "{stage}: a header and 6 cases");
        let json: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(out.join(format!("{stage}.json"))).unwrap(),
        )
        .unwrap();
        assert_eq!(json["schema"], "glint-stages/1");
        assert_eq!(json["scene"], "cornell-set1.toml");
        assert_eq!(json["cases"].as_array().unwrap().len(), 6);
    }
    // The lighting stage has 16 samples of the one area light.
    let lighting = header(&out.join("lighting-inputs.csv"));
    assert!(lighting.contains(&"s15_z".to_owned()) && !lighting.contains(&"s16_x".to_owned()));
}

#[test]
fn glints_own_answers_pass_every_stage() {
    let o = check(vectors(), &[]);
    assert_eq!(o.status.code(), Some(0), "{}{}", stdout(&o), stderr(&o));
    let out = stdout(&o);
    for stage in STAGES {
        let row = score_row(&out, stage);
        assert_eq!(row[1..4], ["64", "64", "64"], "{out}");
        assert!(row[4].ends_with(&format!("{stage}.csv")), "{out}");
    }
    assert!(out.ends_with("every answered case passes\n"), "{out}");
    // As JSON.
    let o = check(vectors(), &["--format", "json"]);
    assert_eq!(o.status.code(), Some(0));
    let json: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(json["schema"], "glint-stages-check/1");
    assert_eq!(json["passed"], true);
}

#[test]
fn a_wrong_sign_of_the_spheres_u_fails_the_intersection_stage() {
    let mut first_sphere: Option<String> = None;
    let dir = answers(&["intersection.csv"], |_, text| {
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let at = |name: &str| header.iter().position(|h| *h == name).unwrap();
        let (u, name) = (at("u"), at("name"));
        let mut out = vec![header.join(",")];
        for line in lines {
            let mut cells: Vec<String> = line.split(',').map(String::from).collect();
            if cells[name].starts_with("sphere") {
                cells[u] = format!("{}", -cells[u].parse::<f64>().unwrap());
            }
            out.push(cells.join(","));
        }
        out.join("\n") + "\n"
    });
    // The first case on a sphere, whose u is not 0 or ½ (where −u is u).
    for line in std::fs::read_to_string(vectors().join("intersection.csv"))
        .unwrap()
        .lines()
    {
        if line.contains(",sphere ") && first_sphere.is_none() {
            first_sphere = Some(line.split(',').next().unwrap().to_owned());
        }
    }
    let first_sphere = first_sphere.expect("a case on a sphere");
    let o = check(dir.path(), &[]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(o.stderr.is_empty(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(
        out.contains(&format!("; the first is {first_sphere}\n")),
        "{out}"
    );
    assert!(out.contains("intersection: "), "{out}");
    assert!(out.contains("uv [u, v]: Glint's ("), "{out}");
    assert!(out.contains("--stage intersect"), "{out}");
    assert!(out.contains("    |     hit object "), "{out}");
    assert_eq!(
        score_row(&out, "camera")[1..],
        ["-", "-", "-", "not", "answered"]
    );
    let row = score_row(&out, "intersection");
    assert_eq!(row[2..4], ["64", "64"], "{out}");
    assert!(row[1].parse::<u32>().unwrap() < 64, "{out}");
    assert!(out.ends_with("1 stage fails: intersection\n"), "{out}");
}

/// `text` (a stage's CSV) with `edit` applied to each row's cells, by
/// column name.
fn edited(text: &str, edit: impl Fn(&mut std::collections::HashMap<String, String>)) -> String {
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let mut out = vec![header.join(",")];
    for line in lines {
        let mut row: std::collections::HashMap<String, String> = header
            .iter()
            .cloned()
            .zip(line.split(',').map(String::from))
            .collect();
        edit(&mut row);
        out.push(
            header
                .iter()
                .map(|h| row[h].clone())
                .collect::<Vec<_>>()
                .join(","),
        );
    }
    out.join("\n") + "\n"
}

#[test]
fn a_scene_without_meshes_needs_no_shading_normal_columns() {
    // Set 1 has no meshes: its shading normals are its geometric normals.
    let dir = answers(&["intersection.csv"], |_, text| {
        let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
        let keep: Vec<usize> = (0..header.len())
            .filter(|&i| !header[i].starts_with("shading_normal_"))
            .collect();
        assert!(keep.len() + 3 == header.len(), "{header:?}");
        text.lines()
            .map(|line| {
                let cells: Vec<&str> = line.split(',').collect();
                keep.iter().map(|&i| cells[i]).collect::<Vec<_>>().join(",")
            })
            .collect::<Vec<_>>()
            .join("\n")
            + "\n"
    });
    let o = check(dir.path(), &[]);
    assert_eq!(o.status.code(), Some(0), "{}{}", stdout(&o), stderr(&o));
    // Given, they are checked.
    let dir = answers(&["intersection.csv"], |_, text| {
        edited(&text, |row| {
            if row["hit"] == "true" {
                row.insert("shading_normal_y".into(), "0.6".into());
            }
        })
    });
    let o = check(dir.path(), &[]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    assert!(
        stdout(&o).contains("shading_normal [shading_normal_x"),
        "{}",
        stdout(&o)
    );
}

#[test]
fn a_failing_case_shows_the_steps_of_glints_expected_value() {
    // The textured spheres: image textures read at the report's level. A
    // level from the natural log, and a light that blocks its own shadow rays.
    let dir = tempfile::tempdir().unwrap();
    let spheres = scene("textured-spheres");
    let o = glint(&["grade", "--stages", &spheres, "--write", "v"], dir.path());
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let read = |name: &str| std::fs::read_to_string(dir.path().join("v").join(name)).unwrap();
    std::fs::create_dir(dir.path().join("a")).unwrap();
    let texture = edited(&read("texture.csv"), |row| {
        if let Ok(level) = row["level"].parse::<f64>() {
            row.insert("level".into(), (level * 2f64.ln()).to_string());
        }
    });
    std::fs::write(dir.path().join("a/texture.csv"), texture).unwrap();
    let lighting = edited(&read("lighting.csv"), |row| {
        if row["s00_verdict"] == "visible" {
            row.insert("s00_verdict".into(), "blocked".into());
            row.insert("s00_blocker".into(), "10".into());
        }
    });
    std::fs::write(dir.path().join("a/lighting.csv"), lighting).unwrap();
    let o = glint(
        &["grade", "--stages", &spheres, "--answers", "a"],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let out = stdout(&o);
    // The texture's steps: the report's level, the two pyramid levels with
    // their sizes and weights, eight texels, and their sum, Glint's value.
    let texture = &out[out.find("texture: ").unwrap()..out.find("lighting: ").unwrap()];
    let steps = &texture[texture
        .find("how Glint's expected values were found:")
        .unwrap()..texture.find("Glint's steps: ").unwrap()];
    assert!(steps.contains("level = log2(L/W) = log2("), "{texture}");
    assert!(
        steps.contains("the report's level, not the render's below"),
        "{texture}"
    );
    let reads = steps
        .lines()
        .find(|l| l.trim_start().starts_with("reads level"))
        .unwrap();
    assert!(
        reads.contains(" × ") && reads.contains(" weight "),
        "{reads}"
    );
    assert_eq!(steps.matches(" texel (").count(), 8, "{texture}");
    let sum = steps
        .lines()
        .find(|l| l.contains("value = Σ weight × texel = ("))
        .unwrap();
    let glints = texture
        .lines()
        .find(|l| l.trim_start().starts_with("value ["))
        .map(|l| l.to_owned());
    assert!(
        glints.is_none(),
        "the value is right, only the level is wrong: {texture}"
    );
    assert!(sum.ends_with(')'), "{sum}");
    // The lighting's: the student's blocker named.
    let lighting = &out[out.find("lighting: ").unwrap()..];
    assert!(
        lighting.contains("s00: Glint's visible, yours blocked by object 10 ("),
        "{lighting}"
    );
}

#[test]
fn unreadable_answers_are_bad_input() {
    let dir = answers(&["film.csv"], |_, text| {
        let mut lines: Vec<String> = text.lines().map(String::from).collect();
        let cells: Vec<&str> = lines[1].split(',').collect();
        lines[1] = format!("{},{},{},abc", cells[0], cells[1], cells[2]);
        lines.join("\n")
    });
    let o = check(dir.path(), &[]);
    assert_input_error(&o, "film.csv:2: 4 fields where the header has 12");
    let dir = answers(&["film.csv"], |_, text| text.replacen(",255,", ",abc,", 1));
    let o = check(dir.path(), &[]);
    assert_input_error(&o, ": column srgb8_");
    assert_input_error(&o, "expected a whole number, got \"abc\"");
    let dir = answers(&["camera.csv"], |_, text| {
        text.replace("camera-007,", "camera-700,")
    });
    assert_input_error(
        &check(dir.path(), &[]),
        "camera.csv:8: unknown id \"camera-700\": the camera cases are camera-001 to camera-064",
    );
    // No answers at all, and a folder that is not there.
    let empty = tempfile::tempdir().unwrap();
    assert_input_error(&check(empty.path(), &[]), "no answers here");
    assert_input_error(
        &check(&empty.path().join("nowhere"), &[]),
        "--answers: no such folder",
    );
}

#[test]
fn a_write_folder_that_cannot_be_made_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("a-file"), "").unwrap();
    let o = glint(
        &["grade", "--stages", &SET1, "--write", "a-file/folder"],
        dir.path(),
    );
    assert_input_error(
        &o,
        "a-file/folder: --write: cannot be made: a-file is a file",
    );
    let o = glint(
        &[
            "grade",
            "--stages",
            &scene("no-such-scene"),
            "--write",
            "out",
        ],
        dir.path(),
    );
    assert_input_error(&o, "no-such-scene.toml");
    assert!(!dir.path().join("out").exists());
}

/// The Python program of docs/grading-stages.md's worked example.
fn python_example() -> String {
    let doc = std::fs::read_to_string(common::repo().join("docs/grading-stages.md")).unwrap();
    let example = doc.split("## A worked example").nth(1).unwrap();
    let code = example.split("```python\n").nth(1).unwrap();
    code.split("```").next().unwrap().to_owned()
}

#[test]
fn the_python_example_in_the_docs_answers_the_camera_stage() {
    if !common::real_part(common::program_missing("python3", "python3")) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let given = dir.path().join("vectors");
    std::fs::create_dir(&given).unwrap();
    std::fs::copy(
        vectors().join("camera-inputs.csv"),
        given.join("camera-inputs.csv"),
    )
    .unwrap();
    std::fs::write(dir.path().join("camera.py"), python_example()).unwrap();
    let ran = std::process::Command::new("python3")
        .arg("camera.py")
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(ran.status.success(), "{}", stderr(&ran));
    let o = check(&dir.path().join("answers"), &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    assert_eq!(score_row(&stdout(&o), "camera")[1..4], ["64", "64", "64"]);
    // The slip the page shows: y not flipped fails every case.
    let slip = python_example().replace("ndc_y = 1 - 2 * y / height", "ndc_y = 2 * y / height - 1");
    std::fs::write(dir.path().join("camera.py"), slip).unwrap();
    let ran = std::process::Command::new("python3")
        .arg("camera.py")
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(ran.status.success());
    let o = check(&dir.path().join("answers"), &[]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stdout(&o).contains("camera: 64 of 64 answered cases fail; the first is camera-001"));
}
