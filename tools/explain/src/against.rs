//! `glint explain --against`: a student's document in the `glint-explain/1`
//! schema, possibly partial, compared with Glint's document for the same
//! pixel and flags, stage by stage in pipeline order (camera, intersection,
//! texture, lighting, film), to find the first stage where the student's
//! numbers part from Glint's.
//!
//! Within a stage, keys are compared in pipeline order ([`PIPELINE_ORDER`]:
//! a lookup's level before the texels it reads, its texels before their
//! value), whatever order the student's document lists them in; samples and
//! mirror reflections in document order. Only the keys the student gives
//! are compared; the keys that describe Glint's own work ([`SKIPPED`]) are
//! not. Before any number, the settings a document records (its sample
//! counts and patterns) must be the command's.
//!
//! Tolerances are [`crate::rules`]', the same as `glint grade --stages`':
//! numbers within [`RELATIVE`] of Glint's, plus [`FLOOR`]; vectors component
//! by component, relative to their largest component, a sphere's `u` modulo
//! 1; unit directions within [`ANGLE`] radians; integers, booleans, strings
//! (kinds, shadow verdicts) and nulls exactly; the 8-bit sRGB value within 1.

use crate::rules::{self, Rule, ANGLE, FLOOR, LEVEL, RELATIVE, UNIT};
use crate::Stage;
use serde::de::{self, Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};
use serde_json::{json, Number, Value};
use std::fmt;

/// Keys that describe Glint's own queries (every object's test, the BVH's
/// work and path), not numbers a ray tracer must reproduce.
pub const SKIPPED: [&str; 3] = ["tests", "work", "bvh"];
/// Keys whose value is a unit direction, compared by angle.
const DIRECTIONS: [&str; 10] = [
    "direction",
    "rx_direction",
    "ry_direction",
    "l",
    "v",
    "n",
    "ng",
    "reflection",
    "geometric_normal",
    "shading_normal",
];
/// Keys whose value is a MIP level, a logarithm: compared within
/// `LEVEL` levels, as `glint grade --stages` compares its `level`.
const LEVELS: [&str; 2] = ["glint_level", "report_level"];
/// The document's own keys besides `samples` and `film`: its schema, its
/// [`SETTINGS`] and its seed.
fn is_header(key: &str) -> bool {
    key == "schema" || key == "seed" || SETTINGS.contains(&key)
}
/// The settings a document records, checked before any number: with
/// other sample counts or patterns every later number differs for that
/// reason alone.
const SETTINGS: [&str; 8] = [
    "texture_level",
    "pixel",
    "resolution",
    "spp",
    "sampler",
    "light_samples",
    "light_sampler",
    "environment_samples",
];
/// Keys in the order the pipeline computes them, by which a stage's keys
/// are compared: what decides a value before the value. Keys not listed
/// follow, in the student's order.
pub const PIPELINE_ORDER: [&str; 48] = [
    // camera
    "raster",
    "ndc",
    "film_point",
    "origin",
    "direction",
    "differentials",
    "rx_origin",
    "rx_direction",
    "ry_origin",
    "ry_direction",
    // intersection
    "depth",
    "intersect",
    "hit",
    "object",
    "kind",
    "triangle",
    "t",
    "point",
    "geometric_normal",
    "shading_normal",
    "front_face",
    "uv",
    "dpdu",
    "dpdv",
    // texture: the footprint, the level, the texels, the value
    "footprint",
    "material_uv",
    "duvdx",
    "duvdy",
    "diffuse",
    "specular",
    "st",
    "dst_dx",
    "dst_dy",
    "report_l",
    "report_w",
    "report_m",
    "report_level",
    "glint_level",
    "level",
    "x",
    "y",
    "texels",
    "weight",
    // lighting
    "shading",
    "v",
    "ng",
    "n",
    "position",
];

/// A JSON value whose objects keep their keys in the file's order.
#[derive(Clone, Debug, PartialEq)]
pub enum Node {
    Null,
    Bool(bool),
    Number(Number),
    String(String),
    Array(Vec<Node>),
    Object(Vec<(String, Node)>),
}

impl Node {
    /// Reads a JSON text; the error has the line and column.
    pub fn parse(text: &str) -> Result<Node, serde_json::Error> {
        serde_json::from_str(text)
    }

    /// The value of `key`, if this is an object that has it.
    pub fn get(&self, key: &str) -> Option<&Node> {
        match self {
            Node::Object(entries) => entries.iter().find(|(k, _)| k == key).map(|(_, v)| v),
            _ => None,
        }
    }

    /// As a `serde_json::Value` (keys sorted), for printing.
    pub fn to_value(&self) -> Value {
        match self {
            Node::Null => Value::Null,
            Node::Bool(b) => Value::Bool(*b),
            Node::Number(n) => Value::Number(n.clone()),
            Node::String(s) => Value::String(s.clone()),
            Node::Array(items) => Value::Array(items.iter().map(Node::to_value).collect()),
            Node::Object(entries) => Value::Object(
                entries
                    .iter()
                    .map(|(k, v)| (k.clone(), v.to_value()))
                    .collect(),
            ),
        }
    }
}

impl<'de> Deserialize<'de> for Node {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(NodeVisitor)
    }
}

struct NodeVisitor;

