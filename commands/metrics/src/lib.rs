//! Image metrics for Glint: how far a test image is from a reference. One job:
//! turn two images of the same size into numbers (means, RMSE, relative MSE,
//! mean FLIP, the largest difference) and per-pixel error maps with their heat
//! maps. `glint diff` prints them; `glint bench` plots error against time with
//! them. Nothing here reads image files (that is
//! [`glint_camera::Film::load`]) or renders.
//!
//! # Conventions
//! - **Inputs** are [`ImageView`]s: linear RGB `f32` pixels, row-major from the
//!   top-left pixel, as a [`glint_camera::Film`] holds them. The *test* image is
//!   measured against the *reference*; the metrics that are not symmetric
//!   (relative MSE, FLIP) divide by or judge against the reference.
//! - **Regions**: every scalar metric covers a [`Region`], a half-open rectangle
//!   `[x0, x1) × [y0, y1)` of pixels (rows from the top), averaged with every
//!   pixel weighing the same; [`Region::full`] is the whole image. Per-pixel maps
//!   ([`flip`], [`rel_mse_map`]) cover the whole image; [`ErrorMap::mean`] and
//!   [`ErrorMap::max`] restrict them to a region.
//! - **Sizes**: every function returns a [`MetricsError`] (and never panics)
//!   if the two images differ in size, a buffer does not fill its stated
//!   size, or the region is empty or outside them; callers whose sizes come
//!   from users report it as an input error, as `glint diff` does.
//! - **Results** are `f64`, summed per row in `f64`.
//! - **Non-finite values are never hidden.** A channel whose two values are
//!   identical (the same bits, which includes the same infinity or NaN) differs
//!   by 0, so an image always measures 0 against itself. Otherwise a NaN or an
//!   infinity on one side makes MSE, RMSE and relative MSE NaN or infinite, and
//!   [`max_difference`] reports it (NaN before any number). [`channel_means`] of
//!   an image with a NaN is NaN; [`non_finite_count`] counts them. FLIP alone
//!   cannot see them: it works on 8-bit sRGB, where NaN is 0 and +∞ is 1.
//! - **Relative MSE** is pbrt-v4's `imgtool` MRSE, `(x − r)² / (r + 0.01)²` per
//!   channel, averaged ([`REL_MSE_EPSILON`] is the 0.01).
//! - **FLIP** is LDR-FLIP (Andersson et al. 2020, "FLIP: A Difference Evaluator
//!   for Alternating Images", HPG), computed by NVIDIA's C++ implementation
//!   through the `nv-flip` crate on both images encoded as 8-bit sRGB exactly as
//!   Glint's PNG writer encodes them (clamped), at the official tool's default
//!   67.02 pixels per degree ([`FLIP_PIXELS_PER_DEGREE`]); values in [0, 1]. Its
//!   mean is checked against the official FLIP 1.7 tool in
//!   `tests/flip_reference.rs` (agreement to about 1e-6).
//!
//! # Entry points
//! - [`compare`] (a [`Comparison`]: means, RMSE, relMSE, mean FLIP, the largest
//!   difference), or each metric alone: [`channel_means`], [`mse`], [`rmse`],
//!   [`rel_mse`], [`max_difference`] ([`MaxDifference`]), [`non_finite_count`].
//! - Per-pixel maps ([`ErrorMap`]): [`flip`], [`rel_mse_map`].
//! - Heat maps: [`heatmap`] (magma colors) and [`save_heatmap`] (PNG, atomically).
//! - [`Region`]: [`Region::parse`] reads `x0,y0,x1,y1`, [`Region::check`] fits it
//!   to an image, [`Region::scaled`] moves it to another resolution.

mod compare;
mod difference;
mod error;
mod error_map;
mod flip;
mod heatmap;
mod image_view;
mod max_difference;
mod means;
mod mse;
mod region;
mod rel_mse;

pub use compare::{compare, compare_with_flip_map, Comparison};
pub use error::MetricsError;
pub use error_map::ErrorMap;
pub use flip::{flip, FLIP_PIXELS_PER_DEGREE};
pub use heatmap::{heatmap, heatmap_png, heatmap_scale, magma, save_heatmap};
pub use image_view::ImageView;
pub use max_difference::{max_difference, MaxDifference};
pub use means::{channel_means, non_finite_count};
pub use mse::{mse, rmse};
pub use region::Region;
pub use rel_mse::{rel_mse, rel_mse_map, REL_MSE_EPSILON};

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
