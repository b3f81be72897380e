//! What every stage shares: a case's values by column, the fields its
//! expected values are checked by, and where the case comes from.
//!
//! A stage's files are tables: one row per case, one column per number. A
//! *field* groups the columns that are checked together (the three of a
//! direction, the two of a uv) under one tolerance ([`Check`]).

use glam::{Vec2, Vec3};
use std::collections::BTreeMap;

/// One cell of a case: a number Glint computed in `f32`, an integer, a
/// boolean, a word, or nothing (a value that does not apply, such as the `t`
/// of a miss).
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Empty,
    Float(f32),
    Int(i64),
    Bool(bool),
    Text(String),
}

impl Value {
    /// The cell as CSV text. Floats are printed in the shortest form that
    /// reads back as the same `f32`, so a reader in any language gets Glint's
    /// number exactly: as a decimal, or with an exponent below 1e-5 and from
    /// 1e16 (`8.626776e-35`, not 34 zeros).
    pub fn csv(&self) -> String {
        match self {
            Value::Empty => String::new(),
            Value::Float(x) => float_text(*x),
            Value::Int(i) => i.to_string(),
            Value::Bool(b) => b.to_string(),
            Value::Text(s) => s.clone(),
        }
    }

    /// The cell as JSON (`null` for [`Value::Empty`] and non-finite numbers).
    pub fn json(&self) -> serde_json::Value {
        match self {
            Value::Empty => serde_json::Value::Null,
            // Through the shortest decimal, so that JSON shows `0.7`, not
            // the f64 nearest the f32 (`0.699999988079071`).
            Value::Float(x) => float_text(*x)
                .parse::<f64>()
                .ok()
                .and_then(serde_json::Number::from_f64)
                .map_or(serde_json::Value::Null, serde_json::Value::Number),
            Value::Int(i) => serde_json::Value::from(*i),
            Value::Bool(b) => serde_json::Value::Bool(*b),
            Value::Text(s) => serde_json::Value::String(s.clone()),
        }
    }

    /// The number, for comparison.
    pub fn number(&self) -> Option<f64> {
        match self {
            Value::Float(x) => Some(f64::from(*x)),
            Value::Int(i) => Some(*i as f64),
            _ => None,
        }
    }
}

/// `x` in the shortest form that reads back as the same `f32` (Rust's
/// `Display` and `LowerExp` both give the fewest digits that do); −0 is
/// written as 0, the same number to every reader.
fn float_text(x: f32) -> String {
    let x = x + 0.0;
    let magnitude = x.abs();
    if magnitude != 0.0 && !(1e-5..1e16).contains(&magnitude) {
        format!("{x:e}")
    } else {
        x.to_string()
    }
}

/// What kind of value a column holds, which decides how an answer is read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Float,
    Int,
    Bool,
    Text,
}

/// How an expected field is compared with an answer. The constants are
/// `glint explain --against`'s ([`glint_explain::against`]), so the two
/// checks agree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Check {
    /// A scalar: `|a − e| ≤ 1e-3·|e| + 1e-6`.
    Relative,
    /// A vector (point, color): each component within `1e-3·max|e_i| + 1e-6`.
    Vector,
    /// A unit direction: at most 1e-3 radians from Glint's, and of length
    /// 1 within 1e-3.
    Direction,
    /// A uv: as [`Check::Vector`], with `u` compared modulo 1 on objects
    /// whose `u` wraps around (spheres), so `0.9999` and `0.0001` agree.
    Uv,
    /// A MIP level, a logarithm: within 0.003 levels (an error of 1e-3 in
    /// each of `L` and `W` moves `log2(L/W)` by up to 0.0029).
    Level,
    /// Equal: hit or miss, object ids, shadow verdicts, 8-bit codes.
    Exact,
    /// Shown, never checked (an object's name).
    Info,
}

