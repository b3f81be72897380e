//! What a texture lookup read, for `glint explain`: the footprint, the MIP
//! level Glint's filter chooses, the levels and texels read with their
//! weights, and the filtered value. (The level the course report chooses
//! needs the camera: `glint_integrator::report_level`.)

use crate::image::reduce_st;
use crate::image_texture::{to_st, ImageTexture, TextureFilter};
use crate::mipmap::{EwaFallback, EwaRead};
use crate::{TexCoord, Texture};
use glam::{Vec2, Vec3};

/// One texel a lookup read, with its weight in the result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexelRead {
    /// Pyramid level (0: the image itself).
    pub level: usize,
    /// Texel coordinates before wrapping (a lookup near an edge reads past it).
    pub x: i64,
    pub y: i64,
    pub weight: f32,
    pub value: Vec3,
}

/// A texture lookup explained ([`Texture::explain`]).
#[derive(Clone, Debug, PartialEq)]
pub struct LookupExplained {
    /// `constant`, `checkerboard`, `checkerboard (box-filtered)`, or the image
    /// filter's name.
    pub kind: String,
    /// Texture coordinates `st = (u, 1 − v)` and their derivatives per pixel
    /// (images only).
    pub st: Option<Vec2>,
    pub dst_dx: Option<Vec2>,
    pub dst_dy: Option<Vec2>,
    /// The level Glint's filter reads ([`ImageTexture::mip_level`]): trilinear
    /// from half the longer axis (never below the shorter one), EWA from the
    /// (clamped) minor axis.
    pub glint_level: Option<f32>,
    /// The texels read and their weights in the result (for EWA, every texel
    /// of the ellipse in each level read).
    pub texels: Vec<TexelRead>,
    /// For an analytic checkerboard, the fraction of the footprint on the
    /// second color.
    pub second_color_fraction: Option<f32>,
    /// The filtered value: [`Texture::evaluate`]'s.
    pub value: Vec3,
}

impl Texture {
    /// [`Texture::evaluate`] at `tc`, with what it read.
    pub fn explain(&self, tc: &TexCoord) -> LookupExplained {
        let value = self.evaluate(tc);
        let mut out = LookupExplained {
            kind: String::new(),
            st: None,
            dst_dx: None,
            dst_dy: None,
            glint_level: None,
            texels: Vec::new(),
            second_color_fraction: None,
            value,
        };
        match self {
            Texture::Constant(_) => out.kind = "constant".into(),
            Texture::Checkerboard(c) => {
                out.kind = if c.analytic {
                    "checkerboard (box-filtered over the footprint)".into()
                } else {
                    "checkerboard".into()
                };
                // value = lerp(colors[0], colors[1], fraction): recover the
                // fraction from the channel where the colors differ most.
                let d = c.colors[1] - c.colors[0];
                let axis = d.abs().max_position();
                if d[axis] != 0.0 {
                    out.second_color_fraction = Some((value[axis] - c.colors[0][axis]) / d[axis]);
                }
            }
            Texture::Image(t) => explain_image(t, tc, &mut out),
        }
        out
    }
}

