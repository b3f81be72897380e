//! What `--against` found: per stage, the keys compared and the first that
//! differ, each with its tolerance; as text and as JSON.

use crate::rules::{ANGLE, FLOOR, LEVEL, RELATIVE, UNIT};
use crate::Stage;
use serde_json::{json, Value};

/// The 8-bit value's tolerance: the radiance is the student's own, and
/// one within tolerance may round either way.
pub(super) const SRGB8_CODES: f64 = 1.0;

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