impl Check {
    /// The tolerance in words, for reports and the files' headers, from
    /// the constants of [`glint_explain::rules`].
    pub fn describe(self) -> String {
        use glint_explain::rules::{ANGLE, FLOOR, LEVEL, RELATIVE, UNIT};
        let vector = format!(
            "each component within {RELATIVE:e} × (Glint's largest |component|) + {FLOOR:e}"
        );
        match self {
            Check::Relative => format!("within {RELATIVE:e} × |Glint's| + {FLOOR:e}"),
            Check::Vector => vector,
            Check::Direction => {
                format!("at most {ANGLE:e} radians from Glint's, and of length 1 within {UNIT:e}")
            }
            Check::Uv => format!("{vector}; u modulo 1 on spheres"),
            Check::Level => format!("within {LEVEL} levels"),
            Check::Exact => "equal".into(),
            Check::Info => "not checked".into(),
        }
    }

    /// The name JSON reports give the tolerance.
    pub fn name(self) -> &'static str {
        match self {
            Check::Relative => "relative",
            Check::Vector => "relative to the largest component",
            Check::Direction => "angular",
            Check::Uv => "uv",
            Check::Level => "absolute",
            Check::Exact => "exact",
            Check::Info => "not checked",
        }
    }
}

/// Columns checked together.
#[derive(Clone, Debug, PartialEq)]
pub struct Field {
    pub name: String,
    pub columns: Vec<String>,
    pub kind: Kind,
    pub check: Check,
    /// An answer may leave its columns out (a scene without meshes, whose
    /// shading normals are its geometric normals); given, they are checked.
    pub optional: bool,
}

impl Field {
    /// One column.
    pub fn scalar(name: &str, kind: Kind, check: Check) -> Field {
        Field {
            name: name.to_owned(),
            columns: vec![name.to_owned()],
            kind,
            check,
            optional: false,
        }
    }

    /// `NAME_x`, `NAME_y`, `NAME_z`.
    pub fn xyz(name: &str, check: Check) -> Field {
        Self::suffixed(name, &XYZ, check)
    }

    /// `NAME_r`, `NAME_g`, `NAME_b`.
    pub fn rgb(name: &str, check: Check) -> Field {
        Self::suffixed(name, &RGB, check)
    }

    /// `NAME_r`, `NAME_g`, `NAME_b` as integers (8-bit codes).
    pub fn rgb_codes(name: &str) -> Field {
        Field {
            kind: Kind::Int,
            ..Self::suffixed(name, &RGB, Check::Exact)
        }
    }

    /// This field, which an answer may leave out.
    pub fn optional(self) -> Field {
        Field {
            optional: true,
            ..self
        }
    }

    /// The two columns `u` and `v`.
    pub fn uv() -> Field {
        Field {
            name: "uv".to_owned(),
            columns: vec!["u".to_owned(), "v".to_owned()],
            kind: Kind::Float,
            check: Check::Uv,
            optional: false,
        }
    }

    fn suffixed(name: &str, suffixes: &[&str], check: Check) -> Field {
        Field {
            name: name.to_owned(),
            columns: suffixes.iter().map(|s| format!("{name}_{s}")).collect(),
            kind: Kind::Float,
            check,
            optional: false,
        }
    }
}

pub const XYZ: [&str; 3] = ["x", "y", "z"];
pub const RGB: [&str; 3] = ["r", "g", "b"];

/// A stage's columns: the inputs a student is given and the fields Glint
/// expects back.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    pub inputs: Vec<String>,
    pub expected: Vec<Field>,
}

impl Layout {
    /// Every expected column, in order.
    pub fn expected_columns(&self) -> impl Iterator<Item = &str> {
        self.expected
            .iter()
            .flat_map(|f| f.columns.iter().map(String::as_str))
    }

    /// The field `column` belongs to.
    pub fn field_of(&self, column: &str) -> Option<&Field> {
        self.expected
            .iter()
            .find(|f| f.columns.iter().any(|c| c == column))
    }
}

/// The pixel and camera sample a case was derived from: camera sample
/// `sample` of `spp` on the grid pattern of pixel `pixel`, and why the pixel
/// was picked.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Origin {
    pub pixel: [u32; 2],
    pub sample: u32,
    pub spp: u32,
    pub why: &'static str,
}

