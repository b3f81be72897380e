//! Renders stopped by Ctrl-C (SIGINT) or SIGTERM: the pixels finished so far are
//! written beside the output (`OUT.partial.exr`), which stays as it was, with
//! one line saying so and the signal's exit status, and `--resume` finishes
//! the partial render into the uninterrupted image, bit for bit.

mod common;

use common::{glint, scene, stderr};
use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

/// A render of a few seconds at most, long enough to be interrupted: the
/// Cornell box at 64 × 64 pixels, `spp` samples each.
fn args(spp: u32, output: &str) -> Vec<String> {
    [
        "render",
        &scene("cornell-set1"),
        "--resolution",
        "64x64",
        "--spp",
        &spp.to_string(),
        "--light-samples",
        "1",
        "--sampler",
        "random",
        "--light-sampler",
        "random",
        "-o",
        output,
    ]
    .map(str::to_owned)
    .to_vec()
}

fn spawn(args: &[String], dir: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_glint"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("glint runs")
}

fn signal(child: &Child, name: &str) {
    let status = Command::new("kill")
        .args([format!("-{name}"), child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(status.success());
}

/// Starts the render, sends `name` once it has had time to start rendering,
/// and returns its output and the time from the signal to its exit. Tries
/// more samples if a render finished before the signal.
fn interrupted(output: &str, name: &str, dir: &Path) -> (Output, Duration, u32) {
    for spp in [4096, 16384, 65536] {
        let child = spawn(&args(spp, output), dir);
        std::thread::sleep(Duration::from_millis(400));
        signal(&child, name);
        let sent = Instant::now();
        let out = child.wait_with_output().unwrap();
        if out.status.code() != Some(0) {
            return (out, sent.elapsed(), spp);
        }
    }
    panic!("every render finished before the signal");
}

fn no_hidden_files(dir: &Path) {
    let hidden: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "left behind: {hidden:?}");
}

#[test]
fn ctrl_c_writes_the_finished_pixels_and_resume_completes_them_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("out.exr"), b"the previous image").unwrap();
    let (out, took, spp) = interrupted("out.exr", "INT", dir.path());
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
    assert!(took < Duration::from_secs(2), "took {took:?} to stop");
    let err = stderr(&out);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("glint: interrupted: wrote out.partial.exr with ")
            && err.contains("out.exr is as it was")
            && err.contains("--resume"),
        "{err}"
    );
    assert_eq!(
        std::fs::read(dir.path().join("out.exr")).unwrap(),
        b"the previous image",
        "the user's image is kept"
    );
    no_hidden_files(dir.path());
    let partial = glint_camera::PartialFilm::load(&dir.path().join("out.partial.exr")).unwrap();
    let done = partial.finished_count();
    assert!(
        done < 64 * 64,
        "{done} pixels: the render was not cut short"
    );
    // Other settings (another seed; another mirror depth, though this scene
    // has no mirror), an edited scene or another size make another render:
    // refused, the partial file left as it was.
    let before = std::fs::read(dir.path().join("out.partial.exr")).unwrap();
    let edited = dir.path().join("edited.toml");
    let text = std::fs::read_to_string(scene("cornell-set1")).unwrap();
    std::fs::write(
        &edited,
        text.replacen("ambient = [0.1", "ambient = [0.2", 1),
    )
    .unwrap();
    let refusals = [
        (vec!["--seed", "7"], "its fingerprint differs"),
        (vec!["--max-depth", "2"], "its fingerprint differs"),
        (vec![], "its fingerprint differs"),
        (
            vec![],
            "the partial image is 64x64 pixels, this render 32x64",
        ),
    ];
    for (i, (other, expected)) in refusals.into_iter().enumerate() {
        let mut a = args(spp, "out.exr");
        match i {
            2 => a[1] = edited.display().to_string(),
            3 => a[3] = "32x64".to_owned(), // after --resolution
            _ => {}
        }
        a.push("--resume".to_owned());
        a.extend(other.iter().map(|s| s.to_string()));
        let refused = glint(
            &a.iter().map(String::as_str).collect::<Vec<_>>(),
            dir.path(),
        );
        common::assert_input_error(&refused, expected);
        assert_eq!(
            std::fs::read(dir.path().join("out.partial.exr")).unwrap(),
            before
        );
    }
    std::fs::remove_file(&edited).unwrap();
    // The thread count and --stats change no pixel: not part of the render.
    let resumed = glint(
        &[
            args(spp, "out.exr"),
            ["--resume", "--threads", "1", "--stats"]
                .map(str::to_owned)
                .to_vec(),
        ]
        .concat()
        .iter()
        .map(String::as_str)
        .collect::<Vec<_>>(),
        dir.path(),
    );
    assert_eq!(resumed.status.code(), Some(0), "{}", stderr(&resumed));
    let full = glint(
        &args(spp, "full.exr")
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>(),
        dir.path(),
    );
    assert_eq!(full.status.code(), Some(0), "{}", stderr(&full));
    let read = |name: &str| std::fs::read(dir.path().join(name)).unwrap();
    assert!(
        read("out.exr") == read("full.exr"),
        "the resumed image differs"
    );
    assert!(
        !dir.path().join("out.partial.exr").exists(),
        "the finished partial render is removed"
    );
    no_hidden_files(dir.path());
}

