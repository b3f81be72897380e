//! Reading a student's answers to a stage: `STAGE.csv` (a header with `id`
//! and the expected columns, one row per case) or `STAGE.json` (a list of
//! objects with `id` and the expected keys, or Glint's own `glint-stages/1`
//! document, whose `expected` objects are read). Other columns and keys are
//! ignored, so a student may copy the inputs through.
//!
//! Bad input is one error naming the file (and the line, for CSV), the
//! column and what was expected: an unreadable file, a missing `id` column or
//! expected column, an unknown or repeated id, a value of the wrong kind.

use super::table::{Kind, Layout};
use super::Stage;
use crate::text::shorten;
use crate::GradeError;
use serde_json::Value as Json;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// One answered value.
#[derive(Clone, Debug, PartialEq)]
pub enum Answer {
    /// An empty cell or `null`: no answer.
    Empty,
    Number(f64),
    Bool(bool),
    Text(String),
}

impl Answer {
    /// As the report shows it.
    pub fn show(&self) -> String {
        match self {
            Answer::Empty => "(none)".to_owned(),
            Answer::Number(x) => x.to_string(),
            Answer::Bool(b) => b.to_string(),
            Answer::Text(s) => format!("\"{}\"", shorten(s)),
        }
    }

    pub fn json(&self) -> Json {
        match self {
            Answer::Empty => Json::Null,
            Answer::Number(x) => serde_json::Number::from_f64(*x).map_or(Json::Null, Json::Number),
            Answer::Bool(b) => Json::Bool(*b),
            Answer::Text(s) => Json::String(s.clone()),
        }
    }
}

/// The answers of one stage, by case id.
#[derive(Clone, Debug, PartialEq)]
pub struct Answers {
    pub file: PathBuf,
    pub rows: BTreeMap<String, BTreeMap<String, Answer>>,
}

/// The stage's answer file in `dir`: `STAGE.csv`, else `STAGE.json`.
pub fn find(dir: &Path, stage: Stage) -> Option<PathBuf> {
    ["csv", "json"]
        .iter()
        .map(|ext| dir.join(format!("{}.{ext}", stage.name())))
        .find(|p| p.is_file())
}

/// What an id that is not a case is told: the ids there are.
fn unknown_id(stage: Stage, id: &str, ids: &BTreeSet<String>) -> String {
    let range = match (ids.first(), ids.last()) {
        (Some(a), Some(b)) => format!("the {} cases are {a} to {b}", stage.name()),
        _ => format!("the scene has no {} cases", stage.name()),
    };
    format!(
        "unknown id \"{}\": {range} (were the vectors written with another --cases?)",
        shorten(id)
    )
}

/// Reads `file`, the answers to `stage`, whose cases have `ids`.
pub fn read(
    file: &Path,
    stage: Stage,
    layout: &Layout,
    ids: &BTreeSet<String>,
) -> Result<Answers, GradeError> {
    let text = glint_scene::read_text(file, glint_scene::MAX_DOCUMENT_BYTES, "an answer file")
        .map_err(|e| {
            GradeError::Input(format!("{}: cannot read the answers: {e}", file.display()))
        })?;
    let is_json = file.extension().is_some_and(|e| e == "json");
    let rows = match is_json {
        true => read_json(&text, stage, layout, ids),
        false => read_csv(&text, stage, layout, ids),
    }
    .map_err(|e| GradeError::Input(format!("{}{e}", file.display())))?;
    Ok(Answers {
        file: file.to_owned(),
        rows,
    })
}

/// The columns an answer must have: every expected one but those shown
/// only (an object's name) and those of optional fields.
fn required(layout: &Layout) -> Vec<(&str, Kind)> {
    checked(layout, false)
}

/// The columns of the optional fields, read where an answer gives them.
fn optional(layout: &Layout) -> Vec<(&str, Kind)> {
    checked(layout, true)
}

fn checked(layout: &Layout, optional: bool) -> Vec<(&str, Kind)> {
    layout
        .expected
        .iter()
        .filter(|f| f.check != super::Check::Info && f.optional == optional)
        .flat_map(|f| f.columns.iter().map(move |c| (c.as_str(), f.kind)))
        .collect()
}

