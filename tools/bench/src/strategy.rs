//! Strategies: what a bench compares. A strategy fixes where samples fall (the
//! pixel, light and environment sample patterns) and, optionally, how every image
//! texture is filtered; everything else comes from the scene file.

use glint_integrator::{RenderSettings, SamplePattern, Scene};
use glint_texture::TextureFilter;

/// One way of rendering the scene that the bench measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Strategy {
    pub pixel: SamplePattern,
    pub light: SamplePattern,
    pub environment: SamplePattern,
    /// Overrides the filtering of every image texture (`None`: each texture's own).
    pub texture_filter: Option<TextureChoice>,
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
        }
    }

    /// The name the tables, files and plots use: `sobol` when one pattern places
    /// every sample, `PIXEL/LIGHT` or `PIXEL/LIGHT/ENVIRONMENT` otherwise, then
    /// `+FILTER` when the texture filter is overridden.
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
                light,
                environment: light,
                texture_filter: None,
            },
            [pixel, light, environment] => Strategy {
                pixel,
                light,
                environment,
                texture_filter: None,
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
    let mut filters = Vec::new();
    for name in list.split(',').map(str::trim) {
        let filter = TextureChoice::from_name(name).ok_or_else(|| {
            format!(
                "unknown texture filter \"{name}\", expected one of {}",
                TextureChoice::NAMES.join(", ")
            )
        })?;
        if filters.contains(&filter) {
            return Err(format!("texture filter \"{name}\" is listed twice"));
        }
        filters.push(filter);
    }
    Ok(filters)
}

/// Every sampler strategy with every texture filter (or with none, keeping each
/// texture's own, when `filters` is empty).
pub fn combine(samplers: &[Strategy], filters: &[TextureChoice]) -> Vec<Strategy> {
    if filters.is_empty() {
        return samplers.to_vec();
    }
    samplers
        .iter()
        .flat_map(|s| {
            filters.iter().map(move |&f| Strategy {
                texture_filter: Some(f),
                ..*s
            })
        })
        .collect()
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
        let with_filter = combine(
            &s[..1],
            &[
                TextureChoice::Filter(TextureFilter::Ewa),
                TextureChoice::AnalyticCheckerboards,
            ],
        );
        assert_eq!(with_filter[0].name(), "sobol+ewa");
        assert_eq!(with_filter[1].name(), "sobol+analytic");
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
        let e = parse_samplers("a/b/c/d").unwrap_err();
        assert!(e.contains("unknown sampler"), "{e}");
        let e = parse_samplers("grid/grid/grid/grid").unwrap_err();
        assert!(e.contains("PIXEL/LIGHT/ENVIRONMENT"), "{e}");
        assert!(parse_texture_filters("ewa,box")
            .unwrap_err()
            .contains("box"));
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
