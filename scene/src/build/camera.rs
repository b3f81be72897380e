//! The `[camera]` table as the camera.

use crate::error::Problem;
use crate::format::CameraTable;
use glint_camera::{Camera, CameraError};

pub(super) fn camera(c: &CameraTable, resolution: glam::UVec2) -> Result<Camera, Problem> {
    Camera::new(
        c.position.0,
        c.look_at.get_ref().0,
        c.up.get_ref().0,
        c.fov.0,
        c.focal_length.0,
        resolution,
    )
    .map_err(|e| {
        // fov, focal length and resolution were range-checked while reading.
        let (field, span) = match e {
            CameraError::UpParallelToForward if !c.up.span().is_empty() => {
                ("camera.up", c.up.span())
            }
            CameraError::UpParallelToForward => ("camera.look_at", c.look_at.span()),
            _ => ("camera.look_at", c.look_at.span()),
        };
        Problem::new(span, field, e.to_string())
    })
}
