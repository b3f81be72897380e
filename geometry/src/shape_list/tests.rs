//! Tests of the queries: nearest hits, `t_max`, and agreement between the BVH,
//! the linear loop and batches of rays.

use super::*;
use crate::lanes::LANES;
use crate::{Plane, Sphere};
use glam::Vec3;

fn scene() -> ShapeList {
    let mut list = ShapeList::new();
    list.push(Sphere::new(Vec3::new(0.0, 0.0, -10.0), 1.0).unwrap());
    list.push(Sphere::new(Vec3::new(0.0, 0.0, -5.0), 1.0).unwrap());
    list.push(Plane::new(Vec3::new(0.0, 0.0, -20.0), Vec3::Z, false).unwrap());
    list
}

#[test]
fn closest_hit_picks_the_nearest_shape_whatever_the_order() {
    for with_bvh in [false, true] {
        let ray = Ray::new(Vec3::ZERO, -Vec3::Z);
        let mut list = scene();
        if with_bvh {
            list.build_bvh();
        }
        let hit = list.closest_hit(&ray, f32::INFINITY).unwrap();
        assert_eq!(hit.shape, 1);
        assert!((hit.t - 4.0).abs() < 1e-6);
        let mut reversed: ShapeList = scene().shapes().iter().rev().copied().collect();
        if with_bvh {
            reversed.build_bvh();
        }
        assert_eq!(reversed.closest_hit(&ray, f32::INFINITY).unwrap().shape, 1);
        // The plane, outside the BVH, is still found.
        let sideways = Ray::new(Vec3::new(5.0, 0.0, 0.0), -Vec3::Z);
        assert_eq!(list.closest_hit(&sideways, f32::INFINITY).unwrap().shape, 2);
    }
}

#[test]
fn any_hit_respects_t_max() {
    for with_bvh in [false, true] {
        let mut list = scene();
        if with_bvh {
            list.build_bvh();
        }
        let ray = Ray::new(Vec3::ZERO, -Vec3::Z);
        assert!(list.any_hit(&ray, 4.5));
        assert!(!list.any_hit(&ray, 3.5));
        assert!(!list.any_hit(&Ray::new(Vec3::ZERO, Vec3::Z), f32::INFINITY));
    }
}

mod bvh_agreement {
    use super::*;
    use crate::{AaBox, Parallelogram, Plane, Sphere, TriangleMesh};
    use glam::{Vec2, Vec3};

