//! The reference image errors are measured against: a file given by the user
//! (from another renderer, say), or Glint's own render at a high sample count,
//! made in independent rounds so that its own noise can be estimated, and cached.
//!
//! **Noise.** A rendered reference is the mean of `K` rounds, each an unbiased
//! render with its own seed (Owen-scrambled Sobol samples, one light and one
//! environment sample per camera sample). The rounds' sample variance `s²` per
//! pixel and channel gives the variance of their mean, `s²/K`, and from it the
//! reference's expected contribution to a measured relative MSE,
//! `mean(s²/K / (ref + 0.01)²)`: an error measured against a noisy reference is on
//! average the true error plus that amount. The bench adds rounds until it is at
//! least ten times below the smallest error it measured.
//!
//! **Cache.** A rendered reference is stored beside the bench's output as
//! `reference-KEY.pfm` (the mean), `reference-KEY-variance.pfm` (`s²/K`) and
//! `reference-KEY.json` (rounds and samples), where KEY is a BLAKE3 hash of the
//! scene file, every asset it loads, the reference's render settings and the
//! Glint version. A later bench of the same inputs starts from it, and adds
//! rounds to it if it needs a quieter reference.

use glam::{DVec3, Vec3};
use glint_camera::Film;
use glint_integrator::RenderSettings;
use glint_metrics::Region;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Rounds a reference starts with: two are the fewest that estimate a variance.
pub const FIRST_ROUNDS: u32 = 2;
/// The most rounds a reference grows to; past it the report says how far the
/// reference's noise is from the goal instead of rendering on.
pub const MAX_ROUNDS: u32 = 64;
/// How far below the smallest measured error the reference's noise must be.
pub const NOISE_MARGIN: f64 = 10.0;

/// Where the reference came from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Origin {
    /// Read from a file the user gave.
    File { path: PathBuf },
    /// Rendered by this bench (or an earlier one, `cached`).
    Rendered { cached: bool, key: String },
}

/// The reference image, with what is known of its noise.
#[derive(Clone, Debug)]
pub struct Reference {
    pub width: u32,
    pub height: u32,
    pub mean: Vec<Vec3>,
    /// Per pixel, the estimated variance of `mean` (`s²/K`); `None` for a file.
    pub variance_of_mean: Option<Vec<Vec3>>,
    pub rounds: u32,
    pub spp_per_round: u32,
    pub origin: Origin,
    /// Time spent rendering it in this bench (zero when read from the cache or a file).
    pub render_time: Duration,
}

impl Reference {
    /// A reference read from an image file.
    pub fn from_film(film: Film, path: &Path) -> Self {
        let resolution = film.resolution();
        Self {
            width: resolution.x,
            height: resolution.y,
            mean: film.pixels().to_vec(),
            variance_of_mean: None,
            rounds: 0,
            spp_per_round: 0,
            origin: Origin::File {
                path: path.to_owned(),
            },
            render_time: Duration::ZERO,
        }
    }

    /// Samples per pixel behind the mean (0 for a file).
    pub fn total_spp(&self) -> u64 {
        self.rounds as u64 * self.spp_per_round as u64
    }

    /// The reference's own expected contribution to a relative MSE measured in
    /// `region`: `mean(var / (ref + 0.01)²)` over its pixels and channels, the
    /// weights of the relative MSE. `None` when the noise is unknown (a file).
    pub fn noise_rel_mse(&self, region: Region) -> Option<f64> {
        let variance = self.variance_of_mean.as_ref()?;
        let mut sum = 0.0;
        for y in region.y0..region.y1 {
            for x in region.x0..region.x1 {
                let i = (y * self.width + x) as usize;
                let (m, v) = (self.mean[i].as_dvec3(), variance[i].as_dvec3());
                for c in 0..3 {
                    sum += v[c] / ((m[c] + 0.01) * (m[c] + 0.01));
                }
            }
        }
        Some(sum / (3 * region.pixel_count()) as f64)
    }
}

