//! The `glint` binary as a user runs it: outputs, exit statuses, error lines.

mod common;

use common::{assert_input_error, glint, scene, stderr, SMALL};
use std::path::Path;

#[test]
fn renders_png_exr_and_pfm_and_prints_a_summary() {
    let dir = tempfile::tempdir().unwrap();
    for ext in ["png", "exr", "pfm"] {
        let out = format!("set1.{ext}");
        let o = glint(
            &[&["render", &scene("cornell-set1"), "-o", &out], &SMALL[..]].concat(),
            dir.path(),
        );
        assert!(o.status.success(), "{}", stderr(&o));
        let summary = String::from_utf8_lossy(&o.stdout);
        assert!(
            summary.starts_with(&format!("wrote {out}: 24x24, 4 spp, 4 light samples")),
            "{summary}"
        );
        assert!(summary.contains("s wall") && summary.contains("rays/s"));
        assert!(std::fs::metadata(dir.path().join(&out)).unwrap().len() > 100);
    }
    // No temporary files are left behind.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 3);
}

#[test]
fn default_output_is_the_scene_name_as_png() {
    let dir = tempfile::tempdir().unwrap();
    let o = glint(
        &[&["render", &scene("point-light")], &SMALL[..]].concat(),
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.path().join("point-light.png").is_file());
}

#[test]
fn one_and_two_threads_write_identical_files() {
    let dir = tempfile::tempdir().unwrap();
    for threads in ["1", "2"] {
        let out = format!("t{threads}.pfm");
        let args = [
            "render",
            &scene("cornell-set3"),
            "-o",
            &out,
            "--threads",
            threads,
            "--sampler",
            "random",
        ];
        let o = glint(&[&args[..], &SMALL[..]].concat(), dir.path());
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let a = std::fs::read(dir.path().join("t1.pfm")).unwrap();
    let b = std::fs::read(dir.path().join("t2.pfm")).unwrap();
    assert_eq!(a, b);
}

#[test]
fn sobol_samplers_render_the_same_file_on_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let env = scene("environment");
    let run = |out: &str, threads: &str, pattern: &str| {
        let args = [
            "render",
            env.as_str(),
            "-o",
            out,
            "--threads",
            threads,
            "--sampler",
            pattern,
            "--light-sampler",
            pattern,
            "--environment-sampler",
            pattern,
            "--environment-samples",
            "4",
        ];
        let o = glint(&[&args[..], &SMALL[..]].concat(), dir.path());
        assert!(o.status.success(), "{}", stderr(&o));
        std::fs::read(dir.path().join(out)).unwrap()
    };
    let one = run("sobol1.pfm", "1", "sobol");
    assert_eq!(one, run("sobol2.pfm", "2", "sobol"));
    assert_ne!(one, run("stratified.pfm", "2", "stratified"));
    // The environment's grid needs a square count, as the others do.
    let args = [
        "render",
        env.as_str(),
        "--environment-sampler",
        "grid",
        "--environment-samples",
        "8",
    ];
    assert_input_error(
        &glint(&args, dir.path()),
        "render settings: environment samples is 8, but the grid pattern needs a perfect square",
    );
    let args = ["render", env.as_str(), "--environment-sampler", "halton"];
    assert_input_error(
        &glint(&args, dir.path()),
        "invalid value 'halton' for '--environment-sampler <PATTERN>'",
    );
}

#[test]
fn bad_input_gives_one_line_exit_2_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, body: &str| std::fs::write(dir.path().join(name), body).unwrap();
    write("syntax.toml", "[camera\nfov = 45\n");
    write(
        "invalid.toml",
        "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nfov = 270\n",
    );
    let cases = [
        ("missing.toml", "missing.toml: cannot read the scene file"),
        ("syntax.toml", "syntax.toml:1:8: unclosed table"),
        (
            "invalid.toml",
            "invalid.toml:4:7: camera.fov: expected a field of view",
        ),
    ];
    for (file, expected) in cases {
        let o = glint(&["render", file, "-o", "out.png"], dir.path());
        assert_input_error(&o, expected);
    }
    let o = glint(
        &["render", &scene("point-light"), "-o", "out.bmp"],
        dir.path(),
    );
    assert_input_error(&o, "unknown output format");
    let o = glint(
        &[
            "render",
            &scene("point-light"),
            "--spp",
            "5",
            "--sampler",
            "grid",
        ],
        dir.path(),
    );
    assert_input_error(&o, "perfect square");
    let o = glint(
        &["render", &scene("point-light"), "-o", "no/dir/out.png"],
        dir.path(),
    );
    assert_input_error(&o, "does not exist");
    let o = glint(
        &["render", &scene("point-light"), "--threads", "0"],
        dir.path(),
    );
    assert_input_error(&o, "threads must be from 1 to 1024, got 0");
    // Usage errors come from clap: also one line and status 2.
    let o = glint(&["render", "--no-such-flag"], dir.path());
    assert_input_error(&o, "unexpected argument '--no-such-flag'");
    let point_light = scene("point-light");
    for (flags, expected) in [
        (["--resolution", "0x5"], "each side from 1 to 16384"),
        (["--spp", "lots"], "invalid value 'lots' for '--spp <N>'"),
        (
            ["--spp", "4000000000"],
            "spp is 4000000000, more than the limit",
        ),
    ] {
        let o = glint(
            &[&["render", point_light.as_str()], &flags[..]].concat(),
            dir.path(),
        );
        assert_input_error(&o, expected);
    }
    // Nothing was written by any failed run.
    let files: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(files.len(), 2, "{files:?}");
}

