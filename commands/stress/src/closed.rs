//! Closed solids: boxes (six walls, one `AaBox`, or a triangle mesh) and an
//! icosahedron mesh, seen from inside (nothing may leak out) and from outside
//! (nothing may shadow a lit point of a convex solid).

use crate::{finite, lit_and_mirrored, off_surface, Counts, Truth};
use glam::{DVec3, Vec3};
use glint_geometry::{spawn_ray_to, AaBox, Hit, Ray, RayTarget, ShapeList, TriangleMesh};

/// How a closed box is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoxKind {
    /// Six two-sided parallelograms meeting at their edges.
    Walls,
    /// One axis-aligned box.
    AaBox,
    /// Twelve triangles sharing the eight corners.
    Mesh,
}

impl BoxKind {
    pub const ALL: [BoxKind; 3] = [BoxKind::Walls, BoxKind::AaBox, BoxKind::Mesh];

    pub fn name(self) -> &'static str {
        match self {
            BoxKind::Walls => "box of 6 walls",
            BoxKind::AaBox => "AaBox",
            BoxKind::Mesh => "box as a mesh",
        }
    }
}

/// The cube's corner `i`: bit 0 picks x from `lo` or `hi`, bit 1 y, bit 2 z.
fn corner(lo: Vec3, hi: Vec3, i: usize) -> Vec3 {
    let pick = |bit: usize, axis: usize| {
        if i >> bit & 1 == 1 {
            hi[axis]
        } else {
            lo[axis]
        }
    };
    Vec3::new(pick(0, 0), pick(1, 1), pick(2, 2))
}

/// The cube's faces as corner indices around each, facing out.
const FACES: [[u32; 4]; 6] = [
    [0, 2, 3, 1], // z = lo
    [4, 5, 7, 6], // z = hi
    [0, 1, 5, 4], // y = lo
    [2, 6, 7, 3], // y = hi
    [0, 4, 6, 2], // x = lo
    [1, 3, 7, 5], // x = hi
];

/// A closed cube of side 2·scale, seen from inside, with a light outside:
/// every camera ray hits a wall, and every shadow ray traced (from a wall the
/// light is in front of, seen from inside) is blocked by another. Rays are
/// aimed at `steps` × `steps` points over each face, edges and corners
/// included when the steps reach 0 and 1.
pub(crate) fn closed_box(at: Vec3, scale: f32, steps: &[f32], kind: BoxKind) -> Counts {
    let (lo, hi) = (at - Vec3::splat(scale), at + Vec3::splat(scale));
    let mut list = ShapeList::new();
    let corners: Vec<Vec3> = (0..8).map(|i| corner(lo, hi, i)).collect();
    match kind {
        BoxKind::AaBox => {
            list.push(AaBox::new(lo, hi).expect("a box"));
        }
        BoxKind::Walls => {
            for wall in AaBox::new(lo, hi).expect("a box").face_parallelograms() {
                list.push(wall);
            }
        }
        BoxKind::Mesh => {
            let triangles = FACES
                .iter()
                .flat_map(|f| [[f[0], f[1], f[2]], [f[0], f[2], f[3]]])
                .collect();
            let mesh = TriangleMesh::new(corners.clone(), triangles, vec![], vec![]);
            list.push_mesh(mesh.expect("a cube mesh"));
        }
    }
    list.build_acceleration();
    let light = at + Vec3::new(7.0, 5.0, -6.0) * scale;
    let eye = at + Vec3::new(0.1, -0.2, 0.15) * scale;
    // The exact distance from the face the normal names.
    let distance = |hit: &Hit| {
        let axis = hit.geometric_normal.abs().max_position();
        let p = hit.point.as_dvec3()[axis];
        let (l, h) = (lo[axis] as f64, hi[axis] as f64);
        (p - l).abs().min((p - h).abs())
    };
    let mut counts = Counts::default();
    for face in 0..6 {
        let (axis, sign) = (face % 3, if face < 3 { -1.0 } else { 1.0 });
        for &u in steps {
            for &v in steps {
                let mut p = [0.0; 3];
                p[axis] = sign;
                p[(axis + 1) % 3] = -1.0 + 2.0 * u;
                p[(axis + 2) % 3] = -1.0 + 2.0 * v;
                let target = at + Vec3::from(p) * scale;
                inside_ray(&list, eye, target, light, &distance, &mut counts);
            }
        }
    }
    counts
}

/// From inside a closed solid: the camera ray towards `target` must hit it,
/// and the shadow ray of a point whose inner side faces `light` (outside) must
/// be blocked.
fn inside_ray(
    list: &ShapeList,
    eye: Vec3,
    target: Vec3,
    light: Vec3,
    distance: &impl Fn(&Hit) -> f64,
    counts: &mut Counts,
) {
    let ray = Ray::new(eye, target - eye);
    counts.rays += 1;
    let Some(hit) = list.closest_hit(&ray, f32::INFINITY) else {
        counts.leaks += 1;
        return;
    };
    if !finite(&hit) {
        counts.non_finite += 1;
        return;
    }
    counts.off_surface += u64::from(off_surface(&hit, distance(&hit)));
    // As the integrator does: a light behind the wall as seen from the
    // viewer's side is below the horizon, and gets no shadow ray.
    let facing = if hit.geometric_normal.dot(ray.direction) < 0.0 {
        hit.geometric_normal
    } else {
        -hit.geometric_normal
    };
    if facing.dot(light - hit.point) > 0.0 {
        let shadow = spawn_ray_to(&hit, &RayTarget::exact(light));
        counts.leaks += u64::from(!list.any_hit(&shadow, 1.0));
    }
}

