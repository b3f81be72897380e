//! The report folder of a class: `index.html` (one row per student; per
//! scene a verdict, the submission, the reference and the heat map as
//! thumbnails; columns sortable by a click; no external scripts, styles or
//! fonts, so it works offline), `grades.csv`, `grades.json`, and `images/`.

use crate::class::{Group, Outcome, Row};
use crate::report::{self, ReportRow};
use crate::submission::Submission;
use crate::GradeError;
use glam::{UVec2, Vec3};
use glint_camera::linear_to_srgb8;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The longest side of a thumbnail, in pixels.
pub const THUMBNAIL: u32 = 160;

fn images_dir(dir: &Path) -> PathBuf {
    dir.join("images")
}

fn internal(path: &Path) -> impl Fn(String) -> GradeError + '_ {
    move |m| GradeError::Internal(format!("{}: {m}", path.display()))
}

/// Saves 8-bit RGB rows as a PNG, atomically.
pub fn save_png(path: &Path, size: UVec2, rgb: &[u8]) -> Result<(), GradeError> {
    let image = image::RgbImage::from_raw(size.x, size.y, rgb.to_vec()).expect("size matches");
    save_image(path, &image)
}

fn save_image(path: &Path, image: &image::RgbImage) -> Result<(), GradeError> {
    let fail = internal(path);
    glint_camera::write_atomically(
        path,
        |e: std::io::Error| fail(e.to_string()),
        |out| {
            image
                .write_to(out, image::ImageFormat::Png)
                .map_err(|e| fail(e.to_string()))
        },
    )
}

/// A PNG and its thumbnail, from linear RGB pixels (clamped, sRGB).
fn save_with_thumbnail(path: &Path, size: UVec2, rgb: Vec<u8>) -> Result<(), GradeError> {
    let image = image::RgbImage::from_raw(size.x, size.y, rgb).expect("size matches");
    save_image(path, &image)?;
    let scale = THUMBNAIL as f32 / size.x.max(size.y) as f32;
    let thumbnail = if scale < 1.0 {
        let (w, h) = (
            ((size.x as f32 * scale).round() as u32).max(1),
            ((size.y as f32 * scale).round() as u32).max(1),
        );
        image::imageops::thumbnail(&image, w, h)
    } else {
        image
    };
    save_image(&thumbnail_path(path), &thumbnail)
}

fn thumbnail_path(path: &Path) -> PathBuf {
    let stem = path
        .file_stem()
        .map_or(String::new(), |s| s.to_string_lossy().into_owned());
    path.with_file_name(format!("{stem}-small.png"))
}

fn srgb8(pixels: &[Vec3]) -> Vec<u8> {
    pixels
        .iter()
        .flat_map(|p| p.to_array())
        .map(linear_to_srgb8)
        .collect()
}

/// Writes the images of graded submission `index`: the submission and its
/// heat map (full size and thumbnails), and its group's reference once.
pub fn write_images(
    dir: &Path,
    index: usize,
    row: &Row,
    submission: &Submission,
    group: &Group,
) -> Result<(), GradeError> {
    let Outcome::Graded(grade) = &row.outcome else {
        return Ok(());
    };
    let images = images_dir(dir);
    std::fs::create_dir_all(&images).map_err(|e| internal(&images)(e.to_string()))?;
    let size = submission.resolution();
    let [submission_png, _, heatmap_png, _] = submission_images(index);
    save_with_thumbnail(
        &images.join(submission_png),
        size,
        srgb8(submission.film.pixels()),
    )?;
    let heat = crate::heatmap::heatmap(grade, &submission.film, &group.references.objects);
    save_with_thumbnail(&images.join(heatmap_png), size, heat)?;
    let [reference_png, _] = reference_images(row.group.unwrap_or(0));
    let reference = images.join(reference_png);
    if !reference.exists() {
        save_with_thumbnail(&reference, size, srgb8(&group.references.mean.mean))?;
    }
    Ok(())
}

/// Writes Glint's render of the mistake that best fits submission `index`
/// (linear pixels of `size`), full size and thumbnail.
pub fn write_fit_image(
    dir: &Path,
    index: usize,
    size: UVec2,
    pixels: &[Vec3],
) -> Result<(), GradeError> {
    let images = images_dir(dir);
    std::fs::create_dir_all(&images).map_err(|e| internal(&images)(e.to_string()))?;
    let [fit, _] = fit_images(index);
    save_with_thumbnail(&images.join(fit), size, srgb8(pixels))
}

/// The image of the best-fitting mistake of submission `index` in a
/// report's `images/`, and its thumbnail.
pub fn fit_images(index: usize) -> [String; 2] {
    ["mistake", "mistake-small"].map(|k| format!("{index}-{k}.png"))
}

