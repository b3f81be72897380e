//! Every kind of bad scene input gives one located, field-named error.

use glint_scene::{parse, SceneError};
use glint_texture::{Texture, TextureFilter, WrapMode};

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
        ("unknown sampler", format!("{CAMERA}[render]\npixel_sampler = \"halton\"\n")),
        ("grid environment sampler, set count not square", format!("{CAMERA}[render]\nenvironment_samples = 8\nenvironment_sampler = \"grid\"\n")),
        ("unknown environment sampler", format!("{CAMERA}[render]\nenvironment_sampler = \"sobel\"\n")),
        ("unknown environment sampling", format!("{CAMERA}[render]\nenvironment_sampling = \"uniform\"\n")),
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
        ("missing image file", format!("{CAMERA}[textures.t.image]\nfile = \"no/such/image.png\"\n[materials.m]\ndiffuse = \"t\"\n")),
        ("unknown image filter", format!("{CAMERA}[textures.t.image]\nfile = \"x.png\"\nfilter = \"cubic\"\n")),
        ("unknown wrap mode", format!("{CAMERA}[textures.t.image]\nfile = \"x.png\"\nwrap = \"border\"\n")),
        ("unknown checker filter", format!("{CAMERA}[textures.t.checkerboard]\ncolors = [[0, 0, 0], [1, 1, 1]]\nchecks = 4\nfilter = \"trilinear\"\n")),
        ("checker image too large", format!("{CAMERA}[textures.t.checker_image]\ncolors = [[0, 0, 0], [1, 1, 1]]\nchecks = 1000\npixels_per_check = 32\n[materials.m]\ndiffuse = \"t\"\n")),
        ("zero uv scale", format!("{CAMERA}[materials.m]\ndiffuse = [1, 1, 1]\nuv_scale = [0, 1]\n")),
        ("environment with two sources", format!("{CAMERA}[environment]\ncolor = [1, 1, 1]\nlatlong = \"sky.hdr\"\n")),
        ("environment with no source", format!("{CAMERA}[environment]\nintensity = 2\n")),
        ("cube map template without {{face}}", format!("{CAMERA}[environment]\ncube_map = \"sky.hdr\"\n")),
        ("missing cube map face", format!("{CAMERA}[environment]\ncube_map = \"no/such/{{face}}.hdr\"\n")),
        ("mirror with a diffuse color", format!("{CAMERA}[materials.m]\nmirror = [1, 1, 1]\ndiffuse = [1, 0, 0]\n")),
        ("material with neither diffuse nor mirror", format!("{CAMERA}[materials.m]\nshininess = 3\n")),
        ("reflectivity above one", format!("{CAMERA}[materials.m]\ndiffuse = [1, 1, 1]\nreflectivity = 1.5\n")),
        ("max depth above the limit", format!("{CAMERA}[render]\nmax_depth = 1000\n")),
        ("box with five face materials", format!("{CAMERA}{MATERIAL}[[box]]\nmin = [0, 0, 0]\nmax = [1, 1, 1]\nface_materials = [\"m\", \"m\", \"m\", \"m\", \"m\"]\n")),
        ("missing mesh file", format!("{CAMERA}[[mesh]]\nfile = \"no/such.obj\"\n")),
        ("mesh with zero scale", format!("{CAMERA}[[mesh]]\nfile = \"x.obj\"\nscale = [1, 0, 1]\n")),
        ("mesh with an unknown material", format!("{CAMERA}{MATERIAL}[[mesh]]\nfile = \"x.obj\"\nmaterial = \"mm\"\n")),
        ("zero tile size", format!("{CAMERA}{MATERIAL}[[plane]]\npoint = [0, 0, 0]\nnormal = [0, 1, 0]\ntile_size = 0\nmaterial = \"m\"\n")),
        ("empty region", format!("{CAMERA}[render]\nresolution = [64, 32]\n[regions]\nfloor = [10, 20, 10, 30]\n")),
        ("region past the image", format!("{CAMERA}[render]\nresolution = [64, 32]\n[regions]\nfloor = [0, 0, 64, 33]\n")),
        ("negative region corner", format!("{CAMERA}[regions]\nfloor = [-1, 0, 4, 4]\n")),
        ("unknown shading model", format!("shading = \"pbr\"\n{CAMERA}")),
        ("intensity in the course's model", format!("{CAMERA}[[point_light]]\nposition = [0, 1, 0]\nintensity = [5, 5, 5]\n")),
        ("color in physical shading", format!("shading = \"physical\"\n{CAMERA}[[point_light]]\nposition = [0, 1, 0]\ncolor = [1, 1, 1]\n")),
        ("physical area light without radiance", format!("shading = \"physical\"\n{CAMERA}[[area_light]]\ncenter = [0, 0, 0]\nedge1 = [1, 0, 0]\nedge2 = [0, 0, 1]\n")),
        ("negative radiance", format!("shading = \"physical\"\n{CAMERA}[[area_light]]\ncenter = [0, 0, 0]\nedge1 = [1, 0, 0]\nedge2 = [0, 0, 1]\nradiance = [1, -1, 1]\n")),
        ("sphere light in the course's model", format!("{CAMERA}[[sphere_light]]\ncenter = [0, 0, 0]\nradius = 1\nradiance = [1, 1, 1]\n")),
        ("unknown area sampling", format!("{CAMERA}[render]\narea_sampling = \"cosine\"\n")),
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
    for pattern in [
        d.settings.pixel_pattern,
        d.settings.light_pattern,
        d.settings.environment_pattern,
    ] {
        assert_eq!(pattern, glint_integrator::SamplePattern::Sobol);
    }
    assert_eq!(d.settings.environment_samples, 16);
    assert_eq!(d.scene.camera.resolution(), glam::UVec2::new(512, 512));
    assert_eq!(d.scene.ambient, glam::Vec3::ZERO);
    assert!(d.scene.lights.is_empty() && d.scene.shapes.is_empty());
}

