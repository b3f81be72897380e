//! A class's results as a table for the terminal, CSV and JSON; the HTML
//! report is [`html`](crate::html). Each submission's row is first put in
//! the words and numbers every format shows ([`ReportRow`]); the formats are
//! made from those alone, so a class graded in parts ([`crate::parts`]) gives
//! the report a single run gives.

use crate::class::{ClassGrades, Outcome, Row};
use crate::{ChannelFinding, ImageGrade, RegionFinding};
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

/// The schema name of the JSON document.
pub const SCHEMA: &str = "glint-grade/2";

/// A submission's verdict in one word: "pass", "fail", "unreadable" (for
/// grading: its format lost what the test needs) or "error" (not read).
pub fn verdict(row: &Row) -> &'static str {
    match &row.outcome {
        Outcome::Graded(g) if g.unreadable.is_some() => "unreadable",
        Outcome::Graded(g) if g.passed => "pass",
        Outcome::Graded(_) => "fail",
        Outcome::Unreadable { .. } => "error",
    }
}

/// A rejected region in a phrase: "left wall: R, G, B too dark by 0.0700
/// (z −25.3)", each channel's direction and size when they differ.
pub fn finding_phrase(f: &RegionFinding) -> String {
    let how = |c: &ChannelFinding| {
        format!(
            "too {} by {}",
            if c.difference > 0.0 { "bright" } else { "dark" },
            significant(c.difference.abs())
        )
    };
    let first = f.strongest();
    // One phrase for all channels when they differ alike (within 10%).
    let same = f
        .channels
        .iter()
        .all(|c| (c.difference - first.difference).abs() <= 0.1 * first.difference.abs());
    let body = if same {
        let names: Vec<&str> = crate::CHANNELS
            .into_iter()
            .filter(|name| f.channels.iter().any(|c| c.channel == *name))
            .collect();
        format!("{} {}", names.join(", "), how(first))
    } else {
        let parts: Vec<String> = f
            .channels
            .iter()
            .map(|c| format!("{} {}", c.channel, how(c)))
            .collect();
        parts.join(", ")
    };
    format!("{}: {body} (z {})", f.region, z_text(first.z))
}

/// What the table and CSV say of a row beyond its verdict.
pub fn summary(row: &Row) -> String {
    match &row.outcome {
        Outcome::Graded(g) if g.unreadable.is_some() => format!(
            "unreadable for grading: {}",
            g.unreadable.as_deref().unwrap_or_default()
        ),
        Outcome::Graded(g) if g.passed => format!(
            "largest |z| {} of {} tests",
            z_text(g.largest_accepted_z),
            g.tests
        ),
        Outcome::Graded(g) => {
            let more = match g.rejected.len() {
                1 => String::new(),
                n => format!("; {} more", n - 1),
            };
            let why = mistakes_phrase(g).map_or(String::new(), |m| format!("; {m}"));
            format!("{}{more}{why}", finding_phrase(&g.rejected[0]))
        }
        Outcome::Unreadable { message } => message.clone(),
    }
}

/// What a failing grade's mistakes say: "consistent with: every light sample
/// at the light's centre: hard shadows (light-centre)" (up to three), or "no
/// known mistake fits"; `None` where none was tested.
pub fn mistakes_phrase(grade: &ImageGrade) -> Option<String> {
    if grade.passed || grade.likely_mistakes.is_empty() {
        return None;
    }
    let fits: Vec<String> = (grade.likely_mistakes.iter())
        .filter(|m| m.consistent)
        .take(3)
        .map(|m| format!("{} ({})", m.description, m.id))
        .collect();
    Some(match fits.is_empty() {
        true => "no known mistake fits".into(),
        false => format!("consistent with: {}", fits.join("; ")),
    })
}

/// The catalogue of mistakes as `glint grade --mistakes` lists it.
pub fn catalogue() -> String {
    let mut out = String::new();
    for m in crate::mistakes::CATALOGUE {
        out += &format!(
            "{:<22} {:<13} {:<13} {}\n",
            m.id,
            m.stage.name(),
            m.how.rendered_as(),
            m.description
        );
    }
    out
}

