//! `glint view`'s API as a script uses it: explain and render answers equal
//! to the command line's bytes, every kind of bad request refused with a
//! 4xx while the server keeps serving, 1000 mixed requests without a failed
//! good one or memory growth, and Ctrl-C stopping it cleanly.

mod common;

use common::{glint, scene, stderr};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A running `glint view`, stopped when dropped.
struct Viewer {
    child: Child,
    url: String,
    port: u16,
    token: String,
}

impl Viewer {
    fn start(args: &[&str]) -> Viewer {
        let mut child = Command::new(env!("CARGO_BIN_EXE_glint"))
            .arg("view")
            .args(args)
            .arg("--no-open")
            .current_dir(common::repo())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("glint view starts");
        let mut first = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut first)
            .unwrap();
        let url = first
            .trim()
            .strip_prefix("http://127.0.0.1:")
            .expect(&first);
        let (port, token) = url.split_once("/?token=").expect(url);
        let token = token.split('#').next().unwrap();
        Viewer {
            port: port.parse().unwrap(),
            token: token.to_owned(),
            url: first.trim().to_owned(),
            child,
        }
    }

    /// `GET path` with the token added: status, headers and body.
    fn get(&self, path: &str) -> Answer {
        let join = if path.contains('?') { '&' } else { '?' };
        self.raw(&format!(
            "GET {path}{join}token={} HTTP/1.1\r\n\r\n",
            self.token
        ))
    }

    /// A request as written (its first line, headers and any body), with the
    /// Host and Connection headers added.
    fn raw(&self, request: &str) -> Answer {
        let mut stream = TcpStream::connect(("127.0.0.1", self.port)).unwrap();
        stream
            .set_read_timeout(Some(Duration::from_secs(120)))
            .unwrap();
        let (head, body) = request.split_once("\r\n").unwrap();
        let headers = "Host: 127.0.0.1\r\nConnection: close\r\n";
        let _ = stream.write_all(format!("{head}\r\n{headers}{body}").as_bytes());
        answer(stream)
    }

    /// Waits for the render with `query` to reach its last step; its body.
    fn finished_render(&self, query: &str) -> Vec<u8> {
        let deadline = Instant::now() + Duration::from_secs(120);
        loop {
            let a = self.get(&format!("/api/render?{query}"));
            assert!(a.status == 200 || a.status == 202, "{}", a.text());
            let spp = a.header("x-spp");
            if a.status == 200 && spp == a.header("x-target-spp") {
                return a.body;
            }
            assert!(Instant::now() < deadline, "the render did not finish");
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    fn memory_kib(&self) -> u64 {
        let status = std::fs::read_to_string(format!("/proc/{}/status", self.child.id())).unwrap();
        let line = status.lines().find(|l| l.starts_with("VmRSS:")).unwrap();
        line.split_whitespace().nth(1).unwrap().parse().unwrap()
    }
}

impl Drop for Viewer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

struct Answer {
    status: u16,
    headers: String,
    body: Vec<u8>,
}

impl Answer {
    fn text(&self) -> String {
        String::from_utf8_lossy(&self.body).into_owned()
    }

    fn header(&self, name: &str) -> String {
        let prefix = format!("{name}:");
        (self.headers.lines())
            .find_map(|l| {
                l.to_ascii_lowercase()
                    .strip_prefix(&prefix)
                    .map(|v| v.trim().to_owned())
            })
            .unwrap_or_default()
    }
}

fn answer(mut stream: TcpStream) -> Answer {
    let mut all = Vec::new();
    let _ = stream.read_to_end(&mut all);
    let split = all
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .expect("an HTTP answer");
    let headers = String::from_utf8_lossy(&all[..split]).into_owned();
    let status = headers.split_whitespace().nth(1).unwrap().parse().unwrap();
    Answer {
        status,
        headers,
        body: all[split + 4..].to_vec(),
    }
}

#[test]
fn explain_answers_the_command_lines_bytes() {
    for (name, pixels, flags) in [
        (
            "cornell-set1",
            ["256,400", "100,30", "511,0"],
            "&spp=4&light-samples=2",
        ),
        (
            "textured-spheres",
            ["200,200", "50,300", "10,10"],
            "&spp=2&sample=1&texture-filter=ewa",
        ),
        (
            "environment",
            ["128,128", "30,200", "250,20"],
            "&spp=2&all-samples",
        ),
    ] {
        let path = scene(name);
        let viewer = Viewer::start(&[&path]);
        for pixel in pixels {
            let a = viewer.get(&format!("/api/explain?pixel={pixel}{flags}"));
            assert_eq!(a.status, 200, "{name} {pixel}: {}", a.text());
            let mut args = vec!["explain", &path, "--pixel", pixel, "--json"];
            let cli_flags: Vec<String> = (flags.split('&').filter(|f| !f.is_empty()))
                .flat_map(|f| match f.split_once('=') {
                    Some((k, v)) => vec![format!("--{k}"), v.to_owned()],
                    None => vec![format!("--{f}")],
                })
                .collect();
            args.extend(cli_flags.iter().map(String::as_str));
            let o = glint(&args, &common::repo());
            assert!(o.status.success(), "{}", stderr(&o));
            assert_eq!(
                a.text(),
                String::from_utf8_lossy(&o.stdout),
                "{name} {pixel}"
            );
        }
    }
}

#[test]
fn a_finished_render_is_glint_renders_image() {
    let path = scene("cornell-set1");
    let viewer = Viewer::start(&[&path]);
    let dir = tempfile::tempdir().unwrap();
    for (query, flags) in [
        (
            "spp=8&resolution=64x48",
            vec!["--spp", "8", "--resolution", "64x48"],
        ),
        (
            "spp=4&sampler=random&resolution=40x40&aov=normal",
            vec![
                "--spp",
                "4",
                "--sampler",
                "random",
                "--resolution",
                "40x40",
                "--aov",
                "normal",
            ],
        ),
    ] {
        let png = viewer.finished_render(&format!("{query}&as=png"));
        let out = dir.path().join("cli.png");
        let mut args = vec!["render", &path, "-o", out.to_str().unwrap()];
        args.extend(flags);
        let o = glint(&args, &common::repo());
        assert!(o.status.success(), "{}", stderr(&o));
        assert_eq!(png, std::fs::read(&out).unwrap(), "{query}");
    }
}

#[test]
fn bad_requests_are_refused_and_the_server_keeps_serving() {
    let dir = tempfile::tempdir().unwrap();
    let image = small_image(dir.path());
    let path = scene("cornell-set1");
    let viewer = Viewer::start(&[&path, image.to_str().unwrap()]);
    let good = "/api/explain?pixel=10,10&spp=1&light-samples=1";
    for (request, status, says) in [
        ("/api/explain?pixel=-1,5", 400, "not a whole number"),
        ("/api/explain?pixel=1e9,5", 400, "not a whole number"),
        (
            "/api/explain?pixel=99999,5",
            400,
            "outside the 512x512 image",
        ),
        ("/api/explain?pixel=abc", 400, "expected X,Y"),
        ("/api/explain?spp=4", 400, "pixel=X,Y"),
        (
            "/api/explain?pixel=1,1&spp=--against=/etc/passwd",
            400,
            "--spp",
        ),
        (
            "/api/explain?pixel=1,1&against=/etc/passwd",
            400,
            "--against is not given",
        ),
        (
            "/api/explain?pixel=1,1&Bad%20Name=1",
            400,
            "not a flag's name",
        ),
        ("/api/explain?pixel=1,1&pixel=2,2", 400, "given twice"),
        ("/api/against?pixel=1,1", 400, "not given --against"),
        ("/api/image?id=../../etc/passwd", 404, "no image"),
        ("/api/image?id=7", 404, "no image"),
        ("/api/image?id=0&as=gif", 400, "expected f32, png or exr"),
        ("/../../etc/passwd", 404, "no page"),
        ("/api/heatmap?a=0&b=render", 400, "no render yet"),
        ("/api/grade?id=0&spp=0", 400, "spp"),
        ("/api/render?spp=abc", 400, "--spp"),
        ("/api/render?aov=glow", 400, "unknown buffer"),
    ] {
        let a = viewer.get(request);
        assert_eq!(a.status, status, "{request}: {}", a.text());
        assert!(a.text().contains(says), "{request}: {}", a.text());
        assert_eq!(viewer.get(good).status, 200, "after {request}");
    }
    // No token, a wrong one, another method, a body, too long a URL.
    let no_token = viewer.raw("GET /api/session HTTP/1.1\r\n\r\n");
    assert_eq!(no_token.status, 403, "{}", no_token.text());
    let wrong = viewer.raw("GET /api/session?token=0123 HTTP/1.1\r\n\r\n");
    assert_eq!(wrong.status, 403);
    let post = viewer.raw(&format!(
        "POST /api/session?token={} HTTP/1.1\r\nContent-Length: 2\r\n\r\n{{}}",
        viewer.token
    ));
    assert_eq!(post.status, 405, "{}", post.text());
    let long = "x".repeat(10_000);
    assert_eq!(viewer.get(&format!("/api/session?q={long}")).status, 414);
    let huge = big_body(&viewer);
    assert_eq!(huge, 413);
    assert_eq!(viewer.get(good).status, 200, "after the bad requests");
}

/// A GET announcing a 100 MB body, of which a megabyte is sent: its status.
fn big_body(viewer: &Viewer) -> u16 {
    let mut stream = TcpStream::connect(("127.0.0.1", viewer.port)).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(30)))
        .unwrap();
    let head = format!(
        "GET /api/session?token={} HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 100000000\r\nConnection: close\r\n\r\n",
        viewer.token
    );
    stream.write_all(head.as_bytes()).unwrap();
    let _ = stream.write_all(&vec![b'x'; 1 << 20]);
    let _ = stream.shutdown(std::net::Shutdown::Write);
    answer(stream).status
}

