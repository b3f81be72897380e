//! Glint's numbers in SIMD lanes: the [`Float`] trait that kernels are written
//! over once, for one `f32` and for lanes of them alike; [`Vector3`] over it;
//! and the lane width the renderer's wavefronts use ([`LANES`], [`F32Lanes`]).
//!
//! Conventions: every operation is the IEEE operation of the scalar type, in
//! glam's order and never fused into a multiply-add, so a kernel's lane gives
//! the scalar kernel's bits and an image does not depend on the lane width.
//! Masks of lanes are lanes of all-ones (true) or all-zeros (false) bits.

mod approx;
mod float;
mod vector;
mod width;

pub use approx::{
    acos_approx, atan2_approx, exp2_approx, log2_approx, powf_approx, sin_cos_approx, ACOS_ERROR,
    ATAN2_ERROR,
};
pub use float::{Float, Mask};
pub use vector::Vector3;
pub use width::*;
