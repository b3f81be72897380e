//! The keys of a `glint-explain/1` document as `--against` treats them:
//! which describe Glint's own work, which are settings, directions and
//! levels, and the pipeline's order of them.

/// Keys that describe Glint's own queries (every object's test, the BVH's
/// work and path), not numbers a ray tracer must reproduce.
pub const SKIPPED: [&str; 3] = ["tests", "work", "bvh"];
/// Keys whose value is a unit direction, compared by angle.
pub(super) const DIRECTIONS: [&str; 10] = [
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
pub(super) const LEVELS: [&str; 2] = ["glint_level", "report_level"];
/// The document's own keys besides `samples` and `film`: its schema, its
/// [`SETTINGS`] and its seed.
pub(super) fn is_header(key: &str) -> bool {
    key == "schema" || key == "seed" || SETTINGS.contains(&key)
}
/// The settings a document records, checked before any number: with
/// other sample counts or patterns every later number differs for that
/// reason alone.
pub(super) const SETTINGS: [&str; 8] = [
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

/// The keys of a lookup's level, which at the report's level decides the
/// lookup's footprint and derivatives, and the lookups that hold them.
pub(super) const LEVEL_KEYS: [&str; 5] = [
    "report_l",
    "report_w",
    "report_m",
    "report_level",
    "glint_level",
];
pub(super) const LOOKUPS: [&str; 2] = ["diffuse", "specular"];
