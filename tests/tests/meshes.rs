//! Triangle meshes through the BVH: watertightness, the shipped bunny scenes,
//! BVH statistics.

use glam::Vec3;
use glint_geometry::{Ray, ShapeList};
use glint_scene::load;
use glint_tests::scene_path;
use rayon::prelude::*;

/// The closed bunny's shapes (mesh only) from its scene, with the BVH built.
fn closed_bunny() -> ShapeList {
    let d = load(&scene_path("bunny")).unwrap();
    let mut list = ShapeList::new();
    list.push_mesh(d.scene.shapes.meshes()[0].clone());
    list.build_bvh();
    list
}

/// A point-hashing generator: reproducible randoms for ray `i`, stream `k`.
fn random(i: u64, k: u64) -> f32 {
    let mut z = i.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ k.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
}

#[test]
fn a_million_rays_at_vertices_and_edges_of_the_closed_bunny_never_leak() {
    let bunny = closed_bunny();
    let mesh = &bunny.meshes()[0];
    let (lo, hi) = (0..mesh.triangle_count() as u32)
        .map(|t| mesh.triangle_bounds(t))
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), (l, h)| {
            (a.min(l), b.max(h))
        });
    let centre = 0.5 * (lo + hi);
    let radius = 2.0 * (hi - lo).length();
    // The triangles around each vertex, to tell whether a target is on the
    // silhouette for a given ray.
    let mut around: Vec<Vec<u32>> = vec![Vec::new(); mesh.vertex_count()];
    for (t, tri) in mesh.indices().iter().enumerate() {
        for &v in tri {
            around[v as usize].push(t as u32);
        }
    }
    let faces_ray = |t: u32, d: Vec3| {
        let [a, b, c] = mesh.corners(t);
        (b - a).cross(c - a).dot(d) < 0.0
    };
    let rays = 1_000_000u64;
    let (checked, entered, leaks): (u64, u64, u64) = (0..rays)
        .into_par_iter()
        .map(|i| {
            // From a random point on a sphere around the bunny, aim at a vertex
            // (half the rays) or at a point on an edge of a random triangle.
            let z = 2.0 * random(i, 0) - 1.0;
            let phi = std::f32::consts::TAU * random(i, 1);
            let r = (1.0 - z * z).sqrt();
            let origin = centre + radius * Vec3::new(r * phi.cos(), z, r * phi.sin());
            let count = mesh.triangle_count() as u32;
            let tri = ((random(i, 2) * count as f32) as u32).min(count - 1);
            let idx = mesh.indices()[tri as usize];
            let corners = mesh.corners(tri);
            let k = (i % 3) as usize;
            let (target, sharing): (Vec3, Vec<u32>) = if i % 2 == 0 {
                (corners[k], around[idx[k] as usize].clone())
            } else {
                let (a, b) = (idx[k], idx[(k + 1) % 3]);
                let shared = around[a as usize]
                    .iter()
                    .copied()
                    .filter(|t| around[b as usize].contains(t))
                    .collect();
                (corners[k].lerp(corners[(k + 1) % 3], random(i, 3)), shared)
            };
            let ray = Ray::new(origin, target - origin);
            let first = bunny.closest_hit(&ray, f32::INFINITY);
            // If every triangle at the target faces the ray, the ray must enter
            // there (or in front of it): no hit, or a back face first, would mean it
            // slipped through a crack. At a silhouette it may just touch or graze,
            // so no verdict there. (Grazing rays at interior targets may meet the
            // front surface a little past the target, as the target is only as exact
            // as f32: that is still an entry.)
            let interior = sharing.iter().all(|&t| faces_ray(t, ray.direction));
            let slipped = interior
                && match &first {
                    None => true,
                    Some(h) => h.geometric_normal.dot(ray.direction) > 0.0,
                };
            // A ray that entered must find the way out: walk the line crossing by
            // crossing (a ray can clip a sliver and leave within 1e-5 of its length,
            // so each step is about one ULP of t) until a back face is met.
            let (went_in, trapped) = match first {
                Some(entry) if interior && entry.geometric_normal.dot(ray.direction) < 0.0 => {
                    (1, u64::from(!leaves_again(&bunny, &ray, entry.t)))
                }
                _ => (0, 0),
            };
            (u64::from(interior), went_in, u64::from(slipped) + trapped)
        })
        .reduce(|| (0, 0, 0), |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2));
    assert!(
        checked > rays / 3,
        "only {checked} rays aimed at interior vertices and edges"
    );
    assert!(entered > rays / 3, "only {entered} rays entered");
    assert_eq!(leaks, 0, "{leaks} of {rays} rays leaked");
}

/// Whether, walking along `ray` from just past `t`, a back face (an exit) is met.
fn leaves_again(list: &ShapeList, ray: &Ray, mut t: f32) -> bool {
    for _ in 0..64 {
        let s = t * (1.0 + 2.0 * f32::EPSILON);
        let rest = Ray::new(ray.at(s), ray.direction);
        let Some(hit) = list.closest_hit(&rest, f32::INFINITY) else {
            return false;
        };
        if hit.geometric_normal.dot(ray.direction) > 0.0 {
            return true;
        }
        t = s + hit.t;
    }
    false
}

#[test]
fn bunny_bvh_statistics() {
    let stats = closed_bunny().bvh_stats().unwrap();
    assert!(stats.max_leaf_size <= 4);
    assert!(stats.leaves >= 5648 / 4);
    let s = format!(
        "nodes {}\nleaves {}\nmax depth {}\nmax leaf size {}\nSAH cost {}\n",
        stats.nodes,
        stats.leaves,
        stats.max_depth,
        stats.max_leaf_size,
        glint_snapfmt::sig5(stats.sah_cost)
    );
    insta::assert_snapshot!(s);
}

#[test]
fn bunny_scenes_load_and_render_the_bunny() {
    for (name, triangles) in [("bunny", 5648), ("bunny-cornell", 3674)] {
        let d = load(&scene_path(name)).unwrap();
        let meshes = d.scene.shapes.meshes();
        assert_eq!(meshes.len(), 1, "{name}");
        assert_eq!(meshes[0].triangle_count(), triangles, "{name}");
        assert!(meshes[0].has_normals(), "{name}: normals read or generated");
        // The camera ray through the image centre meets the bunny (not the walls).
        let c = d.scene.camera.generate_ray(
            d.scene.camera.resolution().x as f32 * 0.5,
            d.scene.camera.resolution().y as f32 * if name == "bunny" { 0.5 } else { 0.75 },
        );
        let hit = d
            .scene
            .shapes
            .closest_hit(&Ray::new(c.origin, c.direction), f32::INFINITY)
            .unwrap();
        assert!(
            matches!(
                d.scene.surfaces[hit.shape as usize],
                glint_integrator::Surface::Mesh(_)
            ),
            "{name}"
        );
    }
}
