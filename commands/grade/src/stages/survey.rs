//! Where the test vectors come from: one closest-hit query through every
//! pixel's centre, and from it the pixels of each kind a stage draws its
//! cases from: spread over the image (stratified), and the awkward ones
//! (silhouettes, edges and corners between objects, pixels that see a light
//! or nothing, grazing angles, the sphere's u seam).
//!
//! Every list is in a fixed order, so the same scene gives the same cases.

use glam::UVec2;
use glint_geometry::{ObjectRef, Ray, Shape};
use glint_integrator::{Scene, Surface};
use glint_lighting::PhongMaterial;
use glint_texture::Texture;
use rayon::prelude::*;

/// The object index of a pixel whose centre sees nothing.
pub const BACKGROUND: u32 = u32::MAX;

/// Below this `|N·D|` a hit is at a grazing angle (about 73° from the normal).
const GRAZING_COS: f32 = 0.3;

/// Within this of a whole number, a sphere's `u` is near its seam.
const SEAM: f32 = 0.02;

/// What a stage needs to know of an object to choose pixels on it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ObjectInfo {
    pub sphere: bool,
    /// The emitting surface of a light.
    pub emitter: bool,
    /// Shaded (not a pure mirror, not a light); for a mesh, any triangle.
    pub shaded: bool,
    /// Its material reads a checkerboard or an image; for a mesh, any triangle's.
    pub textured: bool,
}

/// The pixel centres' hits.
pub struct Survey {
    pub size: UVec2,
    /// Per pixel (row by row), the object its centre sees, or [`BACKGROUND`].
    pub objects: Vec<u32>,
    /// Per pixel, `|N·D|` at its centre's hit (0 on a miss).
    pub cos: Vec<f32>,
    /// Per pixel, the hit's u (0 on a miss).
    pub u: Vec<f32>,
    pub info: Vec<ObjectInfo>,
}

/// Whether `material` reads a checkerboard or an image.
pub fn textured(material: &PhongMaterial) -> bool {
    let varies = |t: &Texture| matches!(t, Texture::Checkerboard(_) | Texture::Image(_));
    varies(&material.diffuse) || material.specular.as_ref().is_some_and(varies)
}

/// The camera ray through raster position `(x, y)`.
pub fn camera_ray(scene: &Scene, x: f32, y: f32) -> Ray {
    let c = scene.camera.generate_ray(x, y);
    Ray::new(c.origin, c.direction)
}

/// What pixel `(x, y)`'s centre sees: the object, `|N·D|` and u (or
/// [`BACKGROUND`], 0, 0).
fn centre(scene: &Scene, x: u32, y: u32) -> (u32, f32, f32) {
    let ray = camera_ray(scene, x as f32 + 0.5, y as f32 + 0.5);
    match scene.shapes.closest_hit(&ray, f32::INFINITY) {
        Some(h) => (h.shape, h.geometric_normal.dot(ray.direction).abs(), h.uv.x),
        None => (BACKGROUND, 0.0, 0.0),
    }
}

fn object_info(scene: &Scene, object: u32) -> ObjectInfo {
    let sphere = matches!(
        scene.shapes.object(object),
        ObjectRef::Shape(Shape::Sphere(_))
    );
    let materials: Vec<&PhongMaterial> = match scene.surfaces[object as usize] {
        Surface::Material(m) => vec![&scene.materials[m as usize]],
        Surface::Emitter(_) => Vec::new(),
        Surface::Mesh(k) => scene.mesh_materials[k as usize]
            .iter()
            .map(|&m| &scene.materials[m as usize])
            .collect(),
    };
    ObjectInfo {
        sphere,
        emitter: matches!(scene.surfaces[object as usize], Surface::Emitter(_)),
        shaded: materials.iter().any(|m| m.has_local_shading()),
        textured: materials.iter().any(|m| textured(m)),
    }
}

impl Survey {
    /// One closest-hit query through each pixel's centre (rows in parallel;
    /// the result does not depend on the thread count).
    pub fn new(scene: &Scene) -> Survey {
        let size = scene.camera.resolution();
        let rows: Vec<Vec<(u32, f32, f32)>> = (0..size.y)
            .into_par_iter()
            .map(|y| (0..size.x).map(|x| centre(scene, x, y)).collect())
            .collect();
        let mut survey = Survey {
            size,
            objects: Vec::new(),
            cos: Vec::new(),
            u: Vec::new(),
            info: (0..scene.shapes.len() as u32)
                .map(|i| object_info(scene, i))
                .collect(),
        };
        for (object, cos, u) in rows.into_iter().flatten() {
            survey.objects.push(object);
            survey.cos.push(cos);
            survey.u.push(u);
        }
        survey
    }

    fn index(&self, [x, y]: [u32; 2]) -> usize {
        (y * self.size.x + x) as usize
    }

    /// The object pixel `p`'s centre sees ([`BACKGROUND`] for none).
    pub fn object(&self, p: [u32; 2]) -> u32 {
        self.objects[self.index(p)]
    }

    /// What is known of the object pixel `p` sees (default for none).
    pub fn info(&self, p: [u32; 2]) -> ObjectInfo {
        match self.object(p) {
            BACKGROUND => ObjectInfo::default(),
            o => self.info[o as usize],
        }
    }

