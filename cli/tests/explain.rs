//! `glint explain` and `glint render --crop` as a user runs them: the four
//! pixels of the issue as text snapshots (every stage's numbers, rounded to 5
//! significant digits), the JSON document and its stages, the explained
//! radiance against the rendered pixel, and bad input.

mod common;
use common::{assert_input_error, glint, scene, stdout};

use glint_camera::Film;
use serde_json::Value;
use std::path::Path;

fn explain(args: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let out = glint(&[&["explain"], args].concat(), dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Nothing is written: explain only prints.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    stdout(&out)
}

#[test]
fn set1_checkered_sphere_partly_facing_away_from_the_light() {
    // Two of the four light samples are below the sphere's horizon here.
    let s = scene("cornell-set1");
    insta::assert_snapshot!(explain(&[&s, "--pixel", "400,192", "--light-samples", "4"]));
}

#[test]
fn set1_floor_in_the_penumbra_of_a_sphere() {
    let s = scene("cornell-set1");
    let text = explain(&[
        &s,
        "--pixel",
        "376,448",
        "--light-samples",
        "4",
        "--stage",
        "light",
    ]);
    assert!(text.contains("blocked by object 0"), "{text}");
    insta::assert_snapshot!(text);
}

#[test]
fn textured_ground_with_its_mip_levels_and_texels() {
    let s = scene("ground-mipmap");
    insta::assert_snapshot!(explain(&[&s, "--pixel", "80,200"]));
}

/// A ground pixel whose EWA ellipse crosses a check edge (after the scene).
const EWA_ACROSS_AN_EDGE: [&str; 6] = [
    "--pixel",
    "40,200",
    "--texture-filter",
    "ewa",
    "--stage",
    "texture",
];

#[test]
fn ewa_lookup_across_a_check_edge() {
    let s = scene("ground-mipmap");
    let text = explain(&[&[s.as_str()][..], &EWA_ACROSS_AN_EDGE].concat());
    assert!(text.contains("texels, weights adding up to"), "{text}");
    insta::assert_snapshot!(text);
}

#[test]
fn the_json_lists_the_bvh_path_and_every_texel_of_an_ellipse() {
    // The bunny's camera ray: the path starts at the root, and the leaf
    // holding the hit triangle is on it.
    let s = scene("bunny");
    let doc = json(&[&s, "--pixel", "240,180", "--stage", "intersect"]);
    let intersect = &doc["samples"][0]["ray"]["intersect"];
    let path = intersect["bvh"].as_array().unwrap();
    assert_eq!(path[0]["node"], 0);
    assert_eq!(path.len() as u64, {
        let w = &intersect["work"];
        w["bvh_nodes"].as_u64().unwrap() + w["bvh_leaves"].as_u64().unwrap()
    });
    let triangle = &intersect["hit"]["triangle"];
    assert!(path.iter().any(|step| step["primitives"]
        .as_array()
        .is_some_and(|p| p.iter().any(|p| p["triangle"] == *triangle))));
    // An EWA lookup: the listed texels' weighted values make the filtered value.
    let s = scene("ground-mipmap");
    let doc = json(&[&[s.as_str()][..], &EWA_ACROSS_AN_EDGE].concat());
    let lookup = &doc["samples"][0]["ray"]["texture"]["diffuse"];
    let texels = lookup["texels"].as_array().unwrap();
    assert!(texels.len() > 16, "{} texels", texels.len());
    let mut sum = [0.0; 3];
    for t in texels {
        for (k, s) in sum.iter_mut().enumerate() {
            *s += t["weight"].as_f64().unwrap() * t["value"][k].as_f64().unwrap();
        }
    }
    for (k, s) in sum.iter().enumerate() {
        let value = lookup["value"][k].as_f64().unwrap();
        assert!(
            (s - value).abs() < 1e-3 * value.max(0.01),
            "{k}: {s} vs {value}"
        );
    }
}

#[test]
fn mirror_sphere_in_the_environment_scene() {
    let s = scene("environment");
    insta::assert_snapshot!(explain(&[
        &s,
        "--pixel",
        "240,135",
        "--environment-samples",
        "4",
    ]));
}

/// Physical shading on a glossy sphere whose lobe samples reach the light:
/// every sample's light and lobe pdfs and the MIS weights between them.
#[test]
fn physical_glossy_highlight_with_its_mis_weights() {
    let s = scene("physical-glossy");
    let text = explain(&[
        &s,
        "--pixel",
        "162,148",
        "--spp",
        "4",
        "--light-samples",
        "2",
        "--all-samples",
    ]);
    assert!(text.contains("by specular lobe"), "{text}");
    assert!(text.matches("MIS weight 0.").count() >= 4, "{text}");
    insta::assert_snapshot!(text);
}

/// The physical Cornell box's floor: each light sample's solid-angle pdf,
/// for two camera samples.
#[test]
fn cornell_physical_floor_with_its_light_pdfs() {
    let s = scene("cornell-physical");
    let text = explain(&[
        &s,
        "--pixel",
        "300,420",
        "--spp",
        "2",
        "--light-samples",
        "4",
        "--all-samples",
    ]);
    assert!(text.contains("light pdf 3"), "{text}");
    insta::assert_snapshot!(text);
}

#[test]
fn bunny_through_the_bvh() {
    let s = scene("bunny");
    let text = explain(&[&s, "--pixel", "240,180", "--light-samples", "4"]);
    assert!(text.contains("(mesh)"), "{text}");
    insta::assert_snapshot!(text);
}

/// The pixel `(x, y)` of the PFM `glint render` writes with `args`.
fn rendered_pixel(args: &[&str], x: u32, y: u32) -> [f32; 3] {
    let dir = tempfile::tempdir().unwrap();
    let out = glint(
        &[&["render"], args, &["-o", "out.pfm"]].concat(),
        dir.path(),
    );
    assert!(out.status.success());
    let film = Film::load(&dir.path().join("out.pfm")).unwrap();
    film.pixel(x, y).to_array()
}

fn json(args: &[&str]) -> Value {
    serde_json::from_str(&explain(&[args, &["--json"]].concat())).unwrap()
}

#[test]
fn the_json_document_holds_the_rendered_pixel_and_every_stage() {
    let s = scene("cornell-set1");
    let flags = [
        s.as_str(),
        "--resolution",
        "48x48",
        "--spp",
        "4",
        "--light-samples",
        "4",
    ];
    let doc = json(&[&flags[..], &["--pixel", "30,20", "--all-samples"]].concat());
    assert_eq!(doc["schema"], "glint-explain/1");
    assert_eq!(doc["samples"].as_array().unwrap().len(), 4);
    let rendered = rendered_pixel(&flags, 30, 20);
    for (k, c) in rendered.iter().enumerate() {
        let explained = doc["film"]["radiance"][k].as_f64().unwrap();
        assert!(
            (explained - *c as f64).abs() <= 1e-4 * (*c as f64).abs(),
            "channel {k}: explained {explained}, rendered {c}"
        );
    }
    let sample = &doc["samples"][0];
    for key in ["camera", "ray", "radiance"] {
        assert!(!sample[key].is_null(), "{key} missing");
    }
    for key in ["intersect", "texture", "light", "radiance"] {
        assert!(!sample["ray"][key].is_null(), "ray.{key} missing");
    }
    // One stage only.
    let camera = json(&[&flags[..], &["--pixel", "30,20", "--stage", "camera"]].concat());
    let only = camera["samples"][0].as_object().unwrap();
    assert_eq!(only.keys().collect::<Vec<_>>(), ["camera", "sample"]);
    assert!(camera["film"].is_null());
    let film = json(&[&flags[..], &["--pixel", "30,20", "--stage", "film"]].concat());
    assert!(!film["film"]["srgb8"].is_null());
    assert!(film["samples"][0].get("camera").is_none());
}

#[test]
fn bad_pixels_and_samples_are_refused() {
    let s = scene("cornell-set1");
    let dir = tempfile::tempdir().unwrap();
    let run = |args: &[&str]| glint(&[&["explain", s.as_str()], args].concat(), dir.path());
    assert_input_error(&run(&["--pixel", "512,0"]), "outside the 512x512 image");
    assert_input_error(&run(&["--pixel", "3"]), "expected X,Y");
    assert_input_error(&run(&["--pixel=-1,4"]), "not a whole number");
    assert_input_error(&run(&["--pixel", "1,1", "--sample", "16"]), "16 samples");
    assert_input_error(
        &run(&["--pixel", "1,1", "--sample", "1", "--all-samples"]),
        "--all-samples",
    );
    assert_input_error(&run(&["--pixel", "1,1", "--stage", "shading"]), "--stage");
    assert_input_error(&run(&[]), "--pixel");
}

#[test]
fn a_crop_is_the_same_pixels_as_the_whole_render() {
    let s = scene("environment");
    let dir = tempfile::tempdir().unwrap();
    let flags = [
        s.as_str(),
        "--resolution",
        "40x30",
        "--spp",
        "4",
        "--environment-samples",
        "4",
    ];
    let render = |extra: &[&str], out: &str| {
        let o = glint(
            &[&["render"], &flags[..], extra, &["-o", out]].concat(),
            dir.path(),
        );
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        Film::load(&dir.path().join(out)).unwrap()
    };
    let whole = render(&[], "whole.pfm");
    let part = render(&["--crop", "7,5,31,22"], "part.pfm");
    assert_eq!((part.resolution().x, part.resolution().y), (24, 17));
    for y in 0..17 {
        for x in 0..24 {
            assert_eq!(
                part.pixel(x, y).to_array().map(f32::to_bits),
                whole.pixel(7 + x, 5 + y).to_array().map(f32::to_bits),
                "({x}, {y})"
            );
        }
    }
    let out = Path::new("bad.png");
    let o = glint(
        &[
            &["render"],
            &flags[..],
            &["--crop", "0,0,41,30", "-o", "bad.png"],
        ]
        .concat(),
        dir.path(),
    );
    assert_input_error(&o, "--crop");
    assert!(!dir.path().join(out).exists());
    let o = glint(
        &[&["render"], &flags[..], &["--crop", "5,5,5,9"]].concat(),
        dir.path(),
    );
    assert_input_error(&o, "empty");
}

#[test]
fn the_text_headings_are_accepted_as_stage_names() {
    let s = scene("cornell-set1");
    let at = [s.as_str(), "--pixel", "376,448", "--light-samples", "1"];
    for (name, heading) in [("intersect", "intersection"), ("light", "lighting")] {
        let by_name = explain(&[&at[..], &["--stage", name]].concat());
        assert!(by_name.contains(&format!("\n  {heading}\n")), "{by_name}");
        assert_eq!(by_name, explain(&[&at[..], &["--stage", heading]].concat()));
    }
    // Help gives the names and says the headings are accepted.
    let o = glint(&["explain", "--help"], Path::new("."));
    let help = stdout(&o);
    assert!(help.contains("intersection and lighting"), "{help}");
}

#[test]
fn the_reports_level_is_a_whole_pixels_and_does_not_change_with_spp() {
    // The textured ground at pixel (80, 200); sample 0 is at the same place in
    // the pixel for any spp (the first Sobol point). The report's level,
    // log2(L/W) with L = 2·t·tan(fov/2)/(r·|N·D|) and W = |J_T|/m, stays;
    // Glint's own level reads finer as the samples share the pixel.
    let s = scene("ground-mipmap");
    let mut glint_levels = Vec::new();
    for spp in ["1", "4", "16"] {
        let doc = json(&[&s, "--pixel", "80,200", "--spp", spp, "--stage", "texture"]);
        let diffuse = &doc["samples"][0]["ray"]["texture"]["diffuse"];
        assert_eq!(diffuse["report_level"], 5.0646, "spp {spp}: {diffuse}");
        assert_eq!(diffuse["report_l"], 0.52291, "spp {spp}");
        assert_eq!(diffuse["report_w"], 0.015625, "spp {spp}");
        assert_eq!(diffuse["report_m"], 256, "spp {spp}");
        glint_levels.push(diffuse["glint_level"].as_f64().unwrap());
    }
    assert!(
        glint_levels[0] > glint_levels[1] && glint_levels[1] > glint_levels[2],
        "{glint_levels:?}"
    );
}

/// The deterministic recipe: one camera sample at the pixel's centre, one
/// light sample at the light's centre.
const DETERMINISTIC: [&str; 8] = [
    "--spp",
    "1",
    "--sampler",
    "grid",
    "--light-samples",
    "1",
    "--light-sampler",
    "grid",
];

/// `glint explain SCENE --pixel PIXEL` with the deterministic recipe and
/// `extra`, against `document` written to a file; the output.
fn against(scene_name: &str, pixel: &str, document: &str, extra: &[&str]) -> std::process::Output {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("student.json"), document).unwrap();
    let s = scene(scene_name);
    let args = [
        &["explain", s.as_str(), "--pixel", pixel][..],
        &DETERMINISTIC,
        &["--against", "student.json"],
        extra,
    ]
    .concat();
    glint(&args, dir.path())
}