fn explain_image(t: &ImageTexture, tc: &TexCoord, out: &mut LookupExplained) {
    let (st, dst0, dst1) = to_st(tc);
    out.kind = t.filter.name().to_owned();
    out.st = Some(st);
    out.dst_dx = Some(dst0);
    out.dst_dy = Some(dst1);
    let image = t.image.image();
    out.glint_level = Some(t.mip_level(tc));
    let reduced = reduce_st(st, t.wrap);
    match t.filter {
        TextureFilter::Nearest => {
            let p = (reduced * image.size()).floor();
            let (x, y) = (p.x as i64, p.y as i64);
            out.texels.push(TexelRead {
                level: 0,
                x,
                y,
                weight: 1.0,
                value: image.texel_wrapped(x, y, t.wrap),
            });
        }
        TextureFilter::Bilinear => bilinear_texels(t, reduced, 0, 1.0, &mut out.texels),
        TextureFilter::Trilinear => {
            trilinear_texels(t, reduced, out.glint_level.unwrap_or(0.0), &mut out.texels)
        }
        TextureFilter::Ewa => match t
            .image
            .pyramid()
            .ewa_explained(st, dst0, dst1, t.wrap)
            .reads
        {
            EwaRead::Texels(read) => {
                let levels = t.image.pyramid().levels();
                out.texels.extend(read.iter().map(|e| TexelRead {
                    level: e.level,
                    x: e.x,
                    y: e.y,
                    weight: e.weight,
                    value: levels[e.level].texel_wrapped(e.x, e.y, t.wrap),
                }));
            }
            EwaRead::Fallback(EwaFallback::Bilinear) => {
                out.kind = "ewa (zero footprint: bilinear)".into();
                bilinear_texels(t, reduced, 0, 1.0, &mut out.texels);
            }
            EwaRead::Fallback(EwaFallback::LastLevel) => {
                out.kind = "ewa (at the last level: its one texel)".into();
                let levels = t.image.pyramid().levels();
                out.texels.push(TexelRead {
                    level: levels.len() - 1,
                    x: 0,
                    y: 0,
                    weight: 1.0,
                    value: levels[levels.len() - 1].texel(0, 0),
                });
            }
            EwaRead::Fallback(EwaFallback::Trilinear { width }) => {
                out.kind = "ewa (ellipse too large: trilinear)".into();
                let level = t.image.pyramid().level_for_width(width);
                trilinear_texels(t, reduced, level, &mut out.texels);
            }
        },
    }
}

impl ImageTexture {
    /// The texels a trilinear lookup at `st` and the given continuous
    /// `level` reads, with their weights: [`crate::MipMap::trilinear_at_level`]'s
    /// (the level clamped to the pyramid the same way), for a level chosen
    /// elsewhere, as the course report's `log2(L/W)`.
    pub fn texels_at_level(&self, st: Vec2, level: f32) -> Vec<TexelRead> {
        let mut texels = Vec::new();
        trilinear_texels(self, reduce_st(st, self.wrap), level, &mut texels);
        texels
    }
}

/// The four texels of a bilinear lookup at `reduced` in `level`, weighted by
/// `weight` times their bilinear weights.
fn bilinear_texels(
    t: &ImageTexture,
    reduced: Vec2,
    level: usize,
    weight: f32,
    out: &mut Vec<TexelRead>,
) {
    let image = &t.image.pyramid().levels()[level];
    let p = reduced * image.size() - 0.5;
    let p0 = p.floor();
    let f = p - p0;
    for (dx, dy, w) in [
        (0, 0, (1.0 - f.x) * (1.0 - f.y)),
        (1, 0, f.x * (1.0 - f.y)),
        (0, 1, (1.0 - f.x) * f.y),
        (1, 1, f.x * f.y),
    ] {
        let (x, y) = (p0.x as i64 + dx, p0.y as i64 + dy);
        out.push(TexelRead {
            level,
            x,
            y,
            weight: weight * w,
            value: image.texel_wrapped(x, y, t.wrap),
        });
    }
}

