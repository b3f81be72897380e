use crate::TexCoord;
use glam::{Vec2, Vec3};

/// `checks × checks` squares over the unit uv square, alternating two colors.
///
/// The check containing `uv` is `(⌊u·N⌋, ⌊v·N⌋)`; it takes `colors[0]` when the sum
/// of its indices is even and `colors[1]` when odd. With an even `checks` the
/// pattern repeats with period 1 in u and v (seamless across the sphere's u = 0
/// seam and between plane tiles); with an odd count, the period is 2.
///
/// With `analytic` filtering the pattern is box-filtered over the pixel's footprint,
/// the parallelogram spanned by `∂uv/∂x` and `∂uv/∂y`: the color is
/// `lerp(colors[0], colors[1], f)` with `f` the fraction of the footprint on odd
/// checks. Along a line the pattern is piecewise constant, changing only where the
/// line crosses a cell boundary, so `f` is integrated exactly along the footprint's
/// major axis (walking those crossings) and by a midpoint rule across its minor axis,
/// with lines under a tenth of a check apart. Unlike filtering over the footprint's
/// bounding box (Quilez, "filterable procedurals"), this keeps the real contrast of
/// long thin footprints that run along the checks' diagonals. Footprints that would
/// need more than `MAX_STEPS` (2048) steps (lines × crossings) use the separable
/// bounding-box integral instead, which is exact for axis-aligned boxes and tends to
/// ½ as footprints grow.
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
        let odd = footprint_odd_fraction(tc.uv * n, tc.duvdx * n, tc.duvdy * n);
        self.colors[0].lerp(self.colors[1], odd)
    }

    /// The course's checkerboard rasterised with `pixels_per_check` texels per
    /// check (the report's image used 32), oriented so that an image texture of it
    /// (looked up at `st = (u, 1 − v)`) shows the same checks as [`Self::evaluate`]
    /// on [0, 1]². Outside it the image repeats every 1 unit of uv; with an odd
    /// `checks` the procedural pattern repeats only every 2, so the two differ there.
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
        self.colors[parity(uv * self.checks as f32) as usize]
    }
}

/// The most steps (lines across the footprint × cell crossings along each) the
/// analytic filter takes before it falls back to the bounding-box integral.
pub const MAX_STEPS: f32 = 2048.0;

/// The fraction of the parallelogram `c + s·a + t·b` (`s, t ∈ [−½, ½]`, in check
/// units) that lies on odd checks.
fn footprint_odd_fraction(c: Vec2, a: Vec2, b: Vec2) -> f32 {
    if !(c.is_finite() && a.is_finite() && b.is_finite()) {
        return parity(c) as f32;
    }
    // The pattern repeats every two checks: keep coordinates small so that f32
    // still resolves every cell boundary (beyond 2^24, k + 1 == k).
    let c = c - 2.0 * (c * 0.5).floor();
    let (major, minor) = if a.length_squared() >= b.length_squared() {
        (a, b)
    } else {
        (b, a)
    };
    if major.length_squared() < 1e-12 {
        return parity(c) as f32;
    }
    // Lines under a tenth of a check apart, and at least two, so that a thin
    // footprint along a row of cell corners is not read as that row alone.
    let lines = (minor.length() * 10.0).ceil().max(2.0);
    let crossings = major.abs().element_sum() + 2.0;
    if lines * crossings > MAX_STEPS {
        let width = a.abs() + b.abs();
        let (fx, fy) = (odd_fraction(c.x, width.x), odd_fraction(c.y, width.y));
        return fx + fy - 2.0 * fx * fy;
    }
    let lines = lines as u32;
    let sum: f32 = (0..lines)
        .map(|j| {
            let t = (j as f32 + 0.5) / lines as f32 - 0.5;
            odd_fraction_along(c + t * minor - 0.5 * major, major)
        })
        .sum();
    sum / lines as f32
}

/// 1 on odd checks (cells whose integer coordinates sum to an odd number), 0 on
/// even ones. f32 → i64 saturates (NaN → 0); the low bit gives the parity of
/// negative cells too (two's complement), and xor cannot overflow.
#[inline]
fn parity(p: Vec2) -> u8 {
    (((p.x.floor() as i64) ^ (p.y.floor() as i64)) & 1) as u8
}

/// The exact fraction of the segment `p0 + s·d`, `s ∈ [0, 1]`, on odd checks.
///
/// The segment meets a vertical cell boundary at `s = (k − p0.x)/d.x` for each
/// integer `k` between its ends, and a horizontal one likewise; every crossing flips
/// the parity. The two sorted sequences are merged on the fly, so no allocation.
fn odd_fraction_along(p0: Vec2, d: Vec2) -> f32 {
    let mut crossings = [axis_crossings(p0.x, d.x), axis_crossings(p0.y, d.y)];
    let first = |c: &AxisCrossings| c.peek().unwrap_or(1.0);
    // The parity in the middle of the first interval, away from any boundary.
    let s1 = first(&crossings[0]).min(first(&crossings[1]));
    let mut odd = parity(p0 + 0.5 * s1 * d) == 1;
    let (mut s, mut covered) = (0.0f32, 0.0f32);
    // Each step passes at least one crossing; the bound ends the loop even if
    // rounding ever made a crossing repeat.
    let max_steps = 2 * (d.abs().element_sum() + 4.0).min(MAX_STEPS) as u32;
    for _ in 0..max_steps {
        let next = match (crossings[0].peek(), crossings[1].peek()) {
            (Some(x), Some(y)) => x.min(y),
            (Some(x), None) => x,
            (None, Some(y)) => y,
            (None, None) => 1.0,
        };
        if odd {
            covered += next - s;
        }
        if next >= 1.0 {
            return covered;
        }
        s = next;
        for c in &mut crossings {
            if c.peek() == Some(next) {
                c.advance();
                odd = !odd;
            }
        }
    }
    covered + if odd { 1.0 - s } else { 0.0 }
}

