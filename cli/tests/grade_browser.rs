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

use common::browser::{base64_decode, browser_missing, Driver};
use common::{glint, scene, stderr};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

#[test]
fn the_report_sorts_by_a_clicked_column_in_headless_chromium() {
    if !common::real_part(browser_missing()) {
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
