//! Texel storage: a linear RGB image and the wrap modes that extend it beyond
//! its borders.

use glam::{Vec2, Vec3};
use glint_lanes::{F32Lanes, Float, Mask, Vec3Lanes, LANES};

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
    /// image, t = 0 at the top row): texel `(⌊s·w⌋, ⌊t·h⌋)`, wrapped.
    #[inline]
    pub fn nearest(&self, st: Vec2, wrap: WrapMode) -> Vec3 {
        let p = (reduce_st(st, wrap) * self.size()).floor();
        self.texel_wrapped(p.x as i64, p.y as i64, wrap)
    }

    /// Bilinear interpolation between the four texel centres around `st`: with
    /// `(x, y) = (s·w − ½, t·h − ½)`, the texels around `(x, y)` blended by the
    /// fractional parts (pbrt-v4 `Image::Bilerp`, section 10.4.3). Written as nested
    /// lerps `a + (b − a)·t` so that equal texels give exactly that texel back.
    #[inline]
    pub fn bilinear(&self, st: Vec2, wrap: WrapMode) -> Vec3 {
        self.bilinear_with(reduce_st(st, wrap), |x, y| self.texel_wrapped(x, y, wrap))
    }

    /// Bilinear interpolation at `st` with texels read by `fetch(x, y)`, which
    /// decides what lies past the image's edges (a wrap mode, the next cube face,
    /// the other side of a pole). Inside the image `fetch` must give the texel
    /// itself: there it is not asked, the four texels being read directly.
    #[inline]
    pub fn bilinear_with(&self, st: Vec2, fetch: impl Fn(i64, i64) -> Vec3) -> Vec3 {
        let (x, y, f) = self.bilinear_corner(st);
        let [t00, t10, t01, t11] = match self.square_at(x, y) {
            Some(i) => {
                let w = self.width as usize;
                let t = &self.texels;
                [t[i], t[i + 1], t[i + w], t[i + w + 1]]
            }
            None => [
                fetch(x, y),
                fetch(x + 1, y),
                fetch(x, y + 1),
                fetch(x + 1, y + 1),
            ],
        };
        lerp(lerp(t00, t10, f.x), lerp(t01, t11, f.x), f.y)
    }

    /// [`Self::bilinear_with`] at `(s, t)` in the lanes of `lanes` whose 2 × 2
    /// texels all lie inside the image, each lane's bits the scalar one's, in
    /// the same operations. Also returns the lanes of `lanes` whose texels do
    /// not all lie inside (zero here), left to the caller's rule past the
    /// edges.
    #[inline]
    pub fn bilinear_inside_lanes(&self, s: F32Lanes, t: F32Lanes, lanes: u32) -> (Vec3Lanes, u32) {
        let (w, h) = (self.width as f32, self.height as f32);
        let half = F32Lanes::splat(0.5);
        let (px, py) = (s * F32Lanes::splat(w) - half, t * F32Lanes::splat(h) - half);
        let (x0, y0) = (px.floor(), py.floor());
        let (fx, fy) = (px - x0, py - y0);
        let inside = Float::ge(x0, F32Lanes::ZERO)
            & Float::ge(y0, F32Lanes::ZERO)
            & Float::lt(x0, F32Lanes::splat(w - 1.0))
            & Float::lt(y0, F32Lanes::splat(h - 1.0));
        let inside = lanes & Mask::bits(inside);
        let (x0, y0) = (x0.to_array(), y0.to_array());
        let first: [usize; LANES] = glint_lanes::array_from_fn(|k| match inside >> k & 1 {
            1 => y0[k] as usize * self.width as usize + x0[k] as usize,
            _ => 0,
        });
        let row = self.width as usize;
        let texels = |offset: usize| gather(&self.texels, &first, offset);
        let (t00, t10, t01, t11) = (texels(0), texels(1), texels(row), texels(row + 1));
        let lerp = |a: Vec3Lanes, b: Vec3Lanes, f: F32Lanes| a + (b - a).scale(f);
        let value = lerp(lerp(t00, t10, fx), lerp(t01, t11, fx), fy);
        let zero = Vec3Lanes::default();
        let value = Vec3Lanes::select(glint_lanes::from_bits(inside), &value, &zero);
        (value, lanes & !inside)
    }

    /// The first of the 2 × 2 texels bilinear filtering reads at `st`, and
    /// the weights of the others.
    #[inline]
    fn bilinear_corner(&self, st: Vec2) -> (i64, i64, Vec2) {
        let p = st * self.size() - 0.5;
        let p0 = p.floor();
        (p0.x as i64, p0.y as i64, p - p0)
    }

    /// The texels [`Self::bilinear_with`] reads at `st` where they all lie
    /// inside the image: the first two, then the two below them.
    #[inline]
    pub fn bilinear_texels(&self, st: Vec2) -> Option<[&[Vec3]; 2]> {
        let (x, y, _) = self.bilinear_corner(st);
        let i = self.square_at(x, y)?;
        let w = self.width as usize;
        Some([&self.texels[i..i + 2], &self.texels[i + w..i + w + 2]])
    }

    /// The index of texel `(x, y)` where the 2 × 2 texels from it lie inside
    /// the image.
    #[inline]
    fn square_at(&self, x: i64, y: i64) -> Option<usize> {
        let (w, h) = (self.width as i64, self.height as i64);
        let inside = x >= 0 && y >= 0 && x + 1 < w && y + 1 < h;
        inside.then(|| (y * w + x) as usize)
    }

    /// `(width, height)` as floats.
    #[inline]
    pub fn size(&self) -> Vec2 {
        Vec2::new(self.width as f32, self.height as f32)
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

/// With [`WrapMode::Clamp`], st is clamped to `[−CLAMP_MARGIN, 1 + CLAMP_MARGIN]`: every
/// lookup that reaches the scan reads at most ~16 texel-widths of the 1×1 level away,
/// so beyond this margin every texel it reads is a border texel anyway.
const CLAMP_MARGIN: f32 = 16.0;

/// `st` moved into a small range where every lookup gives the same result, so huge
/// coordinates keep their f32 precision (and texel indices cannot overflow):
/// Repeat has period 1, Mirror period 2, and Clamp reads only border texels beyond
/// [`CLAMP_MARGIN`]. Non-finite coordinates become 0.
#[inline]
pub(crate) fn reduce_st(st: Vec2, wrap: WrapMode) -> Vec2 {
    let reduce = |x: f32| {
        if !x.is_finite() {
            return 0.0;
        }
        match wrap {
            WrapMode::Repeat => x.rem_euclid(1.0),
            WrapMode::Mirror => x.rem_euclid(2.0),
            WrapMode::Clamp => x.clamp(-CLAMP_MARGIN, 1.0 + CLAMP_MARGIN),
        }
    };
    Vec2::new(reduce(st.x), reduce(st.y))
}

/// Texel `first[k] + offset` in lane k.
#[inline(always)]
fn gather(texels: &[Vec3], first: &[usize; LANES], offset: usize) -> Vec3Lanes {
    let texel = |k: usize| texels[first[k] + offset];
    Vec3Lanes::new(
        glint_lanes::from_fn(|k| texel(k).x),
        glint_lanes::from_fn(|k| texel(k).y),
        glint_lanes::from_fn(|k| texel(k).z),
    )
}

/// `a + (b − a)·t`: exactly `a` when `a = b` (glam's `Vec3::lerp`, `a(1 − t) + b t`,
/// is not), so constant images filter to exactly their constant.
#[inline]
pub(crate) fn lerp(a: Vec3, b: Vec3, t: f32) -> Vec3 {
    a + (b - a) * t
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
