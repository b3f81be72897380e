//! The Phong reflection of [`LANES`] shading points at once, each with its own
//! material, reflectances, normal and viewer: one light direction per lane.
//!
//! [`PhongMaterial::reflect_lanes`] shades [`LANES`] light samples of *one* point;
//! [`PhongLanes`] shades one light sample of each of [`LANES`] points (a pixel's camera
//! samples' hits). Each lane is bit for bit what [`PhongMaterial::reflect`]
//! (or [`PhongMaterial::reflect_diffuse`] where the lane has no specular term)
//! gives for that point: the same operations in the same order, nothing fused.
//! The lobe's power `cos^s` is taken by the repeated squaring of
//! [`f32::powi`] with each lane's own exponent; lanes whose lobe is Blinn–Phong
//! or whose exponent is not an integer are computed one by one.

use crate::material::{lobe_of_cosine, phong_cosine, phong_reflection};
use crate::{Lobes, PhongMaterial, SpecularLobe};
use glam::Vec3;
use glint_geometry::lanes::{self, F32Lanes, Vec3Lanes, LANES};

/// [`LANES`] shading points' Phong parameters, one per lane; lanes never set
/// reflect nothing.
#[derive(Clone, Debug, Default)]
pub struct PhongLanes<'a> {
    materials: [Option<&'a PhongMaterial>; LANES],
    kd: Vec3Lanes,
    ks: Vec3Lanes,
    n: Vec3Lanes,
    v: Vec3Lanes,
    /// Lanes with a specular term (bit k for lane k).
    specular: u32,
    /// Lanes whose lobe is a Phong lobe with an integral exponent, taken in lanes.
    lane_lobes: u32,
    /// The exponents of the lobes taken in lanes, bit by bit: bit k of
    /// `exponent_bits[b]` is bit b of lane k's exponent.
    exponent_bits: [u32; 32],
    /// The bits set in any lane's exponent (their top bit ends the squarings).
    exponent_top: u32,
    /// Each lane's exponent as a float (0 where unset), for sampling lobes.
    shininess: F32Lanes,
    /// Lanes whose lobe is Blinn–Phong's.
    blinn: u32,
}

impl<'a> PhongLanes<'a> {
    /// Sets lane `lane` to the point with `material`, reflectances `kd` and
    /// `ks`, unit normal `n` and unit direction to the viewer `v`; `specular`
    /// says whether its specular term is evaluated (as the scalar path's choice
    /// between [`PhongMaterial::reflect`] and [`PhongMaterial::reflect_diffuse`]).
    #[allow(clippy::too_many_arguments)]
    pub fn set(
        &mut self,
        lane: usize,
        material: &'a PhongMaterial,
        kd: Vec3,
        ks: Vec3,
        n: Vec3,
        v: Vec3,
        specular: bool,
    ) {
        self.kd.set_lane(lane, kd);
        self.ks.set_lane(lane, ks);
        self.n.set_lane(lane, n);
        self.v.set_lane(lane, v);
        self.set_material(1 << lane, material, if specular { 1 << lane } else { 0 });
    }

    /// The lanes `lanes` (bit k for lane k) set to points of one `material`,
    /// with the reflectances, normals and viewer directions of [`Self::set`] in
    /// lanes, the others unset; `specular` holds the lanes whose specular term
    /// is evaluated. Each lane is what [`Self::set`] gives it.
    #[allow(clippy::too_many_arguments)]
    pub fn of_lanes(
        lanes: u32,
        material: &'a PhongMaterial,
        kd: &Vec3Lanes,
        ks: &Vec3Lanes,
        n: &Vec3Lanes,
        v: &Vec3Lanes,
        specular: u32,
    ) -> Self {
        let (mask, unset) = (lanes::from_bits(lanes), Vec3Lanes::default());
        let exponent = lane_exponent(material);
        let with_exponent = if exponent.is_some() { lanes } else { 0 };
        let exponent = exponent.unwrap_or(0);
        Self {
            materials: std::array::from_fn(|k| (lanes >> k & 1 == 1).then_some(material)),
            kd: Vec3Lanes::select(mask, kd, &unset),
            ks: Vec3Lanes::select(mask, ks, &unset),
            n: Vec3Lanes::select(mask, n, &unset),
            v: Vec3Lanes::select(mask, v, &unset),
            specular: specular & lanes,
            lane_lobes: with_exponent,
            exponent_bits: std::array::from_fn(|b| if exponent >> b & 1 == 1 { lanes } else { 0 }),
            exponent_top: exponent,
            shininess: mask.select(F32Lanes::splat(material.shininess), F32Lanes::ZERO),
            blinn: if material.lobe == SpecularLobe::BlinnPhong {
                lanes
            } else {
                0
            },
        }
    }

