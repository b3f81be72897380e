//! Values across the boundary: films and images' bytes, dicts of settings and
//! overrides, dicts of scene tables and TOML.

use glam::{UVec2, Vec3};
use glint_camera::Film;
use glint_integrator::{AreaSampling, EnvironmentSampling, SamplePattern, TextureLevel};
use glint_scene::Overrides;
use glint_texture::TextureFilter;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyByteArray, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

/// An image as it crosses to Python: its values' bytes (native-endian,
/// rows from the top, three channels) in a `bytearray` numpy wraps without a
/// copy (`glint._from_raw`), and its height and width. No numpy crate: the
/// package builds sooner without it, and the bytes are what numpy holds.
pub(crate) type Raw<'py> = (Bound<'py, PyByteArray>, usize, usize);

/// The film as [`Raw`] float32 values.
pub(crate) fn array_of(py: Python<'_>, film: Film) -> PyResult<Raw<'_>> {
    let size = film.resolution();
    let pixels = film.pixels();
    let bytes = PyByteArray::new_with(py, pixels.len() * 12, |out| {
        for (chunk, p) in out.chunks_exact_mut(12).zip(pixels) {
            for (bytes, v) in chunk.chunks_exact_mut(4).zip(p.to_array()) {
                bytes.copy_from_slice(&v.to_ne_bytes());
            }
        }
        Ok(())
    })?;
    Ok((bytes, size.y as usize, size.x as usize))
}

/// RGB8 codes as [`Raw`] uint8 values.
pub(crate) fn codes_of<'py>(py: Python<'py>, size: UVec2, rgb: &[u8]) -> Raw<'py> {
    (PyByteArray::new(py, rgb), size.y as usize, size.x as usize)
}

/// A float32 image's bytes (`glint._to_raw`: a C-contiguous `(height,
/// width, 3)` array's, checked for dtype and shape there) as a film.
pub(crate) fn film_of((bytes, height, width): (&[u8], usize, usize)) -> PyResult<Film> {
    if bytes.len() != height * width * 12 {
        return Err(PyValueError::new_err(format!(
            "an image of {height}x{width} pixels needs {} bytes, these are {}",
            height * width * 12,
            bytes.len()
        )));
    }
    let pixels = bytes
        .chunks_exact(12)
        .map(|c| {
            let v = |k: usize| f32::from_ne_bytes([c[k], c[k + 1], c[k + 2], c[k + 3]]);
            Vec3::new(v(0), v(4), v(8))
        })
        .collect();
    let size = UVec2::new(width as u32, height as u32);
    Film::from_pixels(size, pixels)
        .ok_or_else(|| PyValueError::new_err("the image's size does not match its pixels"))
}

/// The keys [`overrides_of`] takes, in the order the CLI's help lists them.
const OVERRIDE_KEYS: [&str; 14] = [
    "spp",
    "light_samples",
    "pixel_sampler",
    "light_sampler",
    "max_depth",
    "environment_samples",
    "environment_sampler",
    "environment_sampling",
    "area_sampling",
    "mis",
    "seed",
    "resolution",
    "texture_filter",
    "texture_level",
];

/// The settings a dict of keywords replaces: the names of `glint render`'s
/// flags with `_` for `-` (`pixel_sampler` for `--sampler`, `mis=False` for
/// `--no-mis`), values as Python numbers, booleans and names; `resolution`
/// as `(width, height)` or `"WxH"`.
pub(crate) fn overrides_of(dict: &Bound<'_, PyDict>) -> PyResult<Overrides> {
    let mut o = Overrides::default();
    for (key, value) in dict.iter() {
        let key: String = key.extract()?;
        if value.is_none() {
            continue;
        }
        let v = (key.as_str(), &value);
        match key.as_str() {
            "spp" => o.spp = Some(value.extract()?),
            "light_samples" => o.light_samples = Some(value.extract()?),
            "max_depth" => o.max_depth = Some(value.extract()?),
            "environment_samples" => o.environment_samples = Some(value.extract()?),
            "seed" => o.seed = Some(value.extract()?),
            "mis" => o.mis = Some(value.extract()?),
            "pixel_sampler" => {
                o.pixel_sampler = Some(named(v, SamplePattern::from_name, &SamplePattern::NAMES)?)
            }
            "light_sampler" => {
                o.light_sampler = Some(named(v, SamplePattern::from_name, &SamplePattern::NAMES)?)
            }
            "environment_sampler" => {
                o.environment_sampler =
                    Some(named(v, SamplePattern::from_name, &SamplePattern::NAMES)?)
            }
            "environment_sampling" => {
                o.environment_sampling = Some(named(
                    v,
                    EnvironmentSampling::from_name,
                    &EnvironmentSampling::NAMES,
                )?)
            }
            "area_sampling" => {
                o.area_sampling = Some(named(v, AreaSampling::from_name, &AreaSampling::NAMES)?)
            }
            "texture_filter" => {
                o.texture_filter = Some(named(v, TextureFilter::from_name, &TextureFilter::NAMES)?)
            }
            "texture_level" => {
                o.texture_level = Some(named(v, TextureLevel::from_name, &TextureLevel::NAMES)?)
            }
            "resolution" => o.resolution = Some(resolution_of(&value)?),
            _ => {
                return Err(PyTypeError::new_err(format!(
                    "unknown setting \"{key}\"; the settings are {}",
                    OVERRIDE_KEYS.join(", ")
                )))
            }
        }
    }
    Ok(o)
}

