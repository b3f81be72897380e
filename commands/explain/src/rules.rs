//! One rule per number: how a student's value is compared with Glint's.
//! `glint explain --against` and `glint grade --stages` both measure with
//! [`measure`], and the docs' tables state these constants
//! (`commands/explain/tests/docs_rules.rs` fails when they do not).
//!
//! - A number is within [`RELATIVE`] of Glint's, plus [`FLOOR`]: relative,
//!   since a distance in a scene of size 10 and one of size 1e4 are as hard
//!   to get right.
//! - A vector (a point, a colour, uv) component by component within
//!   [`RELATIVE`] times Glint's largest component, plus [`FLOOR`]; a sphere's
//!   `u` modulo 1, as `u = 0.9999` and `u = 0.0001` are the same point across
//!   its seam.
//! - A unit direction at most [`ANGLE`] radians from Glint's, of length 1
//!   within [`UNIT`].
//! - A MIP level within [`LEVEL`] levels; a texel's weight, a share of 1,
//!   within [`RELATIVE`] of 1.
//! - An 8-bit value exactly where the stage gives its input
//!   (`grade --stages`), within 1 where the radiance is the student's own
//!   (`explain --against`).
//! - A shadow ray with a fixed offset `ε` anywhere in [`SHADOW_EPSILON`]
//!   (times the scene's size) decides as Glint does wherever the stage tests
//!   it: the test vectors leave out the samples whose verdict it could flip.

/// The relative tolerance of numbers and vectors.
pub const RELATIVE: f64 = 1e-3;
/// The absolute floor added to the relative tolerance, so that a value Glint
/// rounds to almost nothing (a specular term of 1e-30) matches a zero.
pub const FLOOR: f64 = 1e-6;
/// The largest angle between two unit directions that agree, in radians:
/// about a fifth of a pixel of a 512-pixel, 45° image.
pub const ANGLE: f64 = 1e-3;
/// How far from 1 the length of an answered unit direction may be.
pub const UNIT: f64 = 1e-3;
/// A MIP level's tolerance, in levels: an error of [`RELATIVE`] in each of
/// `L` and `W` moves `log2(L/W)` by up to 0.0029.
pub const LEVEL: f64 = 3e-3;
/// The fixed shadow-ray offsets a ray tracer may use, as fractions of the
/// scene's size (the longest side of the box around its finite shapes):
/// from `1e-5` (above the rounding error of a hit point in 32-bit floats)
/// to `1e-4`. For the Cornell box, 23 units across: 2.3e-4 to 2.3e-3.
pub const SHADOW_EPSILON: [f64; 2] = [1e-5, 1e-4];

/// How a value is compared.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Rule {
    /// A number: `|yours − Glint's| ≤ RELATIVE·|Glint's| + FLOOR`.
    Relative,
    /// A vector: each component within `RELATIVE` times Glint's largest
    /// component, plus `FLOOR`.
    Vector,
    /// A uv: as a vector, `u` modulo its period where it wraps around (1 for
    /// a sphere's; `|s_u|` for the lookup coordinates `u·s_u + o_u` made
    /// from it).
    Uv { u_period: Option<f64> },
    /// A unit direction: at most `ANGLE` radians apart, of length 1 within
    /// `UNIT`.
    Direction,
    /// A MIP level: within `LEVEL`.
    Level,
    /// A share of a whole of 1 (a texel's weight in a lookup): within
    /// `RELATIVE` of the whole, plus `FLOOR`, as a component of a vector
    /// whose largest part is the whole.
    Share,
    /// Whole numbers within `codes` of each other (0: equal).
    Codes { codes: f64 },
}

/// How far apart two values are under a rule, and how far it allows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gap {
    pub apart: f64,
    pub allowed: f64,
    /// What `apart` measures where it is not the difference itself.
    pub note: Option<&'static str>,
}

impl Gap {
    /// Whether the values agree (a NaN never does).
    pub fn agrees(&self) -> bool {
        self.apart <= self.allowed
    }
}