    /// Gives the lanes `lanes` `material`, with specular terms in `specular`.
    fn set_material(&mut self, lanes: u32, material: &'a PhongMaterial, specular: u32) {
        self.specular = (self.specular & !lanes) | specular;
        let exponent = lane_exponent(material);
        let with_exponent = if exponent.is_some() { lanes } else { 0 };
        self.lane_lobes = (self.lane_lobes & !lanes) | with_exponent;
        for k in lanes::each_set(lanes) {
            self.materials[k] = Some(material);
        }
        let mask = lanes::from_bits(lanes);
        self.shininess = mask.select(F32Lanes::splat(material.shininess), self.shininess);
        let blinn = if material.lobe == SpecularLobe::BlinnPhong {
            lanes
        } else {
            0
        };
        self.blinn = (self.blinn & !lanes) | blinn;
        self.set_exponent(lanes, exponent.unwrap_or(0));
    }

    /// Gives the lanes `lanes` the lobe exponent `exponent`.
    fn set_exponent(&mut self, lanes: u32, exponent: u32) {
        self.exponent_top |= exponent;
        let bits = 32 - self.exponent_top.leading_zeros() as usize;
        for (b, lanes_with_bit) in self.exponent_bits.iter_mut().enumerate().take(bits) {
            let with_bit = if exponent >> b & 1 == 1 { lanes } else { 0 };
            *lanes_with_bit = (*lanes_with_bit & !lanes) | with_bit;
        }
    }

    /// The lanes with a specular term.
    pub fn specular_lanes(&self) -> u32 {
        self.specular
    }

    /// Each lane's diffuse reflectance.
    pub fn kd(&self) -> &Vec3Lanes {
        &self.kd
    }

    /// Each lane's specular reflectance.
    pub fn ks(&self) -> &Vec3Lanes {
        &self.ks
    }

    /// Each lane's unit shading normal, on the viewer's side.
    pub fn normals(&self) -> &Vec3Lanes {
        &self.n
    }

    /// Per lane, the fraction of a unit light from direction `l` reflected
    /// towards the lane's viewer: `kd · n·l + ks · lobe`, zero where `n·l ≤ 0`.
    #[inline]
    pub fn reflect(&self, l: &Vec3Lanes) -> Vec3Lanes {
        let specular = lanes::from_bits(self.specular);
        let lobe = |n_dot_l| self.specular_lobe(&self.n, l, n_dot_l);
        phong_reflection(&self.kd, &self.ks, specular, &self.n, l, lobe)
    }

    /// Per lane, the physical BRDF times the cosine for light from the unit
    /// direction `l`: [`PhongMaterial::brdf_cos`] where the lane has a
    /// specular term, [`PhongMaterial::brdf_cos_diffuse`] elsewhere, bit for
    /// bit; zero where `n·l ≤ 0`.
    #[inline]
    pub fn brdf_cos(&self, l: &Vec3Lanes) -> Vec3Lanes {
        let n_dot_l = self.n.dot(l);
        let diffuse = self.kd.scale(F32Lanes::splat(std::f32::consts::FRAC_1_PI));
        let f = if self.specular == 0 {
            diffuse
        } else {
            let lobe = self.specular_lobe(&self.n, l, n_dot_l);
            let norm =
                lanes::from_fn(|k| self.materials[k].map_or(0.0, |m| m.lobe_normalisation()));
            let glossy = diffuse + self.ks.scale(norm).scale(lobe);
            Vec3Lanes::select(lanes::from_bits(self.specular), &glossy, &diffuse)
        };
        let zero = Vec3Lanes::default();
        Vec3Lanes::select(lanes::le(n_dot_l, F32Lanes::ZERO), &zero, &f.scale(n_dot_l))
    }