#[test]
fn a_value_outside_its_list_is_refused_with_the_list() {
    // One line that names the bad value and every value allowed, whichever
    // command and flag.
    let dir = tempfile::tempdir().unwrap();
    let set1 = scene("cornell-set1");
    let cases: [(&[&str], &str); 3] = [
        (
            &["render", &set1, "--sampler", "halton"],
            "invalid value 'halton' for '--sampler <PATTERN>' [possible values: grid, random, stratified, sobol]",
        ),
        (
            &["explain", &set1, "--pixel", "1,1", "--stage", "shading"],
            "invalid value 'shading' for '--stage <STAGE>' [possible values: camera, intersect, texture, light, film]",
        ),
        (
            &["diff", "a.pfm", "b.pfm", "--metric", "psnr"],
            "invalid value 'psnr' for '--metric <METRIC>' [possible values: relmse, rmse, flip, max]",
        ),
    ];
    for (args, expected) in cases {
        assert_input_error(&glint(args, dir.path()), expected);
    }
}

#[test]
fn a_failed_run_leaves_an_existing_output_untouched() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("keep.png"), b"precious").unwrap();
    std::fs::write(dir.path().join("bad.toml"), "[camera]\nfov = 45\n").unwrap();
    let o = glint(&["render", "bad.toml", "-o", "keep.png"], dir.path());
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        std::fs::read(dir.path().join("keep.png")).unwrap(),
        b"precious"
    );
}

#[test]
fn help_documents_every_flag() {
    let o = glint(&["render", "--help"], Path::new("."));
    assert!(o.status.success());
    let help = String::from_utf8_lossy(&o.stdout);
    for flag in [
        "--output",
        "--spp",
        "--light-samples",
        "--sampler",
        "--light-sampler",
        "--environment-samples",
        "--environment-sampler",
        "--threads",
        "--seed",
        "--resolution",
    ] {
        assert!(help.contains(flag), "{flag} undocumented");
    }
    let o = glint(&["--help"], Path::new("."));
    assert!(String::from_utf8_lossy(&o.stdout).contains("render"));
}