    /// xorshift64*: a tiny deterministic generator for test scenes.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f32 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            ((self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32) / (1u64 << 24) as f32
        }
        fn in_cube(&mut self, r: f32) -> Vec3 {
            Vec3::new(self.next(), self.next(), self.next()) * 2.0 * r - r
        }
    }

    /// A UV sphere of `n × 2n` quads (two triangles each).
    fn tessellated_sphere(centre: Vec3, radius: f32, n: u32) -> TriangleMesh {
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..=2 * n {
                let (theta, phi) = (
                    j as f32 / n as f32 * std::f32::consts::PI,
                    i as f32 / n as f32 * std::f32::consts::PI,
                );
                positions.push(
                    centre
                        + radius
                            * Vec3::new(
                                theta.sin() * phi.cos(),
                                theta.cos(),
                                theta.sin() * phi.sin(),
                            ),
                );
            }
        }
        let indices = TriangleMesh::grid_indices(2 * n, n);
        TriangleMesh::new(positions, indices, vec![], vec![]).unwrap()
    }

    /// Even scenes: a BVH over everything; odd ones: what
    /// `build_acceleration` builds for them, spheres and parallelograms in
    /// packets beside a BVH over the rest.
    fn build(list: &mut ShapeList, scene: u32) {
        if scene.is_multiple_of(2) {
            list.build_bvh();
        } else {
            list.build_acceleration();
            assert!(
                list.bvh.is_some() && list.linear.is_some(),
                "packets and a BVH"
            );
        }
    }

    #[test]
    fn shadow_rays_among_culled_occluders_get_the_full_answer_beside_a_bvh() {
        // A lane's worth of shadow rays from one point to a quad, traced in lanes (the BVH
        // walked by all of them at once) and one by one, in every layout: packets
        // beside a BVH, a BVH alone, the linear loop with objects outside its
        // packets, and no acceleration built. Some rays run parallel to an axis,
        // one is NaN, one lane is inactive, and in odd rounds the rays start at
        // as many different points.
        let mut rng = Rng(0x51_7cc1_b727_220a);
        let mut blocked = 0;
        for scene in 0..40 {
            let mut list = random_scene(&mut rng);
            match scene % 4 {
                0 => {
                    list.build_acceleration();
                    assert!(
                        list.bvh.is_some() && list.linear.is_some(),
                        "packets and a BVH"
                    );
                }
                1 => list.build_bvh(),
                2 => {
                    list = small_scene(&mut rng);
                    // A small mesh stays in the loop, outside its packets.
                    list.push_mesh(tessellated_sphere(rng.in_cube(3.0), 0.8, 2));
                    list.build_acceleration();
                    let linear = list.linear.as_ref().expect("the linear loop");
                    assert!(list.bvh.is_none() && !linear.others.is_empty());
                }
                _ => list = small_scene(&mut rng),
            }
            for round in 0..50 {
                let from = rng.in_cube(6.0);
                let (corner, e1, e2) = (rng.in_cube(5.0), rng.in_cube(2.0), rng.in_cube(2.0));
                let corners = [corner, corner + e1, corner + e1 + e2, corner + e2];
                let mut targets: [Vec3; LANES] =
                    std::array::from_fn(|_| corner + rng.next() * e1 + rng.next() * e2);
                // Odd rounds: no culling, and targets off the quad.
                let occluders = if round % 2 == 0 {
                    list.occluders_towards(from, 0.0, &corners, [u32::MAX; 2])
                } else {
                    targets[1].x = from.x;
                    targets[2].y = from.y;
                    if round % 3 == 0 {
                        targets[3] = Vec3::NAN;
                    }
                    Occluders::ALL
                };
                let rays: [Ray; LANES] = std::array::from_fn(|k| {
                    let origin = if round % 2 == 0 {
                        from
                    } else {
                        from + rng.in_cube(0.5)
                    };
                    Ray::new(origin, targets[k] - origin)
                });
                let lanes = crate::RayLanes::new(rays);
                // Some unculled rounds unbounded: 0·∞ = NaN where a ray keeps a
                // coordinate.
                let t_max = if round % 10 == 9 { f32::INFINITY } else { 1.0 };
                let active = 0b1011_1111;
                let lanes_blocked = list.any_hits_among(&occluders, &lanes, t_max, active);
                for (k, ray) in rays.iter().enumerate() {
                    let alone = list.any_hit(ray, t_max);
                    assert_eq!(list.any_hit_among(&occluders, ray, t_max), alone);
                    let expected = alone && active >> k & 1 == 1;
                    assert_eq!(
                        lanes_blocked >> k & 1 == 1,
                        expected,
                        "scene {scene}, lane {k}"
                    );
                    blocked += expected as u32;
                }
            }
        }
        assert!(blocked > 200, "only {blocked} blocked rays");
    }

    /// Three spheres, three parallelograms, a box and a plane: the linear loop,
    /// with the box and the plane outside its packets.
    fn small_scene(rng: &mut Rng) -> ShapeList {
        let mut list = ShapeList::new();
        for _ in 0..3 {
            list.push(Sphere::new(rng.in_cube(4.0), 0.3 + rng.next()).unwrap());
            let corner = rng.in_cube(4.0);
            list.push(
                Parallelogram::new(corner, rng.in_cube(2.0), rng.in_cube(2.0), true).unwrap(),
            );
        }
        let c = rng.in_cube(3.0);
        list.push(AaBox::new(c, c + Vec3::splat(0.5) + rng.in_cube(0.5).abs()).unwrap());
        list.push(Plane::new(rng.in_cube(3.0), rng.in_cube(1.0), false).unwrap());
        list
    }

    fn random_scene(rng: &mut Rng) -> ShapeList {
        let mut list = ShapeList::new();
        for _ in 0..20 {
            let c = rng.in_cube(5.0);
            match (rng.next() * 4.0) as u32 {
                0 => {
                    list.push(Sphere::new(c, 0.2 + rng.next()).unwrap());
                }
                1 => {
                    list.push(
                        AaBox::new(c, c + Vec3::splat(0.3) + rng.in_cube(0.5).abs()).unwrap(),
                    );
                }
                2 => {
                    if let Some(p) = Parallelogram::new(c, rng.in_cube(1.0), rng.in_cube(1.0), true)
                    {
                        list.push(p);
                    }
                }
                _ => {
                    list.push_mesh(tessellated_sphere(c, 0.3 + rng.next(), 6));
                }
            }
        }
        // A few degenerate triangles: zero area, collinear, repeated vertices.
        let p = rng.in_cube(3.0);
        list.push_mesh(
            TriangleMesh::new(
                vec![p, p, p + Vec3::X, p + 2.0 * Vec3::X],
                vec![[0, 1, 2], [0, 2, 3], [1, 1, 1]],
                vec![],
                vec![Vec2::ZERO; 4],
            )
            .unwrap(),
        );
        list
    }

    #[test]
    fn bvh_and_brute_force_agree_on_random_rays_over_random_scenes() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        for scene in 0..40 {
            let linear = random_scene(&mut rng);
            let mut accelerated = linear.clone();
            build(&mut accelerated, scene);
            for _ in 0..500 {
                let origin = rng.in_cube(8.0);
                let toward = rng.in_cube(5.0);
                let ray = Ray::new(origin, toward - origin);
                let (a, b) = (
                    linear.closest_hit(&ray, f32::INFINITY),
                    accelerated.closest_hit(&ray, f32::INFINITY),
                );
                // The query without a surface record finds the same hit.
                for (list, hit) in [(&linear, a), (&accelerated, b)] {
                    let found = list.closest_primitive(&ray, f32::INFINITY);
                    assert_eq!(
                        found.map(|f| (f.t, f.object, f.primitive)),
                        hit.map(|h| (h.t, h.shape, h.primitive))
                    );
                }
                match (a, b) {
                    (None, None) => {}
                    (Some(a), Some(b)) => {
                        assert!(
                            (a.t - b.t).abs() <= 1e-5 * a.t.max(1.0),
                            "t {} vs {}",
                            a.t,
                            b.t
                        );
                        assert!(a.point.is_finite() && a.geometric_normal.is_finite());
                        // Ties go to the lowest index either way: the same primitive.
                        assert_eq!((a.shape, a.primitive), (b.shape, b.primitive));
                    }
                    (a, b) => panic!("linear {:?} vs bvh {:?}", a.map(|h| h.t), b.map(|h| h.t)),
                }
                let t_max = 0.5 + rng.next() * 20.0;
                assert_eq!(
                    linear.any_hit(&ray, t_max),
                    accelerated.any_hit(&ray, t_max)
                );
            }
        }
    }

    /// A mesh of one triangle three times: as given, again (every hit on it
    /// a tie at equal t) and with its corners rotated (hits within an ulp or
    /// two of the first's: the order primitives are met in must not decide).
    fn coincident_triangles(rng: &mut Rng) -> TriangleMesh {
        let (a, b, c) = (rng.in_cube(4.0), rng.in_cube(4.0), rng.in_cube(4.0));
        TriangleMesh::new(
            vec![a, b, c],
            vec![[0, 1, 2], [0, 1, 2], [1, 2, 0]],
            vec![],
            vec![],
        )
        .unwrap()
    }

    /// Rays in lanes (the BVH walked by all of them together, each shape and
    /// triangle tested against all at once) get the answers each ray gets
    /// alone, bit for bit: in every layout (a BVH over everything, packets
    /// beside a BVH, the linear loop with a mesh outside its packets, nothing
    /// built), for rays from one point and from anywhere, with a NaN lane,
    /// rays along the axes and fewer lanes used than there are.
    #[test]
    fn rays_in_lanes_get_the_answers_of_rays_traced_alone() {
        let mut rng = Rng(0x3c6e_f372_fe94_f82b);
        let mut hits = 0;
        for scene in 0..36 {
            let mut list = match scene % 4 {
                3 => {
                    let mut list = small_scene(&mut rng);
                    list.push_mesh(coincident_triangles(&mut rng));
                    list
                }
                _ => {
                    let mut list = random_scene(&mut rng);
                    for _ in 0..3 {
                        list.push_mesh(coincident_triangles(&mut rng));
                    }
                    list
                }
            };
            match scene % 4 {
                0 | 1 => build(&mut list, scene),
                2 => {}
                _ => {
                    list.build_acceleration();
                    let linear = list.linear.as_ref().expect("the linear loop");
                    assert!(list.bvh.is_none() && !linear.others.is_empty());
                }
            }
            for round in 0..60 {
                let from = rng.in_cube(8.0);
                let aim = rng.in_cube(4.0);
                let mut rays: [Ray; LANES] = std::array::from_fn(|_| match round % 2 {
                    0 => Ray::new(from, aim + rng.in_cube(1.0) - from),
                    _ => {
                        let origin = rng.in_cube(8.0);
                        Ray::new(origin, rng.in_cube(5.0) - origin)
                    }
                });
                rays[1] = Ray::new(rays[1].origin, Vec3::AXES[round % 3]);
                if round % 5 == 0 {
                    rays[2] = Ray::new(Vec3::NAN, Vec3::X);
                }
                let used = 1 + round % LANES;
                let found = list.closest_lanes(&crate::RayLanes::new(rays), used);
                for (k, ray) in rays.iter().enumerate().take(used) {
                    let alone = list.closest_primitive(ray, f32::INFINITY);
                    let lane = found.hit(k);
                    assert_eq!(
                        lane.map(|h| (h.t.to_bits(), h.object, h.primitive)),
                        alone.map(|h| (h.t.to_bits(), h.object, h.primitive)),
                        "scene {scene}, round {round}, lane {k}: {ray:?}"
                    );
                    hits += u32::from(alone.is_some());
                }
            }
        }
        assert!(hits > 250 * LANES as u32, "only {hits} hits");
    }

    #[test]
    fn streams_of_rays_get_the_answers_of_rays_traced_alone() {
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        for scene in 0..10 {
            let mut linear = random_scene(&mut rng);
            if scene % 2 == 0 {
                linear
                    .push(Plane::new(rng.in_cube(4.0), rng.in_cube(1.0), scene % 4 == 0).unwrap());
            }
            let mut accelerated = linear.clone();
            build(&mut accelerated, scene);
            let mut rays: Vec<Ray> = (0..300)
                .map(|_| {
                    let origin = rng.in_cube(8.0);
                    Ray::new(origin, rng.in_cube(5.0) - origin)
                })
                .collect();
            rays[7] = Ray::new(Vec3::NAN, Vec3::X);
            let t_max: Vec<f32> = (0..rays.len())
                .map(|i| match i % 3 {
                    0 => f32::INFINITY,
                    _ => 0.5 + rng.next() * 20.0,
                })
                .collect();
            for list in [&linear, &accelerated] {
                let mut hits = vec![None; rays.len()];
                list.closest_primitives(&rays, &t_max, &mut hits);
                let mut occluded = vec![false; rays.len()];
                list.any_hits(&rays, &t_max, &mut occluded);
                for (i, ray) in rays.iter().enumerate() {
                    assert_eq!(hits[i], list.closest_primitive(ray, t_max[i]), "ray {i}");
                    assert_eq!(occluded[i], list.any_hit(ray, t_max[i]), "ray {i}");
                }
                assert!(hits.iter().filter(|h| h.is_some()).count() > 30);
                assert!(occluded.iter().filter(|&&o| o).count() > 30);
            }
        }
    }
}

