//! The text form of an explanation: the document's numbers, stage by stage,
//! mirror reflections indented under the ray that spawned them.

use serde_json::Value;
use std::fmt::Write;

/// A number, vector or other value as the text shows it.
fn f(v: &Value) -> String {
    match v {
        Value::Null => "none".into(),
        Value::Number(n) => n.to_string(),
        Value::Array(items) => {
            let parts: Vec<String> = items.iter().map(f).collect();
            format!("({})", parts.join(", "))
        }
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// Appends `key value` pairs of `object` that exist, on one line.
fn pairs(out: &mut String, indent: &str, object: &Value, keys: &[(&str, &str)]) {
    let parts: Vec<String> = keys
        .iter()
        .filter(|(key, _)| !object[*key].is_null())
        .map(|(key, label)| format!("{label} {}", f(&object[*key])))
        .collect();
    if !parts.is_empty() {
        writeln!(out, "{indent}{}", parts.join("   ")).unwrap();
    }
}

pub(crate) fn render(doc: &Value) -> String {
    let mut out = String::new();
    writeln!(
        out,
        "pixel {} of {} x {}, {} samples per pixel, seed {}",
        f(&doc["pixel"]),
        doc["resolution"][0],
        doc["resolution"][1],
        doc["spp"],
        doc["seed"]
    )
    .unwrap();
    for sample in doc["samples"].as_array().into_iter().flatten() {
        writeln!(out, "\nsample {}", sample["sample"]).unwrap();
        if !sample["camera"].is_null() {
            camera(&mut out, &sample["camera"]);
        }
        if !sample["ray"].is_null() {
            ray_text(&mut out, &sample["ray"]);
        }
        if !sample["radiance"].is_null() {
            writeln!(out, "  sample radiance {}", f(&sample["radiance"])).unwrap();
        }
    }
    if !doc["film"].is_null() {
        let film = &doc["film"];
        writeln!(out, "\nfilm").unwrap();
        writeln!(
            out,
            "  pixel radiance {} (mean of {} samples; linear)",
            f(&film["radiance"]),
            film["samples_averaged"]
        )
        .unwrap();
        writeln!(
            out,
            "  sRGB 8-bit {} (as written to a PNG)",
            f(&film["srgb8"])
        )
        .unwrap();
    }
    let mistake = &doc["mistake"];
    if !mistake.is_null() {
        let id = mistake["id"].as_str().unwrap_or_default();
        let stage = mistake["stage"].as_str().unwrap_or_default();
        let what = mistake["description"].as_str().unwrap_or_default();
        writeln!(out, "\nwith the mistake {id} ({stage} stage: {what})").unwrap();
        let radiance = f(&mistake["radiance"]);
        writeln!(
            out,
            "  pixel radiance {radiance} (linear; as its file reads back)"
        )
        .unwrap();
        writeln!(
            out,
            "  sRGB 8-bit {} (as written to a PNG)",
            f(&mistake["srgb8"])
        )
        .unwrap();
        writeln!(
            out,
            "  (the stages above are right; from the {stage} stage on, a tracer with it parts from them)"
        )
        .unwrap();
    }
    out
}

fn camera(out: &mut String, c: &Value) {
    writeln!(out, "  camera").unwrap();
    pairs(
        out,
        "    ",
        c,
        &[
            ("raster", "raster"),
            ("ndc", "ndc"),
            ("film_point", "film point"),
        ],
    );
    pairs(
        out,
        "    ",
        c,
        &[("origin", "ray origin"), ("direction", "direction")],
    );
    let d = &c["differentials"];
    if !d.is_null() {
        pairs(
            out,
            "    ",
            d,
            &[
                ("rx_direction", "differential x direction"),
                ("ry_direction", "y direction"),
            ],
        );
    }
}

/// The BVH path, a step per line, indented by depth below the root.
fn bvh_text(out: &mut String, sub: &str, path: &Value) {
    let Some(steps) = path.as_array().filter(|s| !s.is_empty()) else {
        return;
    };
    writeln!(out, "{sub}BVH path, in traversal order").unwrap();
    let name = |v: &Value| match (&v["node"], &v["leaf"]) {
        (Value::Null, leaf) => format!("leaf {leaf}"),
        (node, _) => format!("node {node}"),
    };
    for step in steps {
        let depth = step["depth"].as_u64().unwrap_or(0) as usize;
        let at = format!("{sub}  {}", "  ".repeat(depth));
        if step["node"].is_null() {
            let primitives = leaf_primitives_text(&step["primitives"]);
            let limit = match &step["t_max"] {
                Value::Null => "no hit yet".to_owned(),
                // The nearest hit so far, widened by PRUNE_SCALE.
                t => format!("prunes beyond t = {}", f(t)),
            };
            writeln!(out, "{at}{} ({limit}): tests {}", name(step), primitives).unwrap();
        } else {
            let children: Vec<String> = step["children"]
                .as_array()
                .into_iter()
                .flatten()
                .map(|c| match (&c["enter"], &c["visited"]) {
                    (Value::Null, _) => format!("{} missed", name(c)),
                    (t, Value::Bool(true)) => format!("{} at t = {}", name(c), f(t)),
                    (t, _) => format!("{} at t = {} (pruned)", name(c), f(t)),
                })
                .collect();
            writeln!(out, "{at}{}: {}", name(step), children.join(", ")).unwrap();
        }
    }
}

/// A leaf's primitives, a mesh's triangles after their object:
/// `object 1 triangles 4, 5, object 3`.
fn leaf_primitives_text(primitives: &Value) -> String {
    let mut groups: Vec<(Value, Vec<String>)> = Vec::new();
    for p in primitives.as_array().into_iter().flatten() {
        let triangle = (!p["triangle"].is_null()).then(|| p["triangle"].to_string());
        match groups.last_mut() {
            Some((object, triangles)) if *object == p["object"] && triangle.is_some() => {
                triangles.extend(triangle)
            }
            _ => groups.push((p["object"].clone(), triangle.into_iter().collect())),
        }
    }
    let parts: Vec<String> = groups
        .iter()
        .map(|(object, triangles)| match triangles.len() {
            0 => format!("object {object}"),
            1 => format!("object {object} triangle {}", triangles[0]),
            _ => format!("object {object} triangles {}", triangles.join(", ")),
        })
        .collect();
    parts.join(", ")
}

fn ray_text(out: &mut String, ray: &Value) {
    let depth = ray["depth"].as_u64().unwrap_or(0) as usize;
    let indent = "  ".repeat(2 * depth + 1);
    let sub = format!("{indent}  ");
    if depth > 0 {
        let parent = "  ".repeat(2 * depth);
        writeln!(out, "{parent}reflection ray, depth {depth}").unwrap();
    }
    let i = &ray["intersect"];
    if !i.is_null() {
        writeln!(out, "{indent}intersection").unwrap();
        pairs(
            out,
            &sub,
            i,
            &[("origin", "origin"), ("direction", "direction")],
        );
        for test in i["tests"].as_array().into_iter().flatten() {
            let hit = match &test["t"] {
                Value::Null => "miss".to_owned(),
                t => match &test["triangle"] {
                    Value::Null => format!("t = {}", f(t)),
                    tri => format!("t = {} (triangle {tri})", f(t)),
                },
            };
            writeln!(
                out,
                "{sub}object {} {}: {hit}",
                test["object"],
                f(&test["kind"])
            )
            .unwrap();
        }
        let w = &i["work"];
        writeln!(
            out,
            "{sub}the query's work: {} BVH nodes, {} leaves, {} shape tests, {} triangle tests",
            w["bvh_nodes"], w["bvh_leaves"], w["shape_tests"], w["triangle_tests"]
        )
        .unwrap();
        bvh_text(out, &sub, &i["bvh"]);
        match &i["hit"] {
            Value::Null => writeln!(out, "{sub}no hit").unwrap(),
            h => {
                writeln!(
                    out,
                    "{sub}hit object {} ({}) at t = {}{}",
                    h["object"],
                    f(&h["kind"]),
                    f(&h["t"]),
                    if h["front_face"] == Value::Bool(true) {
                        ", front face"
                    } else {
                        ", back face"
                    }
                )
                .unwrap();
                pairs(out, &sub, h, &[("point", "point"), ("uv", "uv")]);
                pairs(
                    out,
                    &sub,
                    h,
                    &[
                        ("geometric_normal", "geometric normal"),
                        ("shading_normal", "shading normal"),
                    ],
                );
                pairs(out, &sub, h, &[("dpdu", "dp/du"), ("dpdv", "dp/dv")]);
            }
        }
    }
    if !ray["environment"].is_null() {
        let e = &ray["environment"];
        writeln!(out, "{indent}environment").unwrap();
        pairs(
            out,
            &sub,
            e,
            &[
                ("direction", "direction"),
                ("filter_width", "filter width"),
                ("radiance", "radiance"),
            ],
        );
    }
    if !ray["emitter"].is_null() {
        writeln!(
            out,
            "{indent}light seen directly: radiance {}",
            f(&ray["emitter"]["radiance"])
        )
        .unwrap();
    }
    texture(out, &ray["texture"], &indent);
    lighting(out, ray, &indent);
    if !ray["mirror"].is_null() {
        pairs(
            out,
            &sub,
            &ray["mirror"],
            &[
                ("reflectivity", "mirror: reflectivity"),
                ("tint", "tint"),
                ("direction", "direction"),
            ],
        );
    }
    if !ray["reflection"].is_null() {
        ray_text(out, &ray["reflection"]);
    }
    if !ray["radiance"].is_null() {
        pairs(
            out,
            &sub,
            &ray["radiance"],
            &[
                ("local", "radiance: local"),
                ("mirror", "mirror"),
                ("value", "total"),
            ],
        );
    }
}

fn texture(out: &mut String, t: &Value, indent: &str) {
    if t.is_null() {
        return;
    }
    let sub = format!("{indent}  ");
    writeln!(out, "{indent}texture").unwrap();
    let fp = &t["footprint"];
    pairs(
        out,
        &sub,
        fp,
        &[("uv", "uv"), ("duvdx", "duv/dx"), ("duvdy", "duv/dy")],
    );
    for (key, label) in [("diffuse", "diffuse"), ("specular", "specular")] {
        let l = &t[key];
        if l.is_null() {
            continue;
        }
        if let Value::String(s) = l {
            writeln!(out, "{sub}{label}: {s}").unwrap();
            continue;
        }
        writeln!(out, "{sub}{label}: {} -> {}", f(&l["kind"]), f(&l["value"])).unwrap();
        let deeper = format!("{sub}  ");
        pairs(
            out,
            &deeper,
            l,
            &[("st", "st"), ("dst_dx", "dst/dx"), ("dst_dy", "dst/dy")],
        );
        levels_text(out, &deeper, l);
        texels_text(out, &deeper, &l["texels"]);
    }
    pairs(out, &sub, t, &[("kd", "kd"), ("ks", "ks")]);
}

/// A lookup's levels on one line: the report's `log2(L/W)` with its `L`, `W`
/// and `m`, Glint's, and a checkerboard's second color's fraction.
fn levels_text(out: &mut String, indent: &str, l: &Value) {
    let mut parts = Vec::new();
    if !l["report_level"].is_null() {
        parts.push(format!(
            "level log2(L/W) {} (L {}, W {}, m {})",
            f(&l["report_level"]),
            f(&l["report_l"]),
            f(&l["report_w"]),
            f(&l["report_m"])
        ));
    }
    for (key, label) in [
        ("glint_level", "Glint's level"),
        ("second_color_fraction", "second color's fraction"),
    ] {
        if !l[key].is_null() {
            parts.push(format!("{label} {}", f(&l[key])));
        }
    }
    if !parts.is_empty() {
        writeln!(out, "{indent}{}", parts.join("   ")).unwrap();
    }
}

/// Texels listed in full up to this many; beyond (an EWA ellipse), each
/// level's count and share and the heaviest texels.
const TEXELS_LISTED: usize = 16;

/// The texels a lookup read, with their weights.
fn texels_text(out: &mut String, indent: &str, texels: &Value) {
    let texels: Vec<&Value> = texels.as_array().into_iter().flatten().collect();
    if texels.len() <= TEXELS_LISTED {
        texels.iter().for_each(|t| texel_line(out, indent, t));
        return;
    }
    texel_levels_text(out, indent, &texels);
    heaviest_texels_text(out, indent, &texels);
}

fn texel_weight(texel: &Value) -> f64 {
    texel["weight"].as_f64().unwrap_or(0.0)
}

/// Each level's texel count and weight sum, in the order read.
fn texel_levels_text(out: &mut String, indent: &str, texels: &[&Value]) {
    let mut levels: Vec<(u64, usize, f64)> = Vec::new();
    for t in texels {
        let level = t["level"].as_u64().unwrap_or(0);
        match levels.iter_mut().find(|(l, _, _)| *l == level) {
            Some((_, count, sum)) => {
                *count += 1;
                *sum += texel_weight(t);
            }
            None => levels.push((level, 1, texel_weight(t))),
        }
    }
    for (level, count, sum) in levels {
        let sum = crate::json::num(sum as f32);
        writeln!(
            out,
            "{indent}level {level}: {count} texels, weights adding up to {}",
            f(&sum)
        )
        .unwrap();
    }
}

/// The heaviest half of [`TEXELS_LISTED`] texels, and how many are left.
fn heaviest_texels_text(out: &mut String, indent: &str, texels: &[&Value]) {
    let shown = TEXELS_LISTED / 2;
    let mut heaviest = texels.to_vec();
    heaviest.sort_by(|a, b| texel_weight(b).total_cmp(&texel_weight(a)));
    writeln!(out, "{indent}the {shown} heaviest:").unwrap();
    let deeper = format!("{indent}  ");
    for t in &heaviest[..shown] {
        texel_line(out, &deeper, t);
    }
    writeln!(
        out,
        "{indent}and {} more (the JSON lists every texel)",
        texels.len() - shown
    )
    .unwrap();
}

fn texel_line(out: &mut String, indent: &str, texel: &Value) {
    writeln!(
        out,
        "{indent}texel ({}, {}) of level {}: weight {}, value {}",
        texel["x"],
        texel["y"],
        texel["level"],
        f(&texel["weight"]),
        f(&texel["value"])
    )
    .unwrap();
}

fn shadow(s: &Value) -> String {
    match s {
        Value::String(s) => s.clone(),
        Value::Object(o) if o.contains_key("not_traced") => {
            format!("no shadow ray ({})", f(&s["not_traced"]))
        }
        Value::Object(o) if o.contains_key("missed_light") => match &s["missed_light"]["hit"] {
            Value::Null => "the lobe ray leaves the scene without reaching the light".into(),
            object => format!(
                "the lobe ray hits object {object} first, at t = {}",
                f(&s["missed_light"]["t"])
            ),
        },
        Value::Object(_) => format!(
            "blocked by object {} at t = {}",
            f(&s["blocked_by"]),
            f(&s["t"])
        ),
        other => f(other),
    }
}

fn lighting(out: &mut String, ray: &Value, indent: &str) {
    let sub = format!("{indent}  ");
    let light = &ray["light"];
    if !ray["shading"].is_null() || !light.is_null() {
        writeln!(out, "{indent}lighting").unwrap();
        pairs(
            out,
            &sub,
            &ray["shading"],
            &[("n", "n"), ("ng", "ng"), ("v", "v")],
        );
    }
    if !light.is_null() {
        if !light["ambient"].is_null() {
            writeln!(out, "{sub}ambient·kd {}", f(&light["ambient"])).unwrap();
        }
        for l in light["lights"].as_array().into_iter().flatten() {
            writeln!(out, "{sub}light {} ({})", l["light"], f(&l["kind"])).unwrap();
            let deeper = format!("{sub}  ");
            for (k, s) in l["samples"].as_array().into_iter().flatten().enumerate() {
                writeln!(out, "{deeper}sample {k}: {}", shadow(&s["shadow"])).unwrap();
                let d3 = format!("{deeper}  ");
                pairs(
                    out,
                    &d3,
                    s,
                    &[
                        ("technique", "by"),
                        ("position", "position"),
                        ("l", "l"),
                        ("n_dot_l", "n·l"),
                    ],
                );
                pairs(
                    out,
                    &d3,
                    s,
                    &[
                        ("reflection", "r"),
                        ("diffuse", "diffuse"),
                        ("specular", "specular"),
                    ],
                );
                pairs(
                    out,
                    &d3,
                    s,
                    &[
                        ("f_cos", "f·cos"),
                        ("light_pdf", "light pdf"),
                        ("lobe_pdf", "lobe pdf"),
                        ("mis_weight", "MIS weight"),
                    ],
                );
                pairs(
                    out,
                    &d3,
                    s,
                    &[
                        ("value", "adds"),
                        ("running_average", "running average"),
                        ("running_sum", "running sum"),
                    ],
                );
            }
            writeln!(out, "{deeper}total {}", f(&l["total"])).unwrap();
        }
        let env = &light["environment"];
        if !env.is_null() {
            writeln!(out, "{sub}environment").unwrap();
            let deeper = format!("{sub}  ");
            for (k, s) in env["samples"].as_array().into_iter().flatten().enumerate() {
                writeln!(out, "{deeper}sample {k}: {}", shadow(&s["shadow"])).unwrap();
                pairs(
                    out,
                    &format!("{deeper}  "),
                    s,
                    &[
                        ("direction", "direction"),
                        ("pdf", "pdf"),
                        ("radiance", "radiance"),
                    ],
                );
                pairs(
                    out,
                    &format!("{deeper}  "),
                    s,
                    &[("f_cos", "f·cos"), ("value", "adds")],
                );
            }
            writeln!(out, "{deeper}total {}", f(&env["total"])).unwrap();
        }
    }
}
