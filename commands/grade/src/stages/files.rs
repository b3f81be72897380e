//! The test-vector files of a stage: `STAGE.json` (schema
//! [`SCHEMA`]), `STAGE.csv` (the same, flat) and
//! `STAGE-inputs.csv` (the inputs only).

use super::probe::explain_flags;
use super::table::{Case, Layout};
use super::{StageVectors, COMMON_CONVENTIONS, SCHEMA};
use serde::ser::{Serialize, SerializeMap, Serializer};
use serde_json::Value as Json;
use std::path::{Path, PathBuf};

/// The columns after the expected ones in `STAGE.csv`: where the case
/// comes from (empty for the film's chosen values).
pub const FROM_COLUMNS: [&str; 5] = ["pixel_x", "pixel_y", "sample", "spp", "why"];

/// JSON whose objects keep their keys in the order given (serde_json's own
/// map sorts them), so that a document reads in a sensible order.
pub enum Ordered {
    Value(Json),
    Object(Vec<(String, Ordered)>),
    Array(Vec<Ordered>),
}

impl Serialize for Ordered {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Ordered::Value(v) => v.serialize(s),
            Ordered::Array(items) => items.serialize(s),
            Ordered::Object(pairs) => {
                let mut map = s.serialize_map(Some(pairs.len()))?;
                for (k, v) in pairs {
                    map.serialize_entry(k, v)?;
                }
                map.end()
            }
        }
    }
}

fn value(v: impl Into<Json>) -> Ordered {
    Ordered::Value(v.into())
}

fn object<const N: usize>(pairs: [(&str, Ordered); N]) -> Ordered {
    Ordered::Object(pairs.into_iter().map(|(k, v)| (k.to_owned(), v)).collect())
}

/// A stage's three files in `dir`: path, text, and the number of cases.
pub fn documents(
    scene: &str,
    requested: u32,
    v: &StageVectors,
    dir: &Path,
) -> Vec<(PathBuf, String, usize)> {
    let name = v.stage.name();
    let json = serde_json::to_string_pretty(&document(scene, requested, v)).expect("JSON") + "\n";
    let n = v.cases.len();
    vec![
        (dir.join(format!("{name}.json")), json, n),
        (
            dir.join(format!("{name}.csv")),
            csv(&v.layout, &v.cases, true),
            n,
        ),
        (
            dir.join(format!("{name}-inputs.csv")),
            csv(&v.layout, &v.cases, false),
            n,
        ),
    ]
}

/// The `glint explain` command that shows a case's pixel and sample,
/// limited to `stage`.
pub fn explain_command(scene: &str, from: &super::Origin, stage: super::Stage) -> String {
    format!(
        "glint explain {scene} {} --stage {}",
        explain_flags(from),
        stage.explain_stage().name()
    )
}

/// The JSON document of a stage (schema `glint-stages/1`).
pub fn document(scene: &str, requested: u32, v: &StageVectors) -> Ordered {
    let conventions = COMMON_CONVENTIONS
        .iter()
        .chain(v.stage.conventions())
        .map(|c| value(*c))
        .collect();
    let fields = v
        .layout
        .expected
        .iter()
        .map(|f| {
            object([
                ("field", value(f.name.as_str())),
                ("columns", value(f.columns.clone())),
                ("tolerance", value(f.check.describe())),
            ])
        })
        .collect();
    let cases = v.cases.iter().map(|c| case_document(scene, v, c)).collect();
    object([
        ("schema", value(SCHEMA)),
        ("stage", value(v.stage.name())),
        ("scene", value(scene)),
        ("cases_requested", value(requested)),
        ("conventions", Ordered::Array(conventions)),
        ("inputs", value(v.layout.inputs.clone())),
        ("expected", Ordered::Array(fields)),
        ("cases", Ordered::Array(cases)),
    ])
}

fn case_document(scene: &str, v: &StageVectors, c: &Case) -> Ordered {
    let cells = |columns: &mut dyn Iterator<Item = &str>| {
        Ordered::Object(
            columns
                .map(|k| (k.to_owned(), Ordered::Value(c.get(k).json())))
                .collect(),
        )
    };
    let from = match &c.from {
        None => value(Json::Null),
        Some(f) => object([
            ("pixel", value(f.pixel.to_vec())),
            ("sample", value(f.sample)),
            ("spp", value(f.spp)),
            ("why", value(f.why)),
            ("explain", value(explain_command(scene, f, v.stage))),
        ]),
    };
    object([
        ("id", value(c.id.as_str())),
        (
            "inputs",
            cells(&mut v.layout.inputs.iter().map(String::as_str)),
        ),
        ("expected", cells(&mut v.layout.expected_columns())),
        ("from", from),
    ])
}

/// The CSV of `cases`: `id`, the inputs, and with `expected` the expected
/// columns and [`FROM_COLUMNS`].
pub fn csv(layout: &Layout, cases: &[Case], expected: bool) -> String {
    let mut header: Vec<&str> = vec!["id"];
    header.extend(layout.inputs.iter().map(String::as_str));
    if expected {
        header.extend(layout.expected_columns());
        header.extend(FROM_COLUMNS);
    }
    let mut out = csv::Writer::from_writer(Vec::new());
    out.write_record(&header).expect("in memory");
    for c in cases {
        let mut row: Vec<String> = header
            .iter()
            .take(header.len() - if expected { FROM_COLUMNS.len() } else { 0 })
            .map(|&k| match k {
                "id" => c.id.clone(),
                k => c.get(k).csv(),
            })
            .collect();
        if expected {
            row.extend(match &c.from {
                Some(f) => [
                    f.pixel[0].to_string(),
                    f.pixel[1].to_string(),
                    f.sample.to_string(),
                    f.spp.to_string(),
                    f.why.to_owned(),
                ],
                None => Default::default(),
            });
        }
        out.write_record(&row).expect("in memory");
    }
    String::from_utf8(out.into_inner().expect("in memory")).expect("UTF-8 cells")
}