/// Reads a PFM written by glint: (width, height, RGB rows from the top).
fn read_pfm(path: &Path) -> (usize, usize, Vec<[f32; 3]>) {
    let bytes = std::fs::read(path).unwrap();
    let header_end = bytes
        .iter()
        .enumerate()
        .filter(|(_, b)| **b == b'\n')
        .nth(2)
        .unwrap()
        .0
        + 1;
    let header = String::from_utf8_lossy(&bytes[..header_end]).into_owned();
    let mut words = header.split_whitespace().skip(1);
    let w: usize = words.next().unwrap().parse().unwrap();
    let h: usize = words.next().unwrap().parse().unwrap();
    let floats: Vec<f32> = bytes[header_end..]
        .chunks(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    let mut rows: Vec<[f32; 3]> = floats.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    // PFM stores the bottom row first.
    let mut top_first = Vec::with_capacity(rows.len());
    for row in rows.chunks_mut(w).rev() {
        top_first.extend_from_slice(row);
    }
    (w, h, top_first)
}

#[test]
fn aovs_write_raw_values_to_float_files_and_false_color_to_png() {
    let dir = tempfile::tempdir().unwrap();
    let point_light = scene("point-light");
    let run = |aov: &str, out: &str| {
        let args = [
            "render",
            point_light.as_str(),
            "-o",
            out,
            "--aov",
            aov,
            "--resolution",
            "32x24",
            "--spp",
            "1",
        ];
        let o = glint(&args, dir.path());
        assert!(o.status.success(), "{aov}: {}", stderr(&o));
    };
    run("normal", "normal.pfm");
    let (w, h, normals) = read_pfm(&dir.path().join("normal.pfm"));
    assert_eq!((w, h), (32, 24));
    // Bottom-left corner sees the ground plane (normal +y); the top row sees sky (0).
    assert_eq!(normals[(h - 1) * w], [0.0, 1.0, 0.0]);
    assert_eq!(normals[0], [0.0, 0.0, 0.0]);
    // At 33x25 the centre pixel's ray is the view direction: from (0, 2.5, 6)
    // towards (0, 0.5, 0), meeting the unit sphere at (0, 1, 0).
    let args = [
        "render",
        point_light.as_str(),
        "-o",
        "depth.pfm",
        "--aov",
        "depth",
        "--resolution",
        "33x25",
        "--spp",
        "1",
        "--sampler",
        "grid",
    ];
    assert!(glint(&args, dir.path()).status.success());
    let (w, _, depth) = read_pfm(&dir.path().join("depth.pfm"));
    let centre = depth[12 * w + 16][0];
    let expected = ray_sphere_distance([0.0, 2.5, 6.0], [0.0, -2.0, -6.0], [0.0, 1.0, 0.0], 1.0);
    assert!((centre - expected).abs() < 1e-4, "{centre} vs {expected}");
    for aov in ["uv", "mip-level", "normal", "depth", "albedo"] {
        run(aov, &format!("{aov}.png"));
        assert!(image_dimensions(&dir.path().join(format!("{aov}.png"))) == (32, 24));
    }
    // Reflection depth in the environment scene: the chrome sphere reflects.
    let env = scene("environment");
    let args = [
        "render",
        env.as_str(),
        "-o",
        "refl.pfm",
        "--aov",
        "reflection-depth",
        "--resolution",
        "48x27",
        "--spp",
        "1",
        "--max-depth",
        "3",
    ];
    let o = glint(&args, dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let (_, _, refl) = read_pfm(&dir.path().join("refl.pfm"));
    let deepest = refl.iter().map(|p| p[0]).fold(0.0f32, f32::max);
    assert!((1.0..=3.0).contains(&deepest), "{deepest}");
    // Objects at the pixel centres of Set 1: the centre pixel sees the back
    // wall (object 4 after the four spheres), a corner of the image nothing.
    let set1 = scene("cornell-set1");
    let args = [
        "render",
        &set1,
        "-o",
        "objects.pfm",
        "--aov",
        "object",
        "--resolution",
        "32x32",
        "--spp",
        "1",
        "--sampler",
        "grid",
    ];
    let o = glint(&args, dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let (w, _, objects) = read_pfm(&dir.path().join("objects.pfm"));
    assert_eq!(
        objects[16 * w + 16],
        [5.0; 3],
        "the back wall, object 4, plus one"
    );
    let ids: std::collections::BTreeSet<u32> = objects.iter().map(|p| p[0] as u32).collect();
    assert_eq!(
        ids,
        (1..=10).collect(),
        "every wall, sphere and the light; no miss"
    );
    let o = glint(
        &["render", point_light.as_str(), "--aov", "bogus"],
        dir.path(),
    );
    assert_input_error(&o, "invalid value 'bogus' for '--aov <BUFFER>'");
}

/// `--texture-filter F` renders what the scene renders with every texture's
/// `filter = "F"` written in its file, to the byte, and the filters differ.
#[test]
fn texture_filter_override_is_the_filter_written_in_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    let ground = scene("ground-mipmap");
    let text = std::fs::read_to_string(&ground).unwrap();
    let textures = Path::new(&ground).parent().unwrap().join("textures/");
    let render = |scene: &str, out: &str, flags: &[&str]| {
        let mut args = vec!["render", scene, "-o", out];
        args.extend(["--resolution", "64x36", "--spp", "1"]);
        args.extend(flags);
        let o = glint(&args, dir.path());
        assert!(o.status.success(), "{}", stderr(&o));
        std::fs::read(dir.path().join(out)).unwrap()
    };
    let mut images = Vec::new();
    for filter in ["nearest", "ewa"] {
        let flagged = render(
            &ground,
            &format!("{filter}-flag.pfm"),
            &["--texture-filter", filter],
        );
        let written = dir.path().join(format!("{filter}.toml"));
        let edited = text
            .replace("filter = \"trilinear\"", &format!("filter = \"{filter}\""))
            .replace(
                "file = \"textures/",
                &format!("file = \"{}", textures.display()),
            );
        assert_ne!(edited, text);
        std::fs::write(&written, edited).unwrap();
        let in_file = render(
            written.to_str().unwrap(),
            &format!("{filter}-file.pfm"),
            &[],
        );
        assert!(
            flagged == in_file,
            "--texture-filter {filter} differs from the file's filter"
        );
        images.push(flagged);
    }
    assert_ne!(images[0], images[1]);
}

/// Distance from `origin` along `direction` to the first hit on a sphere.
fn ray_sphere_distance(origin: [f32; 3], direction: [f32; 3], centre: [f32; 3], r: f32) -> f32 {
    let dot = |a: [f32; 3], b: [f32; 3]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f32>();
    let len = dot(direction, direction).sqrt();
    let d = direction.map(|x| x / len);
    let f = [0, 1, 2].map(|i| origin[i] - centre[i]);
    let b = dot(f, d);
    -b - (b * b - (dot(f, f) - r * r)).sqrt()
}

fn image_dimensions(path: &Path) -> (u32, u32) {
    // PNG: width and height are big-endian u32s at bytes 16..24.
    let bytes = std::fs::read(path).unwrap();
    let be = |i: usize| u32::from_be_bytes(bytes[i..i + 4].try_into().unwrap());
    (be(16), be(20))
}