/// The parameters `s ∈ (0, 1)` where `x0 + s·dx` is an integer, in increasing order.
#[derive(Clone, Copy)]
struct AxisCrossings {
    next_k: f32,
    step: f32,
    x0: f32,
    dx: f32,
}

fn axis_crossings(x0: f32, dx: f32) -> AxisCrossings {
    let (next_k, step) = if dx > 0.0 {
        (x0.floor() + 1.0, 1.0)
    } else {
        (x0.ceil() - 1.0, -1.0)
    };
    AxisCrossings {
        next_k,
        step,
        x0,
        dx,
    }
}

impl AxisCrossings {
    #[inline]
    fn peek(&self) -> Option<f32> {
        if self.dx == 0.0 {
            return None;
        }
        let s = (self.next_k - self.x0) / self.dx;
        (s > 0.0 && s < 1.0).then_some(s)
    }

    #[inline]
    fn advance(&mut self) {
        self.next_k += self.step;
    }
}

/// The fraction of `[x − w/2, x + w/2]` covered by odd cells of a unit grid
/// (exact box filter of the 1D check indicator); the point value when `w` is tiny.
#[inline]
fn odd_fraction(x: f32, w: f32) -> f32 {
    if w.is_nan() || w <= 1e-4 || !w.is_finite() {
        return parity(Vec2::new(x, 0.0)) as f32;
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
    fn analytic_filter_matches_brute_force_on_rotated_footprints() {
        let mut c = Checkerboard::new(Vec3::ZERO, Vec3::ONE, 1);
        c.analytic = true;
        // Thin diagonal footprints keep contrast (checks share a color along a
        // diagonal); a bounding box would average them to one half.
        let cases = [
            (
                Vec2::new(0.5, 0.5),
                Vec2::new(6.0, 6.0),
                Vec2::new(-0.05, 0.05),
            ),
            (
                Vec2::new(3.3, -1.7),
                Vec2::new(2.5, 0.4),
                Vec2::new(0.1, -0.3),
            ),
            (
                Vec2::new(-7.2, 2.05),
                Vec2::new(0.3, 0.2),
                Vec2::new(-0.2, 0.35),
            ),
            (
                Vec2::new(10.1, 4.4),
                Vec2::new(0.0, 12.0),
                Vec2::new(0.6, 0.0),
            ),
        ];
        for (uv, a, b) in cases {
            let n = 600;
            let mut sum = 0.0;
            for j in 0..n {
                for i in 0..n {
                    let s = (i as f32 + 0.5) / n as f32 - 0.5;
                    let t = (j as f32 + 0.5) / n as f32 - 0.5;
                    sum += c.evaluate(uv + s * a + t * b).x;
                }
            }
            let brute = sum / (n * n) as f32;
            let tc = TexCoord {
                uv,
                duvdx: a,
                duvdy: b,
            };
            let got = c.evaluate_filtered(&tc).x;
            assert!((got - brute).abs() < 0.02, "{uv} {a} {b}: {got} vs {brute}");
        }
        let diagonal = TexCoord {
            uv: Vec2::new(0.5, 0.5),
            duvdx: Vec2::new(6.0, 6.0),
            duvdy: Vec2::new(-0.05, 0.05),
        };
        assert!(c.evaluate_filtered(&diagonal).x < 0.2);
    }

    #[test]
    fn huge_coordinates_terminate_and_keep_the_pattern() {
        let mut c = Checkerboard::new(Vec3::ZERO, Vec3::ONE, 1);
        c.analytic = true;
        // 2^24 < x < 2^25: f32 spacing is 2 there, so k + 1 == k.
        for (x, d) in [
            (20_000_002.0, 10.0),
            (20_000_002.0, -10.0),
            (3.0e7, 3.0),
            (1e30, 7.0),
        ] {
            let tc = TexCoord {
                uv: Vec2::new(x, 0.25),
                duvdx: Vec2::new(d, 0.0),
                duvdy: Vec2::new(0.0, 0.05),
            };
            let f = c.evaluate_filtered(&tc).x;
            assert!((0.0..=1.0).contains(&f), "{x} {d}: {f}");
        }
    }

    #[test]
    fn a_line_starting_just_before_a_boundary_keeps_its_parity() {
        // From (0.99999, 0.5) along (1, 0.3): almost all of the way in cell (1, 0),
        // which is odd: the fraction must be close to 1, not to 0.
        let f = odd_fraction_along(Vec2::new(0.99999, 0.5), Vec2::new(1.0, 0.3));
        assert!((f - 0.99999).abs() < 1e-4, "{f}");
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
