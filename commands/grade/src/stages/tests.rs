//! The stages' vectors against Glint's own functions, and the checker
//! against Glint's own answers, perturbed and not.

use super::*;
use crate::stages::answers::Answer;
use glam::{Vec2, Vec3};
use glint_integrator::trace::{Event, SampleSelection};
use glint_texture::{TexCoord, Texture};
use std::sync::OnceLock;

/// Cases per stage in these tests: enough for every kind of pixel, few
/// enough for a debug build.
const N: u32 = 24;

fn scene(name: &str) -> GradeScene {
    let path = format!("{}/../../scenes/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    GradeScene::load(Path::new(&path)).unwrap()
}

/// The Cornell box (Set 1) and its vectors, made once.
fn set1() -> &'static (GradeScene, Vec<StageVectors>) {
    static SET1: OnceLock<(GradeScene, Vec<StageVectors>)> = OnceLock::new();
    SET1.get_or_init(|| {
        let s = scene("cornell-set1");
        let v = vectors(&s, &Stage::ALL, N).unwrap();
        (s, v)
    })
}

fn stage(stage: Stage) -> &'static StageVectors {
    set1().1.iter().find(|v| v.stage == stage).unwrap()
}

fn float(case: &Case, column: &str) -> f32 {
    match case.get(column) {
        Value::Float(x) => *x,
        other => panic!("{}: {column} is {other:?}", case.id),
    }
}

fn xyz(case: &Case, name: &str) -> Vec3 {
    Vec3::from_array(table::XYZ.map(|s| float(case, &format!("{name}_{s}"))))
}

fn rgb(case: &Case, name: &str) -> Vec3 {
    Vec3::from_array(table::RGB.map(|s| float(case, &format!("{name}_{s}"))))
}

#[test]
fn every_stage_has_its_cases_with_every_expected_column() {
    for v in &set1().1 {
        assert_eq!(v.cases.len(), N as usize, "{:?}", v.stage);
        for c in &v.cases {
            assert!(c.id.starts_with(v.stage.name()), "{}", c.id);
            for column in &v.layout.inputs {
                assert!(
                    c.values.contains_key(column) || optional_input(column),
                    "{} {column}",
                    c.id
                );
            }
        }
        // Every case answers at least one expected field.
        for c in &v.cases {
            assert!(
                v.layout
                    .expected_columns()
                    .any(|k| *c.get(k) != Value::Empty),
                "{}",
                c.id
            );
        }
    }
}

/// Inputs that do not apply to every case: a checkerboard's `m`, a point
/// light's normal.
fn optional_input(column: &str) -> bool {
    column == "m" || column.contains("_normal_")
}

#[test]
fn a_camera_case_is_generate_ray_at_its_raster_position() {
    let (s, _) = set1();
    let camera = &s.description.scene.camera;
    for c in &stage(Stage::Camera).cases {
        let ray = camera.generate_ray(float(c, "x"), float(c, "y"));
        assert_eq!(xyz(c, "direction"), ray.direction, "{}", c.id);
        assert_eq!(xyz(c, "origin"), ray.origin, "{}", c.id);
        // The raster position is the case's grid sample of its pixel.
        let from = c.from.as_ref().unwrap();
        let k = (from.spp as f32).sqrt() as u32;
        let cell = Vec2::new((from.sample % k) as f32, (from.sample / k) as f32);
        let want = Vec2::new(from.pixel[0] as f32, from.pixel[1] as f32) + (cell + 0.5) / k as f32;
        assert_eq!(Vec2::new(float(c, "x"), float(c, "y")), want, "{}", c.id);
    }
    // The image's corners are among the cases.
    let pixels: Vec<[u32; 2]> = stage(Stage::Camera)
        .cases
        .iter()
        .map(|c| c.from.as_ref().unwrap().pixel)
        .collect();
    assert!(
        pixels.contains(&[0, 0]) && pixels.contains(&[511, 511]),
        "{pixels:?}"
    );
}

