//! Binary PLY meshes for Mitsuba's `ply` shape: positions, and normals and
//! texture coordinates when the mesh has them.

use glam::{Vec2, Vec3};
use glint_geometry::TriangleMesh;
use std::collections::HashMap;

/// The triangles `triangles` of `mesh` (indices into `mesh.indices()`) as a
/// binary little-endian PLY with only the vertices they use: `x y z`, then
/// `nx ny nz` and `u v` when the mesh has them, and one `vertex_indices` list
/// per face, in the mesh's winding.
pub(super) fn ply(mesh: &TriangleMesh, triangles: &[u32]) -> Vec<u8> {
    let mut remap: HashMap<u32, u32> = HashMap::new();
    let mut used: Vec<u32> = Vec::new();
    let faces: Vec<[u32; 3]> = triangles
        .iter()
        .map(|&t| {
            mesh.indices()[t as usize].map(|v| {
                *remap.entry(v).or_insert_with(|| {
                    used.push(v);
                    used.len() as u32 - 1
                })
            })
        })
        .collect();
    let (normals, uvs) = (mesh.normals(), mesh.uvs());
    let mut header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment written by glint export --mitsuba\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n",
        used.len()
    );
    if !normals.is_empty() {
        header.push_str("property float nx\nproperty float ny\nproperty float nz\n");
    }
    if !uvs.is_empty() {
        header.push_str("property float u\nproperty float v\n");
    }
    header.push_str(&format!(
        "element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        faces.len()
    ));
    let vertex_size =
        4 * (3 + 3 * usize::from(!normals.is_empty()) + 2 * usize::from(!uvs.is_empty()));
    let mut out = Vec::with_capacity(header.len() + used.len() * vertex_size + faces.len() * 13);
    out.extend_from_slice(header.as_bytes());
    let mut put = |x: f32| out.extend_from_slice(&x.to_le_bytes());
    for &v in &used {
        let v = v as usize;
        mesh.positions()[v]
            .to_array()
            .into_iter()
            .for_each(&mut put);
        if !normals.is_empty() {
            // A vertex only degenerate faces use keeps a zero normal in Glint
            // (shaded flat); Mitsuba would normalise it to NaN.
            let n = normals[v].try_normalize().unwrap_or(Vec3::Z);
            n.to_array().into_iter().for_each(&mut put);
        }
        if !uvs.is_empty() {
            let uv: Vec2 = uvs[v];
            uv.to_array().into_iter().for_each(&mut put);
        }
    }
    for face in faces {
        out.push(3);
        for v in face {
            out.extend_from_slice(&(v as i32).to_le_bytes());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_split_mesh_keeps_only_its_vertices_and_the_winding() {
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::ONE];
        let uvs = vec![Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE];
        let mesh = TriangleMesh::new(positions, vec![[0, 1, 2], [1, 3, 2]], vec![], uvs).unwrap();
        let bytes = ply(&mesh, &[1]);
        let end = b"end_header\n";
        let at = bytes.windows(end.len()).position(|w| w == end).unwrap() + end.len();
        let header = std::str::from_utf8(&bytes[..at]).unwrap();
        assert!(header.contains("element vertex 3\n"), "{header}");
        assert!(header.contains("property float u\nproperty float v\n"));
        assert!(!header.contains("nx"));
        let floats: Vec<f32> = bytes[at..at + 3 * 5 * 4]
            .chunks(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        // Vertices 1, 3, 2 of the mesh, in first-use order, with their uv.
        assert_eq!(
            floats,
            [1., 0., 0., 1., 0., 1., 1., 1., 1., 1., 0., 1., 0., 0., 1.]
        );
        assert_eq!(&bytes[at + 60..], &[3, 0, 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0]);
    }
}