/// Glint's own document for the checkered Set 1 sphere's pixel.
fn sphere_document() -> Value {
    let s = scene("cornell-set1");
    json(&[&[s.as_str(), "--pixel", "400,192"][..], &DETERMINISTIC].concat())
}

#[test]
fn glints_own_document_agrees_at_every_stage() {
    let doc = sphere_document().to_string();
    let o = against("cornell-set1", "400,192", &doc, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", common::stderr(&o));
    let text = stdout(&o);
    for stage in ["camera", "intersection", "texture", "lighting", "film"] {
        assert!(text.contains(&format!("  {stage}: agrees (")), "{text}");
    }
    // A partial document agrees too.
    let partial = format!(
        r#"{{"spp": 1, "schema": "glint-explain/1", "film": {{"srgb8": {}}}}}"#,
        sphere_document()["film"]["srgb8"]
    );
    let o = against("cornell-set1", "400,192", &partial, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    assert!(stdout(&o).contains("  camera: not in your document"));
}

#[test]
fn a_perturbed_camera_direction_parts_at_the_camera() {
    let mut doc = sphere_document();
    let direction = &mut doc["samples"][0]["camera"]["direction"];
    direction[0] = (direction[0].as_f64().unwrap() + 0.01).into();
    let o = against("cornell-set1", "400,192", &doc.to_string(), &["--json"]);
    assert_eq!(o.status.code(), Some(1), "{}", common::stderr(&o));
    let report: Value = serde_json::from_str(&stdout(&o)).unwrap();
    let first = &report["first_difference"];
    assert_eq!(first["stage"], "camera", "{report}");
    assert_eq!(first["path"], "samples[0].camera.direction");
    assert_eq!(first["tolerance"]["kind"], "angular");
    assert_eq!(report["agrees"], false);
}

#[test]
fn a_wrong_uv_parts_at_the_intersection_though_the_film_differs_too() {
    // A student's wrong sphere uv: their checker colour, lighting and film
    // follow from it; the film comes before the samples in their file.
    let mut doc = sphere_document();
    let hit = &mut doc["samples"][0]["ray"]["intersect"]["hit"];
    hit["uv"] = serde_json::json!([0.1, 0.2]);
    doc["film"]["radiance"] = serde_json::json!([0.9, 0.9, 0.9]);
    doc["samples"][0]["ray"]["texture"]["kd"] = serde_json::json!([0.9, 0.9, 0.9]);
    let text = doc.to_string();
    assert!(text.find("\"film\"") < text.find("\"samples\""), "{text}");
    let o = against("cornell-set1", "400,192", &text, &[]);
    assert_eq!(o.status.code(), Some(1), "{}", common::stderr(&o));
    let report = stdout(&o);
    assert!(
        report.contains("intersection: PARTS from Glint")
            && report.contains("first difference: samples[0].ray.intersect.hit.uv")
            && report.contains("film: 1 of"),
        "{report}"
    );
    let err = common::stderr(&o);
    assert!(err.contains("intersection stage"), "{err}");
}

#[test]
fn a_bad_document_is_an_input_error() {
    let o = against(
        "cornell-set1",
        "400,192",
        "{\"schema\": \"glint-explain/1\",\n  \"pixel\": [400 192]}",
        &[],
    );
    assert_input_error(&o, "student.json:2:17: expected `,` or `]`");
    let o = against(
        "cornell-set1",
        "400,192",
        r#"{"schema": "glint-explain/2"}"#,
        &[],
    );
    assert_input_error(&o, "student.json: schema is \"glint-explain/2\"");
    let doc = sphere_document().to_string();
    let o = against("cornell-set1", "401,192", &doc, &[]);
    assert_input_error(&o, "pass --pixel 400,192");
    let mut small = sphere_document();
    small["pixel"] = serde_json::json!([40, 19]);
    let o = against(
        "cornell-set1",
        "40,19",
        &small.to_string(),
        &["--resolution", "64x64"],
    );
    assert_input_error(&o, "pass --resolution 512x512");
    let o = against("cornell-set1", "400,192", "", &[]);
    assert_input_error(&o, "student.json:1:0: EOF while parsing a value");
}
