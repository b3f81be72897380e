//! `glint grade` names the mistake behind a failing image: the catalogue
//! (`--mistakes`), a failing submission's `likely_mistakes` (the true one
//! first, or "no known mistake fits" for one not in the catalogue, nothing
//! for a pass), the table's phrase, `--no-mistakes`, and `glint explain
//! --mistake`. The submissions are Glint's renders of edited scenes with
//! their own seeds; measure/mistakes/diagnose.py measures the same on an
//! independent tracer's mistakes.

mod common;

use common::{assert_input_error, glint, scene, stderr, stdout};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// The settings the submissions are rendered with and stated to use.
const STATED: [&str; 8] = [
    "--spp",
    "4",
    "--sampler",
    "stratified",
    "--light-samples",
    "4",
    "--light-sampler",
    "stratified",
];

/// Set 1 with `from` replaced by `to`, written into `dir` as `name`.
fn edited_set1(dir: &Path, name: &str, from: &str, to: &str) -> String {
    let text = std::fs::read_to_string(scene("cornell-set1")).unwrap();
    let changed = text.replace(from, to);
    assert_ne!(text, changed, "{from} is in the scene");
    let path = dir.join(name);
    std::fs::write(&path, changed).unwrap();
    path.to_str().unwrap().to_owned()
}

/// `scene_file` rendered at 48 × 48 with [`STATED`] and its own seed.
fn render(dir: &Path, scene_file: &str, name: &str, seed: &str) -> PathBuf {
    render_with(dir, scene_file, name, seed, &[])
}

/// [`render`] with `extra` flags.
fn render_with(dir: &Path, scene_file: &str, name: &str, seed: &str, extra: &[&str]) -> PathBuf {
    let out = dir.join(name);
    let mut args = vec![
        "render",
        scene_file,
        "--resolution",
        "48x48",
        "--seed",
        seed,
    ];
    args.extend_from_slice(&STATED);
    args.extend_from_slice(extra);
    args.extend_from_slice(&["-o", out.to_str().unwrap()]);
    let o = glint(&args, dir);
    assert!(o.status.success(), "{}", stderr(&o));
    out
}

/// `glint grade SET1 FILES… --format json` under [`STATED`]: each
/// submission's JSON.
fn graded(dir: &Path, files: &[&Path], extra: &[&str]) -> Vec<Value> {
    let set1 = scene("cornell-set1");
    let cache = dir.join("cache");
    let mut args = vec!["grade", set1.as_str(), "--cache", cache.to_str().unwrap()];
    args.extend(files.iter().map(|f| f.to_str().unwrap()));
    args.extend_from_slice(&STATED);
    args.extend_from_slice(&["--format", "json"]);
    args.extend_from_slice(extra);
    let o = glint(&args, dir);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(&o));
    let document: Value = serde_json::from_str(&stdout(&o)).unwrap();
    document["submissions"].as_array().unwrap().clone()
}

