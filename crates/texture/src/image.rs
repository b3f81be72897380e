//! Texel storage: a linear RGB image and the wrap modes that extend it beyond
//! its borders.

use glam::{Vec2, Vec3};

/// A linear RGB image of `f32` texels, row-major with the **top** row first.
///
/// Texel `(x, y)` covers `[x, x+1) × [y, y+1)` in texel space, so its centre is
/// `(x + 0.5, y + 0.5)`; in texture coordinates `st ∈ [0, 1]²` that centre is
/// `((x + 0.5) / width, (y + 0.5) / height)`, with `t = 0` at the top row.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    width: u32,
    height: u32,
    texels: Vec<Vec3>,
}

impl Image {
    /// An image from `width × height` texels, row-major from the top-left.
    ///
    /// # Panics
    /// If a side is zero or `texels.len() != width · height`.
    pub fn new(width: u32, height: u32, texels: Vec<Vec3>) -> Self {
        assert!(width > 0 && height > 0, "image sides must be positive");
        assert_eq!(texels.len(), width as usize * height as usize);
        Self {
            width,
            height,
            texels,
        }
    }

    /// An image whose texel `(x, y)` is `f(x, y)`.
    pub fn from_fn(width: u32, height: u32, mut f: impl FnMut(u32, u32) -> Vec3) -> Self {
        let texels = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect();
        Self::new(width, height, texels)
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    /// All texels, row-major from the top-left.
    pub fn texels(&self) -> &[Vec3] {
        &self.texels
    }

    /// The texel at `(x, y)`, which must lie inside the image.
    #[inline]
    pub fn texel(&self, x: u32, y: u32) -> Vec3 {
        self.texels[y as usize * self.width as usize + x as usize]
    }

    /// The texel at integer coordinates that may lie outside the image,
    /// brought inside by `wrap`.
    #[inline]
    pub fn texel_wrapped(&self, x: i64, y: i64, wrap: WrapMode) -> Vec3 {
        self.texel(wrap.wrap(x, self.width), wrap.wrap(y, self.height))
    }

    /// The texel containing `st` (texture coordinates: [0, 1]² is one copy of the
    /// image, t = 0 at the top row).
    #[inline]
    pub fn nearest(&self, st: Vec2, wrap: WrapMode) -> Vec3 {
        let x = (st.x * self.width as f32).floor();
        let y = (st.y * self.height as f32).floor();
        self.texel_wrapped(saturating_index(x), saturating_index(y), wrap)
    }

    /// Bilinear interpolation between the four texel centres around `st`.
    #[inline]
    pub fn bilinear(&self, st: Vec2, wrap: WrapMode) -> Vec3 {
        let x = st.x * self.width as f32 - 0.5;
        let y = st.y * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (xi, yi) = (saturating_index(x0), saturating_index(y0));
        let texel = |dx: i64, dy: i64| {
            self.texel_wrapped(xi.saturating_add(dx), yi.saturating_add(dy), wrap)
        };
        let top = texel(0, 0).lerp(texel(1, 0), fx);
        let bottom = texel(0, 1).lerp(texel(1, 1), fx);
        let value = top.lerp(bottom, fy);
        if value.is_finite() {
            value
        } else {
            texel(0, 0)
        }
    }

    /// The mean of all texels (accumulated in f64).
    pub fn mean(&self) -> Vec3 {
        let sum = self
            .texels
            .iter()
            .fold(glam::DVec3::ZERO, |acc, t| acc + t.as_dvec3());
        (sum / self.texels.len() as f64).as_vec3()
    }
}

/// A texel index from a floored coordinate; NaN maps to 0 and huge values
/// saturate (wrap modes then bring them inside the image).
#[inline]
fn saturating_index(floored: f32) -> i64 {
    floored as i64
}

/// How texel coordinates outside `[0, n)` map back into the image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WrapMode {
    /// Tile the image: `i mod n`.
    #[default]
    Repeat,
    /// Extend the border texels: `clamp(i, 0, n − 1)`.
    Clamp,
    /// Tile with every other copy mirrored, so edges meet seamlessly.
    Mirror,
}

