//! A check's report: text (a score per stage, then each failing stage's
//! first failing case with `glint explain`'s text) and JSON (schema
//! [`CHECK_SCHEMA`]).

use super::check::{CaseFailure, Difference, StageCheck, StagesCheck};
use super::files::{explain_command, Ordered};
use super::table::{Case, Check, Value, RGB, XYZ};
use super::CHECK_SCHEMA;
use crate::text::number;
use glint_explain::rules::{ANGLE, FLOOR, LEVEL, RELATIVE, UNIT};
use serde_json::Value as Json;
use std::fmt::Write;

/// The report as text.
pub fn text(check: &StagesCheck) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{} stage by stage, answers in {} ({} cases per stage asked for):",
        check.scene,
        check.answers.display(),
        check.cases_requested
    );
    let _ = writeln!(
        out,
        "  {:<13} {:>6} {:>9} {:>6}  file",
        "stage", "passed", "answered", "cases"
    );
    for s in &check.stages {
        let (passed, answered, file) = match &s.file {
            Some(f) => (
                s.passed.to_string(),
                s.answered.to_string(),
                f.display().to_string(),
            ),
            None => ("-".into(), "-".into(), "not answered".into()),
        };
        let _ = writeln!(
            out,
            "  {:<13} {passed:>6} {answered:>9} {:>6}  {file}",
            s.stage.name(),
            s.total.map_or("-".to_owned(), |t| t.to_string())
        );
    }
    for s in &check.stages {
        if let Some(failure) = &s.first_failure {
            out.push('\n');
            failure_text(&mut out, &check.scene, s, failure);
        }
    }
    out.push('\n');
    let failing: Vec<&str> = check
        .stages
        .iter()
        .filter(|s| !s.passes())
        .map(|s| s.stage.name())
        .collect();
    let _ = match failing.len() {
        0 => writeln!(out, "every answered case passes"),
        1 => writeln!(out, "1 stage fails: {}", failing[0]),
        n => writeln!(out, "{n} stages fail: {}", failing.join(", ")),
    };
    out
}

fn failure_text(out: &mut String, scene: &str, s: &StageCheck, f: &CaseFailure) {
    let _ = writeln!(
        out,
        "{}: {} of {} answered cases fail; the first is {}",
        s.stage.name(),
        s.answered - s.passed,
        s.answered,
        f.case.id
    );
    let _ = match &f.case.from {
        Some(from) => writeln!(
            out,
            "  from pixel ({}, {}), camera sample {} of {} on the grid pattern ({})",
            from.pixel[0], from.pixel[1], from.sample, from.spp, from.why
        ),
        None => writeln!(out, "  a chosen value, from no pixel"),
    };
    let _ = writeln!(out, "  inputs:");
    for line in wrap(&grouped(&f.case, &f.inputs), 96) {
        let _ = writeln!(out, "    {line}");
    }
    for d in &f.differences {
        let _ = writeln!(out, "  {}", difference_text(d));
    }
    if !f.steps.is_empty() {
        let _ = writeln!(out, "  how Glint's expected values were found:");
        for line in &f.steps {
            let _ = writeln!(out, "    {line}");
        }
    }
    if let (Some(from), Some(explanation)) = (&f.case.from, &f.explanation) {
        let _ = writeln!(
            out,
            "  Glint's steps: {}",
            explain_command(scene, from, s.stage)
        );
        for line in explanation.lines() {
            let _ = writeln!(out, "    | {line}");
        }
    }
}

/// `name value` pairs of `columns`, a field's three `_x/_y/_z` or `_r/_g/_b`
/// columns as one vector.
fn grouped(case: &Case, columns: &[String]) -> Vec<String> {
    let mut items = Vec::new();
    let mut i = 0;
    while i < columns.len() {
        let triple = columns.get(i..i + 3).and_then(|three| {
            [XYZ, RGB].iter().find_map(|suffixes| {
                let stem = three[0].strip_suffix(&format!("_{}", suffixes[0]))?;
                let all = three
                    .iter()
                    .zip(suffixes)
                    .all(|(c, s)| *c == format!("{stem}_{s}"));
                all.then_some(stem)
            })
        });
        match triple {
            Some(stem) => {
                let values: Vec<String> = columns[i..i + 3]
                    .iter()
                    .map(|c| show(case.get(c)))
                    .collect();
                items.push(format!("{stem} ({})", values.join(", ")));
                i += 3;
            }
            None => {
                items.push(format!("{} {}", columns[i], show(case.get(&columns[i]))));
                i += 1;
            }
        }
    }
    items
}

fn show(v: &Value) -> String {
    match v {
        Value::Empty => "(none)".to_owned(),
        Value::Text(s) => s.clone(),
        other => other.csv(),
    }
}

/// `items` joined by three spaces, in lines of at most `width` characters.
fn wrap(items: &[String], width: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for item in items {
        match lines.last_mut() {
            Some(line) if line.chars().count() + 3 + item.chars().count() <= width => {
                line.push_str("   ");
                line.push_str(item);
            }
            _ => lines.push(item.clone()),
        }
    }
    lines
}

