use crate::TexCoord;
use glam::{Vec2, Vec3};

/// `checks × checks` squares over the unit uv square, alternating two colors.
///
/// The check containing `uv` is `(⌊u·N⌋, ⌊v·N⌋)`; it takes `colors[0]` when the sum
/// of its indices is even and `colors[1]` when odd. With an even `checks` the
/// pattern repeats with period 1 in u and v (seamless across the sphere's u = 0
/// seam and between plane tiles); with an odd count, the period is 2.
///
/// With `analytic` filtering the pattern is box-filtered exactly over the
/// footprint's bounding box in uv (Quilez, "filterable procedurals"): along one
/// axis the fraction of odd checks in `[x − w/2, x + w/2]` is `(I(x + w/2) −
/// I(x − w/2)) / w`, with `I(x) = ⌊x/2⌋ + max(0, (x mod 2) − 1)` the integral of the
/// odd-check indicator; the two axes combine as an exclusive or,
/// `f = fx + fy − 2·fx·fy`, and the color is `lerp(colors[0], colors[1], f)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkerboard {
    pub colors: [Vec3; 2],
    pub checks: u32,
    pub analytic: bool,
}

impl Checkerboard {
    /// The course's checkerboard, point-sampled.
    pub fn new(even: Vec3, odd: Vec3, checks: u32) -> Self {
        Self {
            colors: [even, odd],
            checks,
            analytic: false,
        }
    }

    /// The color over the footprint of `tc`: exact box filtering when `analytic`,
    /// else the check under the point.
    #[inline]
    pub fn evaluate_filtered(&self, tc: &TexCoord) -> Vec3 {
        if !self.analytic {
            return self.evaluate(tc.uv);
        }
        let n = self.checks as f32;
        let x = tc.uv * n;
        let width = n * tc.duvdx.abs().max(tc.duvdy.abs());
        let fx = odd_fraction(x.x, width.x);
        let fy = odd_fraction(x.y, width.y);
        let odd = fx + fy - 2.0 * fx * fy;
        self.colors[0].lerp(self.colors[1], odd)
    }

    /// The course's checkerboard rasterised with `pixels_per_check` texels per
    /// check (the report's image used 32), oriented so that an image texture of it
    /// (looked up at `st = (u, 1 − v)`) shows the same checks as [`Self::evaluate`].
    pub fn to_image(&self, pixels_per_check: u32) -> crate::Image {
        let side = self.checks * pixels_per_check;
        crate::Image::from_fn(side, side, |x, y| {
            let column = x / pixels_per_check;
            let row_from_bottom = self.checks - 1 - y / pixels_per_check;
            self.colors[((column ^ row_from_bottom) & 1) as usize]
        })
    }

    #[inline]
    pub fn evaluate(&self, uv: Vec2) -> Vec3 {
        let cell = (uv * self.checks as f32).floor();
        // f32 → i64 saturates (NaN → 0); the low bit gives the parity of negative
        // cells too (two's complement), and xor cannot overflow.
        let parity = ((cell.x as i64) ^ (cell.y as i64)) & 1;
        self.colors[parity as usize]
    }
}

