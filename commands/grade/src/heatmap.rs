//! The heat map of a grade: the submission in dim gray, each fine block
//! tinted by its strongest evidence, red where the submission is too bright
//! and blue where it is too dark: untinted within the noise (|z| ≤ 2), fully
//! coloured from the z where the test starts to reject; rejected objects are
//! striped in their colour.

use crate::reference::BACKGROUND;
use crate::test::{Outcome, Place};
use crate::ImageGrade;
use glam::Vec3;
use glint_camera::{linear_to_srgb8, Film};
use statrs::distribution::{ContinuousCDF, Normal};

const TOO_BRIGHT: Vec3 = Vec3::new(1.0, 0.15, 0.1);
const TOO_DARK: Vec3 = Vec3::new(0.1, 0.45, 1.0);

/// The heat map of `grade` over `submission`, as 8-bit sRGB rows from the
/// top; `objects` is the object each pixel's centre sees.
pub fn heatmap(grade: &ImageGrade, submission: &Film, objects: &[u32]) -> Vec<u8> {
    let width = submission.resolution().x as usize;
    let critical = critical_z(&grade.outcome);
    let block_z = strongest_fine_block_z(grade, submission.pixels().len(), width);
    let striped = rejected_objects(grade);
    let mut out = Vec::with_capacity(submission.pixels().len() * 3);
    for (i, pixel) in submission.pixels().iter().enumerate() {
        let gray = 0.35 * pixel.dot(Vec3::new(0.2126, 0.7152, 0.0722)).clamp(0.0, 1.0);
        let mut colour = Vec3::splat(gray);
        let z = block_z[i];
        if z != 0.0 {
            let weight = tint_weight(z, critical);
            colour = colour.lerp(tint(z), weight);
        }
        let (x, y) = (i % width, i / width);
        if let Some(&(_, z)) = striped.iter().find(|(object, _)| *object == objects[i]) {
            if (x + y) % 8 < 2 {
                colour = tint(z);
            }
        }
        out.extend(colour.to_array().map(linear_to_srgb8));
    }
    out
}

/// Per pixel, the signed z of the strongest channel of its fine block.
fn strongest_fine_block_z(grade: &ImageGrade, pixels: usize, width: usize) -> Vec<f64> {
    let fine_side = grade.regions.iter().find_map(|place| match place {
        Place::Block { x0, x1, .. } => Some(x1 - x0),
        Place::Object { .. } => None,
    });
    let mut block_z = vec![0.0f64; pixels];
    for finding in &grade.outcome.findings {
        let Place::Block { x0, y0, x1, y1 } = grade.regions[finding.region] else {
            continue;
        };
        // Fine blocks come first and are the narrowest (a last one may be
        // wider by a remainder); coarse ones are four times as wide.
        if Some(x1 - x0) >= fine_side.map(|s| 2 * s) {
            continue;
        }
        for y in y0 as usize..y1 as usize {
            for cell in &mut block_z[y * width + x0 as usize..y * width + x1 as usize] {
                if finding.z.abs() > cell.abs() {
                    *cell = finding.z;
                }
            }
        }
    }
    block_z
}

/// The objects whose own test was rejected, with the signed z of their
/// strongest channel.
fn rejected_objects(grade: &ImageGrade) -> Vec<(u32, f64)> {
    let mut objects: Vec<(u32, f64)> = Vec::new();
    for finding in grade.outcome.findings.iter().filter(|f| f.rejected) {
        if let Place::Object { object } = grade.regions[finding.region] {
            let object = object.unwrap_or(BACKGROUND);
            match objects.iter_mut().find(|(o, _)| *o == object) {
                Some(entry) if finding.z.abs() > entry.1.abs() => entry.1 = finding.z,
                Some(_) => {}
                None => objects.push((object, finding.z)),
            }
        }
    }
    objects
}

/// How strongly a block is tinted: not at all within the noise (|z| ≤ 2),
/// rising to 0.85 where the test rejects.
fn tint_weight(z: f64, critical: f64) -> f32 {
    const NOISE: f64 = 2.0;
    (((z.abs() - NOISE) / (critical - NOISE).max(1e-9)).clamp(0.0, 1.0) * 0.85) as f32
}

fn tint(z: f64) -> Vec3 {
    if z > 0.0 {
        TOO_BRIGHT
    } else {
        TOO_DARK
    }
}

/// The |z| at which a lone finding among the outcome's `m` would be rejected
/// (the first step of Holm's procedure, in normal units).
pub fn critical_z(outcome: &Outcome) -> f64 {
    let m = outcome.findings.len().max(1) as f64;
    -Normal::standard().inverse_cdf(outcome.alpha / (2.0 * m))
}
