//! The conversion checked against Mitsuba 3's documented conventions (its
//! rectangle's and sphere's uv), and the documents of two shipped scenes.

use super::convert::{plane_rectangle, rectangle, sphere};
use super::*;
use glam::{Affine2, Vec2, Vec3, Vec4};
use glint_geometry::{Parallelogram, Plane, Ray, Sphere};
use std::path::Path;

fn repo() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

fn shipped(name: &str) -> SceneDescription {
    crate::load(&repo().join(format!("scenes/{name}.toml"))).unwrap()
}

fn apply(m: [[f32; 4]; 4], p: Vec4) -> Vec3 {
    let row = |r: [f32; 4]| Vec4::from_array(r).dot(p);
    Vec3::new(row(m[0]), row(m[1]), row(m[2]))
}

/// Mitsuba's rectangle at local (x, y) ∈ [−1, 1]²: the world point, its uv
/// `((x + 1)/2, (y + 1)/2)`, and its normal (the inverse transpose on +z).
fn mitsuba_rectangle(m: [[f32; 4]; 4], x: f32, y: f32) -> (Vec3, Vec2, Vec3) {
    let p = apply(m, Vec4::new(x, y, 0.0, 1.0));
    let linear = glam::Mat3::from_cols(apply(m, Vec4::X), apply(m, Vec4::Y), apply(m, Vec4::Z));
    let n = (linear.inverse().transpose() * Vec3::Z).normalize();
    (p, Vec2::new(0.5 * (x + 1.0), 0.5 * (y + 1.0)), n)
}

fn close(a: Vec2, b: Vec2, tolerance: f32) -> bool {
    (a - b).abs().max_element() <= tolerance
}

#[test]
fn rectangles_cover_the_parallelogram_face_its_front_and_keep_its_uv() {
    let cases = [
        // A Cornell wall whose normal is edge1 × edge2's opposite (edges swapped).
        Parallelogram::new(
            Vec3::new(-6., -7., -11.),
            Vec3::new(0., 0., 20.),
            Vec3::new(0., 20., 0.),
            false,
        )
        .unwrap()
        .facing(Vec3::X),
        // A skewed, tilted parallelogram facing edge1 × edge2.
        Parallelogram::new(
            Vec3::new(1., 2., 3.),
            Vec3::new(2., 0.5, -1.),
            Vec3::new(0.7, 1., 0.4),
            true,
        )
        .unwrap(),
    ];
    for p in cases {
        let (m, uv_map) = rectangle(&p);
        for (x, y) in [(-0.8, -0.6), (0.3, -0.9), (0.9, 0.7), (-0.2, 0.4)] {
            let (point, uv, normal) = mitsuba_rectangle(m, x, y);
            assert!(
                normal.dot(p.normal()) > 0.9999,
                "{normal} against {}",
                p.normal()
            );
            let ray = Ray::new(point + p.normal(), -p.normal());
            let t = p
                .hit_distance(&ray, f32::INFINITY)
                .expect("on the parallelogram");
            let glint = p.surface_at(&ray, t);
            assert!((glint.point - point).length() < 1e-4);
            assert!(
                close(uv_map.transform_point2(uv), glint.uv, 1e-5),
                "{uv} → {}",
                glint.uv
            );
        }
    }
}

#[test]
fn spheres_keep_their_place_and_uv() {
    let s = Sphere::new(Vec3::new(2., -3.2, -5.), 1.5).unwrap();
    let (m, uv_map) = sphere(&s);
    for k in 0..200 {
        // Mitsuba's local point and uv: u = atan2(y, x)/2π (in [0, 1)), v = acos(z)/π.
        let (a, b) = (k as f32 * 0.618_034, k as f32 * 0.414_214);
        let z = 1.0 - 2.0 * b.fract();
        let r = (1.0 - z * z).max(0.0).sqrt();
        let local = Vec3::new(
            r * (std::f32::consts::TAU * a).cos(),
            r * (std::f32::consts::TAU * a).sin(),
            z,
        );
        let u = local.y.atan2(local.x) / std::f32::consts::TAU;
        let uv = Vec2::new(
            if u < 0.0 { u + 1.0 } else { u },
            local.z.clamp(-1., 1.).acos() / std::f32::consts::PI,
        );
        let point = apply(m, local.extend(1.0));
        let outward = (point - s.center()).normalize();
        let ray = Ray::new(point + outward, -outward);
        let t = s.hit_distance(&ray, f32::INFINITY).unwrap();
        let glint = s.surface_at(&ray, t);
        assert!((glint.point - point).length() < 1e-4);
        let mapped = uv_map.transform_point2(uv);
        let du = (mapped.x - glint.uv.x).abs();
        assert!(
            du.min(1.0 - du) < 1e-4 && (mapped.y - glint.uv.y).abs() < 1e-4,
            "{mapped} against {}",
            glint.uv
        );
    }
}

