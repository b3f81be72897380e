//! One stage of a student's document walked beside Glint's: keys in the
//! pipeline's order, each number, vector, direction or level held to its
//! rule.

use crate::rules::{self, Rule};
use crate::Stage;
use serde_json::{Number, Value};

use super::comparison::{Difference, StageComparison, Tolerance, SRGB8_CODES};
use super::document::Node;
use super::keys::*;

/// The comparison so far: each stage's count and differences.
pub(super) struct Walk {
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
    /// A walk of the stages `only` names (all of them without), of a
    /// document read at the report's texture level or not.
    pub(super) fn new(only: Option<Stage>, report_level: bool) -> Walk {
        Walk {
            on_sphere: false,
            lookup_period: None,
            report_level,
            only,
            stages: Stage::ALL
                .iter()
                .map(|&stage| StageComparison {
                    stage,
                    compared: 0,
                    differences: Vec::new(),
                })
                .collect(),
        }
    }

    /// Each stage's count and differences.
    pub(super) fn into_stages(self) -> Vec<StageComparison> {
        self.stages
    }

    /// The student's samples, each matched with Glint's sample of the same
    /// index (its `sample` key, else its place in the array).
    pub(super) fn samples(&mut self, yours: &Node, glint: &Value) -> Result<(), String> {
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
    pub(super) fn tree(
        &mut self,
        stage: Stage,
        path: &str,
        key: &str,
        yours: &Node,
        glint: Option<&Value>,
    ) {
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

/// JSON values equal, numbers by value (`3` and `3.0` alike).
pub(super) fn same(a: &Value, b: &Value) -> bool {
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