#[test]
fn an_intersection_case_is_the_closest_hit_of_its_ray() {
    let (s, _) = set1();
    let scene = &s.description.scene;
    let mut spheres = 0;
    for c in &stage(Stage::Intersection).cases {
        let ray = glint_geometry::Ray::new(xyz(c, "origin"), xyz(c, "direction"));
        let hit = scene.shapes.closest_hit(&ray, f32::INFINITY);
        assert_eq!(c.get("hit"), &Value::Bool(hit.is_some()), "{}", c.id);
        let Some(hit) = hit else { continue };
        assert_eq!(float(c, "t"), hit.t, "{}", c.id);
        assert_eq!(xyz(c, "point"), hit.point, "{}", c.id);
        assert_eq!(xyz(c, "geometric_normal"), hit.geometric_normal, "{}", c.id);
        assert_eq!(Vec2::new(float(c, "u"), float(c, "v")), hit.uv, "{}", c.id);
        assert_eq!(c.get("object"), &Value::Int(hit.shape.into()), "{}", c.id);
        let name = &s.description.object_names[hit.shape as usize];
        assert_eq!(c.get("name"), &Value::Text(name.clone()), "{}", c.id);
        assert_eq!(c.periodic_u, name.starts_with("sphere"), "{}", c.id);
        spheres += usize::from(c.periodic_u);
    }
    assert!(spheres >= 3, "{spheres} sphere hits");
    // Awkward pixels are there: silhouettes, and one that sees the light.
    let why: Vec<&str> = stage(Stage::Intersection)
        .cases
        .iter()
        .map(|c| c.from.as_ref().unwrap().why)
        .collect();
    assert!(
        why.contains(&"a sphere's silhouette") && why.contains(&"sees a light"),
        "{why:?}"
    );
}

#[test]
fn a_lighting_case_adds_up_to_the_integrators_local_radiance() {
    let (s, _) = set1();
    let d = &s.description;
    let mut blocked = 0;
    let mut visible = 0;
    for c in &stage(Stage::Lighting).cases {
        let from = c.from.as_ref().unwrap();
        let settings = probe::settings(&d.settings, from.spp);
        let [x, y] = from.pixel;
        let one = SampleSelection::One(from.sample.into());
        let explained = glint_integrator::explain_pixel(&d.scene, &settings, x, y, one).unwrap();
        let local = explained.samples[0]
            .events
            .iter()
            .find_map(|e| match e {
                Event::Radiance {
                    depth: 0, local, ..
                } => Some(*local),
                _ => None,
            })
            .unwrap();
        // Ambient plus the light's term, exactly as the integrator summed them.
        assert_eq!(rgb(c, "total"), local, "{}", c.id);
        // Each sample's terms: what it adds when visible.
        let mut sum = Vec3::ZERO;
        for k in 0..16 {
            let name = format!("s{k:02}");
            let verdict = c.get(&format!("{name}_verdict"));
            if *verdict == Value::Text("visible".into()) {
                sum += rgb(c, &format!("{name}_diffuse")) + rgb(c, &format!("{name}_specular"));
                visible += 1;
            }
            if *verdict == Value::Text("blocked".into()) {
                assert!(
                    matches!(c.get(&format!("{name}_blocker")), Value::Int(0..=3)),
                    "{}",
                    c.id
                );
                blocked += 1;
            }
        }
        let total = rgb(c, "ambient_term") + sum / 16.0;
        assert!(
            (total - local).abs().max_element() < 1e-5,
            "{}: {total} against {local}",
            c.id
        );
    }
    assert!(
        blocked > 10 && visible > 10,
        "{blocked} blocked, {visible} visible samples"
    );
}