/// A stage's answers by id, each a map from column to answer.
type Rows = BTreeMap<String, BTreeMap<String, Answer>>;

/// Errors are returned without the file name, starting with `:LINE: ` or
/// `: `, for [`read`] to put the file in front.
fn read_csv(
    text: &str,
    stage: Stage,
    layout: &Layout,
    ids: &BTreeSet<String>,
) -> Result<Rows, String> {
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let header = reader
        .headers()
        .map_err(|e| format!(":1: {}", csv_message(&e)))?
        .clone();
    let (id_at, columns) = csv_columns(&header, stage, layout)?;
    let mut rows = BTreeMap::new();
    let mut lines: BTreeMap<String, u64> = BTreeMap::new();
    for record in reader.records() {
        let record = record.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line());
            format!(":{line}: {}", csv_message(&e))
        })?;
        let line = record.position().map_or(0, |p| p.line());
        let id = record.get(id_at).unwrap_or("").to_owned();
        if !ids.contains(&id) {
            return Err(format!(":{line}: {}", unknown_id(stage, &id, ids)));
        }
        if let Some(first) = lines.insert(id.clone(), line) {
            return Err(format!(
                ":{line}: id \"{}\" is answered twice (first on line {first})",
                shorten(&id)
            ));
        }
        let cells = csv_cells(&record, &columns).map_err(|e| format!(":{line}: {e}"))?;
        rows.insert(id, cells);
    }
    Ok(rows)
}

/// A required column: its name, kind, and place in the header.
type Column<'a> = (&'a str, Kind, usize);

/// Where the header puts `id`, and each required column.
fn csv_columns<'a>(
    header: &csv::StringRecord,
    stage: Stage,
    layout: &'a Layout,
) -> Result<(usize, Vec<Column<'a>>), String> {
    let position = |name: &str| header.iter().position(|h| h == name);
    let id_at = position("id").ok_or_else(|| {
        format!(
            ":1: no id column: the header must name id and the expected columns ({})",
            shorten(&header.iter().collect::<Vec<_>>().join(","))
        )
    })?;
    let mut columns: Vec<Column> = required(layout)
        .into_iter()
        .map(|(name, kind)| match position(name) {
            Some(at) => Ok((name, kind, at)),
            None => Err(format!(
                ":1: missing column \"{name}\": the {} answers need id and every expected column",
                stage.name()
            )),
        })
        .collect::<Result<_, _>>()?;
    columns.extend(
        optional(layout)
            .into_iter()
            .filter_map(|(name, kind)| Some((name, kind, position(name)?))),
    );
    Ok((id_at, columns))
}

/// One row's answers to `columns`.
fn csv_cells(
    record: &csv::StringRecord,
    columns: &[Column],
) -> Result<BTreeMap<String, Answer>, String> {
    let mut cells = BTreeMap::new();
    for &(name, kind, at) in columns {
        let cell = record.get(at).unwrap_or("");
        let answer = parse_text(cell, kind).map_err(|expected| {
            format!(
                "column {name}: expected {expected}, got \"{}\"",
                shorten(cell)
            )
        })?;
        cells.insert(name.to_owned(), answer);
    }
    Ok(cells)
}

/// The csv crate's message without its own position (the caller gives one).
fn csv_message(e: &csv::Error) -> String {
    match e.kind() {
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => {
            format!("{len} fields where the header has {expected_len}")
        }
        csv::ErrorKind::Utf8 { .. } => "not UTF-8 text".to_owned(),
        _ => e.to_string(),
    }
}

/// A cell of the given kind; the error says what was expected.
fn parse_text(cell: &str, kind: Kind) -> Result<Answer, &'static str> {
    if cell.is_empty() {
        return Ok(Answer::Empty);
    }
    match kind {
        Kind::Float => cell
            .parse::<f64>()
            .map(Answer::Number)
            .map_err(|_| "a number"),
        Kind::Int => match cell.parse::<f64>() {
            Ok(x) if x.fract() == 0.0 => Ok(Answer::Number(x)),
            _ => Err("a whole number"),
        },
        Kind::Bool => match cell.to_ascii_lowercase().as_str() {
            "true" | "1" => Ok(Answer::Bool(true)),
            "false" | "0" => Ok(Answer::Bool(false)),
            _ => Err("true or false"),
        },
        Kind::Text => Ok(Answer::Text(cell.to_owned())),
    }
}