    /// Lane `k`'s material, if the lane is set.
    pub fn material(&self, k: usize) -> Option<&'a PhongMaterial> {
        self.materials[k]
    }

    /// Each lane's specular lobe (unset lanes a Phong lobe of exponent 0),
    /// for [`crate::sample_specular_at`] and [`crate::specular_pdf_at`].
    pub fn lobes(&self) -> Lobes<F32Lanes> {
        Lobes {
            shininess: self.shininess,
            blinn: lanes::from_bits(self.blinn),
        }
    }

    /// Each lane's unit direction to the viewer.
    pub fn viewers(&self) -> &Vec3Lanes {
        &self.v
    }

    /// [`PhongMaterial::specular_lobe`] per lane.
    #[inline]
    fn specular_lobe(&self, n: &Vec3Lanes, l: &Vec3Lanes, n_dot_l: F32Lanes) -> F32Lanes {
        let cosine = phong_cosine(n, l, &self.v, n_dot_l);
        let lobe = lobe_of_cosine(cosine, |cosine| self.powers(cosine));
        let one_by_one = self.specular & !self.lane_lobes;
        if one_by_one == 0 {
            return lobe;
        }
        let n_dot_l = n_dot_l.to_array();
        let mut lobe = lobe.to_array();
        for (k, lobe) in lobe.iter_mut().enumerate() {
            if let Some(m) = self.materials[k].filter(|_| one_by_one >> k & 1 == 1) {
                *lobe = m.specular_lobe(self.n.lane(k), l.lane(k), self.v.lane(k), n_dot_l[k]);
            }
        }
        F32Lanes::new(lobe)
    }

    /// `base^exponent` per lane by the binary exponentiation of [`powi`]: bit
    /// `b` of a lane's exponent multiplies its result by `base^(2^b)`, in the
    /// scalar loop's order; the squarings past a lane's top bit leave its
    /// result alone.
    #[inline]
    fn powers(&self, mut base: F32Lanes) -> F32Lanes {
        let bits = 32 - self.exponent_top.leading_zeros() as usize;
        let bit = |b: usize| lanes::from_bits(self.exponent_bits[b]);
        let mut result = bit(0).select(base, F32Lanes::ONE);
        for b in 1..bits {
            base = base * base;
            result = bit(b).select(result * base, result);
        }
        result
    }
}

