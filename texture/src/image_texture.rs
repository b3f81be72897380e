use crate::{Checkerboard, Image, MipMap, TexCoord, WrapMode};
use glam::{Vec2, Vec3};
use std::sync::{Arc, OnceLock};

/// How an image texture turns a pixel's footprint into a color.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TextureFilter {
    /// The texel under the point, full resolution: aliases under minification.
    Nearest,
    /// Bilinear interpolation at full resolution: smooth magnification, aliases
    /// under minification.
    Bilinear,
    /// Bilinear lookups in the two pyramid levels whose texel size brackets
    /// half the footprint's larger extent (never less than its smaller one),
    /// blended (Williams 1983): isotropic, so it blurs footprints that are long
    /// and thin.
    #[default]
    Trilinear,
    /// Elliptically weighted average over the footprint's ellipse (Heckbert 1989,
    /// pbrt-v4 section 10.4.4): anisotropic.
    Ewa,
}

impl TextureFilter {
    pub const NAMES: [&'static str; 4] = ["nearest", "bilinear", "trilinear", "ewa"];

    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "nearest" => Some(Self::Nearest),
            "bilinear" => Some(Self::Bilinear),
            "trilinear" => Some(Self::Trilinear),
            "ewa" => Some(Self::Ewa),
            _ => None,
        }
    }

    /// The name [`TextureFilter::from_name`] reads.
    pub fn name(self) -> &'static str {
        match self {
            Self::Nearest => "nearest",
            Self::Bilinear => "bilinear",
            Self::Trilinear => "trilinear",
            Self::Ewa => "ewa",
        }
    }

    /// Whether this filter reads the MIP-map pyramid (and so needs a footprint).
    pub fn uses_pyramid(self) -> bool {
        matches!(self, Self::Trilinear | Self::Ewa)
    }
}

/// An image and, built on first need, its MIP-map pyramid. Shared (`Arc`) by
/// every texture that uses the same file, so both are made once.
#[derive(Debug)]
pub struct TextureImage {
    image: Image,
    pyramid: OnceLock<MipMap>,
    /// The procedural pattern the image was rasterised from, if any.
    pattern: Option<Checkerboard>,
}

impl TextureImage {
    pub fn new(image: Image) -> Arc<Self> {
        Arc::new(Self {
            image,
            pyramid: OnceLock::new(),
            pattern: None,
        })
    }

    /// The checkerboard rasterised at `pixels_per_check` texels per check (the
    /// course's checker image), remembering the pattern: a caller comparing
    /// filters can evaluate it analytically instead.
    pub fn from_checkerboard(checkerboard: Checkerboard, pixels_per_check: u32) -> Arc<Self> {
        Arc::new(Self {
            image: checkerboard.to_image(pixels_per_check),
            pyramid: OnceLock::new(),
            pattern: Some(checkerboard),
        })
    }

    pub fn image(&self) -> &Image {
        &self.image
    }

    /// The checkerboard this image was made from ([`TextureImage::from_checkerboard`]).
    pub fn pattern(&self) -> Option<&Checkerboard> {
        self.pattern.as_ref()
    }

    /// The pyramid, built now if no lookup has needed it yet.
    pub fn pyramid(&self) -> &MipMap {
        self.pyramid.get_or_init(|| MipMap::new(self.image.clone()))
    }

    /// Whether the pyramid has been built (only filtered lookups build it).
    pub fn has_pyramid(&self) -> bool {
        self.pyramid.get().is_some()
    }
}

/// An image mapped onto uv, with a wrap mode and a filter.
///
/// Texture coordinates are `st = (u, 1 − v)`: v grows upwards on surfaces while
/// image rows grow downwards, so images appear upright (as in pbrt-v4).
#[derive(Clone, Debug)]
pub struct ImageTexture {
    pub image: Arc<TextureImage>,
    pub wrap: WrapMode,
    pub filter: TextureFilter,
}

impl PartialEq for ImageTexture {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.image, &other.image)
            && self.wrap == other.wrap
            && self.filter == other.filter
    }
}

impl ImageTexture {
    pub fn new(image: Arc<TextureImage>, wrap: WrapMode, filter: TextureFilter) -> Self {
        Self {
            image,
            wrap,
            filter,
        }
    }

    /// The filtered color over the footprint of `tc`.
    #[inline]
    pub fn evaluate(&self, tc: &TexCoord) -> Vec3 {
        let (st, dst0, dst1) = to_st(tc);
        match self.filter {
            TextureFilter::Nearest => self.image.image.nearest(st, self.wrap),
            TextureFilter::Bilinear => self.image.image.bilinear(st, self.wrap),
            TextureFilter::Trilinear => {
                self.image
                    .pyramid()
                    .trilinear(st, footprint_width(dst0, dst1), self.wrap)
            }
            TextureFilter::Ewa => self.image.pyramid().ewa(st, dst0, dst1, self.wrap),
        }
    }

