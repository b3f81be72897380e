//! Values across the boundary: films and numpy arrays, dicts of settings and
//! overrides, dicts of scene tables and TOML.

use glam::{UVec2, Vec3};
use glint_camera::Film;
use glint_integrator::{AreaSampling, EnvironmentSampling, SamplePattern, TextureLevel};
use glint_scene::Overrides;
use glint_texture::TextureFilter;
use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArray3, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

/// The film as a `(height, width, 3)` float32 array: its pixels flattened
/// once into the buffer the array takes over.
pub(crate) fn array_of(py: Python<'_>, film: Film) -> Bound<'_, PyArray3<f32>> {
    let size = film.resolution();
    let (w, h) = (size.x as usize, size.y as usize);
    let values: Vec<f32> = film
        .into_pixels()
        .into_iter()
        .flat_map(|p| p.to_array())
        .collect();
    Array3::from_shape_vec((h, w, 3), values)
        .expect("a film's pixels fill its resolution")
        .into_pyarray(py)
}

/// A `(height, width, 3)` float32 array as a film (the Python side makes it
/// C-contiguous and checks its dtype and shape first).
pub(crate) fn film_of(image: &PyReadonlyArray3<'_, f32>) -> PyResult<Film> {
    let shape = image.shape();
    if shape[2] != 3 {
        return Err(PyValueError::new_err(format!(
            "an image is (height, width, 3): this array's shape is {shape:?}"
        )));
    }
    let values = image
        .as_slice()
        .map_err(|_| PyValueError::new_err("the image array is not C-contiguous"))?;
    let pixels = values
        .chunks_exact(3)
        .map(|c| Vec3::new(c[0], c[1], c[2]))
        .collect();
    let size = UVec2::new(shape[1] as u32, shape[0] as u32);
    Film::from_pixels(size, pixels)
        .ok_or_else(|| PyValueError::new_err("the image array's size does not match its shape"))
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
