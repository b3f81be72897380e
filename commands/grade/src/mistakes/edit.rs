//! Mistakes as changes to the scene file: each edits the TOML document
//! (`docs/scene-format.md`'s keys) so that Glint's correct render of the
//! edited scene is the mistaken render of the original. An edit returns
//! whether it changed anything: one that does not applies to no image of
//! this scene.

use toml::{Table, Value};

/// What an edit may depend on besides the scene.
#[derive(Clone, Copy, Debug)]
pub struct Context {
    /// The submission's width over its height.
    pub aspect: f64,
    /// Its light samples per camera sample, if stated.
    pub light_samples: Option<u32>,
}

/// An edit of the scene document.
pub type Edit = fn(&mut Table, &Context) -> bool;

/// `ambient = [0, 0, 0]`.
pub fn no_ambient(scene: &mut Table, _: &Context) -> bool {
    let lit = scene
        .get("ambient")
        .and_then(colour)
        .is_some_and(|c| c.iter().any(|&x| x != 0.0));
    if lit {
        scene.insert("ambient".into(), colour_value([0.0; 3]));
    }
    lit
}

/// Each material's `specular` replaced by its `diffuse`.
pub fn ks_as_kd(scene: &mut Table, _: &Context) -> bool {
    let mut changed = false;
    for material in tables_in(scene, "materials") {
        let Some(diffuse) = material.get("diffuse").cloned() else {
            continue;
        };
        if material.get("specular").is_some_and(|s| *s != diffuse) {
            material.insert("specular".into(), diffuse);
            changed = true;
        }
    }
    changed
}

/// Every Phong lobe made Blinn–Phong's, the exponent kept.
pub fn blinn(scene: &mut Table, _: &Context) -> bool {
    let mut changed = false;
    for material in tables_in(scene, "materials") {
        let phong = match material.get("lobe") {
            None => true,
            Some(lobe) => lobe.as_str() == Some("phong"),
        };
        if phong {
            material.insert("lobe".into(), Value::String("blinn-phong".into()));
            changed = true;
        }
    }
    changed
}

/// The vertical fov whose half width, at the image's aspect, the stated
/// fov gives: `2·atan(tan(fov/2) / aspect)`.
pub fn fov_horizontal(scene: &mut Table, context: &Context) -> bool {
    if (context.aspect - 1.0).abs() < 1e-9 {
        return false;
    }
    edit_fov(scene, |half| Some((half.tan() / context.aspect).atan()))
}

/// The vertical fov whose half height is `tan(fov)`: twice the fov, for a
/// fov under 90°.
pub fn fov_not_halved(scene: &mut Table, _: &Context) -> bool {
    edit_fov(scene, |half| {
        let fov = 2.0 * half;
        (fov < std::f64::consts::FRAC_PI_2).then_some(fov)
    })
}

/// The camera's `fov` (degrees) replaced by the one `new_half` gives for
/// half of it (radians), when it gives one.
fn edit_fov(scene: &mut Table, new_half: impl Fn(f64) -> Option<f64>) -> bool {
    let Some(camera) = scene.get_mut("camera").and_then(Value::as_table_mut) else {
        return false;
    };
    let Some(fov) = camera.get("fov").and_then(number) else {
        return false;
    };
    let Some(half) = new_half(fov.to_radians() / 2.0) else {
        return false;
    };
    camera.insert("fov".into(), Value::Float((2.0 * half).to_degrees()));
    true
}

/// Every checkerboard's `checks` doubled.
pub fn checker_double(scene: &mut Table, _: &Context) -> bool {
    each_texture(scene, &["checkerboard", "checker_image"], |pattern| {
        let Some(Value::Integer(n)) = pattern.get("checks").cloned() else {
            return false;
        };
        pattern.insert("checks".into(), Value::Integer(2 * n));
        true
    })
}

/// Every image texture (and checkerboard image) read at its nearest texel.
pub fn nearest_texel(scene: &mut Table, _: &Context) -> bool {
    each_texture(scene, &["image", "checker_image"], |image| {
        let nearest = image.get("filter").and_then(Value::as_str) == Some("nearest");
        if !nearest {
            image.insert("filter".into(), Value::String("nearest".into()));
        }
        !nearest
    })
}

