//! `glint export --mitsuba`: every shipped scene as a Mitsuba 3 scene, its
//! warnings, bad input, and (with a Python with the `mitsuba` package:
//! `GLINT_MITSUBA_VENV`, or `target/mitsuba-venv` as `.ci/run` makes it;
//! without, skipped, and under `CI=true` failed) Mitsuba loading and
//! rendering every exported scene, and seeing the same geometry and textures
//! as Glint.

mod common;
use common::{python_with_mitsuba, repo};

use common::{assert_input_error, glint, scene, stderr, stdout};
use std::path::Path;
use std::process::Command;

/// Every shipped scene's name, sorted.
fn shipped_scenes() -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(repo().join("scenes"))
        .unwrap()
        .filter_map(|e| {
            let path = e.unwrap().path();
            (path.extension()? == "toml").then(|| path.file_stem()?.to_str().map(str::to_owned))?
        })
        .collect();
    names.sort();
    names
}

const TINY: [&str; 6] = [
    "--resolution",
    "20x12",
    "--spp",
    "2",
    "--light-samples",
    "1",
];

/// Exports `name` into `dir` as `NAME.xml` with `extra` flags; the output.
fn export(name: &str, dir: &Path, extra: &[&str]) -> std::process::Output {
    let out = format!("{name}.xml");
    glint(
        &[&["export", "--mitsuba", &scene(name), "-o", &out], extra].concat(),
        dir,
    )
}

/// The value of every `name="filename"` property.
fn filenames(xml: &str) -> Vec<String> {
    xml.split("<string name=\"filename\" value=\"")
        .skip(1)
        .map(|p| p[..p.find('"').unwrap()].to_owned())
        .collect()
}

#[test]
fn every_shipped_scene_exports_with_its_files_beside_it() {
    let dir = tempfile::tempdir().unwrap();
    for name in shipped_scenes() {
        let o = export(&name, dir.path(), &TINY);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let summary = stdout(&o);
        assert!(
            summary.starts_with(&format!("wrote {name}.xml"))
                && summary.contains("(Mitsuba 3): 20x12, 2 spp"),
            "{summary}"
        );
        for line in stderr(&o).lines() {
            assert!(line.starts_with("glint: warning: "), "{name}: {line}");
        }
        let xml = std::fs::read_to_string(dir.path().join(format!("{name}.xml"))).unwrap();
        assert!(xml
            .starts_with("<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<scene version=\"3.0.0\">"));
        assert!(xml.ends_with("</scene>\n"));
        for needle in [
            "<sensor type=\"perspective\">",
            "<string name=\"fov_axis\" value=\"y\"/>",
            "<integer name=\"width\" value=\"20\"/>",
            "<integer name=\"height\" value=\"12\"/>",
            "<rfilter type=\"box\"/>",
            "<sampler type=\"independent\">",
            "<integer name=\"sample_count\" value=\"2\"/>",
            "<integrator type=\"direct\">",
            "<integer name=\"emitter_samples\" value=\"1\"/>",
            "<integer name=\"bsdf_samples\" value=\"1\"/>",
        ] {
            assert!(xml.contains(needle), "{name}: no {needle}");
        }
        assert_eq!(
            xml.matches("<shape ").count(),
            xml.matches("</shape>").count()
        );
        for file in filenames(&xml) {
            assert!(
                file.starts_with(&format!("{name}-assets/")),
                "{name}: {file}"
            );
            assert!(dir.path().join(&file).is_file(), "{name}: {file} missing");
        }
    }
    // Nothing but the XML files and the assets folders: no temporary files.
    for entry in std::fs::read_dir(dir.path()).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        assert!(
            name.ends_with(".xml") || name.ends_with("-assets"),
            "{name}"
        );
    }
}

