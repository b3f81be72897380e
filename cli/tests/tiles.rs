//! A render split into pieces: `glint render --tile I/N` and `--crop` write
//! .exr files that say where they belong and which render they are of,
//! `glint assemble` puts them together into the single render's bytes, and
//! `glint farm` writes the scripts that run the tiles on Slurm or GNU
//! parallel (run here by hand and by GNU parallel; the Slurm run is
//! `cli/tests/farm_slurm.rs`, docs/testing.md).

mod common;

use common::{assert_input_error, glint, program_missing, real_part, scene, stderr, stdout};
use std::path::Path;
use std::process::Command;

/// The flags of a quick render: 48 × 41 pixels (a row count no tile count
/// used here divides), 2 samples and 2 light samples.
const QUICK: [&str; 6] = [
    "--resolution",
    "48x41",
    "--spp",
    "2",
    "--light-samples",
    "2",
];

/// A quick render of the bunny in the box.
fn render_args(extra: &[&str]) -> Vec<String> {
    let mut args = vec!["render".to_owned(), scene("bunny-cornell")];
    args.extend(QUICK.iter().chain(extra).map(|s| s.to_string()));
    args
}

fn run(args: &[String], dir: &Path) -> std::process::Output {
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = glint(&args, dir);
    assert_eq!(out.status.code(), Some(0), "{args:?}: {}", stderr(&out));
    out
}

fn bytes(dir: &Path, name: &str) -> Vec<u8> {
    std::fs::read(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn tiles_and_windows_assemble_into_the_single_render_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for format in ["exr", "png", "pfm"] {
        run(&render_args(&["-o", &format!("whole.{format}")]), d);
    }
    for count in [1, 3, 7] {
        let tiles: Vec<String> = (0..count).map(|i| format!("t{count}-{i}.exr")).collect();
        for (i, tile) in tiles.iter().enumerate() {
            let out = run(
                &render_args(&["--tile", &format!("{i}/{count}"), "-o", tile]),
                d,
            );
            assert!(
                stdout(&out).contains(&format!("tile {i}/{count} of 48x41")),
                "{}",
                stdout(&out)
            );
        }
        for format in ["exr", "png", "pfm"] {
            let whole = format!("whole-{count}.{format}");
            // In another order than rendered: the order given does not matter.
            let mut args = vec!["assemble".to_owned()];
            args.extend(tiles.iter().rev().cloned());
            args.extend(["-o".to_owned(), whole.clone()]);
            run(&args, d);
            assert!(
                bytes(d, &whole) == bytes(d, &format!("whole.{format}")),
                "{count} tiles, .{format}: not the single render's bytes"
            );
        }
    }
    // Windows of any shape, an .exr each.
    let windows = ["0,0,48,20", "0,20,30,41", "30,20,48,41"];
    for (k, window) in windows.iter().enumerate() {
        run(
            &render_args(&["--crop", window, "-o", &format!("w{k}.exr")]),
            d,
        );
    }
    run(
        &[
            "assemble",
            "w2.exr",
            "w0.exr",
            "w1.exr",
            "-o",
            "windows.exr",
        ]
        .map(str::to_owned),
        d,
    );
    assert!(bytes(d, "windows.exr") == bytes(d, "whole.exr"));
}

#[test]
fn assemble_refuses_an_incomplete_overlapping_or_mixed_set_and_says_what_to_render() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for i in 0..4 {
        run(
            &render_args(&["--tile", &format!("{i}/4"), "-o", &format!("t{i}.exr")]),
            d,
        );
    }
    run(
        &render_args(&["--seed", "9", "--tile", "1/4", "-o", "seed9.exr"]),
        d,
    );
    run(&render_args(&["--crop", "0,0,48,20", "-o", "top.exr"]), d);
    run(
        &render_args(&["--crop", "0,10,48,41", "-o", "bottom.exr"]),
        d,
    );
    run(&render_args(&["--crop", "0,0,48,30", "-o", "most.exr"]), d);
    run(&render_args(&["-o", "plain.exr"]), d);
    let cases: [(&[&str], &str); 7] = [
        (&["t0.exr", "t2.exr"], "missing tiles 1/4, 3/4; render them"),
        (&["t0.exr", "t1.exr", "t2.exr"], "missing tile 3/4; render it"),
        (&["t0.exr", "t1.exr", "t1.exr", "t2.exr", "t3.exr"], "t1.exr and t1.exr both hold 480 pixels (the first at 0,1)"),
        (&["t0.exr", "seed9.exr", "t2.exr", "t3.exr"], "seed9.exr: a piece of another render than t0.exr"),
        (&["top.exr", "bottom.exr"], "top.exr and bottom.exr both hold 480 pixels (the first at 0,10)"),
        (&["most.exr"], "528 of 1968 pixels are in no piece, in rows 30-40; render the windows"),
        (&["plain.exr"], "plain.exr: cannot read the image: it has no coverage (alpha) channel: not a tile written by glint render --tile or --crop"),
    ];
    for (tiles, expected) in cases {
        let mut args = vec!["assemble"];
        args.extend(tiles);
        args.extend(["-o", "out.png"]);
        assert_input_error(&glint(&args, d), expected);
        assert!(!d.join("out.png").exists(), "{tiles:?}: wrote an image");
    }
    let o = glint(&["assemble", "t0.exr", "-o", "t0.exr"], d);
    assert_input_error(&o, "-o would write over t0.exr, which this run reads");
    let o = glint(&["assemble", "t0.exr", "-o", "out.txt"], d);
    assert_input_error(&o, "unknown output format");
}