/// Applies `edit` to the table of each texture of one of `kinds`
/// (`[textures.NAME.KIND]`); whether any changed.
fn each_texture(
    scene: &mut Table,
    kinds: &[&str],
    mut edit: impl FnMut(&mut Table) -> bool,
) -> bool {
    let mut changed = false;
    for texture in tables_in(scene, "textures") {
        for kind in kinds {
            if let Some(table) = texture.get_mut(*kind).and_then(Value::as_table_mut) {
                changed |= edit(table);
            }
        }
    }
    changed
}

/// Each area light's `color` times the light samples: their sum, not their
/// mean (nothing changes at one sample).
pub fn sum_light_samples(scene: &mut Table, context: &Context) -> bool {
    let Some(samples) = context.light_samples.filter(|&l| l > 1) else {
        return false;
    };
    each_light(scene, "area_light", |light| {
        let c = light.get("color").and_then(colour).unwrap_or([1.0; 3]);
        light.insert(
            "color".into(),
            colour_value(c.map(|x| x * f64::from(samples))),
        );
        c != [0.0; 3]
    })
}

/// Each area light shrunk to a thousandth of its size: every sample at its
/// centre.
pub fn light_centre(scene: &mut Table, _: &Context) -> bool {
    scale_area_lights(scene, 1e-3)
}

/// Each area light twice its size.
pub fn light_twice_size(scene: &mut Table, _: &Context) -> bool {
    scale_area_lights(scene, 2.0)
}

fn scale_area_lights(scene: &mut Table, factor: f64) -> bool {
    each_light(scene, "area_light", |light| {
        let mut scaled = false;
        for edge in ["edge1", "edge2"] {
            if let Some(e) = light.get(edge).and_then(colour) {
                light.insert(edge.into(), colour_value(e.map(|x| x * factor)));
                scaled = true;
            }
        }
        scaled
    })
}

/// Every light's `color` white.
pub fn light_colour_ignored(scene: &mut Table, _: &Context) -> bool {
    let mut changed = false;
    for kind in ["area_light", "point_light"] {
        changed |= each_light(scene, kind, |light| {
            let coloured = light
                .get("color")
                .and_then(colour)
                .is_some_and(|c| c != [1.0; 3]);
            light.insert("color".into(), colour_value([1.0; 3]));
            coloured
        });
    }
    changed
}

/// Each area light doubled by one facing the other way: light from both
/// sides (the back one is invisible from the front, as the front one is
/// from behind).
pub fn two_sided_light(scene: &mut Table, _: &Context) -> bool {
    let Some(Value::Array(lights)) = scene.get_mut("area_light") else {
        return false;
    };
    let mut backs = Vec::new();
    for light in lights.iter() {
        let Some(light) = light.as_table() else {
            continue;
        };
        let (Some(e1), Some(e2)) = (
            light.get("edge1").and_then(colour),
            light.get("edge2").and_then(colour),
        ) else {
            continue;
        };
        let normal = light
            .get("normal")
            .and_then(colour)
            .unwrap_or_else(|| cross(e1, e2));
        let mut back = light.clone();
        back.insert("normal".into(), colour_value(normal.map(|x| -x)));
        if let Some(Value::String(name)) = back.get("name").cloned() {
            back.insert("name".into(), Value::String(format!("{name} (back)")));
        }
        backs.push(Value::Table(back));
    }
    let changed = !backs.is_empty();
    lights.extend(backs);
    changed
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Applies `edit` to each table of the array `kind` (`area_light`); whether
/// any changed.
fn each_light(scene: &mut Table, kind: &str, mut edit: impl FnMut(&mut Table) -> bool) -> bool {
    let Some(Value::Array(lights)) = scene.get_mut(kind) else {
        return false;
    };
    let mut changed = false;
    for light in lights.iter_mut().filter_map(Value::as_table_mut) {
        changed |= edit(light);
    }
    changed
}

/// The tables under `scene[key]` (`materials.NAME`).
fn tables_in<'a>(scene: &'a mut Table, key: &str) -> impl Iterator<Item = &'a mut Table> {
    scene
        .get_mut(key)
        .and_then(Value::as_table_mut)
        .into_iter()
        .flat_map(|t| t.iter_mut().filter_map(|(_, v)| v.as_table_mut()))
}