/// The images of submission `index` in a report's `images/`: the
/// submission and its heat map, each with its thumbnail.
pub fn submission_images(index: usize) -> [String; 4] {
    ["submission", "submission-small", "heatmap", "heatmap-small"]
        .map(|k| format!("{index}-{k}.png"))
}

/// The images of reference set `group` in a report's `images/`: the
/// reference and its thumbnail.
pub fn reference_images(group: usize) -> [String; 2] {
    [
        format!("reference-{group}.png"),
        format!("reference-{group}-small.png"),
    ]
}

/// Writes `index.html`, `grades.csv` and `grades.json` into `dir`.
pub fn write_report(dir: &Path, rows: &[ReportRow]) -> Result<(), GradeError> {
    std::fs::create_dir_all(dir).map_err(|e| internal(dir)(e.to_string()))?;
    let json = serde_json::to_string_pretty(&report::json(rows)).expect("JSON") + "\n";
    for (name, text) in [
        ("grades.csv", report::csv(rows)),
        ("grades.json", json),
        ("index.html", page(rows)),
    ] {
        crate::output::write_text(&dir.join(name), &text)?;
    }
    Ok(())
}

/// HTML-escaped text.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The page: students as rows, scenes as columns.
fn page(rows: &[ReportRow]) -> String {
    let scenes: Vec<&str> = {
        let mut seen = Vec::new();
        for row in rows {
            if !seen.contains(&row.scene.as_str()) {
                seen.push(row.scene.as_str());
            }
        }
        seen
    };
    let mut students: BTreeMap<&str, Vec<(usize, &ReportRow)>> = BTreeMap::new();
    for (i, row) in rows.iter().enumerate() {
        students.entry(&row.student).or_default().push((i, row));
    }
    let mut body = String::new();
    for (student, rows) in &students {
        let passed = rows.iter().filter(|(_, r)| r.passed()).count();
        body += &format!(
            "<tr><td data-sort=\"{0}\">{0}</td><td data-sort=\"{1}\">{1}/{2}</td>",
            escape(student),
            passed,
            scenes.len()
        );
        for scene in &scenes {
            body += &match rows.iter().find(|(_, r)| r.scene == *scene) {
                Some((i, row)) => cell(*i, row),
                None => "<td data-sort=\"-1\" class=\"missing\">no submission</td>".into(),
            };
        }
        body += "</tr>\n";
    }
    let header: String = scenes
        .iter()
        .enumerate()
        .map(|(k, s)| format!("<th data-column=\"{}\">{}</th>", k + 2, escape(s)))
        .collect();
    format!(
        include_str!("report.html"),
        summary = crate::report::counts(rows, Some(students.len())),
        header = header,
        body = body,
    )
}

/// One submission's cell: verdict, thumbnails, and what failed, sorted by
/// [`ReportRow::sort_key`].
fn cell(index: usize, row: &ReportRow) -> String {
    let v = &row.verdict;
    let images = match row.reference.filter(|_| row.graded()) {
        Some(g) => format!(
            "<div class=\"thumbs\">{}{}{}{}</div>",
            thumb(&format!("images/{index}-submission"), "submission"),
            thumb(&format!("images/reference-{g}"), "reference"),
            thumb(&format!("images/{index}-heatmap"), "heat map"),
            match &row.best_fit {
                Some(id) => thumb(
                    &format!("images/{index}-mistake"),
                    &format!("Glint's render with the best-fitting mistake, {id}"),
                ),
                None => String::new(),
            },
        ),
        None => String::new(),
    };
    let view = match row.views.is_empty() {
        true => String::new(),
        false => {
            let items: String = (row.views.iter())
                .map(|v| {
                    format!(
                        "<li>{}: <code>{}</code></li>",
                        escape(&v.region),
                        escape(&v.command)
                    )
                })
                .collect();
            format!(
                "<details class=\"view\"><summary title=\"the commands that open this submission in glint view, framing each rejected region\">view</summary><ul>{items}</ul></details>"
            )
        }
    };
    format!(
        "<td data-sort=\"{}\" class=\"{v}\"><span class=\"verdict\">{v}</span>{images}<div class=\"note\">{}</div><div class=\"file\" title=\"{}\">{}</div>{view}</td>",
        row.sort_key,
        escape(&row.summary),
        escape(&row.format),
        escape(&row.file),
    )
}

fn thumb(stem: &str, label: &str) -> String {
    format!(
        "<a href=\"{stem}.png\" title=\"{label}\"><img src=\"{stem}-small.png\" alt=\"{label}\"></a>"
    )
}
