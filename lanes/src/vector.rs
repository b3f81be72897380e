//! [`Vector3<F>`]: a 3-vector over any [`Float`], glam's [`Vec3`] rounding in
//! every lane.
//!
//! Each method performs glam's scalar operations in glam's order:
//! `a.dot(b)` is `(a.x·b.x + a.y·b.y) + a.z·b.z`, `a × b` is
//! `(a.y·b.z − b.y·a.z, …)`, and nothing is fused into a multiply-add. So
//! `Vector3<f32>` gives `Vec3`'s bits, and each lane of a `Vector3` of lanes
//! gives them too. The `*_splat` forms take one `Vec3` for every lane; they
//! round as the plain forms do with [`Vector3::splat`].

use crate::float::Float;
use glam::Vec3;

/// A 3-vector of [`Float`]s: one vector, or one per lane.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Vector3<F> {
    pub x: F,
    pub y: F,
    pub z: F,
}

impl From<Vec3> for Vector3<f32> {
    #[inline(always)]
    fn from(v: Vec3) -> Self {
        Self {
            x: v.x,
            y: v.y,
            z: v.z,
        }
    }
}

impl From<Vector3<f32>> for Vec3 {
    #[inline(always)]
    fn from(v: Vector3<f32>) -> Self {
        Vec3::new(v.x, v.y, v.z)
    }
}

impl<F: Float> Vector3<F> {
    #[inline(always)]
    pub fn new(x: F, y: F, z: F) -> Self {
        Self { x, y, z }
    }

    /// `v` in every lane.
    #[inline(always)]
    pub fn splat(v: Vec3) -> Self {
        Self::new(F::splat(v.x), F::splat(v.y), F::splat(v.z))
    }

    /// `self · other`, as [`Vec3::dot`] rounds it.
    #[inline(always)]
    pub fn dot(&self, other: &Self) -> F {
        self.x * other.x + self.y * other.y + self.z * other.z
    }

    /// `self · v` for the same `v` in every lane.
    #[inline(always)]
    pub fn dot_splat(&self, v: Vec3) -> F {
        self.dot(&Self::splat(v))
    }

    /// `self × other`, as [`Vec3::cross`] rounds it.
    #[inline(always)]
    pub fn cross(&self, other: &Self) -> Self {
        Self::new(
            self.y * other.z - other.y * self.z,
            self.z * other.x - other.z * self.x,
            self.x * other.y - other.x * self.y,
        )
    }

    /// `self × v` for the same `v` in every lane.
    #[inline(always)]
    pub fn cross_splat(&self, v: Vec3) -> Self {
        self.cross(&Self::splat(v))
    }

    /// `v × other` for the same `v` in every lane.
    #[inline(always)]
    pub fn splat_cross(v: Vec3, other: &Self) -> Self {
        Self::splat(v).cross(other)
    }

    /// Each lane times its own scalar, as `Vec3 * f32`.
    #[inline(always)]
    pub fn scale(&self, s: F) -> Self {
        Self::new(self.x * s, self.y * s, self.z * s)
    }

    /// `s · v` per lane, as `f32 * Vec3`.
    #[inline(always)]
    pub fn scaled_splat(v: Vec3, s: F) -> Self {
        Self::splat(v).scale(s)
    }

    /// `v * other` per component for the same `v` in every lane, as `Vec3 * Vec3`.
    #[inline(always)]
    pub fn scaled_splat_lanes(v: Vec3, other: &Self) -> Self {
        let v = Self::splat(v);
        Self::new(v.x * other.x, v.y * other.y, v.z * other.z)
    }

    /// `self / s` for the same `s` in every lane, as `Vec3 / f32`.
    #[inline(always)]
    pub fn div_splat(&self, s: f32) -> Self {
        let s = F::splat(s);
        Self::new(self.x / s, self.y / s, self.z / s)
    }

    /// `self − v` for the same `v` in every lane.
    #[inline(always)]
    pub fn sub_splat(&self, v: Vec3) -> Self {
        *self - Self::splat(v)
    }

    /// `v − other` for the same `v` in every lane.
    #[inline(always)]
    pub fn splat_sub(v: Vec3, other: &Self) -> Self {
        Self::splat(v) - *other
    }

    /// `v + other` for the same `v` in every lane.
    #[inline(always)]
    pub fn splat_add(v: Vec3, other: &Self) -> Self {
        Self::splat(v) + *other
    }

    /// Each component's magnitude, as [`Vec3::abs`].
    #[inline(always)]
    pub fn abs(&self) -> Self {
        Self::new(self.x.abs(), self.y.abs(), self.z.abs())
    }