#[test]
fn sigterm_keeps_the_users_png_and_writes_the_partial_render_beside_it() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("out.png"), b"a good image").unwrap();
    let (out, _, spp) = interrupted("out.png", "TERM", dir.path());
    assert_eq!(out.status.code(), Some(143), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.starts_with("glint: interrupted: wrote out.partial.exr with ")
            && err.contains("out.png is as it was"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    assert_eq!(
        std::fs::read(dir.path().join("out.png")).unwrap(),
        b"a good image"
    );
    let partial = glint_camera::PartialFilm::load(&dir.path().join("out.partial.exr")).unwrap();
    assert_eq!(partial.film.resolution(), glam::UVec2::new(64, 64));
    // The last pixel of the last band is never reached first.
    assert!(!partial.finished[64 * 64 - 1]);
    // --resume finishes it into the PNG asked for.
    let mut a = args(spp, "out.png");
    a.extend([
        "--resume".to_owned(),
        "--threads".to_owned(),
        "1".to_owned(),
    ]);
    let resumed = glint(
        &a.iter().map(String::as_str).collect::<Vec<_>>(),
        dir.path(),
    );
    assert_eq!(resumed.status.code(), Some(0), "{}", stderr(&resumed));
    let film = glint_camera::Film::load(&dir.path().join("out.png")).unwrap();
    assert_eq!(film.resolution(), glam::UVec2::new(64, 64));
    assert!(!dir.path().join("out.partial.exr").exists());
    no_hidden_files(dir.path());
}

#[test]
fn resume_refuses_what_is_not_a_partial_render() {
    let dir = tempfile::tempdir().unwrap();
    let run = |output: &str| {
        let mut a = args(4, output);
        a.push("--resume".to_owned());
        glint(
            &a.iter().map(String::as_str).collect::<Vec<_>>(),
            dir.path(),
        )
    };
    common::assert_input_error(
        &run("gone.exr"),
        "--resume: there is no partial render gone.partial.exr to finish",
    );
    assert_eq!(
        glint(
            &args(4, "done.partial.exr")
                .iter()
                .map(String::as_str)
                .collect::<Vec<_>>(),
            dir.path()
        )
        .status
        .code(),
        Some(0)
    );
    common::assert_input_error(&run("done.exr"), "no coverage (alpha) channel");
    let unnamed = glint_camera::PartialFilm::new(
        glint_camera::Film::new(glam::UVec2::new(64, 64)),
        vec![false; 64 * 64],
    );
    unnamed
        .save(&dir.path().join("unnamed.partial.exr"))
        .unwrap();
    common::assert_input_error(
        &run("unnamed.exr"),
        "does not record the scene and settings",
    );
}

#[test]
fn ctrl_c_stops_a_mistaken_render_soon_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("out.png"), b"the previous image").unwrap();
    let mut args = args(16384, "out.png");
    args.extend(["--mistake".to_owned(), "no-shadows".to_owned()]);
    let child = spawn(&args, dir.path());
    std::thread::sleep(Duration::from_millis(400));
    signal(&child, "INT");
    let sent = Instant::now();
    let out = child.wait_with_output().unwrap();
    let took = sent.elapsed();
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
    // The one-ray integrator stops between rows: far sooner than the
    // minutes the whole render takes.
    assert!(took < Duration::from_secs(5), "took {took:?} to stop");
    assert!(
        stderr(&out).contains("out.png was not written"),
        "{}",
        stderr(&out)
    );
    assert_eq!(
        std::fs::read(dir.path().join("out.png")).unwrap(),
        b"the previous image"
    );
    no_hidden_files(dir.path());
}