#[test]
fn shapes_and_assets_of_each_kind() {
    let dir = tempfile::tempdir().unwrap();
    let read =
        |name: &str| std::fs::read_to_string(dir.path().join(format!("{name}.xml"))).unwrap();
    assert!(export("bunny", dir.path(), &[]).status.success());
    let bunny = read("bunny");
    assert!(bunny.contains("<shape type=\"ply\" id=\"mesh-0\">"));
    assert!(bunny.contains("<string name=\"filename\" value=\"bunny-assets/mesh-0.ply\"/>"));
    let ply = std::fs::read(dir.path().join("bunny-assets/mesh-0.ply")).unwrap();
    let header = String::from_utf8_lossy(&ply[..300]);
    assert!(
        header.starts_with("ply\nformat binary_little_endian 1.0\n"),
        "{header}"
    );
    assert!(header.contains("property float nx\n"), "{header}");
    assert!(header.contains("element face "), "{header}");
    // The plane under the bunny: a large rectangle; the mesh: twosided.
    assert!(bunny.contains("<shape type=\"rectangle\" id=\"plane-0\">"));
    assert!(
        bunny.contains("<bsdf type=\"twosided\" id=\"clay\">"),
        "{bunny}"
    );

    assert!(export("environment", dir.path(), &[]).status.success());
    let environment = read("environment");
    assert!(environment.contains("<emitter type=\"envmap\">"));
    assert!(environment.contains("value=\"environment-assets/environment.exr\""));
    assert!(
        environment.contains("<bsdf type=\"conductor\" id=\"chrome\">")
            || environment.contains("<bsdf type=\"conductor\">")
    );
    assert!(environment.contains("<bsdf type=\"blendbsdf\">"));
    assert!(environment.contains("<string name=\"wrap_mode\" value=\"clamp\"/>"));
    let exr = std::fs::read(dir.path().join("environment-assets/environment.exr")).unwrap();
    assert_eq!(&exr[..4], &[0x76, 0x2f, 0x31, 0x01], "an OpenEXR file");

    assert!(export("point-light", dir.path(), &[]).status.success());
    let point = read("point-light");
    assert!(point.contains("<emitter type=\"point\">"));
    assert!(point.contains("<point name=\"position\" value=\"2, 5, 3\"/>"));
    assert!(
        !dir.path().join("point-light-assets").exists(),
        "no assets, no folder"
    );
}

#[test]
fn warnings_name_what_is_not_converted() {
    let dir = tempfile::tempdir().unwrap();
    let o = export("cornell-set1", dir.path(), &[]);
    assert!(o.status.success());
    let err = stderr(&o);
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 9, "{err}");
    assert!(lines[0].starts_with("glint: warning: the scene uses the course's Phong model"));
    assert!(lines[0].contains("no distance falloff, no normalisation"));
    assert_eq!(
        lines[1],
        "glint: warning: ambient [0.1, 0.1, 0.1] is dropped: Mitsuba 3 has no ambient term"
    );
    assert!(err.contains(
        "glint: warning: Mitsuba 3 has no Phong lobe: material \"gray\"'s specular term \
         (ks=[0.7, 0.7, 0.7], the diffuse color, shininess 16) is dropped"
    ));
    assert!(stdout(&o).contains(", 9 warnings"));

    let o = export("point-light", dir.path(), &[]);
    assert!(stderr(&o).contains(
        "plane 0 (material \"ground\") is written as a 1.41e5 × 1.41e5 rectangle centred below the camera"
    ), "{}", stderr(&o));
    let o = export("environment", dir.path(), &[]);
    let err = stderr(&o);
    assert!(err.contains("does not follow mirror reflections: the mirrors of materials \"chrome\", \"glazed-red\""), "{err}");
    assert!(err.contains("bitmap textures have no MIP maps"), "{err}");

    // A physical, diffuse scene converts like for like: no warnings.
    std::fs::write(
        dir.path().join("physical.toml"),
        "shading = \"physical\"\n[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nfov = 40\n\
         [materials.white]\ndiffuse = [0.8, 0.8, 0.8]\nspecular = [0, 0, 0]\n\
         [[sphere]]\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"white\"\n\
         [[area_light]]\ncenter = [0, 3, 0]\nedge1 = [1, 0, 0]\nedge2 = [0, 0, 1]\nradiance = [5, 5, 5]\n",
    )
    .unwrap();
    let o = glint(&["export", "--mitsuba", "physical.toml"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stderr(&o), "");
    assert!(
        stdout(&o).starts_with("wrote physical.xml (Mitsuba 3): 512x512, 16 spp"),
        "{}",
        stdout(&o)
    );
    assert!(stdout(&o).ends_with(", 0 warnings\n"));
}