    /// Every pixel, row by row.
    pub fn pixels(&self) -> impl Iterator<Item = [u32; 2]> + '_ {
        (0..self.size.y).flat_map(move |y| (0..self.size.x).map(move |x| [x, y]))
    }

    /// The objects seen by the 8 pixels around `p` (those inside the image):
    /// diagonals included, as a corner of three objects often shows only there.
    fn neighbours(&self, [x, y]: [u32; 2]) -> Vec<u32> {
        let mut seen = Vec::new();
        for dy in -1i64..=1 {
            for dx in -1i64..=1 {
                let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                let inside =
                    nx >= 0 && ny >= 0 && nx < self.size.x as i64 && ny < self.size.y as i64;
                if (dx, dy) != (0, 0) && inside {
                    seen.push(self.object([nx as u32, ny as u32]));
                }
            }
        }
        seen
    }

    /// Whether a neighbour (the 8 around `p`) sees another object than `p`.
    pub fn on_edge(&self, p: [u32; 2]) -> bool {
        let own = self.object(p);
        self.neighbours(p).iter().any(|&o| o != own)
    }

    /// An edge where a sphere meets something else.
    pub fn on_silhouette(&self, p: [u32; 2]) -> bool {
        let own = self.object(p);
        let sphere = |o: u32| o != BACKGROUND && self.info[o as usize].sphere;
        self.neighbours(p)
            .iter()
            .any(|&o| o != own && (sphere(o) || sphere(own)))
    }

    /// Three objects or more (the background counts) around `p`.
    pub fn at_corner(&self, p: [u32; 2]) -> bool {
        let mut seen = self.neighbours(p);
        seen.push(self.object(p));
        seen.sort_unstable();
        seen.dedup();
        seen.len() >= 3
    }

    /// A hit at a grazing angle.
    pub fn grazing(&self, p: [u32; 2]) -> bool {
        self.object(p) != BACKGROUND && self.cos[self.index(p)] < GRAZING_COS
    }

    /// A sphere hit whose `u` is near the seam at `u = 0 = 1`.
    pub fn near_seam(&self, p: [u32; 2]) -> bool {
        let u = self.u[self.index(p)];
        self.info(p).sphere && (u - u.round()).abs() < SEAM
    }

    /// The pixels passing `test` (tested in parallel), in a fixed shuffled
    /// order, so that the first few are spread over the image, not all in
    /// its top rows.
    pub fn awkward(&self, test: impl Fn([u32; 2]) -> bool + Sync) -> Vec<[u32; 2]> {
        let all: Vec<[u32; 2]> = self.pixels().collect();
        let mut found: Vec<[u32; 2]> = all.into_par_iter().filter(|&p| test(p)).collect();
        found.sort_by_key(|&p| mix(self.index(p) as u64));
        found
    }

    /// Pixels spread evenly over the image, passing `test`: the points of the
    /// Halton sequence in bases 2 and 3 (Halton 1960; pbrt-v4 section 8.6:
    /// every prefix is well stratified), each pixel once, up to a limit of
    /// points tried.
    pub fn stratified<'a>(
        &'a self,
        test: impl Fn([u32; 2]) -> bool + 'a,
    ) -> impl Iterator<Item = [u32; 2]> + 'a {
        let mut used = std::collections::BTreeSet::new();
        (1..=HALTON_POINTS).filter_map(move |i| {
            let x = (radical_inverse(i, 2) * self.size.x as f64) as u32;
            let y = (radical_inverse(i, 3) * self.size.y as f64) as u32;
            let p = [x.min(self.size.x - 1), y.min(self.size.y - 1)];
            (test(p) && used.insert(p)).then_some(p)
        })
    }
}

/// How many Halton points [`Survey::stratified`] tries at most.
const HALTON_POINTS: u64 = 1 << 17;

/// The radical inverse of `i` in `base`: its digits mirrored about the point.
fn radical_inverse(mut i: u64, base: u64) -> f64 {
    let (mut value, mut scale) = (0.0, 1.0 / base as f64);
    while i > 0 {
        value += (i % base) as f64 * scale;
        i /= base;
        scale /= base as f64;
    }
    value
}

/// SplitMix64's finaliser (Steele et al. 2014): a fixed, well-mixed order.
pub fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set1() -> glint_scene::SceneDescription {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../scenes/cornell-set1.toml"
        );
        glint_scene::load(std::path::Path::new(path)).unwrap()
    }

    #[test]
    fn halton_points_are_stratified() {
        assert_eq!(radical_inverse(1, 2), 0.5);
        assert_eq!(radical_inverse(6, 2), 0.375);
        assert!((radical_inverse(5, 3) - 7.0 / 9.0).abs() < 1e-12);
    }

    #[test]
    fn the_survey_finds_each_kind_of_pixel_in_the_cornell_box() {
        let mut d = set1();
        d.scene.camera = d.scene.camera.with_resolution(UVec2::new(64, 64)).unwrap();
        let s = Survey::new(&d.scene);
        assert_eq!(s.objects.len(), 64 * 64);
        // The four spheres are objects 0–3, the light object 9.
        assert!(s.info[0].sphere && s.info[0].textured && s.info[0].shaded);
        assert!(s.info[9].emitter && !s.info[9].shaded);
        let silhouettes = s.awkward(|p| s.on_silhouette(p));
        assert!(silhouettes.len() > 20, "{}", silhouettes.len());
        for p in &silhouettes {
            let own = s.object(*p);
            assert!(s.neighbours(*p).iter().any(|&o| o != own), "{p:?}");
        }
        assert!(!s.awkward(|p| s.at_corner(p)).is_empty());
        assert!(s.awkward(|p| s.info(p).emitter).len() > 2);
        assert!(!s.awkward(|p| s.grazing(p)).is_empty());
        // The first few stratified pixels fall in every quarter of the image.
        let first: Vec<[u32; 2]> = s.stratified(|_| true).take(6).collect();
        let quarters: std::collections::BTreeSet<(u32, u32)> =
            first.iter().map(|p| (p[0] / 32, p[1] / 32)).collect();
        assert_eq!(quarters.len(), 4, "{first:?}");
    }
}