#[test]
fn a_plane_becomes_a_rectangle_with_the_planes_uv() {
    for normal in [Vec3::Y, Vec3::new(0.3, 1.0, -0.2), -Vec3::Z] {
        let plane = Plane::new(Vec3::new(0.5, -1.0, 2.0), normal, false)
            .and_then(|p| p.with_tile_size(4.0))
            .unwrap();
        let n = plane.normal();
        let anchor = Vec3::new(1.0, 3.0, 7.0);
        let anchor = anchor - (anchor - plane.point()).dot(n) * n;
        let (m, uv_map) = plane_rectangle(&plane, anchor, 50.0);
        for (x, y) in [(-0.8, -0.6), (0.3, -0.9), (0.01, 0.02), (0.9, 0.7)] {
            let (point, uv, mitsuba_normal) = mitsuba_rectangle(m, x, y);
            assert!(mitsuba_normal.dot(n) > 0.9999);
            let ray = Ray::new(point + n, -n);
            let t = plane.hit_distance(&ray, f32::INFINITY).unwrap();
            let glint = plane.surface_at(&ray, t);
            assert!(
                close(uv_map.transform_point2(uv), glint.uv, 1e-3),
                "{} against {}",
                uv_map.transform_point2(uv),
                glint.uv
            );
        }
    }
}

/// The XML with every number rounded to five significant digits.
fn rounded(xml: &str) -> String {
    let mut out = String::new();
    for (i, part) in xml.split("value=\"").enumerate() {
        if i == 0 {
            out.push_str(part);
            continue;
        }
        let end = part.find('"').unwrap();
        let value: Vec<String> = part[..end]
            .split(' ')
            .map(|token| {
                let (number, comma) = match token.strip_suffix(',') {
                    Some(n) => (n, ","),
                    None => (token, ""),
                };
                match number.parse::<f32>() {
                    Ok(x) => format!("{}{comma}", glint_snapfmt::sig5(x)),
                    Err(_) => token.to_owned(),
                }
            })
            .collect();
        out.push_str("value=\"");
        out.push_str(&value.join(" "));
        out.push_str(&part[end..]);
    }
    out
}

fn warnings(c: &Conversion) -> String {
    c.warnings.iter().map(|w| format!("{w}\n")).collect()
}

#[test]
fn cornell_set1_document() {
    let c = convert(&shipped("cornell-set1"), "cornell-set1-assets");
    assert!(c.files.is_empty());
    insta::assert_snapshot!("cornell-set1.xml", rounded(&c.xml));
    insta::assert_snapshot!("cornell-set1-warnings", warnings(&c));
}

#[test]
fn point_light_document() {
    let c = convert(&shipped("point-light"), "point-light-assets");
    insta::assert_snapshot!("point-light.xml", rounded(&c.xml));
    insta::assert_snapshot!("point-light-warnings", warnings(&c));
}

#[test]
fn every_shipped_scene_converts_with_its_references_defined() {
    let mut names: Vec<String> = std::fs::read_dir(repo().join("scenes"))
        .unwrap()
        .filter_map(|e| {
            let path = e.unwrap().path();
            (path.extension()? == "toml")
                .then(|| path.file_stem().unwrap().to_string_lossy().into_owned())
        })
        .collect();
    names.sort();
    for name in names {
        let c = convert(&shipped(&name), "a");
        let files: Vec<&str> = c.files.iter().map(|f| f.name.as_str()).collect();
        let left_out = c.warnings.iter().any(|w| w.0.contains("is left out"));
        assert!(
            c.xml.contains("<emitter ") || left_out,
            "{name}: no emitter"
        );
        assert_eq!(
            c.xml.matches("<shape ").count(),
            c.xml.matches("</shape>").count()
        );
        // Every referenced id is defined, every file named is written.
        for part in c.xml.split("<ref id=\"").skip(1) {
            let id = &part[..part.find('"').unwrap()];
            assert!(
                c.xml.contains(&format!(" id=\"{id}\">"))
                    || c.xml.contains(&format!(" id=\"{id}\"/>")),
                "{name}: {id}"
            );
        }
        for part in c.xml.split("name=\"filename\" value=\"a/").skip(1) {
            let file = &part[..part.find('"').unwrap()];
            assert!(files.contains(&file), "{name}: {file}");
        }
    }
    // The kinds the shipped scenes exercise: meshes, images, both environment maps.
    let environment = convert(&shipped("environment"), "a");
    let names: Vec<&str> = environment.files.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "texture-0.exr",
            "texture-1.exr",
            "texture-2.exr",
            "texture-3.exr",
            "texture-4.exr",
            "texture-5.exr",
            "environment.exr"
        ]
    );
    // The box of six textures is six two-sided parallelograms.
    assert_eq!(
        environment.xml.matches("type=\"twosided\"").count(),
        6 + 3,
        "{}",
        environment.xml
    );
    let bunny = convert(&shipped("bunny-cornell"), "a");
    assert_eq!(bunny.files.len(), 1);
}