impl<'de> Visitor<'de> for NodeVisitor {
    type Value = Node;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_bool<E: de::Error>(self, v: bool) -> Result<Node, E> {
        Ok(Node::Bool(v))
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Node, E> {
        Ok(Node::Number(v.into()))
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Node, E> {
        Ok(Node::Number(v.into()))
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Node, E> {
        Number::from_f64(v)
            .map(Node::Number)
            .ok_or_else(|| E::custom("a number that is not finite"))
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<Node, E> {
        Ok(Node::String(v.to_owned()))
    }
    fn visit_unit<E: de::Error>(self) -> Result<Node, E> {
        Ok(Node::Null)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Node, A::Error> {
        let mut items = Vec::new();
        while let Some(item) = seq.next_element()? {
            items.push(item);
        }
        Ok(Node::Array(items))
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Node, A::Error> {
        let mut entries = Vec::new();
        while let Some(entry) = map.next_entry::<String, Node>()? {
            entries.push(entry);
        }
        Ok(Node::Object(entries))
    }
}

/// How two values are compared.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tolerance {
    /// A number: `|yours − Glint's| ≤ RELATIVE·|Glint's| + FLOOR`.
    Relative,
    /// A vector (a point, uv, a color): each component within `RELATIVE`
    /// times Glint's largest component, plus `FLOOR`.
    Vector,
    /// A sphere's uv: as `Vector`, its `u` modulo 1.
    PeriodicU,
    /// A MIP level, a logarithm: within `LEVEL` levels.
    Levels,
    /// A texel's weight, a share of 1: within `RELATIVE` of 1.
    Share,
    /// A unit direction: at most `ANGLE` radians apart, of length 1 within
    /// `UNIT`.
    Angular,
    /// Equal: ids, counts, booleans, strings, nulls, the kind of value.
    Exact,
    /// An 8-bit value: within 1 (a radiance within tolerance can round
    /// either way).
    WithinOne,
}

impl Tolerance {
    /// Its name in the JSON report.
    pub fn name(self) -> &'static str {
        match self {
            Tolerance::Relative => "relative",
            Tolerance::Vector => "relative to the largest component",
            Tolerance::PeriodicU => "relative to the largest component, u modulo 1",
            Tolerance::Levels => "levels",
            Tolerance::Share => "relative to the whole",
            Tolerance::Angular => "angular",
            Tolerance::Exact => "exact",
            Tolerance::WithinOne => "within 1",
        }
    }

    /// What it allows, in words.
    pub fn describe(self) -> String {
        match self {
            Tolerance::Relative => format!("within {RELATIVE:e}·|Glint's| + {FLOOR:e}"),
            Tolerance::Vector => format!(
                "each component within {RELATIVE:e}·(Glint's largest |component|) + {FLOOR:e}"
            ),
            Tolerance::PeriodicU => format!(
                "each component within {RELATIVE:e}·(Glint's largest |component|) + {FLOOR:e}, u modulo its period on a sphere (1 for the hit's uv, |uv_scale.u| for the lookup's)"
            ),
            Tolerance::Angular => format!("at most {ANGLE:e} rad apart, of length 1 within {UNIT:e}"),
            Tolerance::Levels => format!("within {LEVEL} levels"),
            Tolerance::Share => format!("within {RELATIVE:e}·1 + {FLOOR:e} (a share of 1)"),
            Tolerance::Exact => "equal".to_owned(),
            Tolerance::WithinOne => "each component within 1".to_owned(),
        }
    }
}

/// A key where the student's document parts from Glint's.
#[derive(Clone, Debug, PartialEq)]
pub struct Difference {
    pub stage: Stage,
    /// Where, as `samples[0].ray.intersect.hit.uv` (indices into the
    /// student's arrays).
    pub path: String,
    pub yours: Value,
    /// Glint's value; `None` where Glint's document has no such key.
    pub glint: Option<Value>,
    pub tolerance: Tolerance,
    /// For numbers and directions: how far apart they are, and how far
    /// the tolerance allows.
    pub gap: Option<(f64, f64)>,
}

/// One stage's share of a comparison.
#[derive(Clone, Debug, PartialEq)]
pub struct StageComparison {
    pub stage: Stage,
    /// Keys compared (a vector counts once).
    pub compared: usize,
    /// The keys that differ, in the order compared.
    pub differences: Vec<Difference>,
}

/// A student's document against Glint's.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    pub pixel: (u64, u64),
    /// The MIP level Glint's textures were read at: `footprint` (the
    /// render's) or `report` (`--texture-level report`).
    pub texture_level: String,
    /// The camera samples the student's document follows, and those the
    /// film averages.
    pub samples_followed: usize,
    pub samples_averaged: u64,
    /// The one stage compared (`--stage`), if only one was.
    pub only: Option<Stage>,
    /// Every stage, in pipeline order.
    pub stages: Vec<StageComparison>,
}

impl Comparison {
    /// Whether every key the student gave agrees with Glint's.
    pub fn agrees(&self) -> bool {
        self.first().is_none()
    }

    /// The first difference in pipeline order: in the first stage that has
    /// one, the first key compared.
    pub fn first(&self) -> Option<&Difference> {
        self.stages.iter().find_map(|s| s.differences.first())
    }

    /// The report as text, naming the student's file `file`: a line per
    /// stage, and the first difference under its stage.
    pub fn text(&self, file: &str) -> String {
        let level = match self.texture_level.as_str() {
            "report" => "textures at the report's level log2(L/W) (--texture-level report)",
            _ => "textures at the render's level (--texture-level report for the report's)",
        };
        let mut lines = vec![format!(
            "{file} against Glint, pixel ({}, {}), {level}, stage by stage in pipeline order:",
            self.pixel.0, self.pixel.1
        )];
        let first = self.first();
        for s in &self.stages {
            lines.push(self.stage_line(s, first.map(|d| d.stage)));
            if let Some(d) = first.filter(|d| d.stage == s.stage) {
                lines.extend(difference_text(d));
            }
        }
        if first.is_some_and(|d| d.stage == Stage::Film)
            && (self.samples_followed as u64) < self.samples_averaged
        {
            lines.push(format!(
                "  the samples followed agree, but the film averages all {} of the pixel's: pass --all-samples (and write every sample) to find the one that parts",
                self.samples_averaged
            ));
        }
        lines.push(match first {
            None => "your document agrees with Glint's everywhere it gives a value".to_owned(),
            Some(d) => format!(
                "the first difference is in the {} stage: look there first",
                d.stage.heading()
            ),
        });
        lines.join("\n") + "\n"
    }

    /// One stage's line: not compared, agreeing, the first to part, or
    /// differing after it.
    fn stage_line(&self, s: &StageComparison, first: Option<Stage>) -> String {
        let heading = s.stage.heading();
        let (n, d) = (s.compared, s.differences.len());
        match (first, d) {
            _ if self.only.is_some_and(|only| only != s.stage) => {
                format!("  {heading}: not compared (--stage)")
            }
            (_, 0) if n == 0 => format!("  {heading}: not in your document"),
            (_, 0) => format!(
                "  {heading}: agrees ({n} {})",
                if n == 1 { "key" } else { "keys" }
            ),
            (Some(f), _) if f == s.stage => {
                format!("  {heading}: PARTS from Glint ({})", differing(d, n))
            }
            (Some(f), _) => format!(
                "  {heading}: {} (perhaps only because of the {} stage)",
                differing(d, n),
                f.heading()
            ),
            (None, _) => unreachable!("a stage with differences makes `first`"),
        }
    }

    /// The report as JSON.
    pub fn json(&self) -> Value {
        let stages: Vec<Value> = self
            .stages
            .iter()
            .map(|s| {
                json!({
                    "stage": s.stage.heading(),
                    "compared": s.compared,
                    "differing": s.differences.len(),
                })
            })
            .collect();
        json!({
            "schema": "glint-explain-against/1",
            "pixel": [self.pixel.0, self.pixel.1],
            "texture_level": self.texture_level,
            "agrees": self.agrees(),
            "stages": stages,
            "first_difference": self.first().map(difference_json),
        })
    }
}

fn difference_text(d: &Difference) -> Vec<String> {
    let glint = match &d.glint {
        Some(v) => v.to_string(),
        None => "(no such key in Glint's document)".to_owned(),
    };
    let mut tolerance = format!("{}: {}", d.tolerance.name(), d.tolerance.describe());
    if let Some((gap, allowed)) = d.gap {
        tolerance += &format!("; apart by {}, allowed {}", sig5(gap), sig5(allowed));
    }
    vec![
        format!("  first difference: {}", d.path),
        format!("    yours:     {}", d.yours),
        format!("    Glint's:   {glint}"),
        format!("    tolerance: {tolerance}"),
    ]
}

/// `x` to 5 significant digits, as the documents print numbers.
fn sig5(x: f64) -> String {
    format!("{x:.4e}").parse::<f64>().unwrap_or(x).to_string()
}

/// "1 of 1 key differs", "2 of 5 keys differ".
fn differing(d: usize, n: usize) -> String {
    let noun = if n == 1 { "key" } else { "keys" };
    let verb = if d == 1 { "differs" } else { "differ" };
    format!("{d} of {n} {noun} {verb}")
}

fn difference_json(d: &Difference) -> Value {
    let mut out = json!({
        "stage": d.stage.heading(),
        "path": d.path,
        "yours": d.yours,
        "glint": d.glint.clone().unwrap_or(Value::Null),
        "in_glint": d.glint.is_some(),
        "tolerance": tolerance_json(d.tolerance),
    });
    if let Some((gap, allowed)) = d.gap {
        out["apart"] = json!(gap);
        out["allowed"] = json!(allowed);
    }
    out
}

/// A tolerance's kind and the constants it uses, no others.
fn tolerance_json(tolerance: Tolerance) -> Value {
    let mut out = json!({ "kind": tolerance.name() });
    match tolerance {
        Tolerance::Relative | Tolerance::Vector | Tolerance::PeriodicU | Tolerance::Share => {
            out["relative"] = json!(RELATIVE);
            out["floor"] = json!(FLOOR);
        }
        Tolerance::Angular => {
            out["radians"] = json!(ANGLE);
            out["unit_length"] = json!(UNIT);
        }
        Tolerance::WithinOne => out["codes"] = json!(SRGB8_CODES),
        Tolerance::Levels => out["levels"] = json!(LEVEL),
        Tolerance::Exact => {}
    }
    out
}

/// The student's document `student` against Glint's `glint` (the whole
/// document for the same pixel and flags), comparing only `only`'s keys if
/// given. `Err` is an input error: not a `glint-explain/1` document,
/// another pixel, resolution, spp or seed, an unknown key at the top, or a
/// sample the flags do not follow.
pub fn compare(student: &Node, glint: &Value, only: Option<Stage>) -> Result<Comparison, String> {
    check_header(student, glint)?;
    check_light_sample_counts(student, glint)?;
    let mut walk = Walk {
        on_sphere: false,
        lookup_period: None,
        report_level: glint["texture_level"].as_str() == Some("report"),
        only,
        stages: Stage::ALL
            .iter()
            .map(|&stage| StageComparison {
                stage,
                compared: 0,
                differences: Vec::new(),
            })
            .collect(),
    };
    let Node::Object(entries) = student else {
        unreachable!("checked by check_header")
    };
    for (key, value) in entries {
        match key.as_str() {
            k if is_header(k) => {}
            "samples" => walk.samples(value, &glint["samples"])?,
            "film" => walk.tree(Stage::Film, "film", "film", value, glint.get("film")),
            other => {
                return Err(format!(
                    "unknown key \"{other}\" at the top of the document (a glint-explain/1 document holds schema, {}, seed, samples and film)",
                    SETTINGS.join(", ")
                ))
            }
        }
    }
    let pixel = &glint["pixel"];
    Ok(Comparison {
        texture_level: glint["texture_level"]
            .as_str()
            .unwrap_or("footprint")
            .to_owned(),
        samples_followed: match student.get("samples") {
            Some(Node::Array(samples)) => samples.len(),
            _ => 0,
        },
        samples_averaged: glint["film"]["samples_averaged"].as_u64().unwrap_or(1),
        only,
        pixel: (
            pixel[0].as_u64().unwrap_or(0),
            pixel[1].as_u64().unwrap_or(0),
        ),
        stages: walk.stages,
    })
}

/// The document is a `glint-explain/1` object for the same pixel,
/// resolution, spp and seed as Glint's (each where it gives them).
fn check_header(student: &Node, glint: &Value) -> Result<(), String> {
    if !matches!(student, Node::Object(_)) {
        return Err("not a JSON object: expected a glint-explain/1 document".to_owned());
    }
    match student.get("schema") {
        Some(Node::String(s)) if s == "glint-explain/1" => {}
        Some(other) => {
            return Err(format!(
                "schema is {}, expected \"glint-explain/1\"",
                other.to_value()
            ))
        }
        None => return Err("no \"schema\": expected \"schema\": \"glint-explain/1\"".to_owned()),
    }
    let differing: Vec<(&str, Value)> = SETTINGS
        .iter()
        .chain(&["seed"])
        .filter_map(|&key| Some((key, student.get(key)?.to_value())))
        .filter(|(key, yours)| !same(yours, &glint[*key]))
        .collect();
    if differing.is_empty() {
        return Ok(());
    }
    let settings = |values: &mut dyn Iterator<Item = (&str, &Value)>| {
        values
            .map(|(key, value)| format!("{key} {value}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    Err(format!(
        "the document records {}, but this command explains {}: pass {} (or record the settings your tracer used)",
        settings(&mut differing.iter().map(|(k, v)| (*k, v))),
        settings(&mut differing.iter().map(|(k, _)| (*k, &glint[*k]))),
        differing
            .iter()
            .map(|(key, yours)| flag_for(key, yours))
            .collect::<Vec<_>>()
            .join(" ")
    ))
}

/// Each light takes as many samples in the student's document as in
/// Glint's, where the document lists them: with another count (the
/// document records no settings) every sample's position differs for that
/// reason alone.
fn check_light_sample_counts(student: &Node, glint: &Value) -> Result<(), String> {
    let Some(Node::Array(samples)) = student.get("samples") else {
        return Ok(());
    };
    for (i, sample) in samples.iter().enumerate() {
        let index = match sample.get("sample") {
            Some(Node::Number(n)) => n.as_u64(),
            _ => Some(i as u64),
        };
        let theirs = glint["samples"]
            .as_array()
            .into_iter()
            .flatten()
            .find(|s| s["sample"].as_u64() == index);
        let (Some(mut ray), Some(mut glint_ray)) = (sample.get("ray"), theirs.map(|t| &t["ray"]))
        else {
            continue;
        };
        loop {
            let lights = ray.get("light").and_then(|l| l.get("lights"));
            if let Some(Node::Array(lights)) = lights {
                for (j, light) in lights.iter().enumerate() {
                    let yours = match light.get("samples") {
                        Some(Node::Array(s)) => s.len(),
                        _ => continue,
                    };
                    let Some(glints) = glint_ray["light"]["lights"][j]["samples"].as_array() else {
                        continue;
                    };
                    if yours != glints.len() {
                        return Err(format!(
                            "samples[{i}] takes {yours} sample{} of light {j} where this command takes {} (--light-samples {}, --light-sampler {}): pass --light-samples {yours} with the pattern your tracer used, or record it as \"light_samples\" and \"light_sampler\"",
                            if yours == 1 { "" } else { "s" },
                            glints.len(),
                            glint["light_samples"],
                            glint["light_sampler"].as_str().unwrap_or("?"),
                        ));
                    }
                }
            }
            match (ray.get("reflection"), glint_ray.get("reflection")) {
                (Some(r), Some(g)) if g.is_object() => (ray, glint_ray) = (r, g),
                _ => break,
            }
        }
    }
    Ok(())
}

/// The flag that gives the command the document's `value` of `key`.
fn flag_for(key: &str, value: &Value) -> String {
    let pair = |separator: &str| match value.as_array().map(Vec::as_slice) {
        Some([a, b]) => format!("{a}{separator}{b}"),
        _ => value.to_string(),
    };
    let plain = value
        .as_str()
        .map_or_else(|| value.to_string(), str::to_owned);
    match key {
        "pixel" => format!("--pixel {}", pair(",")),
        "resolution" => format!("--resolution {}", pair("x")),
        other => format!("--{} {plain}", other.replace('_', "-")),
    }
}

/// JSON values equal, numbers by value (`3` and `3.0` alike).
fn same(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => x.as_f64() == y.as_f64(),
        (Value::Array(x), Value::Array(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|(a, b)| same(a, b))
        }
        (Value::Object(x), Value::Object(y)) => {
            x.len() == y.len() && x.iter().all(|(k, v)| y.get(k).is_some_and(|w| same(v, w)))
        }
        _ => a == b,
    }
}

/// The comparison so far: each stage's count and differences.
struct Walk {
    only: Option<Stage>,
    stages: Vec<StageComparison>,
    /// Whether the ray being walked hit a sphere, whose u (the hit's, its
    /// texture lookup's) is compared modulo 1.
    on_sphere: bool,
    /// On a sphere, the period of the lookup coordinates' u made from it
    /// (`u·s_u + o_u`: `|s_u|`), while its texture stage is walked.
    lookup_period: Option<f64>,
    /// Whether Glint read its textures at the report's level
    /// (`--texture-level report`), where the level decides the footprint.
    report_level: bool,
}

impl Walk {
    /// The student's samples, each matched with Glint's sample of the same
    /// index (its `sample` key, else its place in the array).
    fn samples(&mut self, yours: &Node, glint: &Value) -> Result<(), String> {
        let Node::Array(samples) = yours else {
            return Err("samples is not an array".to_owned());
        };
        for (i, sample) in samples.iter().enumerate() {
            let index = match sample.get("sample") {
                Some(Node::Number(n)) => n.as_u64(),
                None => Some(i as u64),
                Some(_) => None,
            }
            .ok_or_else(|| format!("samples[{i}].sample is not a sample index"))?;
            let theirs = glint
                .as_array()
                .into_iter()
                .flatten()
                .find(|s| s["sample"].as_u64() == Some(index))
                .ok_or_else(|| {
                    format!(
                        "samples[{i}] is sample {index}, which this command does not follow: pass --sample {index} or --all-samples"
                    )
                })?;
            self.sample(&format!("samples[{i}]"), sample, theirs)?;
        }
        Ok(())
    }

    fn sample(&mut self, path: &str, yours: &Node, glint: &Value) -> Result<(), String> {
        let Node::Object(entries) = yours else {
            return Err(format!("{path} is not an object"));
        };
        for (key, value) in entries {
            let at = format!("{path}.{key}");
            match key.as_str() {
                "sample" => {}
                "camera" => self.tree(Stage::Camera, &at, key, value, glint.get(key)),
                "ray" => self.ray(&at, value, glint.get(key)),
                // The sample's radiance is its camera ray's.
                _ => self.tree(Stage::Light, &at, key, value, glint.get(key)),
            }
        }
        Ok(())
    }

    /// A ray: its keys by stage, its reflection a ray again.
    fn ray(&mut self, path: &str, yours: &Node, glint: Option<&Value>) {
        let (Node::Object(entries), Some(glint @ Value::Object(_))) = (yours, glint) else {
            return self.tree(Stage::Intersect, path, "ray", yours, glint);
        };
        let kind = glint.pointer("/intersect/hit/kind").and_then(Value::as_str);
        let outer = std::mem::replace(&mut self.on_sphere, kind == Some("sphere"));
        for (key, value) in in_pipeline_order(entries, self.report_level) {
            let at = format!("{path}.{key}");
            match key {
                "reflection" if glint.get(key).is_some() => self.ray(&at, value, glint.get(key)),
                "reflection" | "depth" | "intersect" | "object" | "triangle" => {
                    self.tree(Stage::Intersect, &at, key, value, glint.get(key))
                }
                "texture" => self.tree(Stage::Texture, &at, key, value, glint.get(key)),
                _ => self.tree(Stage::Light, &at, key, value, glint.get(key)),
            }
        }
        self.on_sphere = outer;
    }

    /// Any value of `stage` under `key`: objects key by key in pipeline
    /// order, arrays of objects element by element, anything else as one
    /// value.
    fn tree(&mut self, stage: Stage, path: &str, key: &str, yours: &Node, glint: Option<&Value>) {
        if self.only.is_some_and(|only| only != stage) {
            return;
        }
        match (yours, glint) {
            (Node::Object(entries), Some(Value::Object(theirs))) => {
                let on_sphere =
                    self.on_sphere || theirs.get("kind").and_then(Value::as_str) == Some("sphere");
                let scale_u = theirs.get("uv_scale").and_then(|s| s[0].as_f64());
                let outer = self.lookup_period;
                if let (true, Some(s)) = (on_sphere, scale_u) {
                    self.lookup_period = Some(s.abs());
                }
                for (k, v) in in_pipeline_order(entries, self.report_level) {
                    let at = format!("{path}.{k}");
                    let u_period = match k {
                        "uv" => on_sphere.then_some(1.0),
                        "material_uv" | "st" => self.lookup_period,
                        _ => None,
                    };
                    match (v, theirs.get(k)) {
                        (Node::Array(_), Some(g)) if u_period.is_some() || k == "uv" => {
                            let rule = Rule::Uv { u_period };
                            self.leaf(stage, &at, k, v, Some(g), Some(rule))
                        }
                        _ => self.tree(stage, &at, k, v, theirs.get(k)),
                    }
                }
                self.lookup_period = outer;
            }
            (Node::Array(items), Some(Value::Array(theirs))) if !is_vector(theirs) => {
                for (i, item) in items.iter().enumerate() {
                    self.tree(stage, &format!("{path}[{i}]"), key, item, theirs.get(i));
                }
            }
            _ => self.leaf(stage, path, key, yours, glint, None),
        }
    }

    /// One value compared as a whole, by `rule` if given, else by what its
    /// key and Glint's value are.
    fn leaf(
        &mut self,
        stage: Stage,
        path: &str,
        key: &str,
        yours: &Node,
        glint: Option<&Value>,
        rule: Option<Rule>,
    ) {
        let result = &mut self.stages[stage as usize];
        result.compared += 1;
        let yours = yours.to_value();
        let verdict = match glint {
            Some(g) => agree(key, &yours, g, rule),
            None => Err((Tolerance::Exact, None)),
        };
        if let Err((tolerance, gap)) = verdict {
            result.differences.push(Difference {
                stage,
                path: path.to_owned(),
                yours,
                glint: glint.cloned(),
                tolerance,
                gap,
            });
        }
    }
}

/// An object's entries in [`PIPELINE_ORDER`], the keys that describe
/// Glint's own work ([`SKIPPED`]) left out; keys not listed last, in the
/// document's order. At the report's level (`report_level`) the level is
/// computed first and decides the footprint: the lookups and their
/// `report_*` keys come before the footprint and the derivatives.
fn in_pipeline_order(entries: &[(String, Node)], report_level: bool) -> Vec<(&str, &Node)> {
    let mut keys: Vec<(&str, &Node)> = entries
        .iter()
        .filter(|(k, _)| !SKIPPED.contains(&k.as_str()))
        .map(|(k, v)| (k.as_str(), v))
        .collect();
    let position = |k: &str| {
        PIPELINE_ORDER
            .iter()
            .position(|p| *p == k)
            .unwrap_or(PIPELINE_ORDER.len())
    };
    // A texture stage's object: its lookups before its footprint.
    let texture = keys.iter().any(|(k, _)| *k == "footprint");
    let first = |k: &str| LEVEL_KEYS.contains(&k) || (texture && LOOKUPS.contains(&k));
    let place = |k: &str| match report_level && first(k) {
        true => (position("footprint"), 0),
        false => (position(k), 1),
    };
    keys.sort_by_key(|(k, _)| place(k));
    keys
}

/// The keys of a lookup's level, which at the report's level decides the
/// lookup's footprint and derivatives, and the lookups that hold them.
const LEVEL_KEYS: [&str; 5] = [
    "report_l",
    "report_w",
    "report_m",
    "report_level",
    "glint_level",
];
const LOOKUPS: [&str; 2] = ["diffuse", "specular"];

/// An array of numbers (or of nulls, Glint's non-finite numbers): a vector.
fn is_vector(items: &[Value]) -> bool {
    !items.is_empty() && items.iter().all(|v| v.is_number() || v.is_null())
}

type Verdict = Result<Tolerance, (Tolerance, Option<(f64, f64)>)>;

/// Whether `yours` agrees with Glint's `glint` under `key` (by `rule` if
/// given), and by which tolerance; on a failure, how far apart they are
/// where that is a number.
fn agree(key: &str, yours: &Value, glint: &Value, rule: Option<Rule>) -> Verdict {
    match (yours, glint) {
        (Value::Array(a), Value::Array(g)) if is_vector(g) => vector(key, a, g, rule),
        (Value::Number(a), Value::Number(g)) => number(key, a, g),
        _ if same(yours, glint) => Ok(Tolerance::Exact),
        _ => Err((Tolerance::Exact, None)),
    }
}

/// The 8-bit value's tolerance: the radiance is the student's own, and
/// one within tolerance may round either way.
const SRGB8_CODES: f64 = 1.0;

/// A number: integers exactly (Glint writes ids and counts as integers),
/// floats relatively.
fn number(key: &str, yours: &Number, glint: &Number) -> Verdict {
    let (a, g) = (
        yours.as_f64().unwrap_or(f64::NAN),
        glint.as_f64().unwrap_or(0.0),
    );
    match (glint.is_f64(), key) {
        (true, _) if LEVELS.contains(&key) => within(Tolerance::Levels, Rule::Level, &[g], &[a]),
        (true, "weight") => within(Tolerance::Share, Rule::Share, &[g], &[a]),
        (false, "srgb8") => within(
            Tolerance::WithinOne,
            Rule::Codes { codes: SRGB8_CODES },
            &[g],
            &[a],
        ),
        (false, _) => within(Tolerance::Exact, Rule::Codes { codes: 0.0 }, &[g], &[a]),
        (true, _) => within(Tolerance::Relative, Rule::Relative, &[g], &[a]),
    }
}

/// A vector: a unit direction by angle, integers exactly (or within 1 for
/// the 8-bit value), a uv by `rule` (a sphere's `u` modulo 1), anything
/// else component by component relative to its largest component.
fn vector(key: &str, yours: &[Value], glint: &[Value], rule: Option<Rule>) -> Verdict {
    let numbers = |v: &[Value]| v.iter().map(Value::as_f64).collect::<Option<Vec<f64>>>();
    let (Some(a), Some(g)) = (numbers(yours), numbers(glint)) else {
        // A null (a number that is not finite) must be matched exactly.
        return match same(&Value::from(yours.to_vec()), &Value::from(glint.to_vec())) {
            true => Ok(Tolerance::Exact),
            false => Err((Tolerance::Exact, None)),
        };
    };
    if a.len() != g.len() {
        return Err((Tolerance::Exact, None));
    }
    if glint
        .iter()
        .all(|v| !v.as_number().is_some_and(Number::is_f64))
    {
        return match key {
            "srgb8" => within(
                Tolerance::WithinOne,
                Rule::Codes { codes: SRGB8_CODES },
                &g,
                &a,
            ),
            _ => within(Tolerance::Exact, Rule::Codes { codes: 0.0 }, &g, &a),
        };
    }
    if DIRECTIONS.contains(&key) && rules::angle_between(&a, &g).is_some() {
        return within(Tolerance::Angular, Rule::Direction, &g, &a);
    }
    match rule {
        Some(rule @ Rule::Uv { u_period: Some(_) }) => within(Tolerance::PeriodicU, rule, &g, &a),
        _ => within(Tolerance::Vector, Rule::Vector, &g, &a),
    }
}

/// Glint's `g` against `a` under `rule`, reported as `tolerance`.
fn within(tolerance: Tolerance, rule: Rule, g: &[f64], a: &[f64]) -> Verdict {
    let gap = rules::measure(rule, g, a);
    if gap.agrees() {
        Ok(tolerance)
    } else {
        // NaN (a student's value that is no number) never agrees.
        Err((tolerance, Some((gap.apart, gap.allowed))))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn glint() -> Value {
        json!({
            "schema": "glint-explain/1", "pixel": [3, 4], "resolution": [8, 8],
            "spp": 1, "sampler": "grid", "light_samples": 1, "light_sampler": "grid",
            "environment_samples": 0, "seed": 0,
            "samples": [{
                "sample": 0,
                "camera": {"raster": [3.5, 4.5], "direction": [0.0, 0.6, -0.8]},
                "ray": {
                    "depth": 0,
                    "intersect": {"tests": [{"object": 0}], "hit": {"kind": "sphere", "object": 2, "t": 10.0, "uv": [0.9, 0.25]}},
                    "texture": {"diffuse": {"report_level": 2.0, "texels": [{"level": 2, "x": 1, "y": 1, "value": [0.5, 0.5, 0.5], "weight": 1.0}], "value": [0.5, 0.5, 0.5]}, "kd": [0.5, 0.5, 0.5]},
                    "light": {"lights": [{"samples": [{"shadow": "unoccluded", "specular": [1.7e-30, 0.0, 0.0]}]}]},
                    "radiance": {"value": [0.3, 0.3, 0.3]}
                },
                "radiance": [0.3, 0.3, 0.3]
            }],
            "film": {"radiance": [0.3, 0.3, 0.3], "srgb8": [149, 149, 149]}
        })
    }

    fn against(student: &str) -> Result<Comparison, String> {
        compare(&Node::parse(student).unwrap(), &glint(), None)
    }

    #[test]
    fn glints_own_document_agrees_and_a_json_object_keeps_the_files_order() {
        let doc = glint().to_string();
        let c = against(&doc).unwrap();
        assert!(c.agrees(), "{}", c.text("x"));
        // Every stage was compared, the BVH's tests skipped.
        let compared: Vec<usize> = c.stages.iter().map(|s| s.compared).collect();
        assert_eq!(compared, [2, 5, 8, 4, 2]);
        let node = Node::parse(r#"{"b": 1, "a": 2}"#).unwrap();
        let Node::Object(entries) = node else {
            panic!()
        };
        assert_eq!(entries[0].0, "b");
    }

    #[test]
    fn the_first_difference_is_in_pipeline_order_whatever_the_files_order() {
        // The film and the uv both differ, and the film comes first in the
        // file: the intersection is reported; within it, the object before
        // the uv though the file lists the uv first.
        let c = against(
            r#"{"schema": "glint-explain/1", "pixel": [3, 4],
                "film": {"radiance": [0.9, 0.3, 0.3]},
                "samples": [{"sample": 0, "ray": {"intersect": {"hit": {"t": 10.0, "uv": [0.6, 0.25], "object": 3}}}}]}"#,
        )
        .unwrap();
        let first = c.first().unwrap();
        assert_eq!(first.stage, Stage::Intersect);
        assert_eq!(first.path, "samples[0].ray.intersect.hit.object");
        assert_eq!(first.tolerance, Tolerance::Exact);
        assert_eq!(c.stages[Stage::Intersect as usize].differences.len(), 2);
        assert_eq!(c.stages[Stage::Film as usize].differences.len(), 1);
        // A lookup's level is compared before the value it decides.
        let c = against(
            r#"{"schema": "glint-explain/1", "pixel": [3, 4], "samples": [{"sample": 0, "ray":
                {"texture": {"diffuse": {"value": [0.4, 0.5, 0.5], "report_level": 2.9}}}}]}"#,
        )
        .unwrap();
        assert_eq!(
            c.first().unwrap().path,
            "samples[0].ray.texture.diffuse.report_level"
        );
    }

    #[test]
    fn a_level_is_compared_in_levels_as_grade_stages_compares_it() {
        let doc = |level: f64| {
            format!(
                r#"{{"schema": "glint-explain/1", "pixel": [3, 4], "samples": [{{"sample": 0, "ray":
                    {{"texture": {{"diffuse": {{"report_level": {level}}}}}}}}}]}}"#
            )
        };
        assert!(against(&doc(2.0029)).unwrap().agrees());
        let c = against(&doc(2.0031)).unwrap();
        assert_eq!(c.first().unwrap().tolerance, Tolerance::Levels);
    }

    #[test]
    fn a_spheres_u_is_compared_modulo_1_as_grade_stages_compares_it() {
        let c = against(
            r#"{"schema": "glint-explain/1", "pixel": [3, 4], "samples": [{"sample": 0, "ray":
                {"intersect": {"hit": {"uv": [-0.1, 0.25]}}}}]}"#,
        )
        .unwrap();
        assert!(c.agrees(), "{}", c.text("x"));
        let c = against(
            r#"{"schema": "glint-explain/1", "pixel": [3, 4], "samples": [{"sample": 0, "ray":
                {"intersect": {"hit": {"uv": [0.8, 0.25]}}}}]}"#,
        )
        .unwrap();
        assert_eq!(c.first().unwrap().tolerance, Tolerance::PeriodicU);
    }

    #[test]
    fn a_lookups_uv_on_a_sphere_wraps_and_at_the_reports_level_the_level_comes_first() {
        let mut g = glint();
        g["samples"][0]["ray"]["texture"]["footprint"] =
            json!({"uv": [0.9, 0.25], "duvdx": [0.01, 0.0]});
        let doc = r#"{"schema": "glint-explain/1", "pixel": [3, 4], "samples": [{"sample": 0, "ray":
            {"texture": {"footprint": {"uv": [-0.1, 0.25], "duvdx": [0.02, 0.0]},
                         "diffuse": {"report_level": 2.9}}}}]}"#;
        let c = compare(&Node::parse(doc).unwrap(), &g, None).unwrap();
        assert_eq!(
            c.first().unwrap().path,
            "samples[0].ray.texture.footprint.duvdx"
        );
        assert_eq!(
            c.stages[Stage::Texture as usize].differences.len(),
            2,
            "the uv agrees"
        );
        g["texture_level"] = json!("report");
        let c = compare(&Node::parse(doc).unwrap(), &g, None).unwrap();
        assert_eq!(
            c.first().unwrap().path,
            "samples[0].ray.texture.diffuse.report_level"
        );
        assert!(c.text("x").contains("textures at the report's level"));
    }

    #[test]
    fn a_film_that_differs_behind_agreeing_samples_asks_for_all_of_them() {
        let mut g = glint();
        g["film"]["samples_averaged"] = json!(4);
        let doc = r#"{"schema": "glint-explain/1", "pixel": [3, 4],
            "samples": [{"sample": 0, "camera": {"raster": [3.5, 4.5]}}],
            "film": {"radiance": [0.2, 0.3, 0.3]}}"#;
        let c = compare(&Node::parse(doc).unwrap(), &g, None).unwrap();
        assert_eq!(c.first().unwrap().stage, Stage::Film);
        assert!(c
            .text("x")
            .contains("the film averages all 4 of the pixel's: pass --all-samples"));
    }

    #[test]
    fn other_settings_are_named_before_any_number() {
        let err = against(
            r#"{"schema": "glint-explain/1", "pixel": [3, 4], "light_samples": 16, "light_sampler": "stratified",
                "samples": [{"sample": 0, "camera": {"raster": [9.0, 9.0]}}]}"#,
        )
        .unwrap_err();
        assert!(
            err.starts_with("the document records light_samples 16, light_sampler \"stratified\", but this command explains light_samples 1, light_sampler \"grid\""),
            "{err}"
        );
        assert!(
            err.contains("pass --light-samples 16 --light-sampler stratified"),
            "{err}"
        );
        // A document that records no settings but lists 2 light samples
        // where the command takes 1.
        let err = against(
            r#"{"schema": "glint-explain/1", "pixel": [3, 4], "samples": [{"sample": 0, "ray":
                {"light": {"lights": [{"samples": [{"shadow": "unoccluded"}, {"shadow": "unoccluded"}]}]}}}]}"#,
        )
        .unwrap_err();
        assert!(
            err.starts_with("samples[0] takes 2 samples of light 0 where this command takes 1 (--light-samples 1, --light-sampler grid)"),
            "{err}"
        );
    }

    #[test]
    fn tolerances_relative_angular_and_exact() {
        // 1e-4 relative passes; a tiny specular against zero passes; a
        // direction 0.5 mrad off passes and 5 mrad off does not.
        let ok = against(
            r#"{"schema": "glint-explain/1", "pixel": [3, 4], "samples": [{"sample": 0,
                "camera": {"raster": [3.5001, 4.5], "direction": [0.0004, 0.6, -0.8]},
                "ray": {"light": {"lights": [{"samples": [{"shadow": "unoccluded", "specular": [0.0, 0.0, 0.0]}]}]}}}]}"#,
        )
        .unwrap();
        assert!(ok.agrees(), "{}", ok.text("x"));
        let off = against(
            r#"{"schema": "glint-explain/1", "pixel": [3, 4], "samples": [{"sample": 0,
                "camera": {"direction": [0.004, 0.6, -0.8]}}]}"#,
        )
        .unwrap();
        assert_eq!(off.first().unwrap().tolerance, Tolerance::Angular);
        let blocked = against(
            r#"{"schema": "glint-explain/1", "pixel": [3, 4], "samples": [{"sample": 0,
                "ray": {"light": {"lights": [{"samples": [{"shadow": {"blocked_by": 1, "t": 0.5}}]}]}}}]}"#,
        )
        .unwrap();
        assert_eq!(blocked.first().unwrap().tolerance, Tolerance::Exact);
    }

    #[test]
    fn another_pixel_schema_or_sample_is_an_input_error() {
        let err = against(r#"{"schema": "glint-explain/1", "pixel": [4, 4]}"#).unwrap_err();
        assert!(err.contains("pass --pixel 4,4"), "{err}");
        let err = against(r#"{"schema": "glint-explain/2", "pixel": [3, 4]}"#).unwrap_err();
        assert!(err.contains("glint-explain/1"), "{err}");
        let err = against(
            r#"{"schema": "glint-explain/1", "pixel": [3, 4], "samples": [{"sample": 2}]}"#,
        )
        .unwrap_err();
        assert!(err.contains("--sample 2"), "{err}");
        let err = against(r#"{"schema": "glint-explain/1", "pixel": [3, 4], "author": "me"}"#)
            .unwrap_err();
        assert!(err.contains("author"), "{err}");
    }
}
