//! The HTML report of `glint grade --report` in a real browser: headless
//! Chromium, driven through ChromeDriver's WebDriver protocol, opens the page
//! from disk with the network off, clicks a column's heading, and the rows
//! are sorted by it; the screenshot shows the failing student's red cell in
//! the first row.
//!
//! Needs Debian's `chromium` and `chromium-driver` packages
//! (`apt-get install chromium chromium-driver`); without them the test says so
//! and passes without checking anything.

mod common;

use common::{glint, scene, stderr};
use serde_json::{json, Value};
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const CHROMIUM: &str = "/usr/bin/chromium";
const CHROMEDRIVER: &str = "/usr/bin/chromedriver";

#[test]
fn the_report_sorts_by_a_clicked_column_in_headless_chromium() {
    let missing =
        (!Path::new(CHROMIUM).is_file() || !Path::new(CHROMEDRIVER).is_file()).then(|| {
            format!("no {CHROMIUM} or {CHROMEDRIVER} (apt-get install chromium chromium-driver)")
        });
    if !common::real_part(missing) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let report = class_report(dir.path());
    let driver = Driver::start(dir.path());
    let session = driver.session(dir.path());
    let page = format!("file://{}", report.join("index.html").display());
    session.call("POST", "url", json!({ "url": page }));

    let students = || -> Vec<String> {
        let rows = session.script("return Array.from(document.querySelectorAll('#grades tbody tr')).map(r => r.cells[0].textContent)");
        rows.as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap().to_owned())
            .collect()
    };
    // In name order as written; "passed" ascending puts the failure first.
    assert_eq!(students(), ["ada", "bo", "cy"]);
    let heading = session.element("th[data-column=\"1\"]");
    session.call("POST", &format!("element/{heading}/click"), json!({}));
    assert_eq!(students(), ["bo", "ada", "cy"]);
    let sorted = session
        .script("return document.querySelector('th[data-column=\"1\"]').getAttribute('aria-sort')");
    assert_eq!(sorted, "ascending");
    session.call("POST", &format!("element/{heading}/click"), json!({}));
    assert_eq!(students()[2], "bo", "a second click sorts descending");
    session.call("POST", &format!("element/{heading}/click"), json!({}));

    // The screenshot: the first row's verdict cell is the fail colour.
    let shot = session.call("GET", "screenshot", Value::Null);
    let png = base64_decode(shot.as_str().unwrap());
    let image = image::load_from_memory(&png).unwrap().to_rgb8();
    let cell = session.script(
        "const r = document.querySelector('#grades tbody tr').cells[2].getBoundingClientRect(); return [r.left + 4, r.top + 4, window.devicePixelRatio]",
    );
    let [x, y, ratio] = [0, 1, 2].map(|i| cell[i].as_f64().unwrap());
    let pixel = image.get_pixel((x * ratio) as u32, (y * ratio) as u32).0;
    assert_eq!(pixel, [0xfd, 0xe8, 0xe6], "the failing cell's background");
    let _ = session.call("DELETE", "", Value::Null);
}