#[test]
fn materials_become_diffuse_mirror_and_blend_bsdfs_with_their_warnings() {
    let text = r#"
ambient = [0.1, 0.2, 0.3]
[camera]
position = [0, 0, 5]
look_at = [0, 0, 0]
fov = 40
[render]
resolution = [8, 6]
seed = 5000000000
[materials.matte]
diffuse = [0.5, 0.5, 0.5]
specular = [0, 0, 0]
[materials.shiny]
diffuse = [0.5, 0.1, 0.1]
specular = [0.3, 0.3, 0.3]
shininess = 60
lobe = "blinn-phong"
reflectivity = 0.25
reflection_tint = [0.9, 0.8, 0.7]
[materials.chrome]
mirror = [0.95, 0.95, 0.95]
[materials.unused]
diffuse = [1, 1, 1]
[[sphere]]
center = [0, 0, 0]
radius = 1
material = "shiny"
[[sphere]]
center = [2, 0, 0]
radius = 1
material = "chrome"
[[parallelogram]]
origin = [-3, -1, -3]
edge1 = [6, 0, 0]
edge2 = [0, 0, 6]
normal = [0, 1, 0]
two_sided = true
material = "matte"
[[box]]
min = [-2, -1, -2]
max = [-1, 0, -1]
material = "matte"
[[point_light]]
position = [0, 4, 0]
"#;
    let c = convert(&crate::parse(text, "inline.toml").unwrap(), "x");
    let xml = rounded(&c.xml);
    assert!(xml.contains("<bsdf type=\"blendbsdf\">"), "{xml}");
    assert!(xml.contains("<float name=\"weight\" value=\"0.25\"/>"));
    assert!(xml.contains("<rgb name=\"specular_reflectance\" value=\"0.9, 0.8, 0.7\"/>"));
    assert!(xml.contains("<bsdf type=\"conductor\">"), "{xml}");
    assert!(!xml.contains("unused"));
    // The two-sided floor, the closed spheres and the box (one BSDF for both
    // flat shapes) are twosided; the box is six rectangles.
    assert_eq!(xml.matches("type=\"twosided\"").count(), 3, "{xml}");
    assert_eq!(xml.matches("id=\"box-0-").count(), 6, "{xml}");
    insta::assert_snapshot!("materials-warnings", warnings(&c));
}

#[test]
fn textures_carry_their_uv_maps_and_images_are_written_once() {
    let c = convert(&shipped("textured-spheres"), "t");
    let images: Vec<&SideFile> = c
        .files
        .iter()
        .filter(|f| f.name.ends_with(".exr"))
        .collect();
    // astronaut, coffee (on a sphere and on the poster) and brick: three images.
    assert_eq!(images.len(), 3);
    let xml = rounded(&c.xml);
    assert!(
        xml.contains("<string name=\"wrap_mode\" value=\"mirror\"/>"),
        "{xml}"
    );
    // The brick sphere: uv_scale [4, 2] on a sphere, then st = (u, 1 − v):
    // s = 4u, t = 1 − 2(1 − v) = 2v − 1.
    assert!(
        xml.contains("<matrix value=\"4 0 0 0 0 2 0 -1 0 0 1 0 0 0 0 1\"/>"),
        "{xml}"
    );
    // The poster (a parallelogram facing edge1 × edge2): t = 1 − v.
    assert!(
        xml.contains("<matrix value=\"1 0 0 0 0 -1 0 1 0 0 1 0 0 0 0 1\"/>"),
        "{xml}"
    );
}