fn number(v: &Value) -> Option<f64> {
    match v {
        Value::Integer(i) => Some(*i as f64),
        Value::Float(f) => Some(*f),
        _ => None,
    }
}

/// A colour or vector: three numbers, or one for all three.
fn colour(v: &Value) -> Option<[f64; 3]> {
    match v {
        Value::Array(a) if a.len() == 3 => {
            let n: Vec<f64> = a.iter().filter_map(number).collect();
            <[f64; 3]>::try_from(n).ok()
        }
        other => number(other).map(|x| [x; 3]),
    }
}

fn colour_value(c: [f64; 3]) -> Value {
    Value::Array(c.iter().map(|&x| Value::Float(x)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    const CONTEXT: Context = Context {
        aspect: 2.0,
        light_samples: Some(16),
    };

    fn edited(text: &str, edit: Edit) -> (bool, Table) {
        let mut table: Table = text.parse().unwrap();
        let changed = edit(&mut table, &CONTEXT);
        (changed, table)
    }

    #[test]
    fn fovs_are_the_ones_the_mistaken_camera_sees() {
        let (changed, t) = edited("[camera]\nfov = 45\n", fov_not_halved);
        assert!(changed);
        let fov = t["camera"]["fov"].as_float().unwrap();
        assert!((fov - 90.0).abs() < 1e-9, "half height tan(45°): fov 90°");
        let (changed, _) = edited("[camera]\nfov = 100\n", fov_not_halved);
        assert!(!changed, "tan(fov) past 90° is no camera");
        let (_, t) = edited("[camera]\nfov = 90\n", fov_horizontal);
        let fov = t["camera"]["fov"].as_float().unwrap();
        assert!((fov - 2.0 * 0.5f64.atan().to_degrees()).abs() < 1e-9);
    }

    #[test]
    fn edits_that_change_nothing_say_so() {
        let (changed, _) = edited("ambient = [0, 0, 0]\n", no_ambient);
        assert!(!changed);
        let (changed, t) = edited("ambient = 0.1\n", no_ambient);
        assert!(changed);
        assert_eq!(colour(&t["ambient"]), Some([0.0; 3]));
        let (changed, _) = edited("[materials.m]\ndiffuse = [1, 0, 0]\n", ks_as_kd);
        assert!(!changed, "no specular: ks is kd already");
        let (changed, _) = edited("[[area_light]]\ncolor = [1, 1, 1]\n", light_colour_ignored);
        assert!(!changed);
        let mut one = CONTEXT;
        one.light_samples = Some(1);
        let mut t: Table = "[[area_light]]\ncolor = [1, 1, 1]\n".parse().unwrap();
        assert!(!sum_light_samples(&mut t, &one));
    }

    #[test]
    fn lights_and_textures_are_edited_in_place() {
        let text = "[[area_light]]\ncenter = [0, 5, 0]\nedge1 = [2, 0, 0]\nedge2 = [0, 0, 2]\n\
                    [textures.c.checkerboard]\ncolors = [[0, 0, 0], [1, 1, 1]]\nchecks = 4\n";
        let (_, t) = edited(text, light_twice_size);
        assert_eq!(colour(&t["area_light"][0]["edge1"]), Some([4.0, 0.0, 0.0]));
        let (_, t) = edited(text, sum_light_samples);
        assert_eq!(colour(&t["area_light"][0]["color"]), Some([16.0; 3]));
        let (_, t) = edited(text, checker_double);
        assert_eq!(
            t["textures"]["c"]["checkerboard"]["checks"].as_integer(),
            Some(8)
        );
        let (changed, t) = edited(text, two_sided_light);
        assert!(changed);
        let lights = t["area_light"].as_array().unwrap();
        assert_eq!(lights.len(), 2);
        assert_eq!(colour(&lights[1]["normal"]), Some([0.0, 4.0, 0.0]));
    }
}
