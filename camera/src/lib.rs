//! The first stage of Glint: a pinhole [`Camera`] that turns continuous raster
//! coordinates into world-space rays, and the [`Film`] that collects the radiance
//! those rays carry and writes it out as an image.
//!
//! # Conventions
//! - World space is right-handed with y up; units are whatever the scene uses.
//! - The vertical field of view is given in **degrees** ([`Camera::new`]) and kept
//!   internally in radians.
//! - Raster space: `(0, 0)` is the top-left corner of the top-left pixel, x grows
//!   to the right and y downwards; pixel `(i, j)` has its centre at `(i + 0.5, j + 0.5)`.
//! - [`Film`] stores **linear** RGB radiance as `f32`. Only the PNG writer applies
//!   the sRGB transfer curve (and clamps); OpenEXR and PFM keep linear floats.
//!   Reading undoes the same: PNG and JPEG are decoded from sRGB, float formats
//!   are read as they are.
//!
//! This crate does not depend on the geometry stage: a camera ray is a plain
//! [`CameraRay`] (origin and unit direction) that later stages wrap in their own type.
//!
//! # Entry points
//! - [`Camera::new`], then [`Camera::generate_ray`] (a [`CameraRay`]) or
//!   [`Camera::generate_ray_differential`] (a [`CameraRayDifferential`]) per raster
//!   position, or [`Camera::generate_rays_lanes`] for [`LANES`] positions at once
//!   in SIMD lanes ([`F32Lanes`], each lane the scalar ray bit for bit);
//!   [`Camera::with_resolution`] changes the film size and keeps the view.
//! - [`Film::new`], [`Film::set_pixel`] or [`Film::pixels_mut`] to fill it, and
//!   [`Film::save`], whose format ([`ImageFormat`]) follows the file extension;
//!   [`linear_to_srgb8`] is the PNG writer's transfer curve.
//! - [`Film::load`] reads an image file back into a film, whatever wrote it:
//!   PNG, JPEG, BMP, TGA, PPM/PGM, Radiance HDR, OpenEXR or PFM, told apart by
//!   content ([`FileFormat`]); integers are decoded from sRGB with
//!   [`srgb_to_linear`], floats kept as stored, NaN and negative values
//!   included; sides over [`MAX_LOAD_SIDE`] are refused. [`Film::read`] also
//!   says what the file was ([`ImageFile`]): how it stored its samples
//!   ([`SampleEncoding`]: the step its values were rounded to, from the data),
//!   its alpha ([`AlphaChannel`]), gray or palette.
//! - Every image reader refuses what is not a regular file, and a header that
//!   claims more pixels than [`MAX_EXPANSION`] times its file could hold, before
//!   taking any pixel memory; [`check_output_file`] and [`check_output_folder`]
//!   check where a command will write, before it works.
//! - Errors: [`CameraError`] and [`FilmError`].

mod atomic_file;
mod camera;
mod film;
mod output_paths;

pub use atomic_file::{stage_atomically, write_atomically, StagedFile};
pub use camera::{
    Camera, CameraError, CameraRay, CameraRayDifferential, CameraRayLanes, F32Lanes, LANES,
};
pub use film::{
    linear_to_srgb, linear_to_srgb8, srgb_to_linear, AlphaChannel, FileFormat, Film, FilmError,
    ImageFile, ImageFormat, PartialFilm, Placement, SampleEncoding, Tile, MAX_EXPANSION,
    MAX_LOAD_SIDE,
};
pub use output_paths::{check_output_file, check_output_folder, MAX_NAME_BYTES};

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