/// One test vector: its id, its cells by column, and where it comes from
/// (none for the film's chosen values).
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    pub id: String,
    pub values: BTreeMap<String, Value>,
    pub from: Option<Origin>,
    /// Whether the expected `u` wraps around (a sphere's): compared modulo 1.
    pub periodic_u: bool,
}

impl Case {
    pub fn new(from: Option<Origin>) -> Case {
        Case {
            id: String::new(),
            values: BTreeMap::new(),
            from,
            periodic_u: false,
        }
    }

    /// The cell of `column` ([`Value::Empty`] if unset).
    pub fn get(&self, column: &str) -> &Value {
        self.values.get(column).unwrap_or(&Value::Empty)
    }

    pub fn set(&mut self, column: impl Into<String>, value: Value) -> &mut Case {
        self.values.insert(column.into(), value);
        self
    }

    pub fn float(&mut self, column: &str, x: f32) -> &mut Case {
        self.set(column, Value::Float(x))
    }

    pub fn int(&mut self, column: &str, i: i64) -> &mut Case {
        self.set(column, Value::Int(i))
    }

    /// `NAME_x`, `NAME_y`, `NAME_z`.
    pub fn xyz(&mut self, name: &str, v: Vec3) -> &mut Case {
        for (s, x) in XYZ.iter().zip(v.to_array()) {
            self.float(&format!("{name}_{s}"), x);
        }
        self
    }

    /// `NAME_r`, `NAME_g`, `NAME_b`.
    pub fn rgb(&mut self, name: &str, c: Vec3) -> &mut Case {
        for (s, x) in RGB.iter().zip(c.to_array()) {
            self.float(&format!("{name}_{s}"), x);
        }
        self
    }

    /// `u` and `v`.
    pub fn uv(&mut self, uv: Vec2) -> &mut Case {
        self.float("u", uv.x).float("v", uv.y)
    }
}

/// Gives the cases ids `STAGE-001`, `STAGE-002`, … in order (at least three
/// digits, more for more cases, so that ids sort in case order).
pub fn number(stage: &str, cases: &mut [Case]) {
    let digits = cases.len().to_string().len().max(3);
    for (i, case) in cases.iter_mut().enumerate() {
        case.id = format!("{stage}-{:0digits$}", i + 1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floats_are_written_so_they_read_back_as_the_same_f32() {
        for x in [
            0.7f32,
            1.0 / 3.0,
            1e-30,
            -2.5e7,
            0.0031308,
            8.626776e-35,
            3e38,
            1e-45,
        ] {
            let text = Value::Float(x).csv();
            assert_eq!(text.parse::<f32>().unwrap(), x, "{text}");
            let json = Value::Float(x).json();
            assert_eq!(json.as_f64().unwrap() as f32, x, "{json}");
        }
        assert_eq!(Value::Float(0.7).json().to_string(), "0.7");
        assert_eq!(Value::Float(f32::NAN).json(), serde_json::Value::Null);
        assert_eq!(Value::Empty.csv(), "");
        assert_eq!(Value::Float(-0.0).csv(), "0");
        assert_eq!(Value::Float(8.626776e-35).csv(), "8.626776e-35");
        assert_eq!(Value::Float(1e-10).csv(), "1e-10");
        assert_eq!(Value::Float(1e6).csv(), "1000000");
    }

    #[test]
    fn ids_are_numbered_in_order_with_enough_digits() {
        let mut few = vec![Case::new(None); 3];
        number("film", &mut few);
        assert_eq!(few[2].id, "film-003");
        let mut many = vec![Case::new(None); 1200];
        number("camera", &mut many);
        assert_eq!(many[0].id, "camera-0001");
        assert_eq!(many[1199].id, "camera-1200");
    }

    #[test]
    fn a_fields_columns_follow_its_name() {
        assert_eq!(
            Field::xyz("direction", Check::Direction).columns,
            ["direction_x", "direction_y", "direction_z"]
        );
        let mut case = Case::new(None);
        case.rgb("kd", Vec3::new(0.1, 0.2, 0.3));
        assert_eq!(case.get("kd_g"), &Value::Float(0.2));
        assert_eq!(case.get("kd_a"), &Value::Empty);
    }
}