#[test]
fn tile_options_are_checked_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cases: [(&[&str], &str); 6] = [
        (
            &["--tile", "4/4", "-o", "t.exr"],
            "expected I/N with 0 ≤ I < N",
        ),
        (
            &["--tile", "0/0", "-o", "t.exr"],
            "expected I/N with 0 ≤ I < N",
        ),
        (
            &["--tile", "a/4", "-o", "t.exr"],
            "expected I/N with whole numbers",
        ),
        (
            &["--tile", "1/4", "-o", "t.png"],
            "--tile 1/4 writes OpenEXR (.exr)",
        ),
        (
            &["--tile", "1/4", "--crop", "0,0,8,8", "-o", "t.exr"],
            "cannot be used with",
        ),
        (
            &["--tile", "45/50", "-o", "t.exr"],
            "the image has 41 rows, one per tile at most, so tile 45 would be empty",
        ),
    ];
    for (extra, expected) in cases {
        let args = render_args(extra);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        assert_input_error(&glint(&args, d), expected);
    }
    assert_eq!(std::fs::read_dir(d).unwrap().count(), 0, "wrote something");
}

/// Writes the farm for 5 tiles into `dir/farm`; returns glint's stdout.
fn write_farm(engine: &str, d: &Path, extra: &[&str]) -> String {
    let mut args = vec!["farm", engine, "render"];
    let bunny = scene("bunny-cornell");
    args.extend([
        bunny.as_str(),
        "--tiles",
        "5",
        "--dir",
        "farm",
        "-o",
        "out/farmed.exr",
    ]);
    args.extend(extra);
    args.push("--");
    args.extend(QUICK);
    let out = glint(&args, d);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    stdout(&out)
}

#[test]
fn farm_scripts_render_the_tiles_and_assemble_the_single_render() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    run(&render_args(&["-o", "whole.exr"]), d);
    let said = write_farm("parallel", d, &["--jobs", "2"]);
    assert!(said.contains("run-parallel.sh"), "{said}");
    let farm = d.join("farm");
    let parallel = std::fs::read_to_string(farm.join("run-parallel.sh")).unwrap();
    for part in ["--joblog", "--resume-failed", "--jobs 2", "::: $(seq 0 4)"] {
        assert!(parallel.contains(part), "{part}: {parallel}");
    }
    // By hand, as any engine runs them: the tiles in any order, then the merge.
    for tile in [3, 0, 4, 1] {
        let status = Command::new(farm.join("render-tile.sh"))
            .arg(tile.to_string())
            .output()
            .unwrap();
        assert!(status.status.success(), "{}", stderr(&status));
    }
    let merge = Command::new(farm.join("assemble.sh")).output().unwrap();
    assert_eq!(merge.status.code(), Some(2), "one tile missing");
    assert!(
        stderr(&merge).contains("missing tile 2/5"),
        "{}",
        stderr(&merge)
    );
    let status = Command::new(farm.join("render-tile.sh"))
        .arg("2")
        .output()
        .unwrap();
    assert!(status.status.success());
    let merge = Command::new(farm.join("assemble.sh")).output().unwrap();
    assert!(merge.status.success(), "{}", stderr(&merge));
    assert!(bytes(d, "out/farmed.exr") == bytes(d, "whole.exr"));
}

#[test]
fn farm_runs_on_gnu_parallel_where_installed() {
    if !real_part(program_missing("parallel", "parallel")) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    run(&render_args(&["-o", "whole.exr"]), d);
    write_farm("parallel", d, &["--run"]);
    assert!(bytes(d, "out/farmed.exr") == bytes(d, "whole.exr"));
    let log = std::fs::read_to_string(d.join("farm/parallel.joblog")).unwrap();
    assert_eq!(log.lines().count(), 6, "a header and five jobs: {log}");
}