/// z with one decimal; a difference where there is no noise at all (a
/// deterministic region) is infinitely many standard errors.
fn z_text(z: f64) -> String {
    if z.is_infinite() {
        if z > 0.0 { "∞" } else { "−∞" }.into()
    } else {
        format!("{z:.1}").replace('-', "−")
    }
}

/// p with two significant digits; below what a double holds, a bound.
fn p_text(p: f64) -> String {
    if p < 1e-300 {
        "< 1e-300".into()
    } else {
        format!("{p:.1e}")
    }
}

/// Four significant digits.
fn significant(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let decimals = (3 - v.abs().log10().floor() as i32).clamp(0, 12) as usize;
    format!("{v:.decimals$}")
}

/// One submission as a class's report shows it, in every format.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReportRow {
    pub student: String,
    pub scene: String,
    pub file: String,
    /// What the file was read as, where it could be read.
    pub format: String,
    /// "pass", "fail", "unreadable" or "error" ([`verdict`]).
    pub verdict: String,
    /// What the table and CSV say beyond the verdict ([`summary`]).
    pub summary: String,
    /// The CSV's cells from `rejected` to `worst_channel`.
    pub numbers: [String; 5],
    /// The submission in `grades.json`.
    pub json: Value,
    /// The HTML cell's sort key: failures by their evidence, then the
    /// unreadable, then errors, then passes.
    pub sort_key: String,
    /// The reference set it is judged against, where its scene and
    /// resolution could be read: the report's `images/reference-G.png`.
    pub reference: Option<usize>,
    /// For a failed submission, each rejected region (at most
    /// [`VIEWS_KEPT`], the strongest first) and the `glint view` command that
    /// opens the submission framing it.
    #[serde(default)]
    pub views: Vec<View>,
    /// The id of the mistake that fits a failed submission best, if one
    /// fits: the report shows Glint's render of it (`images/I-mistake.png`).
    #[serde(default)]
    pub best_fit: Option<String>,
}

/// The rows of a class's grades as the report shows them.
pub fn rows(grades: &ClassGrades) -> Vec<ReportRow> {
    let views = |row: &Row| match grades.groups.get(row.group.unwrap_or(usize::MAX)) {
        Some(group) => views(row, group),
        None => Vec::new(),
    };
    (grades.rows.iter())
        .map(|row| ReportRow {
            views: views(row),
            ..ReportRow::new(row)
        })
        .collect()
}

/// The most rejected regions a report row offers to open in `glint view`.
pub const VIEWS_KEPT: usize = 8;

/// A rejected region and the command that opens its submission in `glint
/// view` framing it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct View {
    pub region: String,
    pub command: String,
}

/// `glint view SCENE FILE --region X0,Y0,X1,Y1` for each rejected region of
/// a failed submission: a block as it is, an object by the box around the
/// pixels whose centres see it.
fn views(row: &Row, group: &crate::class::Group) -> Vec<View> {
    let Outcome::Graded(grade) = &row.outcome else {
        return Vec::new();
    };
    if grade.passed || grade.unreadable.is_some() {
        return Vec::new();
    }
    let references = &group.references;
    let quoted = |text: &str| match text.contains([' ', '\'', '"']) {
        true => format!("'{}'", text.replace('\'', "'\\''")),
        false => text.to_owned(),
    };
    let scene = quoted(&group.scene.path.display().to_string());
    let file = quoted(&row.file);
    (grade.rejected.iter().take(VIEWS_KEPT))
        .filter_map(|r| {
            let [x0, y0, x1, y1] = match r.place {
                crate::Place::Block { x0, y0, x1, y1 } => [x0, y0, x1, y1],
                crate::Place::Object { object } => {
                    let object = object.unwrap_or(crate::reference::BACKGROUND);
                    bounds(&references.objects, references.resolution.x, object)?
                }
            };
            Some(View {
                region: r.region.clone(),
                command: format!("glint view {scene} {file} --region {x0},{y0},{x1},{y1}"),
            })
        })
        .collect()
}