/// The ids of the consistent mistakes, best first.
fn consistent(submission: &Value) -> Vec<String> {
    submission["likely_mistakes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| m["consistent"] == Value::Bool(true))
        .map(|m| m["id"].as_str().unwrap().to_owned())
        .collect()
}

/// `image` with its rows in the opposite order.
fn flipped(image: &Path, out: &Path) -> PathBuf {
    let decoded = image::open(image).unwrap().flipv();
    decoded.save(out).unwrap();
    out.to_owned()
}

#[test]
fn the_catalogue_lists_every_classic_mistake_with_its_stage_and_how_it_is_rendered() {
    let dir = tempfile::tempdir().unwrap();
    let o = glint(&["grade", "--mistakes"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    let ids = [
        "view-sign",
        "sphere-u-sign",
        "no-shadow-offset",
        "no-shadows",
        "no-srgb",
        "sum-light-samples",
        "fov-horizontal",
        "fov-not-halved",
        "pixel-corner",
        "normal-not-normalised",
        "blinn",
        "checker-double",
        "no-ambient",
        "flip-vertical",
        "light-centre",
        "ks-as-kd",
        "light-blocks-itself",
        "ambient-without-kd",
        "specular-cosine",
        "light-colour-ignored",
        "gamma-2.2",
        "light-invisible",
        "two-sided-light",
        "no-lambert-cosine",
        "light-twice-size",
        "fixed-light-samples",
        "uv-swapped",
        "nearest-texel",
        "mip-level-ln",
        "cube-face-swapped",
        "cube-face-mirrored",
    ];
    for id in ids {
        let line = text
            .lines()
            .find(|l| l.split_whitespace().next() == Some(id))
            .unwrap_or_else(|| panic!("{id} missing from:\n{text}"));
        let stage = line.split_whitespace().nth(1).unwrap();
        assert!(
            [
                "camera",
                "intersection",
                "texture",
                "lighting",
                "shading",
                "environment",
                "film"
            ]
            .contains(&stage),
            "{line}"
        );
    }
    for line in text.lines() {
        let how = line.split_whitespace().nth(2).unwrap_or_default();
        assert!(
            ["scene", "lights", "integrator", "film", "noise"].contains(&how),
            "every mistake is rendered (or changes only the noise): {line}"
        );
    }
    let o = glint(&["grade", "--mistakes", "--spp", "4"], dir.path());
    assert_eq!(o.status.code(), Some(2), "--mistakes takes nothing else");
}

#[test]
fn a_failing_submission_is_named_by_its_mistake_and_a_pass_by_none() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let set1 = scene("cornell-set1");
    let no_ambient = edited_set1(
        d,
        "no-ambient.toml",
        "ambient = [0.1, 0.1, 0.1]",
        "ambient = [0, 0, 0]",
    );
    let fov = edited_set1(d, "fov.toml", "fov = 45 ", "fov = 90 ");
    let good = render(d, &set1, "good.png", "11");
    let upside_down = flipped(
        &render(d, &set1, "upright.png", "12"),
        &d.join("flipped.png"),
    );
    let files = [
        good,
        render(d, &no_ambient, "no-ambient.png", "13"),
        render(d, &fov, "fov-not-halved.png", "14"),
        upside_down,
        // Two mistakes: no single one fits.
        flipped(
            &render(d, &no_ambient, "no-ambient-2.png", "15"),
            &d.join("both.png"),
        ),
    ];
    let paths: Vec<&Path> = files.iter().map(PathBuf::as_path).collect();
    let grades = graded(d, &paths, &[]);
    assert_eq!(grades[0]["verdict"], "pass");
    assert_eq!(
        grades[0]["likely_mistakes"],
        Value::Array(vec![]),
        "a pass is given no mistake"
    );
    for (grade, id) in grades[1..].iter().zip([
        "no-ambient",
        "fov-not-halved",
        "flip-vertical",
        "no-ambient+flip-vertical",
    ]) {
        assert_eq!(grade["verdict"], "fail", "{grade}");
        assert_eq!(
            consistent(grade).first().map(String::as_str),
            Some(id),
            "{grade:#}"
        );
        let first = &grade["likely_mistakes"][0];
        assert!(first["description"].as_str().is_some_and(|d| !d.is_empty()));
        assert!(
            first["stage"].is_string() && first["largest_z"].is_number(),
            "{first}"
        );
    }

    // The table's line ends with the finding; --no-mistakes leaves it out.
    let cache = d.join("cache");
    let table = |extra: &[&str]| {
        let mut args = vec!["grade", set1.as_str(), files[1].to_str().unwrap()];
        args.extend_from_slice(&STATED);
        args.extend_from_slice(&["--cache", cache.to_str().unwrap()]);
        args.extend_from_slice(extra);
        stdout(&glint(&args, d))
    };
    let text = table(&[]);
    assert!(
        text.contains("consistent with: ambient term left out (no-ambient)"),
        "{text}"
    );
    let text = table(&["--no-mistakes"]);
    assert!(
        !text.contains("consistent with") && text.contains("FAIL"),
        "{text}"
    );

    // The report shows Glint's render of the best fit beside the
    // submission: nearer it than the correct reference is.
    let report = d.join("report");
    table(&["--report", report.to_str().unwrap()]);
    let page = std::fs::read_to_string(report.join("index.html")).unwrap();
    assert!(
        page.contains("images/0-mistake-small.png") && page.contains("mistake, no-ambient"),
        "{page}"
    );
    let pixels = |name: &str| {
        image::open(report.join("images").join(name))
            .unwrap()
            .to_rgb8()
    };
    let (fit, submitted) = (pixels("0-mistake.png"), pixels("0-submission.png"));
    let reference = pixels("reference-0.png");
    let distance = |a: &image::RgbImage| -> f64 {
        let pairs = a.as_raw().iter().zip(submitted.as_raw());
        pairs
            .map(|(&x, &y)| (x as f64 - y as f64).abs())
            .sum::<f64>()
            / a.len() as f64
    };
    assert!(
        distance(&fit) < distance(&reference) / 2.0,
        "fit {} against reference {}",
        distance(&fit),
        distance(&reference)
    );
}

/// Mistakes Glint renders in its one-ray integrator or in the file, made
/// by `glint render --mistake` with other seeds: each named first, alone
/// and with a scene edit.
#[test]
fn a_mistake_rendered_by_glint_render_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let set1 = scene("cornell-set1");
    let ids = [
        "no-shadows",
        "light-invisible",
        "view-sign",
        "ambient-without-kd",
        "light-blocks-itself",
        "no-srgb",
    ];
    let mut files: Vec<PathBuf> = (ids.iter().enumerate())
        .map(|(i, id)| {
            let seed = (31 + i).to_string();
            render_with(d, &set1, &format!("{id}.png"), &seed, &["--mistake", id])
        })
        .collect();
    // A pair: no shadows in a tracer that also leaves out the ambient term.
    let no_ambient = edited_set1(
        d,
        "no-ambient.toml",
        "ambient = [0.1, 0.1, 0.1]",
        "ambient = [0, 0, 0]",
    );
    files.push(render_with(
        d,
        &no_ambient,
        "both.png",
        "41",
        &["--mistake", "no-shadows"],
    ));
    let paths: Vec<&Path> = files.iter().map(PathBuf::as_path).collect();
    let grades = graded(d, &paths, &[]);
    for (grade, id) in grades
        .iter()
        .zip(ids.into_iter().chain(["no-shadows+no-ambient"]))
    {
        assert_eq!(grade["verdict"], "fail", "{id}: {grade}");
        let named = consistent(grade);
        let first = named.first().map(String::as_str);
        // A pair is named in either order.
        let reversed = id.split('+').rev().collect::<Vec<_>>().join("+");
        assert!(
            first == Some(id) || first == Some(&reversed),
            "{id}: {grade:#}"
        );
    }

    // What cannot be rendered so is refused before any work.
    let out = d.join("x.exr");
    let refused = |mistake: &str, says: &str| {
        let o = glint(
            &[
                "render",
                &set1,
                "--mistake",
                mistake,
                "-o",
                out.to_str().unwrap(),
            ],
            d,
        );
        assert_input_error(&o, says);
        assert!(!out.exists());
    };
    refused("no-srgb", "needs a .png output");
    refused("fixed-light-samples", "changes only the noise");
    refused("mip-level-ln", "changes nothing");
    refused("no-such-mistake", "glint grade --mistakes lists them");
}

#[test]
fn a_mistake_outside_the_catalogue_is_not_given_a_name() {
    // Every material's specular colour white: no mistake Glint knows.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let text = std::fs::read_to_string(scene("cornell-set1")).unwrap();
    let white = text.replace("shininess =", "specular = [1, 1, 1]\nshininess =");
    let path = d.join("specular-white.toml");
    std::fs::write(&path, white).unwrap();
    let image = render(d, path.to_str().unwrap(), "white.png", "21");
    let grades = graded(d, &[&image], &[]);
    assert_eq!(grades[0]["verdict"], "fail");
    assert!(consistent(&grades[0]).is_empty(), "{:#}", grades[0]);
    assert!(
        !grades[0]["likely_mistakes"].as_array().unwrap().is_empty(),
        "they were tested"
    );
    let set1 = scene("cornell-set1");
    let mut args = vec!["grade", set1.as_str(), image.to_str().unwrap()];
    args.extend_from_slice(&STATED);
    let cache = d.join("cache");
    args.extend_from_slice(&["--cache", cache.to_str().unwrap()]);
    assert!(stdout(&glint(&args, d)).contains("no known mistake fits"));
}

#[test]
fn explain_shows_a_pixel_with_a_mistake_switched_on_traced_or_beside_the_right_stages() {
    let dir = tempfile::tempdir().unwrap();
    let set1 = scene("cornell-set1");
    let explain_at = |pixel: &str, extra: &[&str]| {
        let mut args = vec!["explain", set1.as_str(), "--pixel", pixel];
        args.extend_from_slice(&["--resolution", "64x64", "--stage", "light"]);
        args.extend_from_slice(extra);
        glint(&args, dir.path())
    };
    let explain = |extra: &[&str]| explain_at("30,60", extra);
    let correct = stdout(&explain(&[]));
    assert!(correct.contains("ambient·kd (0.07"), "{correct}");
    let o = explain(&["--mistake", "no-ambient"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("ambient·kd (0.0, 0.0, 0.0)"),
        "{}",
        stdout(&o)
    );
    // A stage the one-ray integrator swaps: the right stages, and the pixel
    // as the mistake renders it, glint render --mistake's pixel.
    let o = explain_at("29,58", &["--mistake", "no-shadows", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let document: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let mistake = &document["mistake"];
    assert_eq!(mistake["id"], "no-shadows");
    assert_eq!(mistake["stage"], "lighting");
    let rendered = dir.path().join("no-shadows.pfm");
    let o = glint(
        &[
            "render",
            &set1,
            "--resolution",
            "64x64",
            "--mistake",
            "no-shadows",
            "-o",
            rendered.to_str().unwrap(),
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let film = glint_camera::Film::read(&rendered).unwrap().film;
    let pixel = film.pixels()[58 * 64 + 29];
    for c in 0..3 {
        let shown = mistake["radiance"][c].as_f64().unwrap();
        let want = pixel[c] as f64;
        assert!((shown - want).abs() <= 1e-4 * want, "{shown} for {want}");
    }
    // A pixel in the shadow of a sphere: lit by the mistake.
    let right = &document["samples"][0]["ray"]["radiance"]["value"];
    assert!(right[0].as_f64().unwrap() < 0.5 * pixel.x as f64, "{right}");
    let plain = stdout(&explain_at("29,58", &[]));
    let text = stdout(&explain_at("29,58", &["--mistake", "no-shadows"]));
    assert!(
        text.starts_with(plain.trim_end()),
        "the right stages first:\n{text}"
    );
    assert!(
        text.contains("with the mistake no-shadows (lighting stage: "),
        "{text}"
    );
    // What the file stores: the right pixel written without the sRGB
    // curve; rows upside down, the mirrored pixel's.
    let film = |pixel: &str, extra: &[&str]| {
        let mut args = vec!["explain", set1.as_str(), "--pixel", pixel];
        args.extend_from_slice(&["--resolution", "64x64", "--stage", "film", "--json"]);
        args.extend_from_slice(extra);
        let o = glint(&args, dir.path());
        assert!(o.status.success(), "{}", stderr(&o));
        serde_json::from_str::<serde_json::Value>(&stdout(&o)).unwrap()
    };
    let right = film("29,58", &[]);
    let linear = film("29,58", &["--mistake", "no-srgb"]);
    let codes = |v: &serde_json::Value| v["srgb8"].as_array().unwrap().clone();
    let radiance = right["film"]["radiance"][0].as_f64().unwrap();
    let written = (radiance.clamp(0.0, 1.0) * 255.0).round();
    assert_eq!(
        codes(&linear["mistake"])[0].as_f64(),
        Some(written),
        "{linear}"
    );
    let flipped = film("29,58", &["--mistake", "flip-vertical"]);
    assert_eq!(
        codes(&flipped["mistake"]),
        codes(&film("29,5", &[])["film"])
    );
    for (id, says) in [
        ("no-such-mistake", "glint grade --mistakes lists them"),
        ("fixed-light-samples", "only the noise"),
        ("light-colour-ignored", "changes nothing"),
    ] {
        assert_input_error(&explain(&["--mistake", id]), says);
    }
    let student = dir.path().join("student.json");
    std::fs::write(&student, "{}").unwrap();
    let against = format!("--against={}", student.display());
    assert_input_error(
        &explain(&["--mistake", "view-sign", &against]),
        "nothing to compare --against",
    );
    assert_input_error(
        &explain(&["--mistake", "no-srgb", &against]),
        "nothing to compare --against",
    );
}