#[test]
fn a_texture_case_on_an_image_reads_the_reports_level() {
    let s = scene("textured-spheres");
    let v = &vectors(&s, &[Stage::Texture], 12).unwrap()[0];
    let images: Vec<&Case> = v
        .cases
        .iter()
        .filter(|c| c.get("kind") == &Value::Text("image".into()))
        .collect();
    assert!(images.len() >= 4, "{} image cases", images.len());
    let d = &s.description;
    for c in images {
        let object = match c.get("object") {
            Value::Int(o) => *o as u32,
            other => panic!("{other:?}"),
        };
        let glint_integrator::Surface::Material(m) = d.scene.surfaces[object as usize] else {
            panic!("{}: not a material", c.id);
        };
        let material = &d.scene.materials[m as usize];
        let Texture::Image(image) = &material.diffuse else {
            panic!("{}: not an image", c.id);
        };
        let (l, w, level) = (float(c, "l"), float(c, "w"), float(c, "level"));
        assert!((level - (l / w).log2()).abs() < 1e-5, "{}", c.id);
        let m_texels = image
            .image
            .image()
            .width()
            .max(image.image.image().height());
        assert_eq!(c.get("m"), &Value::Int(m_texels.into()));
        assert!(
            (w - float(c, "jacobian") / m_texels as f32).abs() <= 1e-6 * w,
            "{}",
            c.id
        );
        let uv = material
            .uv_transform
            .apply(&TexCoord::point(Vec2::new(float(c, "u"), float(c, "v"))))
            .uv;
        let st = Vec2::new(uv.x, 1.0 - uv.y);
        let want = image
            .image
            .pyramid()
            .trilinear_at_level(st, level, image.wrap);
        assert_eq!(rgb(c, "value"), want, "{}", c.id);
        // A render at the report's level reads the same value at the case's
        // camera sample: the stage and `glint explain --texture-level
        // report` agree.
        let mut at_report = d.scene.clone();
        at_report.set_texture_level(glint_integrator::TextureLevel::Report);
        let from = c.from.as_ref().unwrap();
        let settings = probe::settings(&d.settings, from.spp);
        let selection = SampleSelection::One(from.sample.into());
        let [x, y] = from.pixel;
        let explained = glint_explain::explain(&at_report, &settings, x, y, selection).unwrap();
        let lookup = &explained.document["samples"][0]["ray"]["texture"]["diffuse"];
        let rendered: Vec<f64> = (0..3)
            .map(|i| lookup["value"][i].as_f64().unwrap())
            .collect();
        for (got, want) in rendered.iter().zip(want.to_array()) {
            // The document's 5 significant digits.
            assert!(
                (got - f64::from(want)).abs() <= 1e-4 * f64::from(want).abs() + 1e-9,
                "{}: {rendered:?} against {want}",
                c.id
            );
        }
        let level = lookup["glint_level"].as_f64().unwrap();
        assert!(
            (level - f64::from(float(c, "level"))).abs() < 1e-3,
            "{}: level {level}",
            c.id
        );
    }
}

#[test]
fn the_cornell_box_is_23_units_across() {
    // Its walls run from −7 to 13 along x and y; docs/scene-format.md and
    // commands/explain/tests/docs_rules.rs state the offsets for this size.
    let (s, _) = set1();
    assert_eq!(lighting::scene_size(&s.description.scene), 23.0);
}

#[test]
fn a_checkerboard_case_is_the_check_under_the_point() {
    let (s, _) = set1();
    for c in &stage(Stage::Texture).cases {
        assert_eq!(c.get("kind"), &Value::Text("checkerboard".into()));
        assert_eq!(c.get("level"), &Value::Empty, "{}", c.id);
        let object = match c.get("object") {
            Value::Int(o) => *o as u32,
            other => panic!("{other:?}"),
        };
        let glint_integrator::SurfaceKind::Material(m) =
            s.description.scene.surface_of_primitive(object, 0)
        else {
            panic!("{}: not a material", c.id);
        };
        let uv = Vec2::new(float(c, "u"), float(c, "v"));
        assert_eq!(rgb(c, "value"), m.diffuse.evaluate_at(uv), "{}", c.id);
    }
}

#[test]
fn the_same_scene_and_count_give_the_same_files() {
    let s = scene("cornell-set1");
    let dirs = [tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap()];
    for d in &dirs {
        write_vectors(&s, 8, d.path()).unwrap();
    }
    let mut files = 0;
    for entry in std::fs::read_dir(dirs[0].path()).unwrap() {
        let name = entry.unwrap().file_name();
        let a = std::fs::read(dirs[0].path().join(&name)).unwrap();
        let b = std::fs::read(dirs[1].path().join(&name)).unwrap();
        assert!(a == b, "{name:?} differs");
        files += 1;
    }
    assert_eq!(files, 15);
}