/// The texels of a trilinear lookup at `level`, clamped to `[0, last]`
/// (NaN reads level 0) as [`crate::MipMap::trilinear_at_level`] clamps it.
fn trilinear_texels(t: &ImageTexture, reduced: Vec2, level: f32, out: &mut Vec<TexelRead>) {
    let level = t.image.pyramid().clamp_level(level);
    let lower = level as usize;
    let frac = level - lower as f32;
    bilinear_texels(t, reduced, lower, 1.0 - frac, out);
    if frac > 0.0 {
        bilinear_texels(t, reduced, lower + 1, frac, out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Checkerboard, Image, TextureImage, WrapMode};

    #[test]
    fn the_texels_at_a_level_make_the_trilinear_value_there() {
        // An odd-sized pyramid (37 × 25: its levels round down), levels
        // between, on, below and past its ends.
        let image = TextureImage::new(Image::from_fn(37, 25, |x, y| {
            Vec3::new(x as f32, y as f32, ((x * 7 + y * 3) % 5) as f32)
        }));
        let texture = ImageTexture::new(image.clone(), WrapMode::Repeat, TextureFilter::Trilinear);
        let st = Vec2::new(0.61, 0.27);
        for level in [3.7643, 2.0, -1.5, 40.0, f32::NAN] {
            let texels = texture.texels_at_level(st, level);
            let sum = texels
                .iter()
                .fold(Vec3::ZERO, |acc, t| acc + t.weight * t.value);
            let want = image
                .pyramid()
                .trilinear_at_level(st, level, WrapMode::Repeat);
            assert!(
                (sum - want).abs().max_element() < 1e-4,
                "level {level}: {sum} against {want}"
            );
            let weights: f32 = texels.iter().map(|t| t.weight).sum();
            assert!(
                (weights - 1.0).abs() < 1e-5,
                "level {level}: weights {weights}"
            );
        }
        let levels: Vec<usize> = texture
            .texels_at_level(st, 3.7643)
            .iter()
            .map(|t| t.level)
            .collect();
        assert_eq!(levels, [3, 3, 3, 3, 4, 4, 4, 4]);
    }

    #[test]
    fn the_weighted_texels_make_the_filtered_value() {
        let image = TextureImage::new(Image::from_fn(16, 8, |x, y| {
            Vec3::new(x as f32, y as f32, ((x * 7 + y * 3) % 5) as f32)
        }));
        let tc = TexCoord {
            uv: Vec2::new(0.37, 0.81),
            duvdx: Vec2::new(0.09, 0.01),
            duvdy: Vec2::new(-0.02, 0.05),
        };
        let footprints = [
            (tc.duvdx, tc.duvdy),
            // A needle, its minor axis lengthened to an eighth of the major.
            (Vec2::new(0.3, 0.05), Vec2::new(0.0, 0.001)),
            // Zero: EWA falls back to bilinear; huge: past the last level.
            (Vec2::ZERO, Vec2::ZERO),
            (Vec2::new(40.0, 0.0), Vec2::new(0.0, 40.0)),
        ];
        for filter in [
            TextureFilter::Nearest,
            TextureFilter::Bilinear,
            TextureFilter::Trilinear,
            TextureFilter::Ewa,
        ]
        .into_iter()
        .flat_map(|filter| footprints.into_iter().enumerate().map(move |f| (filter, f)))
        {
            let (filter, (footprint, (duvdx, duvdy))) = filter;
            let tc = TexCoord { duvdx, duvdy, ..tc };
            let texture =
                Texture::Image(ImageTexture::new(image.clone(), WrapMode::Repeat, filter));
            let explained = texture.explain(&tc);
            let sum = explained
                .texels
                .iter()
                .fold(Vec3::ZERO, |acc, t| acc + t.weight * t.value);
            assert!(
                (sum - explained.value).abs().max_element() < 1e-4,
                "{filter:?}: {sum} against {}",
                explained.value
            );
            let weights: f32 = explained.texels.iter().map(|t| t.weight).sum();
            assert!(
                (weights - 1.0).abs() < 1e-5,
                "{filter:?}: weights {weights}"
            );
            if filter == TextureFilter::Ewa {
                let (kind, texels) = (explained.kind.as_str(), explained.texels.len());
                match footprint {
                    0 | 1 => assert!(kind == "ewa" && texels > 4, "{kind}: {texels} texels"),
                    2 => assert!(kind.contains("bilinear") && texels == 4, "{kind}"),
                    _ => assert!(kind.contains("last level") && texels == 1, "{kind}"),
                }
            }
        }
    }

    #[test]
    fn a_box_filtered_checkerboard_reports_its_blend() {
        let c = Checkerboard {
            colors: [Vec3::ZERO, Vec3::ONE],
            checks: 4,
            analytic: true,
        };
        let tc = TexCoord {
            uv: Vec2::new(0.25, 0.1),
            duvdx: Vec2::new(0.1, 0.0),
            duvdy: Vec2::new(0.0, 0.01),
        };
        let explained = Texture::Checkerboard(c).explain(&tc);
        let fraction = explained.second_color_fraction.unwrap();
        assert!((fraction - 0.5).abs() < 1e-5, "{fraction}");
    }
}