mod found_hits_stay_found {
    use super::*;
    use crate::TriangleMesh;
    use glam::Vec3;

    #[test]
    fn every_triangle_hit_found_yields_a_surface_record() {
        // Many rays at a fine fan of triangles: whenever a distance is found, the
        // surface record must exist too (rounding once turned such hits into misses).
        let mut positions = vec![Vec3::new(0.0, 0.0, -3.0)];
        for i in 0..64 {
            let a = i as f32 / 64.0 * std::f32::consts::TAU;
            positions.push(Vec3::new(a.cos(), a.sin(), -3.0));
        }
        let indices = (0..64u32).map(|i| [0, 1 + i, 1 + (i + 1) % 64]).collect();
        let mut list = ShapeList::new();
        list.push_mesh(TriangleMesh::new(positions, indices, vec![], vec![]).unwrap());
        list.build_bvh();
        let mut found = 0;
        for j in 0..300 {
            for i in 0..300 {
                let d = Vec3::new(i as f32 / 300.0 - 0.5, j as f32 / 300.0 - 0.5, -1.0);
                let ray = Ray::new(Vec3::new(0.013, -0.007, 0.0), d);
                let hit = list.closest_hit(&ray, f32::INFINITY);
                // The fan lies in z = −3 and covers the disk of radius cos(π/64).
                let p = ray.at(3.0);
                let inside = p.x * p.x + p.y * p.y < 0.99;
                if inside {
                    assert!(hit.is_some(), "ray {d} slipped through");
                    found += 1;
                }
            }
        }
        assert!(found > 10_000);
    }
}