#[test]
fn every_sampler_key_takes_every_pattern_name() {
    use glint_integrator::SamplePattern;
    for name in SamplePattern::NAMES {
        let d = parse(
            &format!(
                "{CAMERA}[render]\nspp = 4\npixel_sampler = \"{name}\"\nlight_samples = 9\nlight_sampler = \"{name}\"\nenvironment_samples = 25\nenvironment_sampler = \"{name}\"\n"
            ),
            "ok.toml",
        )
        .unwrap();
        let pattern = SamplePattern::from_name(name);
        assert_eq!(Some(d.settings.pixel_pattern), pattern);
        assert_eq!(Some(d.settings.light_pattern), pattern);
        assert_eq!(Some(d.settings.environment_pattern), pattern);
    }
    // The environment's grid needs a square count only when it samples at all.
    let none =
        format!("{CAMERA}[render]\nenvironment_samples = 0\nenvironment_sampler = \"grid\"\n");
    assert!(parse(&none, "ok.toml").is_ok());
}

#[test]
fn missing_file_names_the_path() {
    let e = glint_scene::load(std::path::Path::new("no/such/scene.toml")).unwrap_err();
    assert!(e
        .to_string()
        .starts_with("no/such/scene.toml: cannot read the scene file"));
}

#[test]
fn image_paths_are_relative_to_the_scene_file_and_loaded_once() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("tex")).unwrap();
    image::RgbImage::from_pixel(4, 2, image::Rgb([255, 128, 0]))
        .save(dir.path().join("tex/orange.png"))
        .unwrap();
    let scene = format!(
        "{CAMERA}[textures.a.image]\nfile = \"tex/orange.png\"\n\
         [textures.b.image]\nfile = \"tex/orange.png\"\nfilter = \"ewa\"\nwrap = \"clamp\"\n\
         [materials.m]\ndiffuse = \"a\"\nspecular = \"b\"\nuv_scale = [2, 3]\nuv_offset = [0.5, 0]\n"
    );
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let d = glint_scene::load(&path).unwrap();
    let m = &d.scene.materials[0];
    let (Texture::Image(a), Some(Texture::Image(b))) = (&m.diffuse, &m.specular) else {
        panic!("{m:?}")
    };
    assert!(
        std::sync::Arc::ptr_eq(&a.image, &b.image),
        "one image, loaded once"
    );
    assert_eq!(
        (a.filter, a.wrap),
        (TextureFilter::Trilinear, WrapMode::Repeat)
    );
    assert_eq!((b.filter, b.wrap), (TextureFilter::Ewa, WrapMode::Clamp));
    assert_eq!(a.image.image().width(), 4);
    let texel = a.image.image().texel(0, 0);
    assert!(
        (texel.x - 1.0).abs() < 1e-6 && (texel.y - 0.215_861).abs() < 1e-5,
        "{texel}"
    );
    assert_eq!(m.uv_transform.scale, glam::Vec2::new(2.0, 3.0));
    assert_eq!(m.uv_transform.offset, glam::Vec2::new(0.5, 0.0));
    // The file read, listed once, for callers that fingerprint a scene's inputs.
    assert_eq!(d.assets.len(), 1, "{:?}", d.assets);
    assert!(d.assets[0].ends_with("tex/orange.png"), "{:?}", d.assets);
}

#[test]
fn textures_no_material_reads_are_not_loaded() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbImage::from_pixel(2, 2, image::Rgb([255, 255, 255]))
        .save(dir.path().join("used.png"))
        .unwrap();
    let scene = format!(
        "{CAMERA}[textures.used.image]\nfile = \"used.png\"\n\
         [textures.unused.image]\nfile = \"missing.png\"\n\
         [materials.m]\ndiffuse = \"used\"\n"
    );
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let d = glint_scene::load(&path).unwrap();
    assert_eq!(d.assets.len(), 1, "{:?}", d.assets);
    assert!(d.assets[0].ends_with("used.png"));
    // Referenced, the missing file is an error naming the field.
    let e = error_of(&format!(
        "{CAMERA}[textures.t.image]\nfile = \"missing.png\"\n[materials.m]\ndiffuse = \"t\"\n"
    ));
    assert!(e.contains("textures.t.image.file"), "{e}");
}