/// Running sums over rounds, per pixel, in f64.
pub struct RoundSums {
    pub width: u32,
    pub height: u32,
    sum: Vec<DVec3>,
    sum_sq: Vec<DVec3>,
    pub rounds: u32,
    pub spp_per_round: u32,
}

impl RoundSums {
    pub fn new(width: u32, height: u32, spp_per_round: u32) -> Self {
        let n = (width * height) as usize;
        Self {
            width,
            height,
            sum: vec![DVec3::ZERO; n],
            sum_sq: vec![DVec3::ZERO; n],
            rounds: 0,
            spp_per_round,
        }
    }

    /// Adds one round's image.
    pub fn add(&mut self, pixels: &[Vec3]) {
        for ((s, q), p) in self.sum.iter_mut().zip(&mut self.sum_sq).zip(pixels) {
            let p = p.as_dvec3();
            *s += p;
            *q += p * p;
        }
        self.rounds += 1;
    }

    /// The reference the rounds so far make.
    pub fn reference(&self, origin: Origin, render_time: Duration) -> Reference {
        let k = self.rounds.max(1) as f64;
        let mean: Vec<Vec3> = self.sum.iter().map(|s| (*s / k).as_vec3()).collect();
        let variance = (self.rounds >= 2).then(|| {
            self.sum
                .iter()
                .zip(&self.sum_sq)
                .map(|(s, q)| {
                    let m = *s / k;
                    let sample_variance = ((*q - k * m * m) / (k - 1.0)).max(DVec3::ZERO);
                    (sample_variance / k).as_vec3()
                })
                .collect()
        });
        Reference {
            width: self.width,
            height: self.height,
            mean,
            variance_of_mean: variance,
            rounds: self.rounds,
            spp_per_round: self.spp_per_round,
            origin,
            render_time,
        }
    }

    /// The sums behind a cached reference (mean and variance of the mean over
    /// `rounds` rounds): `Σx = K·m`, `Σx² = K(K−1)·v + K·m²`.
    pub fn from_reference(r: &Reference) -> Option<Self> {
        let variance = r.variance_of_mean.as_ref()?;
        let k = r.rounds as f64;
        let sum = r.mean.iter().map(|m| m.as_dvec3() * k).collect();
        let sum_sq = r
            .mean
            .iter()
            .zip(variance)
            .map(|(m, v)| {
                let (m, v) = (m.as_dvec3(), v.as_dvec3());
                k * (k - 1.0) * v + k * m * m
            })
            .collect();
        Some(Self {
            width: r.width,
            height: r.height,
            sum,
            sum_sq,
            rounds: r.rounds,
            spp_per_round: r.spp_per_round,
        })
    }
}

/// The seed of reference round `round`: far from the sweep's own seed, so that
/// no round shares a random stream with a measured render.
pub fn round_seed(seed: u64, round: u32) -> u64 {
    glint_integrator::sampling::mix64(seed ^ 0x5245_4645_5245_4e43 ^ ((round as u64 + 1) << 32))
}

/// What the cache key hashes besides the files: the settings of one round.
pub fn settings_fingerprint(settings: &RenderSettings, width: u32, height: u32) -> String {
    format!(
        "{width}x{height} spp={} pixel={} light={}x{} environment={}x{} seed={} max_depth={}",
        settings.spp,
        settings.pixel_pattern.name(),
        settings.light_samples,
        settings.light_pattern.name(),
        settings.environment_samples,
        settings.environment_pattern.name(),
        settings.seed,
        settings.max_depth,
    )
}

/// The cache key: BLAKE3 of the Glint version, the settings and every input
/// file's path and bytes.
pub fn cache_key(version: &str, settings: &str, inputs: &[PathBuf]) -> std::io::Result<String> {
    let mut hasher = blake3::Hasher::new();
    hasher.update(b"glint-bench reference 1\n");
    hasher.update(version.as_bytes());
    hasher.update(b"\n");
    hasher.update(settings.as_bytes());
    hasher.update(b"\n");
    for path in inputs {
        let bytes = std::fs::read(path)?;
        hasher.update(path.file_name().map_or(&[][..], |n| n.as_encoded_bytes()));
        hasher.update(&(bytes.len() as u64).to_le_bytes());
        hasher.update(&bytes);
    }
    Ok(hasher.finalize().to_hex()[..16].to_owned())
}

