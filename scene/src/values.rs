//! Value types of the scene format that validate themselves while they are read,
//! so that a bad number is reported at its own line and column.

use glam::{UVec2, Vec3};
use glint_integrator::SamplePattern;
use glint_lighting::{AreaSampling, EnvironmentSampling, ShadingModel, SpecularLobe};
use glint_texture::{TextureFilter, WrapMode};
use serde::de::{self, Deserialize, Deserializer, Visitor};
use std::fmt;

/// Largest accepted film side, in pixels: bounds the memory a scene can ask for.
pub const MAX_RESOLUTION: u32 = 16384;

/// Largest accepted magnitude of any number in a scene. Beyond it f32 geometry
/// loses all precision (a ULP of 1e12 is 65536) and squares overflow to infinity.
pub const MAX_MAGNITUDE: f32 = 1e12;

/// Any TOML number (integer or float), as written (f64: a value too large
/// for f32 is reported as written, not as infinity); anything else is refused
/// with a message that says a number was expected.
struct Number(f64);

impl<'de> Deserialize<'de> for Number {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Number;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number")
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Number, E> {
                Ok(Number(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Number, E> {
                Ok(Number(v as f64))
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Number, E> {
                Ok(Number(v))
            }
        }
        d.deserialize_any(V)
    }
}

/// A number as written, checked to be finite and of magnitude at most
/// [`MAX_MAGNITUDE`] before it becomes an f32.
fn finite<E: de::Error>(v: f64) -> Result<f32, E> {
    if !v.is_finite() {
        Err(E::custom(format!("expected a finite number, got {v}")))
    } else if v.abs() > MAX_MAGNITUDE as f64 {
        Err(E::custom(format!(
            "expected a number of magnitude at most {MAX_MAGNITUDE:e}, got {v:e}"
        )))
    } else {
        Ok(v as f32)
    }
}

fn number<'de, D: Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
    finite(Number::deserialize(d)?.0)
}

fn pair<'de, D: Deserializer<'de>>(d: D) -> Result<glam::Vec2, D::Error> {
    let items = Vec::<Number>::deserialize(d)?;
    if items.len() != 2 {
        return Err(de::Error::custom(format!(
            "expected 2 numbers [u, v], got {}",
            items.len()
        )));
    }
    Ok(glam::Vec2::new(finite(items[0].0)?, finite(items[1].0)?))
}

fn vector<'de, D: Deserializer<'de>>(d: D) -> Result<Vec3, D::Error> {
    let items = Vec::<Number>::deserialize(d)?;
    if items.len() != 3 {
        return Err(de::Error::custom(format!(
            "expected 3 numbers [x, y, z], got {}",
            items.len()
        )));
    }
    Ok(Vec3::new(
        finite(items[0].0)?,
        finite(items[1].0)?,
        finite(items[2].0)?,
    ))
}

macro_rules! validated {
    ($(#[$doc:meta])* $name:ident($inner:ty) via $read:ident, |$v:ident| $ok:expr, $expected:literal) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct $name(pub $inner);

        impl<'de> Deserialize<'de> for $name {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let $v = $read(d)?;
                if $ok {
                    Ok($name($v))
                } else {
                    Err(de::Error::custom(format!(concat!("expected ", $expected, ", got {}"), $v)))
                }
            }
        }
    };
}

validated!(
    /// A finite number greater than zero.
    Positive(f32) via number, |v| v > 0.0, "a number greater than 0"
);
validated!(
    /// A finite number of at least zero.
    NonNegative(f32) via number, |v| v >= 0.0, "a number of at least 0"
);
validated!(
    /// A point or offset `[x, y, z]` of finite numbers.
    Point(Vec3) via vector, |v| true, "[x, y, z]"
);
validated!(
    /// A direction `[x, y, z]`: finite and not zero.
    Direction(Vec3) via vector, |v| v.try_normalize().is_some(), "a non-zero direction [x, y, z]"
);
validated!(
    /// A linear RGB color `[r, g, b]` with no negative component.
    Color(Vec3) via vector, |v| v.min_element() >= 0.0, "a color [r, g, b] with components of at least 0"
);
validated!(
    /// A pair of finite numbers `[u, v]`.
    UvPair(glam::Vec2) via pair, |v| true, "[u, v]"
);
validated!(
    /// A pair `[u, v]` with no zero component (a uv scale).
    UvScale(glam::Vec2) via pair, |v| v.x != 0.0 && v.y != 0.0, "a scale [u, v] with no zero component"
);
validated!(
    /// A finite number (of at most [`MAX_MAGNITUDE`]).
    Real(f32) via number, |v| true, "a finite number"
);
validated!(
    /// A number from 0 to 1.
    Fraction(f32) via number, |v| (0.0..=1.0).contains(&v), "a number from 0 to 1"
);
validated!(
    /// A vertical field of view in degrees, strictly between 0 and 180.
    FieldOfView(f32) via number, |v| v > 0.0 && v < 180.0, "a field of view in degrees strictly between 0 and 180"
);

/// Exactly `N` values: a TOML array of another length is refused (serde's
/// own arrays read the first `N` and ignore the rest).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Exactly<T, const N: usize>(pub [T; N]);

impl<T, const N: usize> std::ops::Deref for Exactly<T, N> {
    type Target = [T; N];
    fn deref(&self) -> &[T; N] {
        &self.0
    }
}

impl<'de, T: Deserialize<'de>, const N: usize> Deserialize<'de> for Exactly<T, N> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let items = Vec::<T>::deserialize(d)?;
        let count = items.len();
        <[T; N]>::try_from(items)
            .map(Exactly)
            .map_err(|_| de::Error::custom(format!("expected {N} values, got {count}")))
    }
}

