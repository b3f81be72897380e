//! The analytic shapes: spheres, parallelograms, planes and boxes, each with
//! its material and name.

use super::materials::MaterialIds;
use super::Assembly;
use crate::error::Problem;
use crate::format::{BoxTable, SceneFile};
use crate::values::{Direction, Point};
use glam::Vec3;
use glint_geometry::{AaBox, Parallelogram, Plane, Sphere};
use toml::Spanned;

impl Assembly<'_> {
    /// Adds the file's spheres, parallelograms, planes and boxes, in that order.
    pub(super) fn shapes(
        &mut self,
        file: &SceneFile,
        materials: &MaterialIds,
    ) -> Result<(), Problem> {
        for (i, s) in file.sphere.iter().enumerate() {
            let m = materials.get(format!("sphere[{i}].material"), &s.material)?;
            let sphere = Sphere::new(s.center.0, s.radius.0).expect("radius read as positive");
            self.names.add(s.name.as_ref(), format!("sphere[{i}]"))?;
            self.builder.shape(sphere, m);
        }
        for (i, p) in file.parallelogram.iter().enumerate() {
            let field = format!("parallelogram[{i}]");
            let m = materials.get(format!("{field}.material"), &p.material)?;
            let shape = Parallelogram::new(p.origin.0, p.edge1.get_ref().0, p.edge2.0, p.two_sided)
                .ok_or_else(|| no_area(&field, &p.edge1))?;
            let front = front_side(&field, shape.normal(), p.normal.as_ref())?;
            self.names.add(p.name.as_ref(), field)?;
            self.builder.shape(shape.facing(front), m);
        }
        for (i, p) in file.plane.iter().enumerate() {
            let m = materials.get(format!("plane[{i}].material"), &p.material)?;
            // `Direction` guarantees a normal that normalizes.
            let plane = Plane::new(p.point.0, p.normal.0, p.two_sided)
                .and_then(|plane| plane.with_tile_size(p.tile_size.0))
                .expect("normalizable normal, positive tile size");
            self.names.add(p.name.as_ref(), format!("plane[{i}]"))?;
            self.builder.shape(plane, m);
        }
        for (i, b) in file.boxes.iter().enumerate() {
            self.aabox(i, b, materials)?;
        }
        Ok(())
    }

    /// Box `i`: one object of one material, or six faces of six.
    fn aabox(&mut self, i: usize, b: &BoxTable, materials: &MaterialIds) -> Result<(), Problem> {
        let field = format!("box[{i}]");
        let aabox = AaBox::new(b.min.0, b.max.get_ref().0).ok_or_else(|| {
            Problem::new(
                b.max.span(),
                format!("{field}.max"),
                "expected max to be greater than min on every axis",
            )
        })?;
        match (&b.material, &b.face_materials) {
            (Some(material), None) => {
                let m = materials.get(format!("{field}.material"), material)?;
                self.names.add(b.name.as_ref(), field.clone())?;
                self.builder.shape(aabox, m);
            }
            (None, Some(faces)) if faces.get_ref().len() == 6 => {
                for (face, (shape, name)) in aabox
                    .face_parallelograms()
                    .into_iter()
                    .zip(faces.get_ref())
                    .enumerate()
                {
                    let m = materials.get(format!("{field}.face_materials[{face}]"), name)?;
                    self.names.add_face(b.name.as_ref(), &field, face)?;
                    self.builder.shape(shape, m);
                }
            }
            (None, Some(faces)) => {
                return Err(Problem::new(
                    faces.span(),
                    format!("{field}.face_materials"),
                    format!(
                        "expected 6 materials (px nx py ny pz nz), got {}",
                        faces.get_ref().len()
                    ),
                ))
            }
            _ => {
                let span = b.max.span();
                return Err(Problem::new(
                    span,
                    field,
                    "expected exactly one of `material` or `face_materials`",
                ));
            }
        }
        Ok(())
    }
}

pub(super) fn no_area(field: &str, edge1: &Spanned<Point>) -> Problem {
    Problem::new(
        edge1.span(),
        format!("{field}.edge1"),
        "edge1 and edge2 are parallel or zero, so the shape has no area",
    )
}

/// The front side of a flat shape: its `normal` key if given (which must be
/// perpendicular to the edges), else `edge1 × edge2`.
pub(super) fn front_side(
    field: &str,
    cross: Vec3,
    normal: Option<&Spanned<Direction>>,
) -> Result<Vec3, Problem> {
    let Some(normal) = normal else {
        return Ok(cross);
    };
    let n = normal.get_ref().0.normalize();
    if n.dot(cross).abs() < 0.999 {
        return Err(Problem::new(
            normal.span(),
            format!("{field}.normal"),
            format!(
                "expected a normal perpendicular to edge1 and edge2, i.e. along ±[{}, {}, {}]",
                cross.x, cross.y, cross.z
            ),
        ));
    }
    Ok(n)
}