/// Glint's `glint` against the student's `yours` (as many components each)
/// under `rule`.
pub fn measure(rule: Rule, glint: &[f64], yours: &[f64]) -> Gap {
    let largest = glint.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let relative = RELATIVE * largest + FLOOR;
    let gap = |apart, allowed| Gap {
        apart,
        allowed,
        note: None,
    };
    match rule {
        Rule::Relative | Rule::Vector => gap(largest_difference(glint, yours, None), relative),
        Rule::Uv { u_period } => gap(largest_difference(glint, yours, u_period), relative),
        Rule::Level => gap(largest_difference(glint, yours, None), LEVEL),
        Rule::Share => gap(largest_difference(glint, yours, None), RELATIVE + FLOOR),
        Rule::Codes { codes } => gap(largest_difference(glint, yours, None), codes),
        Rule::Direction => {
            let length = yours.iter().map(|x| x * x).sum::<f64>().sqrt();
            if (length - 1.0).abs() > UNIT {
                return Gap {
                    apart: (length - 1.0).abs(),
                    allowed: UNIT,
                    note: Some("not of unit length"),
                };
            }
            Gap {
                apart: angle_between(glint, yours).unwrap_or(f64::NAN),
                allowed: ANGLE,
                note: Some("radians"),
            }
        }
    }
}

/// The largest component difference, the first component modulo
/// `first_period` if given; NaN if any is (or the lengths differ).
fn largest_difference(glint: &[f64], yours: &[f64], first_period: Option<f64>) -> f64 {
    if glint.len() != yours.len() {
        return f64::NAN;
    }
    glint
        .iter()
        .zip(yours)
        .enumerate()
        .map(|(i, (g, y))| {
            let d = y - g;
            match first_period.filter(|p| i == 0 && *p > 0.0) {
                Some(p) => (d - p * (d / p).round()).abs(),
                None => d.abs(),
            }
        })
        .fold(0.0f64, |m, d| {
            if d.is_nan() || m.is_nan() {
                f64::NAN
            } else {
                m.max(d)
            }
        })
}

/// The angle between two vectors, `atan2(|a × b|, a·b)` (accurate at small
/// angles, where `acos` of a dot product near 1 is not); `None` if either
/// has no length.
pub fn angle_between(a: &[f64], b: &[f64]) -> Option<f64> {
    let dot: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    let length = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let (la, lb) = (length(a), length(b));
    if la == 0.0 || lb == 0.0 {
        return None;
    }
    let cross = match (a, b) {
        ([ax, ay, az], [bx, by, bz]) => {
            length(&[ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx])
        }
        _ => ((la * lb).powi(2) - dot * dot).max(0.0).sqrt(),
    };
    Some(cross.atan2(dot))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spheres_u_agrees_across_its_seam_and_nothing_else_wraps() {
        let sphere = Rule::Uv {
            u_period: Some(1.0),
        };
        let seam = measure(sphere, &[0.9999, 0.5], &[0.0001, 0.5]);
        assert!(seam.agrees(), "{seam:?}");
        let unwrapped = measure(sphere, &[0.836, 0.5], &[-0.164, 0.5]);
        assert!(unwrapped.agrees(), "{unwrapped:?}");
        // A lookup's coordinates u·4 + o repeat every 4.
        let scaled = Rule::Uv {
            u_period: Some(4.0),
        };
        assert!(measure(scaled, &[3.344, 0.5], &[-0.656, 0.5]).agrees());
        assert!(!measure(scaled, &[3.344, 0.5], &[2.344, 0.5]).agrees());
        let plain = Rule::Uv { u_period: None };
        assert!(!measure(plain, &[0.836, 0.5], &[-0.164, 0.5]).agrees());
        assert!(!measure(Rule::Vector, &[0.9999, 0.5], &[0.0001, 0.5]).agrees());
    }

    #[test]
    fn numbers_directions_levels_and_codes() {
        assert!(measure(Rule::Relative, &[20.0], &[20.019]).agrees());
        assert!(!measure(Rule::Relative, &[20.0], &[20.021]).agrees());
        assert!(measure(Rule::Relative, &[0.0], &[1e-30]).agrees());
        assert!(!measure(Rule::Relative, &[1.0], &[f64::NAN]).agrees());
        let turned = measure(
            Rule::Direction,
            &[0.0, 0.0, 1.0],
            &[0.002_f64.sin(), 0.0, 0.002_f64.cos()],
        );
        assert_eq!(turned.note, Some("radians"));
        assert!((turned.apart - 0.002).abs() < 1e-12 && !turned.agrees());
        let long = measure(Rule::Direction, &[0.0, 0.0, 1.0], &[0.0, 0.0, 2.0]);
        assert_eq!(long.note, Some("not of unit length"));
        assert!(measure(Rule::Level, &[2.0], &[2.0029]).agrees());
        assert!(!measure(Rule::Level, &[2.0], &[2.0031]).agrees());
        assert!(measure(Rule::Codes { codes: 1.0 }, &[149.0], &[150.0]).agrees());
        assert!(!measure(Rule::Codes { codes: 0.0 }, &[149.0], &[150.0]).agrees());
        assert!(!measure(Rule::Vector, &[1.0, 2.0], &[1.0]).agrees());
    }
}