#[test]
fn bad_input_gives_one_line_exit_2_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let set1 = scene("cornell-set1");
    std::fs::write(dir.path().join("bad.toml"), "[camera]\nfov = 400\n").unwrap();
    std::fs::create_dir(dir.path().join("folder.xml")).unwrap();
    std::fs::write(dir.path().join("theirs-assets"), "a file").unwrap();
    let cases: [(&[&str], &str); 8] = [
        (
            &["export", &set1, "-o", "x.xml"],
            "choose the format to export: --mitsuba",
        ),
        (
            &["export", "--mitsuba", "missing.toml", "-o", "x.xml"],
            "missing.toml: cannot read the scene file",
        ),
        (
            &["export", "--mitsuba", "bad.toml", "-o", "x.xml"],
            "bad.toml:2:7: camera.fov",
        ),
        (
            &["export", "--mitsuba", &set1, "-o", "x.json"],
            "x.json: expected a .xml file name",
        ),
        (
            &["export", "--mitsuba", &set1, "-o", "nowhere/x.xml"],
            "the output directory nowhere does not exist",
        ),
        (
            &["export", "--mitsuba", &set1, "-o", "folder.xml"],
            "folder.xml: is a directory",
        ),
        (
            &["export", "--mitsuba", &set1, "-o", "theirs.xml"],
            "theirs-assets: is in the way",
        ),
        (
            &["export", "--mitsuba", &set1, "--spp", "0"],
            "0 is not in 1..=1048576",
        ),
    ];
    for (args, expected) in cases {
        let o = glint(args, dir.path());
        assert_input_error(&o, expected);
    }
    let mut left: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["bad.toml", "folder.xml", "theirs-assets"]);
}

#[test]
fn a_failed_export_leaves_the_users_files_untouched() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.xml"), "precious").unwrap();
    std::fs::write(dir.path().join("bad.toml"), "[camera]\n").unwrap();
    let o = glint(
        &["export", "--mitsuba", "bad.toml", "-o", "scene.xml"],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        std::fs::read(dir.path().join("scene.xml")).unwrap(),
        b"precious"
    );

    // An assets folder no export wrote is refused, not replaced.
    std::fs::create_dir(dir.path().join("scene-assets")).unwrap();
    std::fs::write(dir.path().join("scene-assets/mine.ply"), "mine").unwrap();
    let o = glint(
        &["export", "--mitsuba", &scene("bunny"), "-o", "scene.xml"],
        dir.path(),
    );
    assert_input_error(
        &o,
        "scene-assets: exists and was not written by glint export",
    );
    assert_eq!(
        std::fs::read(dir.path().join("scene.xml")).unwrap(),
        b"precious"
    );
    assert_eq!(
        std::fs::read(dir.path().join("scene-assets/mine.ply")).unwrap(),
        b"mine"
    );

    // The default output: SCENE-NAME.xml in the current directory.
    let o = glint(&["export", "--mitsuba", &scene("bunny")], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        dir.path().join("bunny.xml").is_file()
            && dir.path().join("bunny-assets/mesh-0.ply").is_file()
    );
}

