//! Indexed triangle meshes.

use crate::error_bounds::gamma;
use crate::triangle::WatertightRay;
use crate::{Hit, Ray};
use glam::{Affine3A, Mat3, Vec2, Vec3};

/// Why a mesh could not be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MeshError {
    #[error("the mesh has no triangles")]
    Empty,
    #[error("triangle {triangle} uses vertex {index}, but there are only {count} vertices")]
    IndexOutOfRange {
        triangle: usize,
        index: u32,
        count: usize,
    },
    #[error("{what} has {got} entries, expected one per vertex ({expected})")]
    AttributeCount {
        what: &'static str,
        got: usize,
        expected: usize,
    },
    #[error("vertex {0} is not finite")]
    NonFinite(usize),
}

/// Triangles sharing vertices: positions, optional per-vertex shading normals and
/// texture coordinates, and three vertex indices per triangle.
///
/// A hit's uv is interpolated from the vertices' (or, without them, is the
/// barycentric `(b1, b2)`); its shading normal is the interpolated vertex normal
/// when the mesh has normals, else the face normal. The geometric normal follows
/// the winding: `(p1 − p0) × (p2 − p0)`.
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleMesh {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    indices: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// A mesh from its parts; `normals` and `uvs` are empty or one per vertex.
    pub fn new(
        positions: Vec<Vec3>,
        indices: Vec<[u32; 3]>,
        normals: Vec<Vec3>,
        uvs: Vec<Vec2>,
    ) -> Result<Self, MeshError> {
        if indices.is_empty() {
            return Err(MeshError::Empty);
        }
        let count = positions.len();
        for (triangle, tri) in indices.iter().enumerate() {
            if let Some(&index) = tri.iter().find(|&&i| i as usize >= count) {
                return Err(MeshError::IndexOutOfRange {
                    triangle,
                    index,
                    count,
                });
            }
        }
        for (what, got) in [("normals", normals.len()), ("uvs", uvs.len())] {
            if got != 0 && got != count {
                return Err(MeshError::AttributeCount {
                    what,
                    got,
                    expected: count,
                });
            }
        }
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(MeshError::NonFinite(i));
        }
        Ok(Self {
            positions,
            normals,
            uvs,
            indices,
        })
    }

    /// A generated mesh for benchmarks and tests: `n × n` quads (two triangles
    /// each) over [−1, 1]² in x, z, displaced to the bumpy height
    /// `y = 0.1·sin(7x)·cos(5z) + 0.05·sin(23x + 17z)`.
    pub fn displaced_grid(n: u32) -> TriangleMesh {
        let n = n.max(1);
        let height = |x: f32, z: f32| {
            0.1 * (7.0 * x).sin() * (5.0 * z).cos() + 0.05 * (23.0 * x + 17.0 * z).sin()
        };
        let mut positions = Vec::with_capacity(((n + 1) * (n + 1)) as usize);
        for j in 0..=n {
            for i in 0..=n {
                let (x, z) = (
                    2.0 * i as f32 / n as f32 - 1.0,
                    2.0 * j as f32 / n as f32 - 1.0,
                );
                positions.push(Vec3::new(x, height(x, z), z));
            }
        }
        TriangleMesh::new(positions, Self::grid_indices(n, n), vec![], vec![])
            .expect("a grid's triangles are valid")
    }

    /// The triangles of a grid of `columns × rows` quads whose `(columns + 1) ×
    /// (rows + 1)` vertices are stored row by row: two triangles per quad, wound
    /// counter-clockwise seen from the side where rows grow towards the viewer
    /// (for vertices in x, z with z = row, the normal is +y).
    pub fn grid_indices(columns: u32, rows: u32) -> Vec<[u32; 3]> {
        let row = columns + 1;
        let mut indices = Vec::with_capacity(2 * columns as usize * rows as usize);
        for j in 0..rows {
            for i in 0..columns {
                let (a, b, c, d) = (
                    j * row + i,
                    j * row + i + 1,
                    (j + 1) * row + i,
                    (j + 1) * row + i + 1,
                );
                indices.push([a, c, b]);
                indices.push([b, c, d]);
            }
        }
        indices
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len()
    }

    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// The three vertex indices of every triangle.
    pub fn indices(&self) -> &[[u32; 3]] {
        &self.indices
    }

    pub fn has_normals(&self) -> bool {
        !self.normals.is_empty()
    }

    /// The vertex positions.
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// The per-vertex shading normals (empty when the mesh has none).
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }

    /// The per-vertex texture coordinates (empty when the mesh has none: a hit's
    /// uv is then its barycentric `(b1, b2)`).
    pub fn uvs(&self) -> &[Vec2] {
        &self.uvs
    }

    /// The three corners of triangle `i`.
    #[inline]
    pub fn corners(&self, i: u32) -> [Vec3; 3] {
        self.indices[i as usize].map(|v| self.positions[v as usize])
    }

    /// Bounds `(min, max)` of triangle `i`.
    pub fn triangle_bounds(&self, i: u32) -> (Vec3, Vec3) {
        let [a, b, c] = self.corners(i);
        (a.min(b).min(c), a.max(b).max(c))
    }

    /// The same mesh with angle-weighted vertex normals (Thürmer and Wüthrich,
    /// "Computing Vertex Normals from Polygonal Facets", JGT 1998): each face adds
    /// its unit normal times its corner angle to its three vertices. Vertices at the
    /// same position share the sum (an OBJ's objects and material groups split
    /// vertices, which would otherwise show seams). Degenerate faces add nothing; a
    /// vertex with no valid face keeps a zero normal and is shaded flat.
    pub fn with_angle_weighted_normals(mut self) -> Self {
        let key = |p: Vec3| p.to_array().map(f32::to_bits);
        let mut sums: std::collections::HashMap<[u32; 3], Vec3> = std::collections::HashMap::new();
        for tri in &self.indices {
            let p = tri.map(|v| self.positions[v as usize]);
            let Some(n) = (p[1] - p[0]).cross(p[2] - p[0]).try_normalize() else {
                continue;
            };
            for k in 0..3 {
                let (e1, e2) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
                let angle = e1.angle_between(e2);
                if angle.is_finite() {
                    *sums.entry(key(p[k])).or_default() += angle * n;
                }
            }
        }
        self.normals = self
            .positions
            .iter()
            .map(|p| {
                sums.get(&key(*p))
                    .copied()
                    .unwrap_or_default()
                    .normalize_or_zero()
            })
            .collect();
        self
    }

    /// The mesh under an affine transform; normals by the inverse transpose. A
    /// mirroring transform (negative determinant, e.g. one negative scale) also
    /// reverses each triangle's winding, so that geometric normals keep pointing
    /// the way they did.
    pub fn transformed(&self, m: &Affine3A) -> Self {
        let normal_matrix: Mat3 = Mat3::from(m.matrix3).inverse().transpose();
        let mirrored = m.matrix3.determinant() < 0.0;
        Self {
            positions: self
                .positions
                .iter()
                .map(|p| m.transform_point3(*p))
                .collect(),
            normals: self
                .normals
                .iter()
                .map(|n| (normal_matrix * *n).normalize_or_zero())
                .collect(),
            uvs: self.uvs.clone(),
            indices: if mirrored {
                self.indices.iter().map(|&[a, b, c]| [a, c, b]).collect()
            } else {
                self.indices.clone()
            },
        }
    }

    /// The largest coordinate magnitude of any vertex (∞ or NaN if one is not finite).
    pub fn max_coordinate(&self) -> f32 {
        self.positions.iter().fold(0.0f32, |m, p| {
            if p.is_finite() {
                m.max(p.abs().max_element())
            } else {
                f32::INFINITY
            }
        })
    }

    /// The hit distance of triangle `i` in (0, t_max), if any.
    #[inline]
    pub fn hit_distance(&self, i: u32, ray: &WatertightRay, t_max: f32) -> Option<f32> {
        let [a, b, c] = self.corners(i);
        ray.intersect(a, b, c, t_max).map(|(t, _)| t)
    }

    /// The surface record of triangle `i` where `ray` meets it before `t_max`.
    pub fn surface_at(&self, i: u32, ray: &Ray, t_max: f32) -> Option<Hit> {
        let [a, b, c] = self.corners(i);
        let (t, bary) = WatertightRay::new(ray).intersect(a, b, c, t_max)?;
        let tri = self.indices[i as usize];
        // The barycentric point is more accurate than o + t·d; it is kept off
        // the triangle's edges by twice its error bound (`pulled_inside`).
        let error = gamma(7) * ((bary[0] * a).abs() + (bary[1] * b).abs() + (bary[2] * c).abs());
        let pulled = pulled_inside(bary, [a, b, c], error);
        let point = pulled[0] * a + pulled[1] * b + pulled[2] * c;
        // Normalising the edges first keeps tiny (but hit) triangles from
        // underflowing to a zero cross product.
        let face = (b - a)
            .normalize_or_zero()
            .cross((c - a).normalize_or_zero())
            .try_normalize()
            .unwrap_or(Vec3::Z);
        let uv_at = |k: usize| -> Vec2 {
            if self.uvs.is_empty() {
                [Vec2::ZERO, Vec2::X, Vec2::Y][k]
            } else {
                self.uvs[tri[k] as usize]
            }
        };
        let (uv0, uv1, uv2) = (uv_at(0), uv_at(1), uv_at(2));
        let uv = bary[0] * uv0 + bary[1] * uv1 + bary[2] * uv2;
        // ∂p/∂u, ∂p/∂v from the uv deltas; for a degenerate uv mapping, any
        // frame around the normal.
        let duv = (uv0 - uv2, uv1 - uv2);
        let (mut dpdu, mut dpdv) = uv_derivatives(duv, (a - c, b - c));
        if !(dpdu.is_finite() && dpdv.is_finite()) || dpdu.cross(dpdv).length_squared() == 0.0 {
            (dpdu, dpdv) = face.any_orthonormal_pair();
        }
        let (shading_normal, dndu, dndv) = self.shading_normal(tri, bary, face, duv);
        Some(Hit {
            t,
            point,
            error,
            geometric_normal: face,
            shading_normal,
            uv,
            dpdu,
            dpdv,
            dndu,
            dndv,
            front_face: face.dot(ray.direction) < 0.0,
            shape: 0,
            primitive: 0,
        })
    }

    /// The shading normal at barycentric point `bary` of the triangle of
    /// corners `tri`, interpolated and turned to the side of its face normal
    /// `face`, and its derivatives along u and v (from the uv deltas `duv`);
    /// `face` where the mesh has no normals or they cancel there.
    fn shading_normal(
        &self,
        tri: [u32; 3],
        bary: [f32; 3],
        face: Vec3,
        duv: (Vec2, Vec2),
    ) -> (Vec3, Vec3, Vec3) {
        if self.normals.is_empty() {
            return (face, Vec3::ZERO, Vec3::ZERO);
        }
        let n = tri.map(|v| self.normals[v as usize]);
        let interpolated = (bary[0] * n[0] + bary[1] * n[1] + bary[2] * n[2]).normalize_or_zero();
        if interpolated == Vec3::ZERO {
            return (face, Vec3::ZERO, Vec3::ZERO);
        }
        let (dndu, dndv) = uv_derivatives(duv, (n[0] - n[2], n[1] - n[2]));
        let s = if interpolated.dot(face) < 0.0 {
            -interpolated
        } else {
            interpolated
        };
        (s, dndu, dndv)
    }
}

