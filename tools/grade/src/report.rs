//! A class's results as a table for the terminal, CSV and JSON; the HTML
//! report is [`html`](crate::html).

use crate::class::{ClassGrades, Outcome, Row};
use crate::{ChannelFinding, ImageGrade, RegionFinding};
use serde_json::{json, Value};

/// The schema name of the JSON document.
pub const SCHEMA: &str = "glint-grade/1";

/// A submission's verdict in one word.
pub fn verdict(row: &Row) -> &'static str {
    match &row.outcome {
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
            format!("{}{more}", finding_phrase(&g.rejected[0]))
        }
        Outcome::Unreadable { message } => message.clone(),
    }
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

/// The class as aligned columns: student, scene, verdict, summary; then the
/// counts.
pub fn table(grades: &ClassGrades) -> String {
    let header = ["student", "scene", "verdict", "where, how much"];
    let rows: Vec<[String; 4]> = grades
        .rows
        .iter()
        .map(|r| {
            [
                r.student.clone(),
                r.scene.clone(),
                verdict(r).to_owned(),
                summary(r),
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
    let count = |v: &str| grades.rows.iter().filter(|r| verdict(r) == v).count();
    out += &format!(
        "\n{} submissions: {} pass, {} fail, {} not graded\n",
        grades.rows.len(),
        count("pass"),
        count("fail"),
        count("error")
    );
    out
}

/// One submission in detail: every rejected region (up to `limit`) with its
/// numbers.
pub fn details(grade: &ImageGrade, limit: usize) -> String {
    let mut out = format!(
        "{}: {} ({}x{}, settings {}; {} tests at α = {})\n",
        grade.file,
        if grade.passed { "pass" } else { "FAIL" },
        grade.resolution[0],
        grade.resolution[1],
        grade.settings,
        grade.tests,
        grade.alpha,
    );
    if grade.passed {
        out += &format!(
            "  no region differs beyond its noise; largest |z| {}; noise {} per pixel\n",
            z_text(grade.largest_accepted_z),
            significant(grade.noise)
        );
        return out;
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
pub const CSV_COLUMNS: [&str; 10] = [
    "student",
    "scene",
    "file",
    "verdict",
    "rejected",
    "tests",
    "largest_z",
    "worst_region",
    "worst_channel",
    "summary",
];

/// The class as CSV, one row per submission.
pub fn csv(grades: &ClassGrades) -> String {
    let mut writer = csv::Writer::from_writer(Vec::new());
    writer.write_record(CSV_COLUMNS).expect("in memory");
    for row in &grades.rows {
        let (rejected, tests, largest, region, channel) = match &row.outcome {
            Outcome::Graded(g) => {
                let worst = g.rejected.first();
                let largest = worst.map_or(g.largest_accepted_z, |f| f.strongest().z);
                (
                    g.rejected.len().to_string(),
                    g.tests.to_string(),
                    format!("{largest:.2}"),
                    worst.map_or(String::new(), |f| f.region.clone()),
                    worst.map_or("", |f| f.strongest().channel).to_owned(),
                )
            }
            Outcome::Unreadable { .. } => Default::default(),
        };
        writer
            .write_record([
                row.student.as_str(),
                &row.scene,
                &row.file,
                verdict(row),
                &rejected,
                &tests,
                &largest,
                &region,
                &channel,
                &summary(row),
            ])
            .expect("in memory");
    }
    String::from_utf8(writer.into_inner().expect("in memory")).expect("UTF-8 cells")
}

/// The class as a JSON document (schema [`SCHEMA`]).
pub fn json(grades: &ClassGrades) -> Value {
    let rows: Vec<Value> = grades
        .rows
        .iter()
        .map(|r| {
            let mut value = serde_json::to_value(r).expect("plain data");
            value["verdict"] = json!(verdict(r));
            value
        })
        .collect();
    let count = |v: &str| grades.rows.iter().filter(|r| verdict(r) == v).count();
    json!({
        "schema": SCHEMA,
        "submissions": rows,
        "pass": count("pass"),
        "fail": count("fail"),
        "error": count("error"),
    })
}