#[test]
fn farm_writes_a_slurm_job_array_and_a_merge_job_that_waits_for_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let extra = [
        "--max-running",
        "2",
        "--time",
        "00:10:00",
        "--mem",
        "1G",
        "--cpus",
        "2",
    ];
    let said = write_farm("slurm", d, &extra);
    let farm = std::fs::canonicalize(d.join("farm")).unwrap();
    let array = farm.join("render.sbatch");
    assert!(
        said.contains(&format!("job=$(sbatch --parsable {})", array.display()))
            && said.contains("sbatch --dependency=afterok:${job%%;*}"),
        "{said}"
    );
    let script = std::fs::read_to_string(&array).unwrap();
    for line in [
        "#SBATCH --array=0-4%2",
        "#SBATCH --time=00:10:00",
        "#SBATCH --mem=1G",
        "#SBATCH --cpus-per-task=2",
        "#SBATCH --requeue",
        "render_%A_%a.log",
        "render-tile.sh \"$SLURM_ARRAY_TASK_ID\"",
    ] {
        assert!(script.contains(line), "{line}: {script}");
    }
    let merge = std::fs::read_to_string(farm.join("assemble.sbatch")).unwrap();
    assert!(merge.contains("assemble.sh"), "{merge}");
    let tile = std::fs::read_to_string(farm.join("render-tile.sh")).unwrap();
    assert!(
        tile.contains("${SLURM_CPUS_PER_TASK:-1}") && tile.contains("--resume"),
        "{tile}"
    );
}

#[test]
fn farm_options_are_checked_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let bunny = scene("bunny-cornell");
    let cases: [(&[&str], &str); 8] = [
        (
            &["slurm", "render", &bunny, "--tiles", "0"],
            "expected at least 1 tile",
        ),
        (
            &["slurm", "render", &bunny, "--tiles", "4", "--time", "soon"],
            "expected a Slurm time limit",
        ),
        (
            &["slurm", "render", &bunny, "--tiles", "4", "--mem", "lots"],
            "expected a memory size",
        ),
        (
            &["slurm", "render", &bunny, "--tiles", "4", "--cpus", "0"],
            "invalid value '0' for '--cpus",
        ),
        (
            &[
                "slurm",
                "render",
                &bunny,
                "--tiles",
                "4",
                "--max-running",
                "0",
            ],
            "invalid value '0' for '--max-running",
        ),
        (
            &[
                "parallel", "render", &bunny, "--tiles", "4", "--", "--spp", "x",
            ],
            "render options after --: invalid value 'x' for '--spp",
        ),
        (
            &[
                "parallel", "render", &bunny, "--tiles", "4", "--", "--crop", "0,0,4,4",
            ],
            "--crop is set by glint farm for each task",
        ),
        (
            &[
                "parallel",
                "render",
                &bunny,
                "--tiles",
                "99",
                "--",
                "--resolution",
                "48x41",
            ],
            "--tiles 99: the image has 41 rows",
        ),
    ];
    for (args, expected) in cases {
        let mut all = vec!["farm"];
        all.extend(args);
        assert_input_error(&glint(&all, d), expected);
    }
    let spaced = [
        "farm", "slurm", "render", &bunny, "--tiles", "4", "--dir", "a b",
    ];
    assert_input_error(&glint(&spaced, d), "cannot hold a path with spaces");
    // An engine that is not there, asked to start: refused before writing.
    for (engine, start, expected) in [
        (
            "parallel",
            "--run",
            "GNU parallel (parallel) is not installed here",
        ),
        (
            "slurm",
            "--submit",
            "Slurm's sbatch (sbatch) is not installed here",
        ),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_glint"))
            .args(["farm", engine, "render", &bunny, "--tiles", "4", start])
            .env("PATH", "")
            .current_dir(d)
            .output()
            .unwrap();
        assert_input_error(&out, expected);
    }
    assert_eq!(std::fs::read_dir(d).unwrap().count(), 0, "wrote something");
}

#[test]
fn a_stopped_tile_resumes_to_the_bytes_of_one_rendered_in_one_go() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let args = |spp: u32, out: &str| -> Vec<String> {
        let mut a = render_args(&["--tile", "1/2", "-o", out]);
        a[1] = scene("cornell-set1");
        a[3] = "64x64".into();
        a[5] = spp.to_string();
        a[7] = "1".into();
        a
    };
    for spp in [4096u32, 16384, 65536] {
        let child = Command::new(env!("CARGO_BIN_EXE_glint"))
            .args(args(spp, "tile.exr"))
            .current_dir(d)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(400));
        let kill = Command::new("kill")
            .args(["-TERM", &child.id().to_string()])
            .status()
            .unwrap();
        assert!(kill.success());
        let out = child.wait_with_output().unwrap();
        if out.status.code() == Some(0) {
            // Finished before the signal: more samples, from no output.
            std::fs::remove_file(d.join("tile.exr")).unwrap();
            continue;
        }
        assert_eq!(out.status.code(), Some(143), "{}", stderr(&out));
        let err = stderr(&out);
        // Counted among the tile's own 32 rows of 64 pixels.
        assert!(err.contains(" of 2048 pixels rendered"), "{err}");
        assert!(!d.join("tile.exr").exists());
        let mut resume = args(spp, "tile.exr");
        resume.push("--resume".into());
        run(&resume, d);
        assert!(
            !d.join("tile.partial.exr").exists(),
            "the partial file stays"
        );
        run(&args(spp, "straight.exr"), d);
        assert!(bytes(d, "tile.exr") == bytes(d, "straight.exr"));
        return;
    }
    panic!("every render finished before the signal");
}

