//! The camera stage (report sections 2.1 and 2.2): a raster position to the
//! camera ray, [`glint_camera::Camera::generate_ray`] on the scene's camera
//! at its resolution.

use super::probe::{collect, Plan, Probe};
use super::table::{Case, Check, Field, Layout};
use super::Context;
use crate::GradeError;

/// Inputs `x`, `y` (pixels from the image's top-left corner, y down; pixel
/// `(i, j)` has its centre at `(i + 0.5, j + 0.5)`), `width`, `height`;
/// expected the ray's `origin` and unit `direction`.
pub fn layout() -> Layout {
    Layout {
        inputs: ["x", "y", "width", "height"].map(String::from).to_vec(),
        expected: vec![
            Field::xyz("origin", Check::Vector),
            Field::xyz("direction", Check::Direction),
        ],
    }
}

/// `n` cases: pixels spread over the image, its four corner pixels and its
/// centre.
pub fn cases(cx: &Context, n: usize) -> Result<Vec<Case>, GradeError> {
    let size = cx.survey.size;
    let corners = [
        [0, 0],
        [size.x - 1, 0],
        [0, size.y - 1],
        [size.x - 1, size.y - 1],
        [size.x / 2, size.y / 2],
    ];
    let plans = vec![
        Plan::new("spread over the image", 0.0, cx.survey.stratified(|_| true)),
        Plan::new(
            "a corner or the centre of the image",
            corners.len() as f64 / n.max(1) as f64,
            corners.into_iter(),
        ),
    ];
    collect(cx.scene, cx.settings, n, plans, |p| Some(case(cx, p)))
}

fn case(cx: &Context, p: &Probe) -> Case {
    let size = cx.survey.size;
    let mut case = Case::new(Some(p.from.clone()));
    case.float("x", p.raster.x)
        .float("y", p.raster.y)
        .int("width", size.x.into())
        .int("height", size.y.into())
        .xyz("origin", p.ray.origin)
        .xyz("direction", p.ray.direction);
    case
}