/// The regular icosahedron of circumradius `scale` about `at`: its twelve
/// vertices and twenty faces, wound to face out.
fn icosahedron(at: Vec3, scale: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let mut unit = Vec::new();
    for (a, b) in [(1.0, phi), (-1.0, phi), (1.0, -phi), (-1.0, -phi)] {
        unit.extend([
            DVec3::new(0.0, a, b),
            DVec3::new(a, b, 0.0),
            DVec3::new(b, 0.0, a),
        ]);
    }
    // Faces: the triples of vertices two apart from each other (the edge length).
    let mut faces = Vec::new();
    let edge = |i: usize, j: usize| (unit[i].distance(unit[j]) - 2.0).abs() < 1e-9;
    for i in 0..12 {
        for j in i + 1..12 {
            for k in j + 1..12 {
                if edge(i, j) && edge(j, k) && edge(i, k) {
                    let n = (unit[j] - unit[i]).cross(unit[k] - unit[i]);
                    let out = n.dot(unit[i]) > 0.0;
                    let (j, k) = if out { (j, k) } else { (k, j) };
                    faces.push([i as u32, j as u32, k as u32]);
                }
            }
        }
    }
    assert_eq!(faces.len(), 20, "an icosahedron has twenty faces");
    let radius = unit[0].length();
    let vertices = unit
        .iter()
        .map(|v| at + (*v / radius).as_vec3() * scale)
        .collect();
    (vertices, faces)
}

/// Points over every face of a triangle mesh: `a·(p₁ − p₀) + b·(p₂ − p₀)` from
/// `p₀` for `a`, `b` in `steps` with `a + b ≤ 1` (its vertices and edges
/// included when the steps reach 0 and 1).
fn face_targets(vertices: &[Vec3], faces: &[[u32; 3]], steps: &[f32]) -> Vec<Vec3> {
    let mut targets = Vec::new();
    for f in faces {
        let [p0, p1, p2] = f.map(|i| vertices[i as usize]);
        for &a in steps {
            for &b in steps.iter().filter(|&&b| a + b <= 1.0) {
                targets.push(p0 + a * (p1 - p0) + b * (p2 - p0));
            }
        }
    }
    targets
}

/// The icosahedron as one mesh and the exact distance of a hit from the plane
/// of the triangle it reports.
fn icosahedron_list(at: Vec3, scale: f32) -> (ShapeList, Vec<Vec3>, Vec<[u32; 3]>) {
    let (vertices, faces) = icosahedron(at, scale);
    let mut list = ShapeList::new();
    let mesh = TriangleMesh::new(vertices.clone(), faces.clone(), vec![], vec![]);
    list.push_mesh(mesh.expect("an icosahedron"));
    list.build_acceleration();
    (list, vertices, faces)
}

fn triangle_distance(vertices: &[Vec3], faces: &[[u32; 3]], hit: &Hit) -> f64 {
    let [a, b, c] = faces[hit.primitive as usize].map(|i| vertices[i as usize].as_dvec3());
    let n = (b - a).cross(c - a).normalize();
    (hit.point.as_dvec3() - a).dot(n)
}

/// From inside the icosahedron, rays at points over every face, its shared
/// edges and vertices included: none may escape, and shadow rays towards a
/// light outside must be blocked.
pub(crate) fn icosahedron_inside(at: Vec3, scale: f32, steps: &[f32]) -> Counts {
    let (list, vertices, faces) = icosahedron_list(at, scale);
    let eye = at + Vec3::new(0.1, -0.2, 0.15) * scale;
    let light = at + Vec3::new(3.0, 2.0, -2.5) * scale;
    let distance = |hit: &Hit| triangle_distance(&vertices, &faces, hit);
    let mut counts = Counts::default();
    for target in face_targets(&vertices, &faces, steps) {
        inside_ray(&list, eye, target, light, &distance, &mut counts);
    }
    counts
}

/// From outside the convex icosahedron, rays at the same points: a point seen
/// from the front whose normal faces the light is lit, and its mirror ray
/// meets nothing. (A ray aimed exactly at a silhouette edge touches the face
/// behind it as well, at the same point within rounding, and may report that
/// one, whose mirror ray rightly goes in: only front hits are judged.)
pub(crate) fn icosahedron_outside(at: Vec3, scale: f32, steps: &[f32]) -> Counts {
    let (list, vertices, faces) = icosahedron_list(at, scale);
    let eye = at + Vec3::new(2.0, 3.0, 4.0) * scale;
    let light = at + Vec3::new(-3.0, 4.0, 2.0) * 10.0 * scale;
    let truth = Truth {
        distance: |hit: &Hit| triangle_distance(&vertices, &faces, hit),
        judged: |hit: &Hit| hit.front_face,
        mirror_escapes: true,
    };
    let mut counts = Counts::default();
    for target in face_targets(&vertices, &faces, steps) {
        let ray = Ray::new(eye, target - eye);
        lit_and_mirrored(&list, &ray, light, &truth, &mut counts);
    }
    counts
}