#[test]
fn an_export_replaces_its_own_assets_and_refuses_anyone_elses() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bunny.xml");
    let description = shipped("bunny");
    let exported = export(&description, &out).unwrap();
    let folder = dir.path().join("bunny-assets");
    assert_eq!(exported.assets, Some((folder.clone(), 1)));
    assert!(folder.join("mesh-0.ply").is_file() && folder.join(".glint-export").is_file());
    // Again: the folder is the export's own, so it is replaced.
    std::fs::write(folder.join("stale.txt"), "x").unwrap();
    export(&description, &out).unwrap();
    assert!(!folder.join("stale.txt").exists());
    // Nothing but the XML and the folder is left beside them.
    let mut entries: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    entries.sort();
    assert_eq!(entries, ["bunny-assets", "bunny.xml"]);

    // A folder of that name that no export wrote is left alone, and so is the XML.
    let other = dir.path().join("mine.xml");
    std::fs::write(&other, "mine").unwrap();
    std::fs::create_dir(dir.path().join("mine-assets")).unwrap();
    std::fs::write(dir.path().join("mine-assets/notes.txt"), "mine").unwrap();
    let e = export(&description, &other).unwrap_err();
    assert!(e.is_bad_input());
    assert!(
        e.to_string()
            .contains("mine-assets: exists and was not written by glint export"),
        "{e}"
    );
    assert_eq!(std::fs::read_to_string(&other).unwrap(), "mine");
    assert_eq!(
        std::fs::read_to_string(dir.path().join("mine-assets/notes.txt")).unwrap(),
        "mine"
    );
    assert!(export(&description, &dir.path().join("x.json"))
        .unwrap_err()
        .is_bad_input());
}

#[test]
fn uv_maps_compose_in_the_order_lookups_apply_them() {
    // Checked on one point: the sphere's map, then the material's, then the texture's.
    let shape = Affine2::from_cols(Vec2::X, -Vec2::Y, Vec2::Y);
    let material =
        Affine2::from_scale_angle_translation(Vec2::new(4.0, 2.0), 0.0, Vec2::new(0.5, 0.0));
    let composed = material * shape;
    let p = composed.transform_point2(Vec2::new(0.25, 0.25));
    assert_eq!(p, Vec2::new(0.25 * 4.0 + 0.5, (1.0 - 0.25) * 2.0));
}

#[test]
fn a_mesh_of_several_materials_is_split_one_ply_per_material() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("two.mtl"),
        "newmtl red\nKd 0.8 0.1 0.1\nKs 0 0 0\nnewmtl blue\nKd 0.1 0.1 0.8\nKs 0 0 0\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("two.obj"),
        "mtllib two.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
         usemtl red\nf 1/1 2/2 3/3\nusemtl blue\nf 1/1 3/3 4/4\n",
    )
    .unwrap();
    let text = "[camera]\nposition = [0.5, 0.5, 3]\nlook_at = [0.5, 0.5, 0]\nfov = 40\n\
                [[mesh]]\nfile = \"two.obj\"\ntranslate = [0, 0, -1]\nscale = 2\n\
                [[point_light]]\nposition = [0, 0, 5]\n";
    let description = crate::parse_in(text, "inline.toml", dir.path()).unwrap();
    let c = convert(&description, "a");
    let names: Vec<&str> = c.files.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names, ["mesh-0-0.ply", "mesh-0-1.ply"]);
    assert!(c.xml.contains("two.obj:red"), "{}", c.xml);
    assert!(c
        .xml
        .contains("<rgb name=\"reflectance\" value=\"0.1, 0.1, 0.8\"/>"));
    // Each file holds its one triangle, transformed (scale 2, then z − 1), with uv.
    for file in &c.files {
        let SideContents::Bytes(bytes) = &file.contents else {
            panic!("a PLY")
        };
        let end = b"end_header\n";
        let at = bytes.windows(end.len()).position(|w| w == end).unwrap() + end.len();
        let header = std::str::from_utf8(&bytes[..at]).unwrap();
        assert!(header.contains("element vertex 3\n") && header.contains("element face 1\n"));
        assert!(header.contains("property float u\n") && header.contains("property float nx\n"));
        let first: Vec<f32> = bytes[at..at + 12]
            .chunks(4)
            .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
            .collect();
        assert_eq!(first, [0.0, 0.0, -1.0]);
    }
}