/// Glint's vectors of set 1 written to a fresh folder, with `edit` applied
/// to the text of each file.
fn answers_dir(edit: impl Fn(&str, String) -> Option<String>) -> tempfile::TempDir {
    let (s, all) = set1();
    let dir = tempfile::tempdir().unwrap();
    for v in all {
        for (path, text, _) in files::documents(&scene_name(s), N, v, dir.path()) {
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if let Some(text) = edit(&name, text) {
                std::fs::write(&path, text).unwrap();
            }
        }
    }
    dir
}

fn check_dir(dir: &Path) -> StagesCheck {
    let (s, _) = set1();
    check::check(s, N, dir).unwrap()
}

#[test]
fn glints_own_files_score_full_marks_as_csv_and_as_json() {
    for ext in ["csv", "json"] {
        // Only STAGE.csv, or only STAGE.json.
        let dir = answers_dir(|name, text| {
            (name.ends_with(ext) && !name.contains("inputs")).then_some(text)
        });
        let checked = check_dir(dir.path());
        assert!(checked.passed(), "{ext}");
        for s in &checked.stages {
            let n = N as usize;
            let score = (s.passed, s.answered, s.total);
            assert_eq!(score, (n, n, Some(n)), "{ext} {:?}", s.stage);
            assert!(s.file.as_ref().unwrap().extension().unwrap() == ext);
        }
    }
}

/// Set 1's vectors with one cell of one stage's CSV changed by `change`.
fn with_cell(stage: Stage, id: &str, column: &str, change: impl Fn(f64) -> f64) -> StagesCheck {
    let dir = answers_dir(|name, text| {
        if name != format!("{}.csv", stage.name()) {
            return None;
        }
        let mut reader = csv::Reader::from_reader(text.as_bytes());
        let header = reader.headers().unwrap().clone();
        let at = header.iter().position(|h| h == column).unwrap();
        let mut out = csv::Writer::from_writer(Vec::new());
        out.write_record(&header).unwrap();
        for record in reader.records() {
            let mut row: Vec<String> = record.unwrap().iter().map(String::from).collect();
            if row[0] == id {
                row[at] = change(row[at].parse().unwrap()).to_string();
            }
            out.write_record(&row).unwrap();
        }
        Some(String::from_utf8(out.into_inner().unwrap()).unwrap())
    });
    check_dir(dir.path())
}

#[test]
fn one_value_beyond_its_tolerance_fails_exactly_its_case() {
    let c = &stage(Stage::Intersection).cases[5];
    let t = f64::from(float(c, "t"));
    // 1e-3 relative plus the floor: just inside passes, just outside fails.
    let inside = with_cell(Stage::Intersection, &c.id, "t", |t| t * (1.0 + 0.9e-3));
    assert!(inside.passed());
    let outside = with_cell(Stage::Intersection, &c.id, "t", |t| t * (1.0 + 1.1e-3));
    let s = &outside.stages[1];
    assert_eq!((s.passed, s.answered), (N as usize - 1, N as usize));
    let failure = s.first_failure.as_ref().unwrap();
    assert_eq!(failure.case.id, c.id);
    assert_eq!(failure.differences.len(), 1);
    let d = &failure.differences[0];
    assert_eq!(d.field.name, "t");
    assert!((d.apart.unwrap() - t * 1.1e-3).abs() < 1e-6 * t, "{d:?}");
    // The other stages still pass.
    assert!(outside
        .stages
        .iter()
        .filter(|s| s.stage != Stage::Intersection)
        .all(StageCheck::passes));
}

