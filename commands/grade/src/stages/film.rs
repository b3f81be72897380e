//! The film stage: a pixel's linear radiance to the 8-bit sRGB code a PNG
//! stores, [`glint_camera::linear_to_srgb8`] per channel: clamp to [0, 1],
//! the sRGB curve (IEC 61966-2-1: `12.92·c` up to `c = 0.0031308`, else
//! `1.055·c^(1/2.4) − 0.055`), times 255, rounded to nearest (halves up).
//!
//! Codes are checked exactly. The inputs are given to the student as
//! numbers that read back as Glint's own `f32`, and none lies within
//! [`MARGIN`] of a code's rounding boundary (`k + ½`), where `f32` and `f64`
//! arithmetic could round apart; anywhere else a correct program gets the
//! same code.

use super::probe::{collect, Plan, Probe};
use super::table::{Case, Field, Layout};
use super::Context;
use crate::GradeError;
use glam::Vec3;
use glint_camera::linear_to_srgb8;

/// How near (in codes) a value may come to a rounding boundary `k + ½`.
const MARGIN: f64 = 0.005;

/// Chosen values: below 0, 0, tiny, the curve's toe `0.0031308` and either
/// side of it, mid-grey, just below 1, 1, above 1 and huge, then the values
/// just below and above the boundaries between codes 0 | 1, 1 | 2, 10 | 11,
/// 64 | 65, 127 | 128, 200 | 201 and 254 | 255 (a hundredth of a code either
/// side, [`boundary_pairs`]).
const CHOSEN: [f32; 12] = [
    -0.5,
    0.0,
    1e-10,
    0.003_130_8,
    0.003,
    0.0032,
    0.18,
    0.5,
    0.99,
    1.0,
    1.5,
    1e6,
];

/// The codes whose upper rounding boundaries [`boundary_pairs`] straddles.
const BOUNDARY_CODES: [u32; 7] = [0, 1, 10, 64, 127, 200, 254];

/// Inputs `radiance_r/g/b` (linear); expected `srgb8_r/g/b` (0 to 255).
pub fn layout() -> Layout {
    Layout {
        inputs: ["radiance_r", "radiance_g", "radiance_b"]
            .map(String::from)
            .to_vec(),
        expected: vec![Field::rgb_codes("srgb8")],
    }
}

/// The sRGB curve in `f64`, times 255: where a value falls between codes.
fn encoded(c: f64) -> f64 {
    let c = c.clamp(0.0, 1.0);
    let e = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    e * 255.0
}

/// The inverse of [`encoded`]: the linear value encoded as `code`.
fn decoded(code: f64) -> f64 {
    let e = code / 255.0;
    if e <= 0.04045 {
        e / 12.92
    } else {
        ((e + 0.055) / 1.055).powf(2.4)
    }
}

/// Whether `c` is at least [`MARGIN`] from every rounding boundary.
fn clear(c: f32) -> bool {
    let e = encoded(c.into());
    (e - e.floor() - 0.5).abs() >= MARGIN
}

/// The linear values a hundredth of a code below and above each boundary
/// `k + ½` of [`BOUNDARY_CODES`].
fn boundary_pairs() -> Vec<f32> {
    BOUNDARY_CODES
        .iter()
        .flat_map(|&k| [-0.01, 0.01].map(|d| decoded(k as f64 + 0.5 + d) as f32))
        .collect()
}

/// The chosen values, three to a case.
fn chosen_cases() -> Vec<Case> {
    let values: Vec<f32> = CHOSEN.into_iter().chain(boundary_pairs()).collect();
    values
        .chunks(3)
        .map(|c| {
            let mut rgb = [0.5; 3];
            rgb[..c.len()].copy_from_slice(c);
            case(Vec3::from_array(rgb), None)
        })
        .collect()
}

fn case(radiance: Vec3, from: Option<super::table::Origin>) -> Case {
    let mut case = Case::new(from);
    case.rgb("radiance", radiance);
    for (channel, c) in ["r", "g", "b"].iter().zip(radiance.to_array()) {
        case.int(&format!("srgb8_{channel}"), linear_to_srgb8(c).into());
    }
    case
}

/// `n` cases: the chosen values (up to half of them), then pixels' radiance
/// as the render writes it (the mean of the pixel's samples): spread over
/// the image, pixels that see a light (past 1), and edges between objects.
pub fn cases(cx: &Context, n: usize) -> Result<Vec<Case>, GradeError> {
    let mut chosen = chosen_cases();
    chosen.truncate(n.div_ceil(2));
    let s = &cx.survey;
    let plans = vec![
        Plan::new("spread over the image", 0.0, s.stratified(|_| true)),
        Plan::new(
            "sees a light",
            0.1,
            s.awkward(|p| s.info(p).emitter).into_iter(),
        ),
        Plan::new(
            "an edge between objects",
            0.1,
            s.awkward(|p| s.on_edge(p)).into_iter(),
        ),
    ];
    let pixels = collect(cx.scene, cx.settings, n - chosen.len(), plans, pixel_case)?;
    Ok(pixels.into_iter().chain(chosen).collect())
}

fn pixel_case(p: &Probe) -> Option<Case> {
    let r = p.radiance;
    (r.is_finite() && r.to_array().into_iter().all(clear)).then(|| case(r, Some(p.from.clone())))
}

#[cfg(test)]
mod tests {
    use super::super::table::Value;
    use super::*;

    #[test]
    fn the_boundary_values_round_to_the_codes_either_side() {
        let pairs = boundary_pairs();
        for (pair, k) in pairs.chunks(2).zip(BOUNDARY_CODES) {
            assert_eq!(u32::from(linear_to_srgb8(pair[0])), k, "{pair:?}");
            assert_eq!(u32::from(linear_to_srgb8(pair[1])), k + 1, "{pair:?}");
            assert!(clear(pair[0]) && clear(pair[1]));
        }
    }

    #[test]
    fn the_chosen_values_cover_the_curve() {
        let cases = chosen_cases();
        let codes: Vec<i64> = cases
            .iter()
            .flat_map(|c| ["srgb8_r", "srgb8_g", "srgb8_b"].map(|k| c.get(k).clone()))
            .map(|v| match v {
                Value::Int(i) => i,
                other => panic!("{other:?}"),
            })
            .collect();
        // -0.5, 0, 1e-10 → 0; the toe 0.0031308 → 10; 1, 1.5, 1e6 → 255.
        assert_eq!(&codes[..4], [0, 0, 0, 10]);
        assert_eq!(&codes[9..12], [255, 255, 255]);
        // Every chosen value is clear of a boundary, and the encoder in f64
        // rounds as Glint's does in f32.
        for c in CHOSEN {
            assert!(clear(c), "{c}");
            let e = encoded(c.into());
            assert_eq!(
                i64::from(linear_to_srgb8(c)),
                (e + 0.5).floor() as i64,
                "{c}"
            );
        }
    }
}