/// The exponent of `material`'s lobe where it is taken in lanes: a Phong lobe
/// with a non-negative integral exponent (else the lane is taken alone).
fn lane_exponent(material: &PhongMaterial) -> Option<u32> {
    let in_lanes = material.lobe == SpecularLobe::Phong
        && material.integral_exponent()
        && material.shininess >= 0.0;
    in_lanes.then_some(material.shininess as u32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::powi;

    #[test]
    fn powers_give_the_bits_of_powi_for_each_lanes_exponent() {
        let material = PhongMaterial::new(Vec3::ONE, 1.0);
        let mut lanes = PhongLanes::default();
        let exponents = [0u32, 1, 2, 3, 16, 22, 120, 1024];
        for (k, &e) in exponents.iter().enumerate() {
            lanes.set(k, &material, Vec3::ONE, Vec3::ONE, Vec3::Y, Vec3::Y, true);
            lanes.set_exponent(1 << k, e);
        }
        for base in [0.0f32, 0.3, 0.5, 0.9, 0.99999, 1.0] {
            let out = lanes.powers(F32Lanes::splat(base)).to_array();
            for (k, &e) in exponents.iter().enumerate() {
                let expected = powi(base, e as i32, 1.0);
                assert_eq!(out[k].to_bits(), expected.to_bits(), "{base}^{e}");
            }
        }
    }

    #[test]
    fn points_in_lanes_reflect_the_scalar_bits() {
        let materials: Vec<PhongMaterial> = [1.0, 16.0, 22.0, 120.0, 7.5, 2000.0, 0.0, 40.0]
            .iter()
            .enumerate()
            .map(|(k, &s)| PhongMaterial {
                lobe: if k == 7 {
                    SpecularLobe::BlinnPhong
                } else {
                    SpecularLobe::Phong
                },
                ..PhongMaterial::new(Vec3::new(0.7, 0.5, 0.2), s)
            })
            .collect();
        let unit = |a: f32, b: f32| Vec3::new(a.sin() * b.cos(), a.cos(), a.sin() * b.sin());
        for batch in 0..40 {
            let f = batch as f32;
            let mut lanes = PhongLanes::default();
            let mut points = Vec::new();
            for k in 0..LANES {
                let (m, g) = (&materials[(k + batch) % materials.len()], k as f32);
                let kd = Vec3::new(0.1 * g, 0.9 - 0.1 * g, 0.5);
                let ks = if batch % 3 == 0 {
                    Vec3::ZERO
                } else {
                    Vec3::splat(0.3)
                };
                let n = unit(0.2 * f + g, 0.7 * g);
                let v = unit(0.3 * f - g, 1.1 * g + f);
                let specular = (batch + k) % 4 != 0;
                if (batch + 2 * k) % 7 != 0 {
                    lanes.set(k, m, kd, ks, n, v, specular);
                    points.push((k, m, kd, ks, n, v, specular));
                }
            }
            // Directions around each lane's horizon and mirror peak, a zero and a NaN.
            let l: [Vec3; LANES] = std::array::from_fn(|k| match (batch, k) {
                (0, 0) => Vec3::ZERO,
                (1, 1) => Vec3::new(f32::NAN, 1.0, 0.0),
                _ => unit(0.37 * (k + LANES * batch) as f32 - 1.5, 0.4 * f),
            });
            let out = lanes.reflect(&Vec3Lanes::from_lanes(l));
            for (k, m, kd, ks, n, v, specular) in points {
                let scalar = if specular {
                    m.reflect(kd, ks, n, l[k], v)
                } else {
                    m.reflect_diffuse(kd, n, l[k])
                };
                let lane = out.lane(k);
                for axis in 0..3 {
                    assert!(
                        lane[axis].to_bits() == scalar[axis].to_bits()
                            || (lane[axis].is_nan() && scalar[axis].is_nan()),
                        "batch {batch} lane {k} s={}: {lane} against {scalar}",
                        m.shininess
                    );
                }
            }
        }
    }

    /// Lanes set together with one material reflect what lanes set one by one do.
    #[test]
    fn lanes_made_together_are_lanes_set_one_by_one() {
        let unit = |a: f32| Vec3::new(a.sin(), a.cos(), 0.3 * a).normalize();
        let shiny = PhongMaterial::new(Vec3::new(0.7, 0.5, 0.2), 22.0);
        let kd: [Vec3; LANES] = std::array::from_fn(|k| Vec3::new(0.1 * k as f32, 0.5, 0.9));
        let ks: [Vec3; LANES] = std::array::from_fn(|k| Vec3::splat(0.05 * k as f32));
        let n: [Vec3; LANES] = std::array::from_fn(|k| unit(0.1 * k as f32));
        let v: [Vec3; LANES] = std::array::from_fn(|k| unit(0.2 - 0.05 * k as f32));
        let (lanes, specular) = (0b1011_0110, 0b0011_0100);
        let x = |a: [Vec3; LANES]| Vec3Lanes::from_lanes(a);
        let together =
            PhongLanes::of_lanes(lanes, &shiny, &x(kd), &x(ks), &x(n), &x(v), specular | 1);
        let mut one_by_one = PhongLanes::default();
        for k in lanes::each_set(lanes) {
            one_by_one.set(k, &shiny, kd[k], ks[k], n[k], v[k], specular >> k & 1 == 1);
        }
        assert_eq!(together.specular_lanes(), one_by_one.specular_lanes());
        assert_eq!(together.specular_lanes(), 0b0011_0100);
        let l = x(std::array::from_fn(|k| unit(0.15 * k as f32 + 0.02)));
        let (a, b) = (together.reflect(&l), one_by_one.reflect(&l));
        for k in 0..LANES {
            assert_eq!(
                a.lane(k).to_array().map(f32::to_bits),
                b.lane(k).to_array().map(f32::to_bits)
            );
        }
        assert!(a.lane(2) != Vec3::ZERO, "lit lanes reflect something");
    }
}