/// The cache's description of a stored reference.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct CacheEntry {
    key: String,
    width: u32,
    height: u32,
    rounds: u32,
    spp_per_round: u32,
    settings: String,
}

/// The three files of a cached reference.
pub struct CachePaths {
    mean: PathBuf,
    variance: PathBuf,
    entry: PathBuf,
}

impl CachePaths {
    pub fn new(dir: &Path, key: &str) -> Self {
        Self {
            mean: dir.join(format!("reference-{key}.pfm")),
            variance: dir.join(format!("reference-{key}-variance.pfm")),
            entry: dir.join(format!("reference-{key}.json")),
        }
    }

    /// The cached reference, if all three files are there and agree; anything
    /// else (missing, truncated, another size) counts as no cache.
    pub fn load(&self, key: &str, width: u32, height: u32) -> Option<Reference> {
        self.load_rounds(key, width, height, FIRST_ROUNDS)
    }

    /// [`CachePaths::load`], accepting references of at least `min_rounds`
    /// rounds (one for a deterministic render, whose variance is zero).
    pub fn load_rounds(
        &self,
        key: &str,
        width: u32,
        height: u32,
        min_rounds: u32,
    ) -> Option<Reference> {
        let entry: CacheEntry =
            serde_json::from_str(&std::fs::read_to_string(&self.entry).ok()?).ok()?;
        let mean = Film::load(&self.mean).ok()?;
        let variance = Film::load(&self.variance).ok()?;
        let size = glam::UVec2::new(width, height);
        let fits = entry.key == key
            && (entry.width, entry.height) == (width, height)
            && entry.rounds >= min_rounds
            && mean.resolution() == size
            && variance.resolution() == size;
        fits.then(|| Reference {
            width,
            height,
            mean: mean.pixels().to_vec(),
            variance_of_mean: Some(variance.pixels().to_vec()),
            rounds: entry.rounds,
            spp_per_round: entry.spp_per_round,
            origin: Origin::Rendered {
                cached: true,
                key: key.to_owned(),
            },
            render_time: Duration::ZERO,
        })
    }

