//! Numbers as the document holds them (5 significant digits), and the
//! document cut down to one stage.

use crate::Stage;
use glam::{Vec2, Vec3};
use glint_geometry::{BvhRef, BvhVisit};
use glint_integrator::ReportLevel;
use glint_texture::LookupExplained;
use serde_json::{json, Value};

/// `x` rounded to 5 significant digits; `null` if not finite.
pub(crate) fn num(x: f32) -> Value {
    if !x.is_finite() {
        return Value::Null;
    }
    if x == 0.0 {
        return json!(0.0);
    }
    let rounded: f64 = format!("{:.4e}", x as f64).parse().expect("a float");
    json!(rounded)
}

pub(crate) fn v2(v: Vec2) -> Value {
    Value::Array(vec![num(v.x), num(v.y)])
}

pub(crate) fn v3(v: Vec3) -> Value {
    Value::Array(vec![num(v.x), num(v.y), num(v.z)])
}

/// A BVH node or leaf as `{"node": i}` or `{"leaf": i}`.
fn bvh_ref(r: BvhRef) -> Value {
    match r {
        BvhRef::Node(node) => json!({ "node": node }),
        BvhRef::Leaf(leaf) => json!({ "leaf": leaf }),
    }
}

/// The query's path through the BVH, one entry per step.
pub(crate) fn bvh_path(visits: &[BvhVisit]) -> Value {
    let step = |v: &BvhVisit| match v {
        BvhVisit::Node {
            node,
            depth,
            children,
        } => {
            let children: Vec<Value> = children
                .iter()
                .map(|c| {
                    let mut child = bvh_ref(c.child);
                    child["enter"] = c.enter.map_or(Value::Null, num);
                    child["visited"] = json!(c.visited);
                    child
                })
                .collect();
            json!({ "node": node, "depth": depth, "children": children })
        }
        BvhVisit::Leaf {
            leaf,
            depth,
            primitives,
            t_max,
        } => {
            let primitives: Vec<Value> = primitives
                .iter()
                .map(|p| match p.triangle {
                    Some(triangle) => json!({ "object": p.object, "triangle": triangle }),
                    None => json!({ "object": p.object }),
                })
                .collect();
            json!({ "leaf": leaf, "depth": depth, "t_max": num(*t_max), "primitives": primitives })
        }
    };
    Value::Array(visits.iter().map(step).collect())
}

/// What a texture lookup read; for an image, with the report's level
/// `report` (`None`: not a camera ray's hit, or not finite).
pub(crate) fn lookup(l: &LookupExplained, report: Option<ReportLevel>) -> Value {
    let mut out = json!({ "kind": l.kind, "value": v3(l.value) });
    if let (Some(st), Some(dx), Some(dy)) = (l.st, l.dst_dx, l.dst_dy) {
        out["st"] = v2(st);
        out["dst_dx"] = v2(dx);
        out["dst_dy"] = v2(dy);
        out["report_level"] = report.map_or(Value::Null, |r| num(r.level));
        if let Some(r) = report {
            out["report_l"] = num(r.l);
            out["report_w"] = num(r.w);
            out["report_m"] = json!(r.m);
        }
    }
    if let Some(level) = l.glint_level {
        out["glint_level"] = num(level);
    }
    if !l.texels.is_empty() {
        out["texels"] = l
            .texels
            .iter()
            .map(|t| {
                json!({"level": t.level, "x": t.x, "y": t.y, "weight": num(t.weight), "value": v3(t.value)})
            })
            .collect();
    }
    if let Some(f) = l.second_color_fraction {
        out["second_color_fraction"] = num(f);
    }
    out
}

/// The document with only `stage`'s parts of each sample (and the header).
pub(crate) fn only_stage(document: &Value, stage: Stage) -> Value {
    let mut out = document.clone();
    let ray_keys: &[&str] = match stage {
        Stage::Intersect => &["depth", "intersect"],
        Stage::Texture => &["depth", "texture"],
        Stage::Light => &[
            "depth",
            "shading",
            "light",
            "environment",
            "emitter",
            "mirror",
            "radiance",
        ],
        Stage::Camera | Stage::Film => &[],
    };
    if let Some(samples) = out["samples"].as_array_mut() {
        for sample in samples {
            let Some(map) = sample.as_object_mut() else {
                continue;
            };
            map.retain(|k, _| {
                k == "sample"
                    || (k == "camera" && stage == Stage::Camera)
                    || (k == "ray" && !ray_keys.is_empty())
            });
            if let Some(ray) = map.get_mut("ray") {
                keep_ray_keys(ray, ray_keys);
            }
        }
    }
    if stage != Stage::Film {
        if let Some(map) = out.as_object_mut() {
            map.remove("film");
        }
    }
    out
}

/// Keeps `keys` (and the nested reflections) of a ray and its reflections.
fn keep_ray_keys(ray: &mut Value, keys: &[&str]) {
    if let Some(map) = ray.as_object_mut() {
        map.retain(|k, _| k == "reflection" || keys.contains(&k.as_str()));
        if let Some(reflection) = map.get_mut("reflection") {
            keep_ray_keys(reflection, keys);
        }
    }
}