/// An sshd of the test's own on 127.0.0.1, ended when dropped.
struct Sshd(std::process::Child);

impl Drop for Sshd {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Starts an sshd on a free port of 127.0.0.1 that takes a key made in
/// `dir`; returns it and the GNU parallel login line that reaches it, or why
/// it cannot run here.
fn start_sshd(dir: &Path) -> Result<(Sshd, String), String> {
    let sshd = ["/usr/sbin/sshd", "/usr/local/sbin/sshd"]
        .into_iter()
        .find(|p| Path::new(p).exists())
        .ok_or("no sshd (apt-get install openssh-server)")?;
    for key in ["host_key", "client_key"] {
        let made = Command::new("ssh-keygen")
            .args(["-q", "-t", "ed25519", "-N", "", "-f"])
            .arg(dir.join(key))
            .status()
            .map_err(|e| format!("no ssh-keygen ({e})"))?;
        assert!(made.success());
    }
    std::fs::copy(dir.join("client_key.pub"), dir.join("authorized_keys")).unwrap();
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map_err(|e| e.to_string())?
        .port();
    let config = format!(
        "Port {port}\nListenAddress 127.0.0.1\nHostKey {host}\nAuthorizedKeysFile {keys}\n\
         StrictModes no\nUsePAM no\nPasswordAuthentication no\nKbdInteractiveAuthentication no\n\
         PermitRootLogin prohibit-password\nPidFile {pid}\n",
        host = dir.join("host_key").display(),
        keys = dir.join("authorized_keys").display(),
        pid = dir.join("sshd.pid").display(),
    );
    std::fs::write(dir.join("sshd_config"), config).unwrap();
    // Run as root, sshd wants its privilege separation folder.
    let _ = std::fs::create_dir_all("/run/sshd");
    let child = Command::new(sshd)
        .arg("-D")
        .arg("-f")
        .arg(dir.join("sshd_config"))
        .arg("-E")
        .arg(dir.join("sshd.log"))
        .spawn()
        .map_err(|e| format!("sshd does not start ({e})"))?;
    let server = Sshd(child);
    let login = format!(
        "ssh -p {port} -i {} -o StrictHostKeyChecking=no -o UserKnownHostsFile=/dev/null -o LogLevel=ERROR -o BatchMode=yes 127.0.0.1",
        dir.join("client_key").display()
    );
    let start = std::time::Instant::now();
    loop {
        let probe = Command::new("sh")
            .arg("-c")
            .arg(format!("{login} true"))
            .output();
        if probe.is_ok_and(|o| o.status.success()) {
            return Ok((server, login));
        }
        if start.elapsed() > std::time::Duration::from_secs(10) {
            let log = std::fs::read_to_string(dir.join("sshd.log")).unwrap_or_default();
            return Err(format!("cannot log in to the test's sshd: {}", log.trim()));
        }
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
}

#[test]
fn farm_runs_on_gnu_parallel_over_ssh_to_this_machine() {
    if !real_part(program_missing("parallel", "parallel")) {
        return;
    }
    let keys = tempfile::tempdir().unwrap();
    let (_server, login) = match start_sshd(keys.path()) {
        Ok(started) => started,
        Err(why) => {
            assert!(!real_part(Some(why)));
            return;
        }
    };
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    run(&render_args(&["-o", "whole.exr"]), d);
    // Two jobs at a time on the one machine, reached over ssh.
    std::fs::write(d.join("machines.txt"), format!("2/{login}\n")).unwrap();
    write_farm("parallel", d, &["--sshloginfile", "machines.txt", "--run"]);
    assert!(bytes(d, "out/farmed.exr") == bytes(d, "whole.exr"));
    let log = std::fs::read_to_string(d.join("farm/parallel.joblog")).unwrap();
    let over_ssh = log.lines().skip(1).filter(|l| l.contains("ssh -p")).count();
    assert_eq!(over_ssh, 5, "every tile over ssh: {log}");
}
