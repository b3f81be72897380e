//! Strategies: what a bench compares. A strategy fixes where samples fall (the
//! pixel, light and environment sample patterns) and, optionally, how every image
//! texture is filtered, how physical shading samples area lights and how the
//! environment's directions are drawn; everything else comes from the scene file.

use glint_integrator::{AreaSampling, EnvironmentSampling, RenderSettings, SamplePattern, Scene};
use glint_texture::TextureFilter;

/// One way of rendering the scene that the bench measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Strategy {
    pub pixel: SamplePattern,
    pub light: SamplePattern,
    pub environment: SamplePattern,
    /// Overrides the filtering of every image texture (`None`: each texture's own).
    pub texture_filter: Option<TextureChoice>,
    /// Overrides how physical shading samples area lights (`None`: the scene's).
    pub light_strategy: Option<LightStrategy>,
    /// Overrides how environment directions are drawn (`None`: the scene's).
    pub environment_sampling: Option<EnvironmentSampling>,
}

/// How physical shading samples area lights: the density of light samples,
/// and whether glossy lobes are sampled too, combined by multiple importance
/// sampling. Named `SAMPLING` or `SAMPLING+mis` (`area+mis`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LightStrategy {
    pub sampling: AreaSampling,
    pub mis: bool,
}

impl LightStrategy {
    pub fn from_name(name: &str) -> Option<Self> {
        let (sampling, mis) = match name.strip_suffix("+mis") {
            Some(sampling) => (sampling, true),
            None => (name, false),
        };
        Some(Self {
            sampling: AreaSampling::from_name(sampling)?,
            mis,
        })
    }

    pub fn name(self) -> String {
        let mis = if self.mis { "+mis" } else { "" };
        format!("{}{mis}", self.sampling.name())
    }
}

/// How a strategy filters image textures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TextureChoice {
    /// Every image with this filter.
    Filter(TextureFilter),
    /// Images rasterised from a checkerboard (`checker_image`) as the procedural
    /// checkerboard, box-filtered exactly over the footprint; other images with
    /// EWA.
    AnalyticCheckerboards,
}

impl TextureChoice {
    /// The names `--texture-filters` takes.
    pub const NAMES: [&'static str; 5] = ["nearest", "bilinear", "trilinear", "ewa", "analytic"];

    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "analytic" => Some(Self::AnalyticCheckerboards),
            other => TextureFilter::from_name(other).map(Self::Filter),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::Filter(f) => f.name(),
            Self::AnalyticCheckerboards => "analytic",
        }
    }

    fn apply(self, scene: &mut Scene) {
        match self {
            Self::Filter(f) => scene.override_texture_filter(f),
            Self::AnalyticCheckerboards => scene.use_analytic_checkerboards(TextureFilter::Ewa),
        }
    }
}

impl Strategy {
    /// The same pattern for the pixel, the lights and the environment.
    pub fn uniform(pattern: SamplePattern) -> Self {
        Self {
            pixel: pattern,
            light: pattern,
            environment: pattern,
            texture_filter: None,
            light_strategy: None,
            environment_sampling: None,
        }
    }

    /// The name the tables, files and plots use: `sobol` when one pattern places
    /// every sample, `PIXEL/LIGHT` or `PIXEL/LIGHT/ENVIRONMENT` otherwise, then
    /// `+FILTER` when the texture filter is overridden, `+LIGHTS` when the
    /// light strategy is (`sobol+area+mis`) and `+SAMPLING` when the
    /// environment's sampling is (`sobol+cosine`).
    pub fn name(&self) -> String {
        let mut name = self.pixel.name().to_owned();
        if self.light != self.pixel || self.environment != self.light {
            name = format!("{name}/{}", self.light.name());
        }
        if self.environment != self.light {
            name = format!("{name}/{}", self.environment.name());
        }
        if let Some(filter) = self.texture_filter {
            name = format!("{name}+{}", filter.name());
        }
        if let Some(lights) = self.light_strategy {
            name = format!("{name}+{}", lights.name());
        }
        if let Some(sampling) = self.environment_sampling {
            name = format!("{name}+{}", sampling.name());
        }
        name
    }

    /// The name with every character a file name should not hold replaced by `-`.
    pub fn file_stem(&self) -> String {
        self.name()
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
            .collect()
    }

