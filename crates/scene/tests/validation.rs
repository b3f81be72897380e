//! Every kind of bad scene input gives one located, field-named error.

use glint_scene::{parse, SceneError};

const CAMERA: &str = "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nfov = 45\n";
const MATERIAL: &str = "[materials.m]\ndiffuse = [1, 1, 1]\n";

fn error_of(body: &str) -> String {
    match parse(body, "bad.toml") {
        Ok(_) => panic!("accepted:\n{body}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn each_kind_of_bad_input_has_its_own_message() {
    let cases: Vec<(&str, String)> = vec![
        ("syntax error", "[camera\nfov = 45\n".into()),
        ("missing camera", "ambient = [0, 0, 0]\n".into()),
        ("unknown top-level key", format!("colour = 1\n{CAMERA}")),
        ("unknown key in [camera]", format!("{CAMERA}colour = 1\n")),
        ("huge number", format!("{CAMERA}{MATERIAL}[[sphere]]\ncenter = [0, 0, 0]\nradius = 1e20\nmaterial = \"m\"\n")),
        ("direction too small to normalize", format!("{CAMERA}{MATERIAL}[[plane]]\npoint = [0, 0, 0]\nnormal = [1e-30, 0, 0]\nmaterial = \"m\"\n")),
        ("unknown key in a table", format!("{CAMERA}{MATERIAL}[[sphere]]\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\nradiuss = 2\n")),
        ("negative radius", format!("{CAMERA}{MATERIAL}[[sphere]]\ncenter = [0, 0, 0]\nradius = -1\nmaterial = \"m\"\n")),
        ("zero radius", format!("{CAMERA}{MATERIAL}[[sphere]]\ncenter = [0, 0, 0]\nradius = 0\nmaterial = \"m\"\n")),
        ("missing radius", format!("{CAMERA}{MATERIAL}[[sphere]]\ncenter = [0, 0, 0]\nmaterial = \"m\"\n")),
        ("zero resolution", format!("{CAMERA}[render]\nresolution = [0, 512]\n")),
        ("fov 0", "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nfov = 0\n".into()),
        ("fov 180", "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nfov = 180\n".into()),
        ("camera at its look-at point", "[camera]\nposition = [1, 2, 3]\nlook_at = [1, 2, 3]\nfov = 45\n".into()),
        ("up parallel to view", "[camera]\nposition = [0, 5, 0]\nlook_at = [0, 0, 0]\nfov = 45\n".into()),
        ("degenerate parallelogram", format!("{CAMERA}{MATERIAL}[[parallelogram]]\norigin = [0, 0, 0]\nedge1 = [1, 0, 0]\nedge2 = [-2, 0, 0]\nmaterial = \"m\"\n")),
        ("normal not perpendicular", format!("{CAMERA}{MATERIAL}[[parallelogram]]\norigin = [0, 0, 0]\nedge1 = [1, 0, 0]\nedge2 = [0, 1, 0]\nnormal = [1, 0, 1]\nmaterial = \"m\"\n")),
        ("degenerate area light", format!("{CAMERA}[[area_light]]\ncenter = [0, 0, 0]\nedge1 = [0, 0, 0]\nedge2 = [0, 1, 0]\n")),
        ("unknown material", format!("{CAMERA}{MATERIAL}[[sphere]]\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"mm\"\n")),
        ("unknown texture", format!("{CAMERA}[materials.m]\ndiffuse = \"checks\"\n")),
        ("spp 0", format!("{CAMERA}[render]\nspp = 0\n")),
        ("grid with non-square spp", format!("{CAMERA}[render]\nspp = 8\npixel_sampler = \"grid\"\n")),
        ("grid light sampler, default count ok, set count not square", format!("{CAMERA}[render]\nlight_samples = 2\nlight_sampler = \"grid\"\n")),
        ("spp above the limit", format!("{CAMERA}[render]\nspp = 4000000000\n")),
        ("unknown sampler", format!("{CAMERA}[render]\npixel_sampler = \"sobol\"\n")),
        ("NaN", format!("ambient = [0, nan, 0]\n{CAMERA}")),
        ("infinity", format!("{CAMERA}{MATERIAL}[[sphere]]\ncenter = [0, 0, -inf]\nradius = 1\nmaterial = \"m\"\n")),
        ("string for a number", format!("{CAMERA}{MATERIAL}[[sphere]]\ncenter = [0, 0, 0]\nradius = \"big\"\nmaterial = \"m\"\n")),
        ("two components", format!("{CAMERA}[[point_light]]\nposition = [0, 1]\n")),
        ("negative color", format!("{CAMERA}[[point_light]]\nposition = [0, 1, 0]\ncolor = [1, -1, 1]\n")),
        ("box with min above max", format!("{CAMERA}{MATERIAL}[[box]]\nmin = [0, 0, 0]\nmax = [1, -1, 1]\nmaterial = \"m\"\n")),
        ("zero plane normal", format!("{CAMERA}{MATERIAL}[[plane]]\npoint = [0, 0, 0]\nnormal = [0, 0, 0]\nmaterial = \"m\"\n")),
        ("unknown lobe", format!("{CAMERA}[materials.m]\ndiffuse = [1, 1, 1]\nlobe = \"cook-torrance\"\n")),
        ("negative shininess", format!("{CAMERA}[materials.m]\ndiffuse = [1, 1, 1]\nshininess = -2\n")),
        ("unknown texture kind", format!("{CAMERA}[textures.t.marble]\nscale = 1\n")),
    ];
    let mut report = String::new();
    for (name, body) in &cases {
        let message = error_of(body);
        assert!(
            !message.contains('\n'),
            "{name}: more than one line: {message}"
        );
        assert!(
            message.starts_with("bad.toml:"),
            "{name}: no location: {message}"
        );
        report.push_str(&format!("{name}:\n  {message}\n"));
    }
    insta::assert_snapshot!(report);
}

#[test]
fn error_points_at_the_offending_line_and_column() {
    let body = format!(
        "{CAMERA}{MATERIAL}[[sphere]]\ncenter = [0, 0, 0]\nradius = -1\nmaterial = \"m\"\n"
    );
    match parse(&body, "bad.toml") {
        Err(SceneError::Invalid {
            line,
            column,
            field,
            ..
        }) => {
            assert_eq!((line, column), (9, 10));
            assert_eq!(field.as_deref(), Some("sphere[0].radius"));
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_minimal_scene_gets_the_documented_defaults() {
    let d = parse(CAMERA, "ok.toml").unwrap();
    assert_eq!(d.settings.spp, 16);
    assert_eq!(d.settings.light_samples, 16);
    assert_eq!(d.settings.seed, 0);
    assert_eq!(d.scene.camera.resolution(), glam::UVec2::new(512, 512));
    assert_eq!(d.scene.ambient, glam::Vec3::ZERO);
    assert!(d.scene.lights.is_empty() && d.scene.shapes.is_empty());
}

#[test]
fn missing_file_names_the_path() {
    let e = glint_scene::load(std::path::Path::new("no/such/scene.toml")).unwrap_err();
    assert!(e
        .to_string()
        .starts_with("no/such/scene.toml: cannot read the scene file"));
}