impl WrapMode {
    pub const NAMES: [&'static str; 3] = ["repeat", "clamp", "mirror"];

    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "repeat" => Some(Self::Repeat),
            "clamp" => Some(Self::Clamp),
            "mirror" => Some(Self::Mirror),
            _ => None,
        }
    }

    /// The index in `[0, n)` that `i` maps to.
    #[inline]
    pub fn wrap(self, i: i64, n: u32) -> u32 {
        let n = n as i64;
        let wrapped = match self {
            WrapMode::Repeat => i.rem_euclid(n),
            WrapMode::Clamp => i.clamp(0, n - 1),
            WrapMode::Mirror => {
                let period = i.rem_euclid(2 * n);
                if period < n {
                    period
                } else {
                    2 * n - 1 - period
                }
            }
        };
        wrapped as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_modes_outside_the_image() {
        let n = 4;
        let got = |mode: WrapMode| -> Vec<u32> { (-6..10).map(|i| mode.wrap(i, n)).collect() };
        assert_eq!(
            got(WrapMode::Repeat),
            [2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1]
        );
        assert_eq!(
            got(WrapMode::Clamp),
            [0, 0, 0, 0, 0, 0, 0, 1, 2, 3, 3, 3, 3, 3, 3, 3]
        );
        assert_eq!(
            got(WrapMode::Mirror),
            [2, 3, 3, 2, 1, 0, 0, 1, 2, 3, 3, 2, 1, 0, 0, 1]
        );
        // Huge indices stay in range.
        for mode in [WrapMode::Repeat, WrapMode::Clamp, WrapMode::Mirror] {
            assert!(mode.wrap(i64::MAX / 4, 7) < 7);
            assert!(mode.wrap(i64::MIN / 4, 7) < 7);
        }
    }

    #[test]
    fn point_lookups_at_and_between_texel_centres() {
        let img = Image::from_fn(4, 2, |x, y| Vec3::splat((x + 10 * y) as f32));
        let centre = |x: f32, y: f32| Vec2::new((x + 0.5) / 4.0, (y + 0.5) / 2.0);
        assert_eq!(
            img.nearest(centre(2.0, 1.0), WrapMode::Clamp),
            Vec3::splat(12.0)
        );
        assert_eq!(
            img.bilinear(centre(2.0, 1.0), WrapMode::Clamp),
            Vec3::splat(12.0)
        );
        assert_eq!(
            img.bilinear(centre(1.5, 0.0), WrapMode::Clamp),
            Vec3::splat(1.5)
        );
        assert_eq!(
            img.bilinear(centre(1.0, 0.5), WrapMode::Clamp),
            Vec3::splat(6.0)
        );
        // Across the right edge, repeat blends the last column with the first.
        assert_eq!(
            img.bilinear(centre(3.5, 0.0), WrapMode::Repeat),
            Vec3::splat(1.5)
        );
        assert_eq!(
            img.bilinear(centre(3.5, 0.0), WrapMode::Clamp),
            Vec3::splat(3.0)
        );
        // Outside [0, 1]: wrap modes decide.
        assert_eq!(
            img.nearest(Vec2::new(-0.1, 0.25), WrapMode::Repeat),
            Vec3::splat(3.0)
        );
        assert_eq!(
            img.nearest(Vec2::new(-0.1, 0.25), WrapMode::Clamp),
            Vec3::splat(0.0)
        );
        assert_eq!(
            img.nearest(Vec2::new(-0.1, 0.25), WrapMode::Mirror),
            Vec3::splat(0.0)
        );
        assert_eq!(
            img.nearest(Vec2::new(1.3, 0.25), WrapMode::Mirror),
            Vec3::splat(2.0)
        );
        for st in [
            Vec2::splat(f32::NAN),
            Vec2::splat(1e30),
            Vec2::splat(-f32::INFINITY),
        ] {
            assert!(img.bilinear(st, WrapMode::Repeat).is_finite());
            assert!(img.nearest(st, WrapMode::Mirror).is_finite());
        }
    }

    #[test]
    fn texels_are_row_major_from_the_top() {
        let img = Image::from_fn(3, 2, |x, y| Vec3::new(x as f32, y as f32, 0.0));
        assert_eq!(img.texel(2, 1), Vec3::new(2.0, 1.0, 0.0));
        assert_eq!(img.texels()[3], Vec3::new(0.0, 1.0, 0.0));
        assert_eq!(
            img.texel_wrapped(-1, 2, WrapMode::Repeat),
            Vec3::new(2.0, 0.0, 0.0)
        );
        assert_eq!(img.mean(), Vec3::new(1.0, 0.5, 0.0));
    }
}
