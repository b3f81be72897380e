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

mod comparison;
mod document;
mod keys;
mod walk;

pub use comparison::{Comparison, Difference, StageComparison, Tolerance};
pub use document::{located, Node};
use keys::*;
pub use keys::{PIPELINE_ORDER, SKIPPED};
use walk::{same, Walk};

use crate::Stage;
use serde_json::Value;

/// The student's document `student` against Glint's `glint` (the whole
/// document for the same pixel and flags), comparing only `only`'s keys if
/// given. `Err` is an input error: not a `glint-explain/1` document,
/// another pixel, resolution, spp or seed, an unknown key at the top, or a
/// sample the flags do not follow.
pub fn compare(student: &Node, glint: &Value, only: Option<Stage>) -> Result<Comparison, String> {
    check_header(student, glint)?;
    check_light_sample_counts(student, glint)?;
    let mut walk = Walk::new(only, glint["texture_level"].as_str() == Some("report"));
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
        stages: walk.into_stages(),
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

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

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