    /// The largest component, as [`Vec3::max_element`]: `x.max(y.max(z))`.
    #[inline(always)]
    pub fn max_element(&self) -> F {
        self.x.max(self.y.max(self.z))
    }

    /// Per lane, `if_true` where `mask` holds, else `if_false`.
    #[inline(always)]
    pub fn select(mask: F::Mask, if_true: &Self, if_false: &Self) -> Self {
        Self::new(
            F::select(mask, if_true.x, if_false.x),
            F::select(mask, if_true.y, if_false.y),
            F::select(mask, if_true.z, if_false.z),
        )
    }

    /// [`Vec3::try_normalize`] per lane: the unit vectors, and the mask of the
    /// lanes where it succeeds (`1/length` finite and positive).
    #[inline(always)]
    pub fn try_normalize(&self) -> (Self, F::Mask) {
        let rcp = F::ONE / self.dot(self).sqrt();
        let ok = rcp.is_finite() & rcp.gt(F::ZERO);
        (self.scale(rcp), ok)
    }

    /// [`Vec3::normalize`] per lane: `self · (1/length)`, rounded as glam rounds it.
    #[inline(always)]
    pub fn normalize(&self) -> Self {
        self.scale(F::ONE / self.dot(self).sqrt())
    }

    /// Two unit vectors that make an orthonormal basis with the unit `self`,
    /// as glam's `Vec3::any_orthonormal_pair` makes them, bit for bit: the
    /// branch-free basis of Duff et al., "Building an Orthonormal Basis,
    /// Revisited" (JCGT 6(1), 2017).
    #[inline(always)]
    pub fn any_orthonormal_pair(&self) -> (Self, Self) {
        let sign = self.z.signum();
        let a = -(F::ONE / (sign + self.z));
        let b = self.x * self.y * a;
        (
            Self::new(
                F::ONE + sign * self.x * self.x * a,
                sign * b,
                -(sign * self.x),
            ),
            Self::new(b, sign + self.y * self.y * a, -self.y),
        )
    }

    /// The lanes equal to zero in every component (as `Vec3 == Vec3::ZERO`).
    #[inline(always)]
    pub fn is_zero(&self) -> F::Mask {
        self.x.eq(F::ZERO) & self.y.eq(F::ZERO) & self.z.eq(F::ZERO)
    }
}

impl<F: Float> std::ops::Add for Vector3<F> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl<F: Float> std::ops::Sub for Vector3<F> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

/// Component by component, as glam's `Vec3 * Vec3` (a colour's filter).
impl<F: Float> std::ops::Mul for Vector3<F> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self::new(self.x * o.x, self.y * o.y, self.z * o.z)
    }
}

impl<F: Float> std::ops::Neg for Vector3<F> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self::new(-self.x, -self.y, -self.z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{F32Lanes, LANES};

    /// The basis is glam's, bit for bit, in one lane and in many: on every
    /// axis, either side of z = 0 (the sign's switch, −0 included) and at
    /// random.
    #[test]
    fn orthonormal_pairs_are_glams_in_every_lane() {
        let normals: [Vec3; LANES] = std::array::from_fn(|k| match k {
            0 => Vec3::Z,
            1 => -Vec3::Z,
            2 => Vec3::X,
            3 => Vec3::new(0.6, 0.8, -0.0),
            4 => Vec3::new(0.0, -1.0, -1e-7).normalize(),
            _ => {
                let a = 0.9 * k as f32;
                Vec3::new(a.sin(), (0.4 * k as f32).cos(), a.cos() - 0.3).normalize()
            }
        });
        let lanes = Vector3::new(
            F32Lanes::new(normals.map(|n| n.x)),
            F32Lanes::new(normals.map(|n| n.y)),
            F32Lanes::new(normals.map(|n| n.z)),
        );
        let (t, b) = lanes.any_orthonormal_pair();
        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
        for (k, n) in normals.iter().enumerate() {
            let (gt, gb) = n.any_orthonormal_pair();
            let (st, sb) = Vector3::new(n.x, n.y, n.z).any_orthonormal_pair();
            let lane = |v: &Vector3<F32Lanes>| {
                Vec3::new(v.x.to_array()[k], v.y.to_array()[k], v.z.to_array()[k])
            };
            assert_eq!(bits(Vec3::new(st.x, st.y, st.z)), bits(gt), "{n}");
            assert_eq!(bits(Vec3::new(sb.x, sb.y, sb.z)), bits(gb), "{n}");
            assert_eq!(bits(lane(&t)), bits(gt), "lane {k}");
            assert_eq!(bits(lane(&b)), bits(gb), "lane {k}");
        }
    }
}
