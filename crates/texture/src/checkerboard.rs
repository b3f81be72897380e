use glam::{Vec2, Vec3};

/// `checks × checks` squares over the unit uv square, alternating two colors.
///
/// The check containing `uv` is `(⌊u·N⌋, ⌊v·N⌋)`; it takes `colors[0]` when the sum
/// of its indices is even and `colors[1]` when odd. With an even `checks` the
/// pattern repeats with period 1 in u and v (seamless across the sphere's u = 0
/// seam and between plane tiles); with an odd count, the period is 2.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkerboard {
    pub colors: [Vec3; 2],
    pub checks: u32,
}

impl Checkerboard {
    pub fn new(even: Vec3, odd: Vec3, checks: u32) -> Self {
        Self {
            colors: [even, odd],
            checks,
        }
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