/// A class of three (one failing) graded into a report; its folder.
fn class_report(dir: &Path) -> PathBuf {
    let set1 = scene("cornell-set1");
    let text = std::fs::read_to_string(&set1).unwrap();
    let dark = dir.join("dark.toml");
    std::fs::write(
        &dark,
        text.replace("ambient = [0.1, 0.1, 0.1]", "ambient = [0, 0, 0]"),
    )
    .unwrap();
    let scenes = dir.join("scenes");
    std::fs::create_dir(&scenes).unwrap();
    std::fs::copy(&set1, scenes.join("set1.toml")).unwrap();
    for (student, scene_file) in [
        ("ada", set1.as_str()),
        ("bo", dark.to_str().unwrap()),
        ("cy", set1.as_str()),
    ] {
        let out = dir.join("class").join(student);
        std::fs::create_dir_all(&out).unwrap();
        let out = out.join("set1.png");
        let args = [
            "render",
            scene_file,
            "--resolution",
            "32x32",
            "--spp",
            "4",
            "--light-samples",
            "4",
            "-o",
            out.to_str().unwrap(),
        ];
        let o = glint(&args, dir);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let report = dir.join("report");
    let o = glint(
        &[
            "grade", "--class", "class", "--scenes", "scenes", "--cache", "cache", "--report",
            "report",
        ],
        dir,
    );
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    report
}

/// A ChromeDriver process on a free local port, stopped when dropped.
struct Driver {
    child: Child,
    port: u16,
}

impl Driver {
    fn start(dir: &Path) -> Driver {
        let port = TcpListener::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap()
            .port();
        let child = Command::new(CHROMEDRIVER)
            .arg(format!("--port={port}"))
            .current_dir(dir)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("chromedriver starts");
        let driver = Driver { child, port };
        let deadline = Instant::now() + Duration::from_secs(20);
        while request(port, "GET", "/status", None).is_err() {
            assert!(Instant::now() < deadline, "chromedriver did not answer");
            std::thread::sleep(Duration::from_millis(100));
        }
        driver
    }

    /// A headless Chromium session, cut off from the network, with a fresh
    /// profile.
    fn session(&self, dir: &Path) -> Session<'_> {
        let profile = dir.join("chromium-profile");
        let args = [
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--window-size=1200,900",
            "--force-device-scale-factor=1",
            "--proxy-server=127.0.0.1:9",
        ];
        let mut args: Vec<String> = args.iter().map(|a| a.to_string()).collect();
        args.push(format!("--user-data-dir={}", profile.display()));
        let capabilities = json!({"capabilities": {"alwaysMatch": {
            "browserName": "chrome",
            "goog:chromeOptions": {"binary": CHROMIUM, "args": args}
        }}});
        let answer = request(self.port, "POST", "/session", Some(capabilities)).unwrap();
        let id = answer["value"]["sessionId"]
            .as_str()
            .expect("a session")
            .to_owned();
        Session { driver: self, id }
    }
}

impl Drop for Driver {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

struct Session<'a> {
    driver: &'a Driver,
    id: String,
}

impl Session<'_> {
    /// A WebDriver command of this session; its `value`.
    fn call(&self, method: &str, command: &str, body: Value) -> Value {
        let path = match command {
            "" => format!("/session/{}", self.id),
            c => format!("/session/{}/{c}", self.id),
        };
        let body = (!body.is_null()).then_some(body);
        let answer = request(self.driver.port, method, &path, body).unwrap();
        assert!(
            answer["value"].get("error").is_none(),
            "{command}: {answer}"
        );
        answer["value"].clone()
    }

    fn script(&self, script: &str) -> Value {
        self.call(
            "POST",
            "execute/sync",
            json!({"script": script, "args": []}),
        )
    }

    /// The WebDriver id of the element `selector` finds.
    fn element(&self, selector: &str) -> String {
        let found = self.call(
            "POST",
            "element",
            json!({"using": "css selector", "value": selector}),
        );
        found
            .as_object()
            .and_then(|o| o.values().next())
            .and_then(Value::as_str)
            .expect("an element")
            .to_owned()
    }
}

/// One HTTP/1.1 request to localhost, its JSON answer.
fn request(port: u16, method: &str, path: &str, body: Option<Value>) -> std::io::Result<Value> {
    let mut stream = TcpStream::connect(("127.0.0.1", port))?;
    stream.set_read_timeout(Some(Duration::from_secs(60)))?;
    let body = body.map(|b| b.to_string()).unwrap_or_default();
    write!(
        stream,
        "{method} {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
        body.len()
    )?;
    // ChromeDriver keeps the connection open: read the headers, then as many
    // bytes as Content-Length says.
    let mut answer = Vec::new();
    let mut byte = [0u8; 1];
    while !answer.ends_with(b"\r\n\r\n") {
        if stream.read(&mut byte)? == 0 {
            return Err(std::io::Error::other("the connection closed"));
        }
        answer.push(byte[0]);
    }
    let headers = String::from_utf8_lossy(&answer).to_ascii_lowercase();
    let length: usize = headers
        .lines()
        .find_map(|l| l.strip_prefix("content-length:"))
        .and_then(|v| v.trim().parse().ok())
        .ok_or_else(|| std::io::Error::other(format!("no length in {headers}")))?;
    let mut body = vec![0u8; length];
    stream.read_exact(&mut body)?;
    serde_json::from_slice(&body).map_err(|e| std::io::Error::other(e.to_string()))
}

fn base64_decode(text: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    };
    let digits: Vec<u8> = text.bytes().filter(|&c| c != b'=').map(value).collect();
    let mut out = Vec::with_capacity(digits.len() * 3 / 4);
    for chunk in digits.chunks(4) {
        let n = chunk
            .iter()
            .enumerate()
            .fold(0u32, |n, (i, &d)| n | (d as u32) << (18 - 6 * i));
        out.extend(&n.to_be_bytes()[1..chunk.len()]);
    }
    out
}