    /// Stores a rendered reference; each file is written to a temporary file
    /// and renamed into place, the description last.
    pub fn store(&self, key: &str, settings: &str, r: &Reference) -> Result<(), String> {
        if let Some(dir) = self.entry.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        let variance = r
            .variance_of_mean
            .as_ref()
            .ok_or("a reference without a noise estimate is not cached")?;
        let size = glam::UVec2::new(r.width, r.height);
        for (path, pixels) in [(&self.mean, &r.mean), (&self.variance, variance)] {
            let mut film = Film::new(size);
            film.pixels_mut().copy_from_slice(pixels);
            film.save(path).map_err(|e| e.to_string())?;
        }
        let entry = CacheEntry {
            key: key.to_owned(),
            width: r.width,
            height: r.height,
            rounds: r.rounds,
            spp_per_round: r.spp_per_round,
            settings: settings.to_owned(),
        };
        let text = serde_json::to_string_pretty(&entry).map_err(|e| e.to_string())?;
        crate::output::write_atomically(&self.entry, text.as_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn constant(width: u32, height: u32, value: f32) -> Vec<Vec3> {
        vec![Vec3::splat(value); (width * height) as usize]
    }

    #[test]
    fn rounds_give_the_mean_and_the_variance_of_the_mean() {
        let mut sums = RoundSums::new(2, 1, 16);
        for v in [1.0, 2.0, 3.0, 6.0] {
            sums.add(&constant(2, 1, v));
        }
        let r = sums.reference(
            Origin::Rendered {
                cached: false,
                key: "k".into(),
            },
            Duration::ZERO,
        );
        assert_eq!(r.mean[0], Vec3::splat(3.0));
        // Sample variance of 1, 2, 3, 6 is 14/3; of their mean, 14/12.
        let v = r.variance_of_mean.as_ref().unwrap()[1];
        assert!((v.x - 14.0 / 12.0).abs() < 1e-6, "{v}");
        let noise = r.noise_rel_mse(Region::full(2, 1)).unwrap();
        assert!((noise - (14.0 / 12.0) / (3.01f64 * 3.01)).abs() < 1e-6);
        assert_eq!(r.total_spp(), 64);
        // Back to sums and on with one more round: as if never interrupted.
        let mut resumed = RoundSums::from_reference(&r).unwrap();
        resumed.add(&constant(2, 1, 8.0));
        sums.add(&constant(2, 1, 8.0));
        let (a, b) = (
            resumed.reference(r.origin.clone(), Duration::ZERO),
            sums.reference(r.origin.clone(), Duration::ZERO),
        );
        assert!((a.mean[0] - b.mean[0]).abs().max_element() < 1e-6);
        let (va, vb) = (
            a.variance_of_mean.unwrap()[0],
            b.variance_of_mean.unwrap()[0],
        );
        assert!((va - vb).abs().max_element() < 1e-5, "{va} {vb}");
    }

    #[test]
    fn one_round_has_no_noise_estimate() {
        let mut sums = RoundSums::new(1, 1, 4);
        sums.add(&constant(1, 1, 0.5));
        let r = sums.reference(
            Origin::Rendered {
                cached: false,
                key: "k".into(),
            },
            Duration::ZERO,
        );
        assert!(r.noise_rel_mse(Region::full(1, 1)).is_none());
    }

    #[test]
    fn the_key_follows_every_input() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.toml");
        std::fs::write(&a, "x = 1").unwrap();
        let key = |v: &str, s: &str| cache_key(v, s, std::slice::from_ref(&a)).unwrap();
        let k = key("0.1.0", "spp=1");
        assert_eq!(k.len(), 16);
        assert_eq!(k, key("0.1.0", "spp=1"));
        assert_ne!(k, key("0.1.1", "spp=1"));
        assert_ne!(k, key("0.1.0", "spp=2"));
        std::fs::write(&a, "x = 2").unwrap();
        assert_ne!(k, key("0.1.0", "spp=1"));
        assert!(cache_key("v", "s", &[dir.path().join("missing")]).is_err());
        assert_ne!(round_seed(0, 0), round_seed(0, 1));
        assert_ne!(round_seed(0, 0), 0);
    }

    #[test]
    fn a_stored_reference_loads_back_and_a_broken_one_is_ignored() {
        let dir = tempfile::tempdir().unwrap();
        let mut sums = RoundSums::new(3, 2, 8);
        sums.add(&constant(3, 2, 0.25));
        sums.add(&constant(3, 2, 0.75));
        let origin = Origin::Rendered {
            cached: false,
            key: "abc".into(),
        };
        let r = sums.reference(origin, Duration::ZERO);
        let paths = CachePaths::new(dir.path(), "abc");
        paths.store("abc", "settings", &r).unwrap();
        let back = paths.load("abc", 3, 2).unwrap();
        assert_eq!(back.mean, r.mean);
        assert_eq!(back.variance_of_mean, r.variance_of_mean);
        assert_eq!((back.rounds, back.spp_per_round), (2, 8));
        assert!(matches!(back.origin, Origin::Rendered { cached: true, .. }));
        assert!(paths.load("abc", 4, 2).is_none(), "another size");
        assert!(paths.load("abd", 3, 2).is_none(), "another key");
        std::fs::write(dir.path().join("reference-abc.pfm"), b"PF\n3 2\n").unwrap();
        assert!(paths.load("abc", 3, 2).is_none(), "a truncated image");
    }
}