    /// Puts the strategy's patterns into `settings` and its filter into `scene`.
    pub fn apply(&self, scene: &mut Scene, settings: &mut RenderSettings) {
        settings.pixel_pattern = self.pixel;
        settings.light_pattern = self.light;
        settings.environment_pattern = self.environment;
        if let Some(choice) = self.texture_filter {
            choice.apply(scene);
        }
        if let Some(lights) = self.light_strategy {
            settings.area_sampling = lights.sampling;
            settings.mis = lights.mis;
        }
        if let Some(sampling) = self.environment_sampling {
            settings.environment_sampling = sampling;
        }
    }

    /// Whether the strategy can place the given numbers of samples (the grid
    /// pattern needs perfect squares).
    pub fn supports(&self, spp: u32, light_samples: u32, environment_samples: u32) -> bool {
        self.pixel.supports(spp)
            && self.light.supports(light_samples)
            && (environment_samples == 0 || self.environment.supports(environment_samples))
    }
}

/// Parses a list of sampler strategies: `random,stratified,sobol,grid`, where each
/// entry is one pattern for every sample, or `PIXEL/LIGHT` (the environment
/// following the light), or `PIXEL/LIGHT/ENVIRONMENT`.
pub fn parse_samplers(list: &str) -> Result<Vec<Strategy>, String> {
    let mut strategies = Vec::new();
    for entry in list.split(',').map(str::trim) {
        let patterns = entry
            .split('/')
            .map(|name| {
                SamplePattern::from_name(name.trim()).ok_or_else(|| {
                    format!(
                        "unknown sampler \"{name}\" in \"{entry}\", expected one of {}",
                        SamplePattern::NAMES.join(", ")
                    )
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let strategy = match patterns[..] {
            [all] => Strategy::uniform(all),
            [pixel, light] => Strategy {
                pixel,
                ..Strategy::uniform(light)
            },
            [pixel, light, environment] => Strategy {
                light,
                environment,
                ..Strategy::uniform(pixel)
            },
            _ => {
                return Err(format!(
                    "\"{entry}\": expected PATTERN, PIXEL/LIGHT or PIXEL/LIGHT/ENVIRONMENT"
                ))
            }
        };
        if strategies.contains(&strategy) {
            return Err(format!("sampler \"{entry}\" is listed twice"));
        }
        strategies.push(strategy);
    }
    Ok(strategies)
}

/// Parses a list of texture filters (`nearest,bilinear,trilinear,ewa,analytic`).
pub fn parse_texture_filters(list: &str) -> Result<Vec<TextureChoice>, String> {
    let expected = TextureChoice::NAMES.join(", ");
    parse_names(list, "texture filter", TextureChoice::from_name, &expected)
}

/// Parses a list of light strategies (`solid-angle+mis,solid-angle,area+mis,area`).
pub fn parse_light_strategies(list: &str) -> Result<Vec<LightStrategy>, String> {
    let expected = format!(
        "{}, each optionally followed by +mis",
        AreaSampling::NAMES.join(", ")
    );
    parse_names(list, "light strategy", LightStrategy::from_name, &expected)
}

/// Parses a list of environment samplings (`luminance,cosine`).
pub fn parse_environment_samplings(list: &str) -> Result<Vec<EnvironmentSampling>, String> {
    let expected = EnvironmentSampling::NAMES.join(", ");
    parse_names(
        list,
        "environment sampling",
        EnvironmentSampling::from_name,
        &expected,
    )
}

/// A comma-separated list of `what`s, each named once, refusing an unknown
/// name (saying which names are `expected`) or one listed twice.
fn parse_names<T: PartialEq>(
    list: &str,
    what: &str,
    from_name: impl Fn(&str) -> Option<T>,
    expected: &str,
) -> Result<Vec<T>, String> {
    let mut values = Vec::new();
    for name in list.split(',').map(str::trim) {
        let value = from_name(name)
            .ok_or_else(|| format!("unknown {what} \"{name}\", expected one of {expected}"))?;
        if values.contains(&value) {
            return Err(format!("{what} \"{name}\" is listed twice"));
        }
        values.push(value);
    }
    Ok(values)
}

/// What a bench varies besides the sample patterns; an empty list keeps the
/// scene's own.
#[derive(Clone, Debug, Default)]
pub struct Choices {
    pub filters: Vec<TextureChoice>,
    pub lights: Vec<LightStrategy>,
    pub environments: Vec<EnvironmentSampling>,
}

/// Every sampler strategy with every texture filter, every light strategy
/// and every environment sampling of `choices`.
pub fn combine(samplers: &[Strategy], choices: &Choices) -> Vec<Strategy> {
    fn each<T: Copy>(list: &[T]) -> Vec<Option<T>> {
        if list.is_empty() {
            vec![None]
        } else {
            list.iter().copied().map(Some).collect()
        }
    }
    let mut all = Vec::new();
    for s in samplers {
        for texture_filter in each(&choices.filters) {
            for light_strategy in each(&choices.lights) {
                for environment_sampling in each(&choices.environments) {
                    all.push(Strategy {
                        texture_filter,
                        light_strategy,
                        environment_sampling,
                        ..*s
                    });
                }
            }
        }
    }
    all
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_short_when_one_pattern_places_everything() {
        let s = parse_samplers("sobol, stratified/random, grid/grid/random, random").unwrap();
        let names: Vec<String> = s.iter().map(Strategy::name).collect();
        assert_eq!(
            names,
            ["sobol", "stratified/random", "grid/grid/random", "random"]
        );
        let filters = Choices {
            filters: vec![
                TextureChoice::Filter(TextureFilter::Ewa),
                TextureChoice::AnalyticCheckerboards,
            ],
            ..Choices::default()
        };
        let with_filter = combine(&s[..1], &filters);
        assert_eq!(with_filter[0].name(), "sobol+ewa");
        assert_eq!(with_filter[1].name(), "sobol+analytic");
        let lights = parse_light_strategies("solid-angle+mis, area").unwrap();
        let environments = parse_environment_samplings("cosine").unwrap();
        let with_lights = combine(
            &s[..2],
            &Choices {
                lights,
                environments,
                ..Choices::default()
            },
        );
        let names: Vec<String> = with_lights.iter().map(Strategy::name).collect();
        assert_eq!(
            names,
            [
                "sobol+solid-angle+mis+cosine",
                "sobol+area+cosine",
                "stratified/random+solid-angle+mis+cosine",
                "stratified/random+area+cosine"
            ]
        );
        let mut settings = RenderSettings::default();
        let camera = glint_camera::Camera::new(
            glam::Vec3::Z,
            glam::Vec3::ZERO,
            glam::Vec3::Y,
            45.0,
            1.0,
            glam::UVec2::ONE,
        )
        .unwrap();
        let mut scene = glint_integrator::SceneBuilder::new().build(camera).unwrap();
        with_lights[1].apply(&mut scene, &mut settings);
        assert_eq!(
            (settings.area_sampling, settings.mis),
            (AreaSampling::Area, false)
        );
        assert_eq!(settings.environment_sampling, EnvironmentSampling::Cosine);
        assert_eq!(
            parse_texture_filters("trilinear, analytic").unwrap(),
            [
                TextureChoice::Filter(TextureFilter::Trilinear),
                TextureChoice::AnalyticCheckerboards
            ]
        );
        assert_eq!(s[1].file_stem(), "stratified-random");
    }

    #[test]
    fn bad_lists_are_refused_with_the_entry_named() {
        let e = parse_samplers("sobol,halton").unwrap_err();
        assert!(e.contains("\"halton\""), "{e}");
        let e = parse_samplers("sobol,sobol").unwrap_err();
        assert!(e.contains("twice"), "{e}");
        let e = parse_environment_samplings("cosine,uniform").unwrap_err();
        assert!(
            e.contains("\"uniform\"") && e.contains("luminance, cosine"),
            "{e}"
        );
        let e = parse_environment_samplings("cosine, cosine").unwrap_err();
        assert!(e.contains("twice"), "{e}");
        let e = parse_samplers("a/b/c/d").unwrap_err();
        assert!(e.contains("unknown sampler"), "{e}");
        let e = parse_samplers("grid/grid/grid/grid").unwrap_err();
        assert!(e.contains("PIXEL/LIGHT/ENVIRONMENT"), "{e}");
        assert!(parse_texture_filters("ewa,box")
            .unwrap_err()
            .contains("box"));
        assert!(parse_light_strategies("area,cosine+mis")
            .unwrap_err()
            .contains("\"cosine+mis\""));
        assert!(parse_light_strategies("area+mis,area+mis")
            .unwrap_err()
            .contains("twice"));
    }

    #[test]
    fn grid_needs_square_counts() {
        let grid = Strategy::uniform(SamplePattern::Grid);
        assert!(grid.supports(16, 4, 0));
        assert!(!grid.supports(8, 1, 1));
        assert!(!grid.supports(4, 2, 1));
        assert!(Strategy::uniform(SamplePattern::Random).supports(8, 2, 3));
    }
}