mod lanes {
    use super::*;
    use crate::bvh::test_support::XorShift;
    use crate::{Parallelogram, RayLanes};

    #[test]
    fn rays_in_a_frustum_find_their_hits_among_the_objects_it_meets() {
        // Narrow frusta of `LANES` rays (a pixel's) from random points, against
        // random spheres and parallelograms, some tiny and some far, some
        // axis-aligned walls, planes and boxes: the objects the frustum can meet hold every hit,
        // and with them the hits are each ray's own. Rays on the frustum's
        // edges and corners are included.
        let mut rng = XorShift(0x7a11_c0de_5eed_0001);
        let (mut hits, mut culled, mut plane_hits, mut box_hits) = (0, 0, 0, 0);
        for scene in 0..80 {
            let mut list = ShapeList::new();
            let scale = [1.0, 1e-3, 1e3][scene % 3];
            for k in 0..12 {
                let c = rng.vec3(-4.0, 4.0) * scale;
                if k % 2 == 0 {
                    let r = (0.05 + rng.unit()) * scale;
                    list.push(Sphere::new(c, r).unwrap());
                } else if k % 3 == 0 {
                    // A wall in an axis plane, as a room's are.
                    let (a, b) =
                        [(Vec3::X, Vec3::Y), (Vec3::Y, Vec3::Z), (Vec3::Z, Vec3::X)][k % 9 / 3];
                    let (e1, e2) = (a * 6.0 * scale, b * 5.0 * scale);
                    list.push(Parallelogram::new(c, e1, e2, false).unwrap());
                } else {
                    let (e1, e2) = (rng.vec3(-2.0, 2.0) * scale, rng.vec3(-2.0, 2.0) * scale);
                    list.push(Parallelogram::new(c, e1, e2, k % 4 == 1).unwrap());
                }
            }
            if scene % 4 == 1 {
                // Unbounded planes, one-sided and two-sided: tested in every frustum.
                for two_sided in [false, true] {
                    let (p, n) = (rng.vec3(-4.0, 4.0) * scale, rng.vec3(-1.0, 1.0));
                    list.push(crate::Plane::new(p, n, two_sided).unwrap());
                }
            }
            if scene % 4 == 3 {
                // Boxes, tested in every frustum: one among the objects, and
                // a sky box around them all, seen from inside.
                let (c, h) = (rng.vec3(-4.0, 4.0) * scale, rng.vec3(0.2, 2.0) * scale);
                list.push(crate::AaBox::new(c - h, c + h).unwrap());
                let sky = Vec3::splat(30.0 * scale);
                list.push(crate::AaBox::new(-sky, sky).unwrap());
            }
            list.build_acceleration();
            for _ in 0..100 {
                let apex = rng.vec3(-6.0, 6.0) * scale;
                let axis = (rng.vec3(-4.0, 4.0) * scale - apex).normalize();
                let (side, up) = axis.any_orthonormal_pair();
                let (a, b) = (0.002 + 0.05 * rng.unit(), 0.002 + 0.05 * rng.unit());
                let direction = |u: f32, v: f32| {
                    axis + side * (a * (2.0 * u - 1.0)) + up * (b * (2.0 * v - 1.0))
                };
                let corners =
                    [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)].map(|(u, v)| direction(u, v));
                let rays: [Ray; LANES] = std::array::from_fn(|k| {
                    let (u, v) = match k {
                        0 => (0.0, 0.0),
                        1 => (1.0, rng.unit()),
                        _ => (rng.unit(), rng.unit()),
                    };
                    Ray::new(apex, direction(u, v))
                });
                let candidates = list.objects_in_frustum(apex, corners);
                culled += 12 - candidates.count_ones().min(12);
                let found = list.closest_lanes_among(&RayLanes::new(rays), LANES, candidates);
                for (k, ray) in rays.iter().enumerate() {
                    assert_eq!(found.hit(k), list.closest_primitive(ray, f32::INFINITY));
                    hits += found.hit(k).is_some() as u32;
                    let beyond = found.hit(k).is_some_and(|h| h.object >= 12);
                    plane_hits += (beyond && scene % 4 == 1) as u32;
                    box_hits += (beyond && scene % 4 == 3) as u32;
                }
            }
        }
        assert!(hits > 2000, "only {hits} hits");
        assert!(plane_hits > 200, "only {plane_hits} plane hits");
        assert!(box_hits > 200, "only {box_hits} box hits");
        assert!(culled > 40_000, "the frusta leave out objects ({culled})");
    }

    /// A sphere and an axis-aligned wall that reach only just inside a
    /// frustum's side plane, mostly outside it, are kept: the ray along the
    /// frustum's edge hits them both.
    #[test]
    fn objects_reaching_just_inside_a_side_plane_are_kept() {
        let mut rng = XorShift(0x5eed_f00d_0bad_cafe);
        for round in 0..300 {
            let scale = [1.0, 1e-3, 1e3][round % 3];
            let apex = rng.vec3(-6.0, 6.0) * scale;
            let (a, b) = (0.002 + 0.05 * rng.unit(), 0.002 + 0.05 * rng.unit());
            let direction =
                |u: f32, v: f32| Vec3::new(a * (2.0 * u - 1.0), b * (2.0 * v - 1.0), -1.0);
            let corners =
                [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)].map(|(u, v)| direction(u, v));
            let edge = Ray::new(apex, direction(1.0, rng.unit()));
            let t = (1.0 + 4.0 * rng.unit()) * scale;
            let p = edge.at(t);
            let mut list = ShapeList::new();
            // The sphere's centre a little outside the plane: the edge ray passes inside its radius.
            let r = 0.01 * t;
            let outward = Vec3::new(1.0, 0.0, a).normalize();
            list.push(Sphere::new(p + outward * (0.98 * r), r).unwrap());
            // A wall across the edge at depth t, reaching 10⁻⁴·t inside the edge ray.
            let wall_z = Vec3::new(0.0, 0.0, p.z - apex.z) + apex;
            let origin = Vec3::new(p.x - 1e-4 * t, p.y - 0.1 * t, wall_z.z);
            list.push(Parallelogram::new(origin, Vec3::X * t, Vec3::Y * 0.2 * t, false).unwrap());
            list.build_acceleration();
            let candidates = list.objects_in_frustum(apex, corners);
            assert_eq!(candidates & 0b11, 0b11, "round {round}: {candidates:b}");
            // Each alone is hit by the edge ray (so culling it would lose a hit).
            for (object, alone) in [(0u32, 0b01u64), (1, 0b10)] {
                let found = list.closest_lanes_among(&RayLanes::new([edge; LANES]), 1, alone);
                assert_eq!(
                    found.hit(0).map(|h| h.object),
                    Some(object),
                    "round {round}"
                );
            }
        }
    }

    /// The walls of a room seen from inside: a pixel's frustum meets the wall
    /// it looks at, not the walls beside and behind it (which their bounding
    /// spheres alone would not tell).
    #[test]
    fn a_pixel_looking_at_one_wall_culls_the_others() {
        let mut list = ShapeList::new();
        let wall = |o: [f32; 3], e1: Vec3, e2: Vec3| {
            Parallelogram::new(Vec3::from(o), e1 * 20.0, e2 * 20.0, false).unwrap()
        };
        list.push(wall([-10.0, -10.0, -10.0], Vec3::X, Vec3::Y)); // back
        list.push(wall([-10.0, -10.0, -10.0], Vec3::Z, Vec3::Y)); // left
        list.push(wall([10.0, -10.0, -10.0], Vec3::Z, Vec3::Y)); // right
        list.push(wall([-10.0, -10.0, -10.0], Vec3::X, Vec3::Z)); // floor
        list.build_acceleration();
        let d = 0.001;
        let corners = [(-d, -d), (d, -d), (d, d), (-d, d)].map(|(x, y)| Vec3::new(x, y, -1.0));
        assert_eq!(
            list.objects_in_frustum(Vec3::new(0.0, 0.0, 5.0), corners),
            0b0001
        );
        // Corners that span no frustum cull nothing.
        assert_eq!(list.objects_in_frustum(Vec3::ZERO, [Vec3::Z; 4]), u64::MAX);
    }

    #[test]
    fn eight_rays_at_once_find_the_hits_each_finds_alone() {
        let mut rng = XorShift(0x0dd_b1a5_e5ba_d5ee);
        let mut hits = 0;
        for scene in 0..60 {
            let mut list = ShapeList::new();
            for k in 0..(3 + scene % 9) {
                if k % 3 == 0 {
                    list.push(Sphere::new(rng.vec3(-3.0, 3.0), 0.3 + rng.unit()).unwrap());
                } else {
                    let p = Parallelogram::new(
                        rng.vec3(-3.0, 3.0),
                        rng.vec3(-3.0, 3.0),
                        rng.vec3(-3.0, 3.0),
                        k % 2 == 0,
                    )
                    .unwrap();
                    list.push(p);
                }
            }
            // A duplicate of the first shape: every hit on it is a tie at equal t,
            // which must go to the lower index.
            let first = *list.shapes().first().unwrap();
            list.push(first);
            list.build_acceleration();
            for _ in 0..40 {
                let origin = rng.vec3(-5.0, 5.0);
                let rays: [Ray; LANES] =
                    std::array::from_fn(|_| Ray::new(origin, rng.vec3(-3.0, 3.0) - origin));
                let found = list.closest_primitives_lanes(&RayLanes::new(rays), LANES);
                for (ray, lane) in rays.iter().zip(found) {
                    assert_eq!(lane, list.closest_primitive(ray, f32::INFINITY));
                    hits += lane.is_some() as u32;
                }
            }
        }
        assert!(hits > 3000, "only {hits} hits");
    }
}