    /// The (continuous) pyramid level the filter reads; 0 for unfiltered lookups.
    pub fn mip_level(&self, tc: &TexCoord) -> f32 {
        let (_, dst0, dst1) = to_st(tc);
        match self.filter {
            TextureFilter::Nearest | TextureFilter::Bilinear => 0.0,
            TextureFilter::Trilinear => self
                .image
                .pyramid()
                .level_for_width(footprint_width(dst0, dst1)),
            TextureFilter::Ewa => self.image.pyramid().ewa_level(dst0, dst1),
        }
    }
}

/// `(st, ∂st/∂x, ∂st/∂y)` from uv: t = 1 − v flips the v derivatives.
#[inline]
pub(crate) fn to_st(tc: &TexCoord) -> (Vec2, Vec2, Vec2) {
    let flip = |d: Vec2| Vec2::new(d.x, -d.y);
    (
        Vec2::new(tc.uv.x, 1.0 - tc.uv.y),
        flip(tc.duvdx),
        flip(tc.duvdy),
    )
}

/// The footprint's extent for an isotropic filter: half its longer axis, but
/// never less than its shorter one. A bilinear lookup in a box-filtered level
/// already spreads over about twice that level's texel, so a level whose
/// texel is the whole footprint blurs twice too much; one level finer (half
/// the longer axis) matches the pixel's box filter, and no finer than the
/// shorter axis keeps a squashed footprint from aliasing along it.
#[inline]
fn footprint_width(dst0: Vec2, dst1: Vec2) -> f32 {
    let (a, b) = (dst0.length(), dst1.length());
    (0.5 * a.max(b)).max(a.min(b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn filter_names_round_trip() {
        for name in TextureFilter::NAMES {
            assert_eq!(
                TextureFilter::from_name(name).map(TextureFilter::name),
                Some(name)
            );
        }
        assert_eq!(TextureFilter::from_name("box"), None);
    }

    fn checker_image() -> Arc<TextureImage> {
        TextureImage::new(Image::from_fn(64, 64, |x, y| {
            Vec3::splat(((x / 8 + y / 8) % 2) as f32)
        }))
    }

    #[test]
    fn unfiltered_lookups_never_build_the_pyramid() {
        let image = checker_image();
        let tc = TexCoord {
            uv: Vec2::new(0.3, 0.6),
            duvdx: Vec2::new(0.2, 0.0),
            duvdy: Vec2::new(0.0, 0.2),
        };
        for filter in [TextureFilter::Nearest, TextureFilter::Bilinear] {
            ImageTexture::new(image.clone(), WrapMode::Repeat, filter).evaluate(&tc);
        }
        assert!(!image.has_pyramid());
        ImageTexture::new(image.clone(), WrapMode::Repeat, TextureFilter::Trilinear).evaluate(&tc);
        assert!(image.has_pyramid());
    }

    #[test]
    fn images_appear_upright_v_up() {
        // Top row red, bottom row blue: v = 1 (top of a surface) reads the top row.
        let img = TextureImage::new(Image::from_fn(
            1,
            2,
            |_, y| if y == 0 { Vec3::X } else { Vec3::Z },
        ));
        let tex = ImageTexture::new(img, WrapMode::Clamp, TextureFilter::Nearest);
        assert_eq!(tex.evaluate(&TexCoord::point(Vec2::new(0.5, 0.9))), Vec3::X);
        assert_eq!(tex.evaluate(&TexCoord::point(Vec2::new(0.5, 0.1))), Vec3::Z);
    }

    #[test]
    fn wide_footprints_average_towards_the_mean() {
        let image = checker_image();
        let tc = |w: f32| TexCoord {
            // The centre of a check: sharp lookups see one color only.
            uv: Vec2::new(0.3125, 0.5625),
            duvdx: Vec2::new(w, 0.0),
            duvdy: Vec2::new(0.0, w),
        };
        for filter in [TextureFilter::Trilinear, TextureFilter::Ewa] {
            let tex = ImageTexture::new(image.clone(), WrapMode::Repeat, filter);
            let sharp = tex.evaluate(&tc(1.0 / 64.0));
            let blurred = tex.evaluate(&tc(0.5));
            assert!((sharp.x - 0.5).abs() > 0.3, "{filter:?} {sharp}");
            assert!((blurred.x - 0.5).abs() < 0.05, "{filter:?} {blurred}");
            assert!(tex.mip_level(&tc(0.5)) > tex.mip_level(&tc(1.0 / 64.0)));
        }
    }
}