/// The derivatives along u and v of a quantity over a triangle whose corner
/// differences are `d = (q₀ − q₂, q₁ − q₂)` and uv differences `duv = (uv₀ −
/// uv₂, uv₁ − uv₂)`: the solution of `duv · (∂q/∂u, ∂q/∂v) = d` (pbrt-v4,
/// section 6.5.3), or zero where the uv mapping is degenerate.
fn uv_derivatives((duv02, duv12): (Vec2, Vec2), (d02, d12): (Vec3, Vec3)) -> (Vec3, Vec3) {
    let det = duv02.x * duv12.y - duv02.y * duv12.x;
    match det.abs() > 1e-12 {
        true => {
            let inv = 1.0 / det;
            (
                (duv12.y * d02 - duv02.y * d12) * inv,
                (duv02.x * d12 - duv12.x * d02) * inv,
            )
        }
        false => (Vec3::ZERO, Vec3::ZERO),
    }
}

/// Barycentric coordinates `bary` of a point on the triangle `[a, b, c]`, moved
/// inside so that the point lies at least twice the length of its error bound
/// `error` from every edge (at most to the centroid): a point computed on an
/// edge is, within rounding, on the neighbouring triangle too, and a ray
/// leaving it across a concave edge (the inside of a closed box) or a convex
/// one could meet that triangle at t ≈ 0 ([`crate::error_bounds`]). The
/// distance from the edge opposite vertex `i` is `bᵢ · hᵢ`, with the height
/// `hᵢ = 2·area / |opposite edge|`.
fn pulled_inside(bary: [f32; 3], [a, b, c]: [Vec3; 3], error: Vec3) -> [f32; 3] {
    let twice_area = (b - a).cross(c - a).length();
    let reach = 2.0 * error.length();
    let opposite = [(c - b).length(), (a - c).length(), (b - a).length()];
    let least = opposite.map(|edge| (reach * edge / twice_area).min(1.0 / 3.0));
    if !least.iter().all(|l| l.is_finite()) || (0..3).all(|i| bary[i] >= least[i]) {
        return bary;
    }
    let raised: [f32; 3] = std::array::from_fn(|i| bary[i].max(least[i]));
    let sum = raised[0] + raised[1] + raised[2];
    raised.map(|x| x / sum)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> TriangleMesh {
        TriangleMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            vec![[0, 1, 2], [0, 2, 3]],
            vec![],
            vec![Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y],
        )
        .unwrap()
    }

    #[test]
    fn invalid_meshes_are_refused() {
        assert_eq!(
            TriangleMesh::new(vec![Vec3::ZERO], vec![], vec![], vec![]),
            Err(MeshError::Empty)
        );
        let e =
            TriangleMesh::new(vec![Vec3::ZERO; 3], vec![[0, 1, 3]], vec![], vec![]).unwrap_err();
        assert_eq!(
            e,
            MeshError::IndexOutOfRange {
                triangle: 0,
                index: 3,
                count: 3
            }
        );
        let e = TriangleMesh::new(vec![Vec3::ZERO; 3], vec![[0, 1, 2]], vec![Vec3::Z], vec![])
            .unwrap_err();
        assert!(matches!(
            e,
            MeshError::AttributeCount {
                what: "normals",
                ..
            }
        ));
        let e = TriangleMesh::new(vec![Vec3::NAN; 3], vec![[0, 1, 2]], vec![], vec![]).unwrap_err();
        assert_eq!(e, MeshError::NonFinite(0));
    }

    #[test]
    fn hit_interpolates_uv_and_has_a_consistent_frame() {
        let mesh = quad();
        let ray = Ray::new(Vec3::new(0.25, 0.6, 1.0), -Vec3::Z);
        let hit = (0..2)
            .find_map(|i| mesh.surface_at(i, &ray, f32::INFINITY))
            .unwrap();
        assert!((hit.point - Vec3::new(0.25, 0.6, 0.0)).length() < 1e-6);
        assert!((hit.uv - Vec2::new(0.25, 0.6)).length() < 1e-6);
        assert!((hit.dpdu - Vec3::X).length() < 1e-6 && (hit.dpdv - Vec3::Y).length() < 1e-6);
        assert!((hit.geometric_normal - Vec3::Z).length() < 1e-6);
        assert!(hit.front_face);
    }

    #[test]
    fn angle_weighted_normals_of_a_tetrahedron_point_outwards() {
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
        // Outward winding.
        let idx = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        let mesh = TriangleMesh::new(p.clone(), idx, vec![], vec![])
            .unwrap()
            .with_angle_weighted_normals();
        let centre = Vec3::splat(0.25);
        for (v, n) in p.iter().zip(&mesh.normals) {
            assert!((n.length() - 1.0).abs() < 1e-5);
            assert!(n.dot(*v - centre) > 0.0, "vertex {v} normal {n}");
        }
        // The origin's three faces meet at right angles with equal weights: the
        // normal is the diagonal.
        assert!((mesh.normals[0] + Vec3::splat(1.0 / 3f32.sqrt())).length() < 1e-5);
    }

    #[test]
    fn a_mirroring_transform_keeps_faces_pointing_outwards() {
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
        let idx = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        let tetra = TriangleMesh::new(p, idx, vec![], vec![]).unwrap();
        let mirror = Affine3A::from_scale(Vec3::new(-1.0, 2.0, 1.0));
        let t = tetra.transformed(&mirror);
        let centre = mirror.transform_point3(Vec3::splat(0.25));
        for i in 0..4 {
            let [a, b, c] = t.corners(i);
            let outward = (b - a).cross(c - a).dot((a + b + c) / 3.0 - centre);
            assert!(outward > 0.0, "triangle {i} points inwards");
        }
    }

    #[test]
    fn transforms_move_points_and_keep_normals_perpendicular() {
        let mesh = quad().with_angle_weighted_normals();
        let m = Affine3A::from_scale_rotation_translation(
            Vec3::new(2.0, 0.5, 1.0),
            glam::Quat::from_rotation_y(0.7),
            Vec3::new(1.0, 2.0, 3.0),
        );
        let t = mesh.transformed(&m);
        assert!((t.positions[1] - m.transform_point3(Vec3::X)).length() < 1e-6);
        let [a, b, c] = t.corners(0);
        // Normalising the edges first keeps tiny (but hit) triangles from
        // underflowing to a zero cross product.
        let face = (b - a)
            .normalize_or_zero()
            .cross((c - a).normalize_or_zero())
            .try_normalize()
            .unwrap_or(Vec3::Z);
        assert!((t.normals[0] - face).length() < 1e-5);
    }
}