/// A count of at least 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Count(pub u32);

impl<'de> Deserialize<'de> for Count {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        match u32::deserialize(d)? {
            0 => Err(de::Error::custom(
                "expected a whole number of at least 1, got 0",
            )),
            n => Ok(Count(n)),
        }
    }
}

/// A film resolution `[width, height]`, each from 1 to [`MAX_RESOLUTION`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Resolution(pub UVec2);

impl<'de> Deserialize<'de> for Resolution {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let sides = Vec::<u32>::deserialize(d)?;
        let [w, h] = sides[..] else {
            return Err(de::Error::custom(format!(
                "expected a resolution [width, height], two whole numbers, got {} numbers",
                sides.len()
            )));
        };
        parse_resolution_parts(w, h)
            .map(Resolution)
            .map_err(de::Error::custom)
    }
}

/// Checks a resolution's sides; shared by the file format and the command line.
pub fn parse_resolution_parts(w: u32, h: u32) -> Result<UVec2, String> {
    if (1..=MAX_RESOLUTION).contains(&w) && (1..=MAX_RESOLUTION).contains(&h) {
        Ok(UVec2::new(w, h))
    } else {
        Err(format!(
            "expected a resolution [width, height] with each side from 1 to {MAX_RESOLUTION}, got [{w}, {h}]"
        ))
    }
}

/// Reads one of a fixed set of names.
fn named<'de, D: Deserializer<'de>, T>(
    d: D,
    names: &[&str],
    parse: impl Fn(&str) -> Option<T>,
) -> Result<T, D::Error> {
    let name = String::deserialize(d)?;
    parse(&name).ok_or_else(|| {
        let list = names.iter().map(|n| format!("\"{n}\"")).collect::<Vec<_>>();
        de::Error::custom(format!(
            "expected one of {}, got \"{name}\"",
            list.join(", ")
        ))
    })
}

/// A sample pattern name: `"grid"`, `"random"`, `"stratified"` or `"sobol"`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pattern(pub SamplePattern);

impl<'de> Deserialize<'de> for Pattern {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        named(d, &SamplePattern::NAMES, SamplePattern::from_name).map(Pattern)
    }
}

/// An area-light sampling name: `"solid-angle"` or `"area"`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AreaSamplingName(pub AreaSampling);

impl<'de> Deserialize<'de> for AreaSamplingName {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        named(d, &AreaSampling::NAMES, AreaSampling::from_name).map(AreaSamplingName)
    }
}

/// An environment sampling name: `"luminance"` or `"cosine"`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvironmentSamplingName(pub EnvironmentSampling);

impl<'de> Deserialize<'de> for EnvironmentSamplingName {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        named(
            d,
            &EnvironmentSampling::NAMES,
            EnvironmentSampling::from_name,
        )
        .map(EnvironmentSamplingName)
    }
}

/// A specular lobe name: `"phong"` or `"blinn-phong"`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lobe(pub SpecularLobe);

impl<'de> Deserialize<'de> for Lobe {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        named(d, &["phong", "blinn-phong"], |n| match n {
            "phong" => Some(SpecularLobe::Phong),
            "blinn-phong" => Some(SpecularLobe::BlinnPhong),
            _ => None,
        })
        .map(Lobe)
    }
}

/// A shading model name: `"phong"` or `"physical"`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Shading(pub ShadingModel);

impl<'de> Deserialize<'de> for Shading {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        named(d, &["phong", "physical"], |n| match n {
            "phong" => Some(ShadingModel::Phong),
            "physical" => Some(ShadingModel::Physical),
            _ => None,
        })
        .map(Shading)
    }
}

/// A wrap mode name: `"repeat"`, `"clamp"` or `"mirror"`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wrap(pub WrapMode);

impl<'de> Deserialize<'de> for Wrap {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        named(d, &WrapMode::NAMES, WrapMode::from_name).map(Wrap)
    }
}

/// An image filter name: `"nearest"`, `"bilinear"`, `"trilinear"` or `"ewa"`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Filter(pub TextureFilter);

impl<'de> Deserialize<'de> for Filter {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        named(d, &TextureFilter::NAMES, TextureFilter::from_name).map(Filter)
    }
}

/// The procedural checkerboard's filter: `"point"` or `"analytic"` (`true`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CheckerFilter(pub bool);

impl<'de> Deserialize<'de> for CheckerFilter {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        named(d, &["point", "analytic"], |n| match n {
            "point" => Some(false),
            "analytic" => Some(true),
            _ => None,
        })
        .map(CheckerFilter)
    }
}

/// A scale: one number (uniform) or `[sx, sy, sz]`, with no zero component.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scale3(pub Vec3);

impl<'de> Deserialize<'de> for Scale3 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Vec3;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a scale: a number or [sx, sy, sz]")
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Vec3, E> {
                Ok(Vec3::splat(finite(v as f64)?))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Vec3, E> {
                Ok(Vec3::splat(finite(v as f64)?))
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Vec3, E> {
                Ok(Vec3::splat(finite(v)?))
            }
            fn visit_seq<A: de::SeqAccess<'de>>(self, seq: A) -> Result<Vec3, A::Error> {
                vector(de::value::SeqAccessDeserializer::new(seq))
            }
        }
        let v = d.deserialize_any(V)?;
        if v.cmpeq(Vec3::ZERO).any() {
            return Err(de::Error::custom(format!(
                "expected a scale with no zero component, got [{}, {}, {}]",
                v.x, v.y, v.z
            )));
        }
        Ok(Scale3(v))
    }
}
