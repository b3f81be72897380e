//! The `[environment]` table as the environment light.

use crate::error::Problem;
use crate::format::EnvironmentTable;
use glint_lighting::EnvironmentLight;
use glint_texture::{load_image, CubeMap, Environment, Image, LatLongMap, MAX_IMAGE_TEXELS};
use std::path::{Path, PathBuf};
use toml::Spanned;

/// The environment light: one source (constant, cube map, lat-long image), turned
/// and scaled.
pub(super) fn environment(
    spanned: &Spanned<EnvironmentTable>,
    base_dir: &Path,
    assets: &mut Vec<PathBuf>,
) -> Result<EnvironmentLight, Problem> {
    let e = spanned.get_ref();
    let sources = [e.color.is_some(), e.cube_map.is_some(), e.latlong.is_some()];
    if sources.iter().filter(|s| **s).count() != 1 {
        return Err(Problem::new(
            spanned.span(),
            "environment",
            "expected exactly one of `color`, `cube_map` or `latlong`",
        ));
    }
    let mut maps = Maps { base_dir, assets };
    let map = if let Some(c) = e.color {
        Environment::Constant(c.0)
    } else if let Some(template) = &e.cube_map {
        maps.cube_map(template)?
    } else {
        let file = e.latlong.as_ref().expect("one source");
        let image = maps.read(file, file.get_ref(), "environment.latlong")?;
        Environment::LatLong(LatLongMap::new(image))
    };
    Ok(EnvironmentLight::new(
        map,
        e.rotation.0.to_radians(),
        e.intensity.0,
    ))
}

/// Reads environment images from `base_dir`, listing each in `assets`.
struct Maps<'a> {
    base_dir: &'a Path,
    assets: &'a mut Vec<PathBuf>,
}

impl Maps<'_> {
    /// The image at `path` (which the file's `field`, `file`, names).
    fn read(&mut self, file: &Spanned<String>, path: &str, field: &str) -> Result<Image, Problem> {
        let path = self.base_dir.join(path);
        let image =
            load_image(&path).map_err(|err| Problem::new(file.span(), field, err.to_string()))?;
        self.assets.push(path);
        Ok(image)
    }

    /// The six faces named by `template`, whose `{face}` is each of
    /// `px nx py ny pz nz`, as a cube map.
    fn cube_map(&mut self, template: &Spanned<String>) -> Result<Environment, Problem> {
        if !template.get_ref().contains("{face}") {
            return Err(Problem::new(
                template.span(),
                "environment.cube_map",
                "expected a path template containing {face}, e.g. \"studio/{face}.hdr\"",
            ));
        }
        let mut faces = Vec::with_capacity(6);
        for face in ["px", "nx", "py", "ny", "pz", "nz"] {
            faces.push(self.read(
                template,
                &template.get_ref().replace("{face}", face),
                "environment.cube_map",
            )?);
        }
        let faces: [Image; 6] = faces.try_into().expect("six faces");
        let texels: u64 = faces
            .iter()
            .map(|f| f.width() as u64 * f.height() as u64)
            .sum();
        if texels > MAX_IMAGE_TEXELS {
            return Err(Problem::new(
                template.span(),
                "environment.cube_map",
                format!("the six faces have {texels} texels in all, more than the limit of {MAX_IMAGE_TEXELS}"),
            ));
        }
        let cube = CubeMap::new(faces)
            .map_err(|m| Problem::new(template.span(), "environment.cube_map", m))?;
        Ok(Environment::CubeMap(cube))
    }
}