fn small_image(dir: &Path) -> std::path::PathBuf {
    let out = dir.join("student.png");
    let o = glint(
        &[
            "render",
            &scene("cornell-set1"),
            "--resolution",
            "32x32",
            "--spp",
            "1",
            "-o",
            out.to_str().unwrap(),
        ],
        dir,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    out
}

#[test]
fn a_thousand_mixed_requests_fail_no_good_one_and_grow_no_memory() {
    let dir = tempfile::tempdir().unwrap();
    let image = small_image(dir.path());
    let path = scene("cornell-set1");
    let viewer = Viewer::start(&[&path, image.to_str().unwrap()]);
    let good = [
        "/api/session",
        "/api/image?id=0",
        "/api/explain?pixel=5,7&spp=1&light-samples=1",
        "/api/image?id=0&as=png",
    ];
    let bad = [
        "/api/explain?pixel=-3,2",
        "/api/image?id=9",
        "/nowhere",
        "/api/explain?pixel=1,1&spp=x",
    ];
    for request in good {
        assert_eq!(viewer.get(request).status, 200);
    }
    let before = viewer.memory_kib();
    for i in 0..1000 {
        let request = match i % 2 {
            0 => good[i / 2 % good.len()],
            _ => bad[i / 2 % bad.len()],
        };
        let a = viewer.get(request);
        match i % 2 {
            0 => assert_eq!(a.status, 200, "{request}: {}", a.text()),
            _ => assert!((400..500).contains(&a.status), "{request}: {}", a.status),
        }
    }
    let grown = viewer.memory_kib().saturating_sub(before);
    assert!(grown < 50 * 1024, "memory grew by {grown} KiB");
}

#[test]
fn ctrl_c_stops_the_server_cleanly() {
    let viewer = Viewer::start(&[&scene("cornell-set1")]);
    assert_eq!(viewer.get("/api/session").status, 200);
    let mut viewer = viewer;
    send_sigint(viewer.child.id());
    let status = viewer.child.wait().unwrap();
    assert_eq!(status.code(), Some(0));
    let mut err = String::new();
    viewer
        .child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    assert!(err.contains("glint view: stopped"), "{err}");
}

fn send_sigint(pid: u32) {
    let o = Command::new("kill")
        .args(["-INT", &pid.to_string()])
        .output()
        .unwrap();
    assert!(o.status.success());
}

#[test]
fn a_failed_submission_in_the_report_says_how_to_view_its_rejected_block() {
    let dir = tempfile::tempdir().unwrap();
    let manifest = common::small_class(dir.path());
    let mut args = vec!["grade", "--class", manifest.to_str().unwrap()];
    args.extend(["--report", "report", "--scenes", "scenes"]);
    args.extend_from_slice(&common::CORRECT[..8]);
    let o = glint(&args, dir.path());
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let html = std::fs::read_to_string(dir.path().join("report/index.html")).unwrap();
    // Bo's Set 2 is a render of Set 1: failed, with its command.
    let start = html
        .find("glint view ")
        .expect("a view command in the report");
    let command = &html[start..start + html[start..].find("</code>").unwrap()];
    assert!(
        command.contains("set2.toml") && command.contains("class/bo/set2.png"),
        "{command}"
    );
    // Every rejected region (blocks and objects) has its command, framing
    // pixels of the 32 × 32 submission.
    let commands: Vec<&str> = (html.split("<code>").skip(1))
        .map(|c| &c[..c.find("</code>").unwrap()])
        .filter(|c| c.starts_with("glint view "))
        .collect();
    assert!(commands.len() > 1, "{commands:?}");
    for command in &commands {
        let region = command.split("--region ").nth(1).expect(command);
        let [x0, y0, x1, y1] =
            [0, 1, 2, 3].map(|i| region.split(',').nth(i).unwrap().parse::<u32>().unwrap());
        assert!(x0 < x1 && x1 <= 32 && y0 < y1 && y1 <= 32, "{command}");
    }
    let region = command.split("--region ").nth(1).expect(command);
    // The command opens the view framing that block.
    let image = dir.path().join("class/bo/set2.png");
    let viewer = Viewer::start(&[
        &scene("cornell-set2"),
        image.to_str().unwrap(),
        "--region",
        region,
    ]);
    assert_eq!(viewer.get("/api/session").status, 200);
    assert!(
        viewer.url.ends_with(&format!("#region={region}")),
        "{}",
        viewer.url
    );
    let refused = glint(
        &[
            "view",
            &scene("cornell-set2"),
            "--region",
            "0,0,4,4",
            "--no-open",
        ],
        dir.path(),
    );
    common::assert_input_error(&refused, "--region frames the first image");
}
