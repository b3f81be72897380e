//! `glint grade` on the files students' ray tracers write, by programs other
//! than Glint: every format is read as what it is and judged through what it
//! did to the render (rounding to the step its data shows, a shared
//! exponent, half floats, JPEG's tables and subsampling); a format that lost
//! what the test needs is "unreadable" for grading, neither pass nor fail.
//!
//! The files are `camera/tests/data/formats` (one correct 40 × 24 render of
//! Set 1 by the independent tracer, saved by Pillow, OpenCV, OpenEXR's
//! bindings, stb_image_write and by hand). Every render and reference has a
//! fixed seed, so every verdict here is deterministic.

mod common;

use common::{glint, repo, scene, stderr, stdout};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The settings the files' render was made with.
const FIXTURE_SETTINGS: [&str; 8] = [
    "--spp",
    "4",
    "--sampler",
    "stratified",
    "--light-samples",
    "4",
    "--light-sampler",
    "stratified",
];

fn formats_dir() -> PathBuf {
    repo().join("camera/tests/data/formats")
}

/// Each graded file's JSON, by file name.
fn graded(o: &std::process::Output) -> BTreeMap<String, serde_json::Value> {
    let json: serde_json::Value = serde_json::from_str(&stdout(o)).unwrap();
    json["submissions"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            let file = Path::new(s["file"].as_str().unwrap());
            let name = file.file_name().unwrap().to_string_lossy().into_owned();
            (name, s.clone())
        })
        .collect()
}

#[test]
fn every_format_a_student_writes_is_graded_through_what_it_did() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("cache");
    let set1 = scene("cornell-set1");
    let mut files: Vec<PathBuf> = std::fs::read_dir(formats_dir())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e != "md"))
        .collect();
    files.sort();
    assert!(files.len() >= 35, "{files:?}");
    let mut args = vec!["grade", "--cache", cache.to_str().unwrap(), &set1];
    args.extend(files.iter().map(|f| f.to_str().unwrap()));
    args.extend(FIXTURE_SETTINGS);
    args.extend(["--format", "json"]);
    let o = glint(&args, dir.path());
    // Some are unreadable for grading: exit status 1, as for a failure.
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let grades = graded(&o);
    assert_eq!(grades.len(), files.len());

    let unreadable = [
        ("render-png-palette.png", "a palette image of"),
        ("render-jpeg-q30-420.jpg", "a JPEG of quality 30"),
        ("render-png-gray.png", "a gray image of a scene in colour"),
        ("render-pgm-p5.pgm", "a gray image of a scene in colour"),
        ("render-pgm-p2.pgm", "a gray image of a scene in colour"),
        ("render-jpeg-gray.jpg", "a gray image of a scene in colour"),
    ];
    for (name, grade) in &grades {
        match unreadable.iter().find(|(n, _)| n == name) {
            Some((_, why)) => {
                assert_eq!(grade["verdict"], "unreadable", "{name}: {grade}");
                let reason = grade["unreadable"].as_str().unwrap();
                assert!(reason.starts_with(why), "{name}: {reason}");
            }
            None => assert_eq!(grade["verdict"], "pass", "{name}: {grade}"),
        }
    }
    for (name, format) in [
        ("render-jpeg-q75-420.jpg", "JPEG, quality 75, 4:2:0"),
        (
            "render-jpeg-q85-progressive.jpg",
            "JPEG, progressive, quality 85, 4:2:0",
        ),
        ("render-jpeg-stb.jpg", "JPEG, quality 90, 4:2:0"),
        ("render-jpeg-gray.jpg", "JPEG, gray, quality 90"),
        (
            "render-png16-of-8bit.png",
            "PNG, 16-bit RGB, values on 8-bit steps",
        ),
        ("render-tga16.tga", "TGA, 16-bit RGB, values on 32 levels"),
        ("render-hdr-cv.pic", "Radiance HDR"),
        ("render-exr-half.exr", "OpenEXR, half float"),
        ("render-ppm-1023.ppm", "PPM (P3), maxval 1023"),
    ] {
        assert_eq!(grades[name]["format"], format, "{name}");
    }
    let translucent = &grades["render-png-translucent.png"];
    assert!(
        translucent["notes"][0]
            .as_str()
            .unwrap()
            .starts_with("its alpha channel is below 1 in 480 pixels"),
        "{translucent}"
    );
}

#[test]
fn another_encoders_jpeg_of_a_right_render_passes_and_of_a_wrong_one_fails_with_its_mistake_named()
{
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let set1 = scene("cornell-set1");
    let text = std::fs::read_to_string(&set1).unwrap();
    let wrong = d.join("no-ambient.toml");
    std::fs::write(
        &wrong,
        text.replace("ambient = [0.1, 0.1, 0.1]", "ambient = [0, 0, 0]"),
    )
    .unwrap();
    let mut jpegs = Vec::new();
    for (scene_file, name) in [(set1.as_str(), "right"), (wrong.to_str().unwrap(), "wrong")] {
        let png = d.join(format!("{name}.png"));
        let mut args = vec!["render", scene_file, "--resolution", "48x32", "-o"];
        args.push(png.to_str().unwrap());
        args.extend(FIXTURE_SETTINGS);
        let o = glint(&args, d);
        assert!(o.status.success(), "{}", stderr(&o));
        // The image crate's own JPEG encoder: neither libjpeg nor Glint's.
        let rgb = image::open(&png).unwrap().into_rgb8();
        let jpeg = d.join(format!("{name}.jpg"));
        let mut out = std::fs::File::create(&jpeg).unwrap();
        image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, 90)
            .encode_image(&rgb)
            .unwrap();
        jpegs.push(jpeg);
    }
    let cache = d.join("cache");
    let mut args = vec!["grade", "--cache", cache.to_str().unwrap(), &set1];
    args.extend(jpegs.iter().map(|f| f.to_str().unwrap()));
    args.extend(FIXTURE_SETTINGS);
    args.extend(["--format", "json"]);
    let o = glint(&args, d);
    let grades = graded(&o);
    assert_eq!(
        grades["right.jpg"]["verdict"], "pass",
        "{}",
        grades["right.jpg"]
    );
    assert_eq!(
        grades["wrong.jpg"]["verdict"], "fail",
        "{}",
        grades["wrong.jpg"]
    );
    // Its mistake is named: the mutants judged through its encoding.
    let first = &grades["wrong.jpg"]["likely_mistakes"][0];
    assert_eq!(first["id"], "no-ambient", "{}", grades["wrong.jpg"]);
    assert_eq!(first["consistent"], true, "{first}");
}