/// The fraction of `[x − w/2, x + w/2]` covered by odd cells of a unit grid
/// (exact box filter of the 1D check indicator); the point value when `w` is tiny.
#[inline]
fn odd_fraction(x: f32, w: f32) -> f32 {
    if w.is_nan() || w <= 1e-4 || !w.is_finite() {
        return ((x.floor() as i64) & 1) as f32;
    }
    let integral = |x: f32| {
        let half = x * 0.5;
        half.floor() + (2.0 * (half - half.floor()) - 1.0).max(0.0)
    };
    ((integral(x + 0.5 * w) - integral(x - 0.5 * w)) / w).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn alternates_across_check_boundaries_including_negative_uv() {
        let c = Checkerboard::new(Vec3::ZERO, Vec3::ONE, 4);
        assert_eq!(c.evaluate(Vec2::new(0.1, 0.1)), Vec3::ZERO);
        assert_eq!(c.evaluate(Vec2::new(0.3, 0.1)), Vec3::ONE);
        assert_eq!(c.evaluate(Vec2::new(0.3, 0.3)), Vec3::ZERO);
        assert_eq!(c.evaluate(Vec2::new(0.99, 0.01)), Vec3::ONE);
        assert_eq!(c.evaluate(Vec2::new(-0.1, 0.1)), Vec3::ONE);
        assert_eq!(c.evaluate(Vec2::new(-0.1, -0.1)), Vec3::ZERO);
        // Period 1: the pattern at uv + (1, 0) equals the pattern at uv.
        for i in 0..50 {
            let uv = Vec2::new(i as f32 * 0.0173, i as f32 * 0.0311);
            assert_eq!(c.evaluate(uv), c.evaluate(uv + Vec2::X));
        }
    }

    #[test]
    fn huge_and_nan_uv_do_not_panic() {
        let c = Checkerboard::new(Vec3::ZERO, Vec3::ONE, 8);
        for uv in [
            Vec2::splat(1e30),
            Vec2::new(-1e30, 1e30),
            Vec2::splat(f32::NAN),
        ] {
            let color = c.evaluate(uv);
            assert!(color == Vec3::ZERO || color == Vec3::ONE);
        }
    }

    #[test]
    fn analytic_filter_is_the_box_average() {
        let mut c = Checkerboard::new(Vec3::ZERO, Vec3::ONE, 4);
        c.analytic = true;
        let tc = |uv: Vec2, w: f32| TexCoord {
            uv,
            duvdx: Vec2::new(w, 0.0),
            duvdy: Vec2::new(0.0, w),
        };
        // Tiny footprint: the point value.
        for uv in [
            Vec2::new(0.1, 0.1),
            Vec2::new(0.3, 0.1),
            Vec2::new(-0.4, 0.7),
        ] {
            assert_eq!(c.evaluate_filtered(&tc(uv, 0.0)), c.evaluate(uv));
        }
        // A footprint of whole check pairs averages to exactly one half.
        let half = c.evaluate_filtered(&tc(Vec2::new(0.37, 0.61), 0.5));
        assert!((half.x - 0.5).abs() < 1e-5, "{half}");
        // Compare with a brute-force box average over the footprint.
        for (uv, w) in [
            (Vec2::new(0.13, 0.4), 0.1),
            (Vec2::new(0.5, 0.5), 0.3),
            (Vec2::new(2.7, -1.2), 0.07),
        ] {
            let n = 400;
            let mut sum = 0.0;
            for j in 0..n {
                for i in 0..n {
                    let o = (Vec2::new(i as f32, j as f32) + 0.5) / n as f32 - 0.5;
                    sum += c.evaluate(uv + o * w).x;
                }
            }
            let brute = sum / (n * n) as f32;
            let exact = c.evaluate_filtered(&tc(uv, w)).x;
            assert!((exact - brute).abs() < 5e-3, "{uv} {w}: {exact} vs {brute}");
        }
    }

    #[test]
    fn the_rasterised_checker_matches_the_procedural_one() {
        let c = Checkerboard::new(Vec3::X, Vec3::Y, 4);
        let img = c.to_image(32);
        assert_eq!((img.width(), img.height()), (128, 128));
        for (u, v) in [(0.1, 0.1), (0.3, 0.1), (0.9, 0.95), (0.6, 0.4)] {
            let st = Vec2::new(u, 1.0 - v);
            assert_eq!(
                img.nearest(st, crate::WrapMode::Repeat),
                c.evaluate(Vec2::new(u, v))
            );
        }
    }

    #[test]
    fn covers_both_colors_equally() {
        let c = Checkerboard::new(Vec3::ZERO, Vec3::ONE, 8);
        let n = 64;
        let mut sum = 0.0;
        for j in 0..n {
            for i in 0..n {
                let uv = (Vec2::new(i as f32, j as f32) + 0.5) / n as f32;
                sum += c.evaluate(uv).x;
            }
        }
        assert_eq!(sum, (n * n / 2) as f32);
    }
}