/// `surface_point` is `surface_record` with a sphere's derivatives left zero:
/// every other field the same bits, on spheres and a plane.
#[test]
fn surface_points_are_surface_records_without_sphere_derivatives() {
    let list = scene();
    let mut compared = 0;
    for k in 0..400 {
        let a = k as f32 * 0.37;
        let ray = Ray::new(
            Vec3::new(0.5 * a.sin(), 0.4 * a.cos(), 0.0),
            Vec3::new(0.1 * (1.3 * a).sin(), 0.1 * (0.7 * a).cos(), -1.0),
        );
        let Some(found) = list.closest_primitive(&ray, f32::INFINITY) else {
            continue;
        };
        let record = list.surface_record(&ray, found).unwrap();
        let point = list.surface_point(&ray, found).unwrap();
        let is_sphere = matches!(
            list.object(found.object),
            ObjectRef::Shape(Shape::Sphere(_))
        );
        let expected = if is_sphere {
            crate::Hit {
                dpdu: Vec3::ZERO,
                dpdv: Vec3::ZERO,
                dndu: Vec3::ZERO,
                dndv: Vec3::ZERO,
                ..record
            }
        } else {
            record
        };
        assert_eq!(format!("{point:?}"), format!("{expected:?}"), "ray {ray:?}");
        compared += 1;
    }
    assert!(compared > 300, "{compared} hits");
}