/// The value of setting `key` named as one of `names`.
fn named<T>(
    (key, value): (&str, &Bound<'_, PyAny>),
    parse: fn(&str) -> Option<T>,
    names: &[&str],
) -> PyResult<T> {
    let name: String = value.extract()?;
    parse(&name).ok_or_else(|| {
        PyValueError::new_err(format!(
            "{key}: unknown value \"{name}\"; expected one of {}",
            names.join(", ")
        ))
    })
}

/// `(width, height)` or `"WxH"`, checked as the file's resolution is.
fn resolution_of(value: &Bound<'_, PyAny>) -> PyResult<UVec2> {
    let (w, h): (u32, u32) = match value.extract::<String>() {
        Ok(text) => {
            let parts = text
                .split_once(['x', 'X'])
                .and_then(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)));
            parts.ok_or_else(|| {
                PyValueError::new_err(format!(
                    "resolution: expected \"WxH\", e.g. \"640x480\", got \"{text}\""
                ))
            })?
        }
        Err(_) => value.extract()?,
    };
    glint_scene::parse_resolution_parts(w, h)
        .map_err(|e| PyValueError::new_err(format!("resolution: {e}")))
}

/// A dict of the scene file's tables as TOML text.
pub(crate) fn toml_of(scene: &Bound<'_, PyAny>) -> PyResult<String> {
    let toml::Value::Table(table) = toml_value(scene, "")? else {
        return Err(PyTypeError::new_err(
            "a scene is a path, TOML text or a dict of tables",
        ));
    };
    toml::to_string(&table).map_err(|e| PyValueError::new_err(format!("scene dict: {e}")))
}

/// One Python value as TOML; `at` names where it is, for errors.
fn toml_value(value: &Bound<'_, PyAny>, at: &str) -> PyResult<toml::Value> {
    let at_key = |key: &str| match at {
        "" => key.to_string(),
        _ => format!("{at}.{key}"),
    };
    if let Ok(dict) = value.cast::<PyDict>() {
        let mut table = toml::Table::new();
        for (key, item) in dict.iter() {
            let key: String = key.extract().map_err(|_| {
                PyTypeError::new_err(format!("scene dict: a key of {at} is not a string"))
            })?;
            let item = toml_value(&item, &at_key(&key))?;
            table.insert(key, item);
        }
        return Ok(toml::Value::Table(table));
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        let items = value
            .try_iter()?
            .enumerate()
            .map(|(i, item)| toml_value(&item?, &format!("{at}[{i}]")));
        return Ok(toml::Value::Array(items.collect::<PyResult<_>>()?));
    }
    if value.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(value.extract()?));
    }
    if value.is_instance_of::<PyInt>() {
        return Ok(toml::Value::Integer(value.extract()?));
    }
    if value.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(value.extract()?));
    }
    if value.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(value.extract()?));
    }
    // numpy scalars and anything else that says what number it is.
    if let Ok(x) = value
        .call_method0("__float__")
        .and_then(|f| f.extract::<f64>())
    {
        return Ok(toml::Value::Float(x));
    }
    let kind = value.get_type().name()?;
    Err(PyTypeError::new_err(format!(
        "scene dict: {at} is a {kind}; expected a dict, list, string, number or bool"
    )))
}