#[test]
fn the_first_failing_case_is_explained_at_its_pixel_and_stage() {
    let c = &stage(Stage::Camera).cases[2];
    let checked = with_cell(Stage::Camera, &c.id, "direction_y", |y| y + 0.01);
    assert!(!checked.passed());
    let failure = checked.stages[0].first_failure.as_ref().unwrap();
    assert_eq!(failure.case.id, c.id);
    assert_eq!(failure.differences[0].field.name, "direction");
    let from = c.from.as_ref().unwrap();
    let text = failure.explanation.as_ref().unwrap();
    let heading = format!(
        "pixel ({}, {}) of 512 x 512, {} samples per pixel",
        from.pixel[0], from.pixel[1], from.spp
    );
    assert!(text.starts_with(&heading), "{text}");
    assert!(
        text.contains(&format!("sample {}\n", from.sample)),
        "{text}"
    );
    // The camera stage only.
    assert!(
        text.contains("raster") && !text.contains("intersection"),
        "{text}"
    );
    let report = report_text(&checked);
    assert!(
        report.contains(&format!(
            "camera: 1 of {N} answered cases fail; the first is {}",
            c.id
        )),
        "{report}"
    );
    assert!(
        report.contains(&format!("--pixel {},{}", from.pixel[0], from.pixel[1])),
        "{report}"
    );
    let json: serde_json::Value = serde_json::from_str(&report_json(&checked)).unwrap();
    assert_eq!(json["schema"], CHECK_SCHEMA);
    assert_eq!(json["passed"], false);
    assert_eq!(json["stages"][0]["first_failure"]["id"], c.id.as_str());
    assert_eq!(
        json["stages"][0]["first_failure"]["differences"][0]["tolerance"]["kind"],
        "angular"
    );
}

#[test]
fn a_wrong_verdict_or_code_fails_and_a_missing_stage_is_not_answered() {
    let lit = stage(Stage::Lighting)
        .cases
        .iter()
        .find(|c| c.get("s05_verdict") == &Value::Text("visible".into()))
        .unwrap();
    let dir = answers_dir(|name, text| match name {
        // Every visible sample of one case answered as blocked.
        "lighting.csv" => {
            let row = csv_row(&text, &lit.id);
            Some(text.replace(&row, &row.replace("visible", "blocked")))
        }
        // The first film case's red code one higher.
        "film.json" => {
            let mut document: serde_json::Value = serde_json::from_str(&text).unwrap();
            let code = &mut document["cases"][0]["expected"]["srgb8_r"];
            *code = (code.as_i64().unwrap() + 1).into();
            Some(document.to_string())
        }
        _ => None,
    });
    let checked = check_dir(dir.path());
    let by = |s: Stage| checked.stages.iter().find(|c| c.stage == s).unwrap();
    assert_eq!(by(Stage::Camera).file, None);
    assert_eq!(by(Stage::Camera).total, None);
    assert!(by(Stage::Camera).passes());
    let lighting = by(Stage::Lighting);
    assert_eq!(lighting.answered - lighting.passed, 1);
    let failure = lighting.first_failure.as_ref().unwrap();
    assert_eq!(failure.case.id, lit.id);
    assert!(failure
        .differences
        .iter()
        .all(|d| d.field.name.ends_with("_verdict")));
    let s05 = failure
        .differences
        .iter()
        .find(|d| d.field.name == "s05_verdict")
        .unwrap();
    assert_eq!(s05.answered, [Answer::Text("blocked".into())]);
    let film = by(Stage::Film);
    assert_eq!(film.answered - film.passed, 1);
    let code = &film.first_failure.as_ref().unwrap().differences[0];
    assert_eq!(code.field.name, "srgb8");
    assert!(!checked.passed());
}

/// The line of case `id` in a CSV text.
fn csv_row(text: &str, id: &str) -> String {
    text.lines()
        .find(|l| l.starts_with(&format!("{id},")))
        .unwrap()
        .to_owned()
}

#[test]
fn an_answer_folder_without_answers_or_with_bad_ones_is_bad_input() {
    let (s, _) = set1();
    let empty = tempfile::tempdir().unwrap();
    let e = check::check(s, N, empty.path()).unwrap_err();
    assert!(
        matches!(&e, GradeError::Input(m) if m.contains("no answers here")),
        "{e}"
    );
    let missing = check::check(s, N, &empty.path().join("nowhere")).unwrap_err();
    assert!(
        matches!(&missing, GradeError::Input(m) if m.contains("no such folder")),
        "{missing}"
    );
    std::fs::write(
        empty.path().join("film.csv"),
        "id,srgb8_r,srgb8_g\nfilm-001,1,2\n",
    )
    .unwrap();
    let e = check::check(s, N, empty.path()).unwrap_err();
    assert!(
        matches!(&e, GradeError::Input(m) if m.ends_with("film.csv:1: missing column \"srgb8_b\": the film answers need id and every expected column")),
        "{e}"
    );
}
