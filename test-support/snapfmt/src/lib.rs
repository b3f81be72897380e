//! Formatting for snapshot tests: floats rounded to five significant digits, so
//! that snapshots stay identical across machines, compilers and instruction sets
//! while still locking every stage's numbers tightly.
//!
//! # Entry points
//! [`sig5`] for one `f32`; [`vec3`] and [`vec2`] for glam vectors.

use glam::{Vec2, Vec3};

/// `x` rounded to five significant digits, printed in its shortest form.
/// Negative zero prints as `0` so that sign-of-zero noise never shows up in a diff.
pub fn sig5(x: f32) -> String {
    if x == 0.0 {
        return "0".into();
    }
    if !x.is_finite() {
        return format!("{x}");
    }
    let rounded: f64 = format!("{:.4e}", x as f64).parse().expect("valid float");
    format!("{rounded}")
}

/// A vector as `(x, y, z)` with each component passed through [`sig5`].
pub fn vec3(v: Vec3) -> String {
    format!("({}, {}, {})", sig5(v.x), sig5(v.y), sig5(v.z))
}

/// A 2-vector as `(x, y)` with each component passed through [`sig5`].
pub fn vec2(v: Vec2) -> String {
    format!("({}, {})", sig5(v.x), sig5(v.y))
}

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounds_to_five_significant_digits() {
        assert_eq!(sig5(1.234_567), "1.2346");
        assert_eq!(sig5(-0.000_123_456_7), "-0.00012346");
        assert_eq!(sig5(-0.0), "0");
        assert_eq!(sig5(123_456.0), "123460");
        assert_eq!(vec3(Vec3::new(1.0, 0.5, -2.0)), "(1, 0.5, -2)");
    }
}