#[test]
fn bsdf_samples_replace_the_light_samples_as_the_integrators_bsdf_samples() {
    let dir = tempfile::tempdir().unwrap();
    let integrator = |name: &str| {
        let xml = std::fs::read_to_string(dir.path().join(format!("{name}.xml"))).unwrap();
        let emitter = xml.contains("<integer name=\"emitter_samples\" value=\"4\"/>");
        let start = xml.find("name=\"bsdf_samples\" value=\"").unwrap() + 27;
        let bsdf = xml[start..].split('"').next().unwrap().to_owned();
        (emitter, bsdf)
    };
    let o = export(
        "cornell-set1",
        dir.path(),
        &["--light-samples", "4", "--bsdf-samples", "0"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("direct integrator with 4 emitter and 0 BSDF samples"));
    assert_eq!(integrator("cornell-set1"), (true, "0".to_owned()));
    let o = export(
        "cornell-set1",
        dir.path(),
        &["--light-samples", "4", "--bsdf-samples", "2"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(integrator("cornell-set1"), (true, "2".to_owned()));
    // Point lights keep their one emitter sample.
    let o = export(
        "point-light",
        dir.path(),
        &["--light-samples", "4", "--bsdf-samples", "0"],
    );
    assert!(stdout(&o).contains("direct integrator with 1 emitter and 0 BSDF samples"));
    assert!(stderr(&o).contains("emitter_samples = 1 and bsdf_samples = 0, not 4 and 0"));
}

#[test]
fn help_documents_the_subcommand() {
    let o = glint(&["export", "--help"], Path::new("."));
    assert!(o.status.success());
    let help = stdout(&o);
    for flag in [
        "--mitsuba",
        "--output",
        "--spp",
        "--light-samples",
        "--seed",
        "--resolution",
    ] {
        assert!(help.contains(flag), "{flag} undocumented");
    }
    assert!(stdout(&glint(&["--help"], Path::new("."))).contains("export"));
}

// ---------------------------------------------------------------------------
// In Mitsuba itself, where it is installed.

/// Loads the XML in `sys.argv[1]` and renders it (`scalar_rgb`); prints
/// `finite MEAN` or `nonfinite COUNT`.
const LOAD_AND_RENDER: &str = r#"
import math, sys
import mitsuba as mi
mi.set_variant("scalar_rgb")
image = mi.TensorXf(mi.render(mi.load_file(sys.argv[1])))
values = [float(v) for v in image.array]
bad = sum(1 for v in values if not math.isfinite(v))
print(f"nonfinite {bad}" if bad else f"finite {sum(values) / len(values)}")
"#;

/// Renders the XML in `sys.argv[1]` with Mitsuba's albedo AOV at 64 spp and
/// compares it with the linear RGB EXR in `sys.argv[2]` (Glint's `--aov
/// albedo`): prints the four quadrants' means of both (top-left, top-right,
/// bottom-left, bottom-right) and the fraction of pixels more than 0.1 apart.
const ALBEDO: &str = r#"
import sys
import mitsuba as mi
mi.set_variant("scalar_rgb")
scene = mi.load_file(sys.argv[1])
aov = mi.load_dict({"type": "aov", "aovs": "a:albedo"})
t = mi.TensorXf(mi.render(scene, integrator=aov, spp=64))
h, w, c = t.shape
m = [float(v) for v in t.array]
b = mi.Bitmap(sys.argv[2]).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32)
g = [float(v) for v in mi.TensorXf(b).array]
def quadrants(img, stride):
    out = []
    for qy in range(2):
        for qx in range(2):
            s = n = 0
            for y in range(qy * h // 2, (qy + 1) * h // 2):
                for x in range(qx * w // 2, (qx + 1) * w // 2):
                    for k in range(3):
                        s += img[(y * w + x) * stride + k]
                        n += 1
            out.append(s / n)
    return out
off = sum(1 for i in range(w * h) if max(abs(g[3 * i + k] - m[c * i + k]) for k in range(3)) > 0.1)
print(" ".join(f"{x:.5f}" for x in quadrants(g, 3) + quadrants(m, c)), off / (w * h))
"#;

#[test]
fn mitsuba_loads_and_renders_every_exported_scene() {
    let Some(python) = python_with_mitsuba() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    for name in shipped_scenes() {
        let o = export(&name, dir.path(), &TINY);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        // Mitsuba in a process of its own, started from elsewhere: the XML's
        // relative paths must resolve beside it.
        let o = Command::new(&python)
            .args(["-c", LOAD_AND_RENDER])
            .arg(dir.path().join(format!("{name}.xml")))
            .current_dir(repo())
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(
            o.status.success() && text.starts_with("finite "),
            "{name}: {text}{}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}

#[test]
fn mitsuba_sees_the_same_geometry_and_textures_as_glint() {
    let Some(python) = python_with_mitsuba() else {
        return;
    };
    // Glint's albedo AOV against Mitsuba's, quadrant by quadrant: an image
    // mirrored or turned, a misplaced shape or texture would move them. The
    // scenes are asymmetric (red left wall, green right; textures on spheres
    // and a poster; a mesh and a plane; image textures and a point light).
    // Where they differ by design: Glint's albedo of a light is its color
    // (Mitsuba's black BSDF gives 0), filtered textures, antialiased edges.
    let dir = tempfile::tempdir().unwrap();
    for name in ["cornell-set2", "textured-spheres", "bunny", "ground-mipmap"] {
        let res = ["--resolution", "96x72"];
        let o = glint(
            &[
                &[
                    "render",
                    &scene(name),
                    "--aov",
                    "albedo",
                    "--spp",
                    "16",
                    "-o",
                    "albedo.exr",
                ],
                &res[..],
            ]
            .concat(),
            dir.path(),
        );
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(export(name, dir.path(), &res).status.success());
        let o = Command::new(&python)
            .args(["-c", ALBEDO])
            .arg(dir.path().join(format!("{name}.xml")))
            .arg(dir.path().join("albedo.exr"))
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(
            o.status.success(),
            "{name}: {text}{}",
            String::from_utf8_lossy(&o.stderr)
        );
        let numbers: Vec<f64> = text
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        let (glint_quadrants, mitsuba_quadrants, off) = (&numbers[..4], &numbers[4..8], numbers[8]);
        for (g, m) in glint_quadrants.iter().zip(mitsuba_quadrants) {
            assert!(
                (g - m).abs() < 0.025,
                "{name}: quadrant means {glint_quadrants:?} against {mitsuba_quadrants:?}"
            );
        }
        assert!(
            off < 0.025,
            "{name}: {:.1}% of pixels differ by more than 0.1",
            100.0 * off
        );
    }
}