/// The half-open box around the pixels of `objects` (one per pixel, rows of
/// `width`) that hold `object`.
fn bounds(objects: &[u32], width: u32, object: u32) -> Option<[u32; 4]> {
    let mut found = None::<[u32; 4]>;
    for (i, _) in objects.iter().enumerate().filter(|(_, &o)| o == object) {
        let (x, y) = (i as u32 % width, i as u32 / width);
        found = Some(match found {
            None => [x, y, x + 1, y + 1],
            Some([x0, y0, x1, y1]) => [x0.min(x), y0.min(y), x1.max(x + 1), y1.max(y + 1)],
        });
    }
    found
}

impl ReportRow {
    pub fn new(row: &Row) -> ReportRow {
        let mut json = serde_json::to_value(row).expect("plain data");
        json["verdict"] = json!(verdict(row));
        ReportRow {
            student: row.student.clone(),
            scene: row.scene.clone(),
            file: row.file.clone(),
            format: match &row.outcome {
                Outcome::Graded(g) => g.format.clone(),
                Outcome::Unreadable { .. } => String::new(),
            },
            verdict: verdict(row).to_owned(),
            summary: summary(row),
            numbers: csv_numbers(row),
            json,
            sort_key: sort_key(row).to_string(),
            reference: row.group,
            views: Vec::new(),
            best_fit: match &row.outcome {
                Outcome::Graded(g) => (g.likely_mistakes.first())
                    .filter(|m| m.consistent)
                    .map(|m| m.id.clone()),
                Outcome::Unreadable { .. } => None,
            },
        }
    }

    pub fn passed(&self) -> bool {
        self.verdict == "pass"
    }

    /// Whether it was graded, and has images in the report.
    pub fn graded(&self) -> bool {
        self.verdict != "error"
    }
}

/// Orders failures by their evidence, then the unreadable, then errors, then
/// passes.
fn sort_key(row: &Row) -> f64 {
    match &row.outcome {
        Outcome::Graded(g) if g.unreadable.is_some() => 4e8,
        Outcome::Graded(g) if g.passed => 1e9 - g.largest_accepted_z,
        Outcome::Graded(g) => g
            .rejected
            .first()
            .map_or(0.0, |f| -f.strongest().z.abs().min(1e8)),
        Outcome::Unreadable { .. } => 5e8,
    }
}

/// How many rows have the verdict `v`.
fn count(rows: &[ReportRow], v: &str) -> usize {
    rows.iter().filter(|r| r.verdict == v).count()
}

/// The class as aligned columns: student, scene, verdict, summary; then the
/// counts.
pub fn table(report: &[ReportRow]) -> String {
    let header = ["student", "scene", "verdict", "where, how much"];
    let rows: Vec<[String; 4]> = report
        .iter()
        .map(|r| {
            [
                r.student.clone(),
                r.scene.clone(),
                r.verdict.clone(),
                r.summary.clone(),
            ]
        })
        .collect();
    let width = |k: usize| {
        rows.iter()
            .map(|r| r[k].chars().count())
            .chain([header[k].len()])
            .max()
            .unwrap_or(0)
    };
    let widths = [width(0), width(1), width(2)];
    let line = |cells: [&str; 4]| {
        let mut text = String::new();
        for (k, cell) in cells.iter().enumerate() {
            match widths.get(k) {
                Some(&w) => text += &format!("{cell:<w$}  "),
                None => text += cell,
            }
        }
        text.trim_end().to_owned() + "\n"
    };
    let mut out = line(header);
    for r in &rows {
        out += &line([&r[0], &r[1], &r[2], &r[3]]);
    }
    out += &format!("\n{}\n", counts(report, None));
    out
}

/// "3 submissions: 1 pass, 1 fail, 1 not graded", with the unreadable for
/// grading where there are any, and "from N students" where `students` says.
pub fn counts(report: &[ReportRow], students: Option<usize>) -> String {
    let from = students.map_or(String::new(), |n| format!(" from {n} students"));
    let unreadable = match count(report, "unreadable") {
        0 => String::new(),
        n => format!(", {n} unreadable for grading"),
    };
    format!(
        "{} submissions{from}: {} pass, {} fail{unreadable}, {} not graded",
        report.len(),
        count(report, "pass"),
        count(report, "fail"),
        count(report, "error")
    )
}