/// A JSON value of the given kind; the error says what was expected.
fn parse_json(value: &Json, kind: Kind) -> Result<Answer, &'static str> {
    match (value, kind) {
        (Json::Null, _) => Ok(Answer::Empty),
        (Json::Number(x), Kind::Float) => Ok(Answer::Number(x.as_f64().unwrap_or(f64::NAN))),
        (Json::Number(x), Kind::Int) => match x.as_f64() {
            Some(x) if x.fract() == 0.0 => Ok(Answer::Number(x)),
            _ => Err("a whole number"),
        },
        (Json::Bool(b), Kind::Bool) => Ok(Answer::Bool(*b)),
        (Json::String(s), Kind::Text) => Ok(Answer::Text(s.clone())),
        (_, Kind::Float) => Err("a number"),
        (_, Kind::Int) => Err("a whole number"),
        (_, Kind::Bool) => Err("true or false"),
        (_, Kind::Text) => Err("a string"),
    }
}

fn read_json(
    text: &str,
    stage: Stage,
    layout: &Layout,
    ids: &BTreeSet<String>,
) -> Result<Rows, String> {
    let document: Json =
        serde_json::from_str(text).map_err(|e| glint_explain::against::located(&e))?;
    // Glint's own document: its cases' expected objects.
    let glint = document.get("schema").and_then(Json::as_str) == Some(super::SCHEMA);
    let items = match (&document, glint) {
        (Json::Array(items), _) => items,
        (Json::Object(o), true) => o
            .get("cases")
            .and_then(Json::as_array)
            .ok_or(": a glint-stages/1 document without a cases array".to_owned())?,
        _ => return Err(": expected a list of objects with id and the expected keys".to_owned()),
    };
    let mut rows = BTreeMap::new();
    for (i, item) in items.iter().enumerate() {
        let at = |m: String| format!(": case {i}: {m}");
        let id = item
            .get("id")
            .and_then(Json::as_str)
            .ok_or_else(|| at("expected an object with a string id".into()))?;
        if !ids.contains(id) {
            return Err(at(unknown_id(stage, id, ids)));
        }
        let cells = match glint {
            true => item.get("expected").unwrap_or(&Json::Null),
            false => item,
        };
        let answers =
            json_cells(cells, layout).map_err(|e| at(format!("(id \"{}\") {e}", shorten(id))))?;
        if rows.insert(id.to_owned(), answers).is_some() {
            return Err(at(format!("id \"{}\" is answered twice", shorten(id))));
        }
    }
    Ok(rows)
}