#[test]
fn regions_are_read_in_pixels_and_sorted_by_name() {
    let d = parse(
        &format!("{CAMERA}[render]\nresolution = [64, 32]\n[regions]\nshadow = [8, 16, 40, 32]\nall = [0, 0, 64, 32]\n"),
        "r.toml",
    )
    .unwrap();
    assert_eq!(
        d.regions,
        [
            ("all".to_owned(), [0, 0, 64, 32]),
            ("shadow".to_owned(), [8, 16, 40, 32])
        ]
    );
    assert!(parse(CAMERA, "r.toml").unwrap().regions.is_empty());
}

#[test]
fn objects_are_named_in_shape_list_order() {
    let body = format!(
        "{CAMERA}{MATERIAL}[[parallelogram]]\nname = \" left wall \"\norigin = [0, 0, 0]\nedge1 = [1, 0, 0]\nedge2 = [0, 1, 0]\nmaterial = \"m\"\n\
         [[sphere]]\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n\
         [[box]]\nname = \"crate\"\nmin = [0, 0, 0]\nmax = [1, 1, 1]\nface_materials = [\"m\", \"m\", \"m\", \"m\", \"m\", \"m\"]\n\
         [[area_light]]\nname = \"lamp\"\ncenter = [0, 3, 0]\nedge1 = [1, 0, 0]\nedge2 = [0, 0, 1]\n"
    );
    let d = parse(&body, "n.toml").unwrap();
    // Spheres enter the shape list first, then parallelograms, planes, boxes,
    // meshes and the lights' surfaces.
    assert_eq!(
        d.object_names,
        [
            "sphere[0]",
            "left wall",
            "crate.px",
            "crate.nx",
            "crate.py",
            "crate.ny",
            "crate.pz",
            "crate.nz",
            "lamp"
        ]
    );
    assert_eq!(d.object_names.len(), d.scene.surfaces.len());

    let sphere = |name: &str| {
        format!("{CAMERA}{MATERIAL}[[sphere]]\nname = \"a\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n[[sphere]]\nname = {name}\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n")
    };
    let duplicate = error_of(&sphere("\"a\""));
    assert!(
        duplicate.contains("sphere[1].name: another object is already named \"a\""),
        "{duplicate}"
    );
    let empty = error_of(&sphere("\"  \""));
    assert!(
        empty.contains("sphere[1].name: expected a name of 1 to 60 characters, got 0"),
        "{empty}"
    );
    let long = error_of(&sphere(&format!("\"{}\"", "x".repeat(61))));
    assert!(long.contains("got 61"), "{long}");
}

#[test]
fn meshes_load_with_their_materials_and_bad_files_get_located_errors() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, body: &str| std::fs::write(dir.path().join(name), body).unwrap();
    write(
        "tri.mtl",
        "newmtl shiny\nKd 0.2 0.4 0.6\nKs 0.5 0.5 0.5\nNs 50\n",
    );
    write(
        "tri.obj",
        "mtllib tri.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nusemtl shiny\nf 1 2 3\nusemtl missing\nf 2 4 3\n",
    );
    write("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n");
    write("empty.obj", "v 0 0 0\n");
    let scene = |mesh: &str| {
        let path = dir.path().join("scene.toml");
        std::fs::write(&path, format!("{CAMERA}[[mesh]]\n{mesh}")).unwrap();
        glint_scene::load(&path)
    };
    let d = scene("file = \"tri.obj\"\ntranslate = [0, 0, -2]\nrotate = [0, 90, 0]\nscale = 2\n")
        .unwrap();
    let mesh = &d.scene.shapes.meshes()[0];
    assert_eq!(mesh.triangle_count(), 2);
    // Scaled by 2, turned 90° about y (x → −z), moved to z = −2.
    let [a, b, _] = mesh.corners(0);
    assert!((a - glam::Vec3::new(0.0, 0.0, -2.0)).length() < 1e-5, "{a}");
    assert!((b - glam::Vec3::new(0.0, 0.0, -4.0)).length() < 1e-5, "{b}");
    let names = &d.material_names;
    assert!(names.iter().any(|n| n == "tri.obj:shiny"), "{names:?}");
    assert!(
        names.iter().any(|n| n == "(default mesh material)"),
        "{names:?}"
    );
    let files: Vec<String> = d
        .assets
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(files, ["tri.obj", "tri.mtl"], "the OBJ and its MTL");
    let per_triangle = &d.scene.mesh_materials[0];
    let shiny = &d.scene.materials[per_triangle[0] as usize];
    assert_eq!(shiny.shininess, 50.0);
    assert_ne!(per_triangle[0], per_triangle[1]);

    let e = scene("file = \"bad.obj\"\n").unwrap_err().to_string();
    assert!(e.contains("mesh[0].file") && e.contains("bad.obj"), "{e}");
    let e = scene("file = \"empty.obj\"\n").unwrap_err().to_string();
    assert!(e.contains("mesh[0].file") && e.contains("no faces"), "{e}");
}