/// One submission in detail: what its file was read as, every rejected
/// region (up to `limit`) with its numbers.
pub fn details(grade: &ImageGrade, limit: usize) -> String {
    if let Some(reason) = &grade.unreadable {
        return format!(
            "{}: unreadable for grading ({}x{}, {}): {reason}\n",
            grade.file, grade.resolution[0], grade.resolution[1], grade.format,
        );
    }
    let mut out = format!(
        "{}: {} ({}x{}, {}, settings {}; {} tests at α = {})\n",
        grade.file,
        if grade.passed { "pass" } else { "FAIL" },
        grade.resolution[0],
        grade.resolution[1],
        grade.format,
        grade.settings,
        grade.tests,
        grade.alpha,
    );
    for note in &grade.notes {
        out += &format!("  note: {note}\n");
    }
    if grade.passed {
        out += &format!(
            "  no region differs beyond its noise; largest |z| {}; noise {} per pixel\n",
            z_text(grade.largest_accepted_z),
            significant(grade.noise)
        );
        return out;
    }
    if let Some(why) = mistakes_phrase(grade) {
        out += &format!("  {why}\n");
    }
    for f in grade.rejected.iter().take(limit) {
        out += &format!("  {} ({} pixels)\n", finding_phrase(f), f.pixels);
        for c in &f.channels {
            out += &format!(
                "    {} mean {}, expected {} to {}, z {}, p {}\n",
                c.channel,
                significant(c.observed),
                significant(c.expected[0]),
                significant(c.expected[1]),
                z_text(c.z),
                p_text(c.p),
            );
        }
    }
    if grade.rejected.len() > limit {
        out += &format!(
            "  … and {} more rejected regions\n",
            grade.rejected.len() - limit
        );
    }
    out
}

/// The CSV columns.
pub const CSV_COLUMNS: [&str; 11] = [
    "student",
    "scene",
    "file",
    "format",
    "verdict",
    "rejected",
    "tests",
    "largest_z",
    "worst_region",
    "worst_channel",
    "summary",
];

/// The CSV's cells from `rejected` to `worst_channel`: empty where the
/// submission was not graded.
fn csv_numbers(row: &Row) -> [String; 5] {
    match &row.outcome {
        Outcome::Graded(g) if g.unreadable.is_some() => Default::default(),
        Outcome::Graded(g) => {
            let worst = g.rejected.first();
            let largest = worst.map_or(g.largest_accepted_z, |f| f.strongest().z);
            [
                g.rejected.len().to_string(),
                g.tests.to_string(),
                format!("{largest:.2}"),
                worst.map_or(String::new(), |f| f.region.clone()),
                worst.map_or("", |f| f.strongest().channel).to_owned(),
            ]
        }
        Outcome::Unreadable { .. } => Default::default(),
    }
}

/// The class as CSV, one row per submission.
pub fn csv(report: &[ReportRow]) -> String {
    let mut writer = csv::Writer::from_writer(Vec::new());
    writer.write_record(CSV_COLUMNS).expect("in memory");
    for row in report {
        let [rejected, tests, largest, region, channel] = &row.numbers;
        writer
            .write_record([
                row.student.as_str(),
                &row.scene,
                &row.file,
                &row.format,
                &row.verdict,
                rejected,
                tests,
                largest,
                region,
                channel,
                &row.summary,
            ])
            .expect("in memory");
    }
    String::from_utf8(writer.into_inner().expect("in memory")).expect("UTF-8 cells")
}

/// The class as a JSON document (schema [`SCHEMA`]).
pub fn json(report: &[ReportRow]) -> Value {
    let rows: Vec<&Value> = report.iter().map(|r| &r.json).collect();
    json!({
        "schema": SCHEMA,
        "submissions": rows,
        "pass": count(report, "pass"),
        "fail": count(report, "fail"),
        "unreadable": count(report, "unreadable"),
        "error": count(report, "error"),
    })
}
