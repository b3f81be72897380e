//! Heat maps: an [`ErrorMap`] colored with the magma color map, and writing one
//! as a PNG.

use crate::{ErrorMap, MetricsError};
use std::io::Write;
use std::path::Path;
use std::sync::OnceLock;

/// The 256 colors of the magma color map (black through purple and orange to
/// light yellow), as FLIP's tools use it.
pub fn magma() -> &'static [[u8; 3]; 256] {
    static LUT: OnceLock<[[u8; 3]; 256]> = OnceLock::new();
    LUT.get_or_init(|| {
        let bytes = nv_flip::magma_lut().to_vec();
        std::array::from_fn(|i| [bytes[3 * i], bytes[3 * i + 1], bytes[3 * i + 2]])
    })
}

/// Colors each value of `map` with the magma color map: `value / scale`,
/// clamped to [0, 1], picks entry `round(255 · t)`, so 0 is black and `scale` or
/// more is light yellow. NaN is drawn as the top of the scale (it is an error
/// worth seeing). Use `scale = 1` for FLIP, whose values lie in [0, 1]. Rows
/// from the top, as in the map.
///
/// # Errors
/// If `scale` is not positive and finite, or the map's values do not fill it.
pub fn heatmap(map: &ErrorMap, scale: f32) -> Result<Vec<[u8; 3]>, MetricsError> {
    if !(scale.is_finite() && scale > 0.0) {
        return Err(MetricsError::Scale(scale));
    }
    map.check()?;
    let lut = magma();
    Ok(map
        .values
        .iter()
        .map(|&v| {
            let t = if v.is_nan() {
                1.0
            } else {
                (v / scale).clamp(0.0, 1.0)
            };
            lut[(t * 255.0).round() as usize]
        })
        .collect())
}

/// The scale a heat map of relative errors is drawn on: the 99th percentile
/// of the finite `values` (so that a few outliers do not darken the rest),
/// or 1 where that is not positive.
pub fn heatmap_scale(values: impl Iterator<Item = f32>) -> f32 {
    let mut values: Vec<f32> = values.filter(|v| v.is_finite()).collect();
    values.sort_by(f32::total_cmp);
    values
        .get(values.len().saturating_sub(1) * 99 / 100)
        .copied()
        .filter(|v| *v > 0.0)
        .unwrap_or(1.0)
}

/// `rgb` (`width × height` colors, rows from the top) encoded as an 8-bit RGB
/// PNG, or why not (colors that do not fill the size).
pub fn heatmap_png(width: u32, height: u32, rgb: &[[u8; 3]]) -> Result<Vec<u8>, String> {
    crate::error::check_length("a heat map", width, height, rgb.len())
        .map_err(|e| e.to_string())?;
    let bytes: Vec<u8> = rgb.iter().flatten().copied().collect();
    let image = image::RgbImage::from_raw(width, height, bytes)
        .ok_or_else(|| "its colors do not fill it".to_owned())?;
    let mut out = std::io::Cursor::new(Vec::new());
    image
        .write_to(&mut out, image::ImageFormat::Png)
        .map_err(|e| e.to_string())?;
    Ok(out.into_inner())
}

/// Writes `rgb` (`width × height` colors, rows from the top) as an 8-bit RGB PNG
/// at `path`. The image goes to a temporary file beside `path` that is renamed
/// over it once complete, so a failed write never leaves a partial file and
/// never destroys what was at `path`; a replaced file keeps its permissions.
/// Errors name the file; `rgb` not holding `width × height` colors is one.
pub fn save_heatmap(path: &Path, width: u32, height: u32, rgb: &[[u8; 3]]) -> Result<(), String> {
    let fail =
        |e: &dyn std::fmt::Display| format!("{}: cannot write the heat map: {e}", path.display());
    let png = heatmap_png(width, height, rgb).map_err(|e| fail(&e))?;
    glint_camera::write_atomically(
        path,
        |e| fail(&e),
        |out| out.write_all(&png).map_err(|e| fail(&e)),
    )
}