fn difference_text(d: &Difference) -> String {
    let expected: Vec<String> = d.expected.iter().map(show).collect();
    let answered: Vec<String> = d.answered.iter().map(|a| a.show()).collect();
    let list = |v: &[String]| match v.len() {
        1 => v[0].clone(),
        _ => format!("({})", v.join(", ")),
    };
    let mut text = format!(
        "{} [{}]: Glint's {}, yours {}",
        d.field.name,
        d.field.columns.join(", "),
        list(&expected),
        list(&answered)
    );
    match (d.apart, d.allowed, d.note) {
        (Some(apart), Some(allowed), note) => {
            let unit = match note {
                Some("radians") => " radians",
                _ => "",
            };
            let what = match note {
                Some("not of unit length") => "its length is off 1 by",
                _ => "apart",
            };
            let _ = write!(
                text,
                ": {what} {}{unit}, allowed {}{unit}",
                number(apart),
                number(allowed)
            );
        }
        (_, _, Some(note)) => {
            let _ = write!(text, ": {note}");
        }
        _ => {}
    }
    let _ = write!(text, " (tolerance: {})", d.field.check.describe());
    text
}

fn value(v: impl Into<Json>) -> Ordered {
    Ordered::Value(v.into())
}

fn object(pairs: Vec<(&str, Ordered)>) -> Ordered {
    Ordered::Object(pairs.into_iter().map(|(k, v)| (k.to_owned(), v)).collect())
}

/// The report as JSON (schema `glint-stages-check/1`).
pub fn json(check: &StagesCheck) -> Ordered {
    let stages = check
        .stages
        .iter()
        .map(|s| stage_json(&check.scene, s))
        .collect();
    object(vec![
        ("schema", value(CHECK_SCHEMA)),
        ("scene", value(check.scene.as_str())),
        ("answers", value(check.answers.display().to_string())),
        ("cases_requested", value(check.cases_requested)),
        ("passed", value(check.passed())),
        ("stages", Ordered::Array(stages)),
    ])
}

fn stage_json(scene: &str, s: &StageCheck) -> Ordered {
    let failure = match &s.first_failure {
        None => value(Json::Null),
        Some(f) => failure_json(scene, s, f),
    };
    object(vec![
        ("stage", value(s.stage.name())),
        (
            "file",
            value(s.file.as_ref().map(|f| f.display().to_string())),
        ),
        ("total", value(s.total)),
        ("answered", value(s.answered)),
        ("passed", value(s.passed)),
        ("passes", value(s.passes())),
        ("first_failure", failure),
    ])
}

fn failure_json(scene: &str, s: &StageCheck, f: &CaseFailure) -> Ordered {
    let from = match &f.case.from {
        None => value(Json::Null),
        Some(from) => object(vec![
            ("pixel", value(from.pixel.to_vec())),
            ("sample", value(from.sample)),
            ("spp", value(from.spp)),
            ("why", value(from.why)),
            ("explain", value(explain_command(scene, from, s.stage))),
        ]),
    };
    let inputs = f
        .inputs
        .iter()
        .map(|c| (c.clone(), value(f.case.get(c).json())))
        .collect();
    let differences = f.differences.iter().map(difference_json).collect();
    object(vec![
        ("id", value(f.case.id.as_str())),
        ("from", from),
        ("inputs", Ordered::Object(inputs)),
        ("differences", Ordered::Array(differences)),
        ("steps", value(f.steps.clone())),
        ("explanation", value(f.explanation.clone())),
    ])
}

fn difference_json(d: &Difference) -> Ordered {
    let check = d.field.check;
    let mut tolerance = vec![
        ("kind", value(check.name())),
        ("description", value(check.describe())),
    ];
    match check {
        Check::Relative | Check::Vector | Check::Uv => {
            tolerance.push(("relative", value(RELATIVE)));
            tolerance.push(("floor", value(FLOOR)));
        }
        Check::Direction => {
            tolerance.push(("radians", value(ANGLE)));
            tolerance.push(("unit_length", value(UNIT)));
        }
        Check::Level => tolerance.push(("levels", value(LEVEL))),
        Check::Exact | Check::Info => {}
    }
    object(vec![
        ("field", value(d.field.name.as_str())),
        ("columns", value(d.field.columns.clone())),
        (
            "glint",
            Ordered::Array(d.expected.iter().map(|v| value(v.json())).collect()),
        ),
        (
            "yours",
            Ordered::Array(d.answered.iter().map(|a| value(a.json())).collect()),
        ),
        ("tolerance", object(tolerance)),
        ("apart", value(d.apart)),
        ("allowed", value(d.allowed)),
        ("note", value(d.note)),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectors_are_grouped_and_lines_wrapped() {
        let mut case = Case::new(None);
        case.xyz("origin", glam::Vec3::new(0.0, 0.5, 10.0))
            .float("x", 2.5);
        let columns: Vec<String> = ["origin_x", "origin_y", "origin_z", "x", "y"]
            .map(String::from)
            .to_vec();
        assert_eq!(
            grouped(&case, &columns),
            ["origin (0, 0.5, 10)", "x 2.5", "y (none)"]
        );
        let items = ["a".repeat(10), "b".repeat(10), "c".repeat(10)];
        assert_eq!(wrap(&items, 23).len(), 2);
    }
}