/// One JSON object's answers to the layout's required keys.
fn json_cells(cells: &Json, layout: &Layout) -> Result<BTreeMap<String, Answer>, String> {
    let mut answers = BTreeMap::new();
    let given = required(layout)
        .into_iter()
        .map(|(name, kind)| {
            let value = cells
                .get(name)
                .ok_or_else(|| format!("no key \"{name}\""))?;
            Ok((name, kind, value))
        })
        .collect::<Result<Vec<_>, String>>()?;
    let optional = optional(layout)
        .into_iter()
        .filter_map(|(name, kind)| Some((name, kind, cells.get(name)?)));
    for (name, kind, value) in given.into_iter().chain(optional) {
        let answer = parse_json(value, kind).map_err(|expected| {
            format!(
                "{name}: expected {expected}, got {}",
                shorten(&value.to_string())
            )
        })?;
        answers.insert(name.to_owned(), answer);
    }
    Ok(answers)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stages::table::{Check, Field};

    fn layout() -> Layout {
        Layout {
            inputs: vec!["x".into()],
            expected: vec![
                Field::scalar("hit", Kind::Bool, Check::Exact),
                Field::scalar("t", Kind::Float, Check::Relative),
                Field::scalar("object", Kind::Int, Check::Exact),
                Field::scalar("name", Kind::Text, Check::Info),
            ],
        }
    }

    fn ids() -> BTreeSet<String> {
        ["intersection-001", "intersection-002"]
            .map(String::from)
            .into()
    }

    fn csv(text: &str) -> Result<Rows, String> {
        read_csv(text, Stage::Intersection, &layout(), &ids())
    }

    #[test]
    fn csv_answers_are_read_by_column_name_in_any_order() {
        let rows = csv("object,x,t,id,hit\n3,9,1.5,intersection-002,TRUE\n,,,intersection-001,0\n")
            .unwrap();
        let two = &rows["intersection-002"];
        assert_eq!(two["t"], Answer::Number(1.5));
        assert_eq!(two["hit"], Answer::Bool(true));
        assert_eq!(two["object"], Answer::Number(3.0));
        assert_eq!(rows["intersection-001"]["t"], Answer::Empty);
        assert_eq!(rows["intersection-001"]["hit"], Answer::Bool(false));
    }

    #[test]
    fn each_kind_of_bad_csv_has_its_own_message() {
        let cases = [
            ("x,t\n", ":1: no id column"),
            ("id,hit,t\n", ":1: missing column \"object\""),
            ("id,hit,t,object\nintersection-009,1,2,3\n", ":2: unknown id \"intersection-009\": the intersection cases are intersection-001 to intersection-002"),
            ("id,hit,t,object\nintersection-001,1,2,3\nintersection-001,1,2,3\n", ":3: id \"intersection-001\" is answered twice (first on line 2)"),
            ("id,hit,t,object\nintersection-001,1,two,3\n", ":2: column t: expected a number, got \"two\""),
            ("id,hit,t,object\nintersection-001,1,2,3.5\n", ":2: column object: expected a whole number"),
            ("id,hit,t,object\nintersection-001,yes,2,3\n", ":2: column hit: expected true or false"),
            ("id,hit,t,object\nintersection-001,1,2\n", ":2: 3 fields where the header has 4"),
        ];
        for (text, want) in cases {
            let e = csv(text).unwrap_err();
            assert!(e.starts_with(want), "{text:?}: {e}");
        }
        let long = format!(
            "id,hit,t,object\nintersection-001,1,{},3\n",
            "9x".repeat(50)
        );
        let e = csv(&long).unwrap_err();
        assert!(e.ends_with("…\""), "{e}");
    }

    #[test]
    fn json_answers_are_a_list_or_glints_own_document() {
        let json = |text: &str| read_json(text, Stage::Intersection, &layout(), &ids());
        let list =
            json(r#"[{"id": "intersection-001", "hit": true, "t": 2, "object": 4}]"#).unwrap();
        assert_eq!(list["intersection-001"]["t"], Answer::Number(2.0));
        let glint = json(
            r#"{"schema": "glint-stages/1", "cases": [{"id": "intersection-002",
                "inputs": {"x": 1}, "expected": {"hit": false, "t": null, "object": null, "name": null}}]}"#,
        )
        .unwrap();
        assert_eq!(glint["intersection-002"]["hit"], Answer::Bool(false));
        let bad = [
            ("[1, 2", ":1:5: EOF while parsing a list"),
            ("{\"a\": 1}", ": expected a list of objects"),
            (
                "[{\"hit\": true}]",
                ": case 0: expected an object with a string id",
            ),
            (
                "[{\"id\": \"intersection-001\", \"hit\": true, \"t\": \"2\", \"object\": 1}]",
                ": case 0: (id \"intersection-001\") t: expected a number, got \"2\"",
            ),
            (
                "[{\"id\": \"intersection-001\", \"hit\": true, \"t\": 2}]",
                ": case 0: (id \"intersection-001\") no key \"object\"",
            ),
        ];
        for (text, want) in bad {
            let e = json(text).unwrap_err();
            assert!(e.starts_with(want), "{text:?}: {e}");
        }
    }
}
