//! Samples of one area light in lanes, one sample a lane, in the course's
//! model.
//!
//! For N samples of an area light, the integrator sums, over the samples that
//! face the point, the Phong reflection of each unoccluded one (report section
//! 2.5). Sample by sample the work is a chain of dependent steps (the light
//! point, the direction and its square root, the Phong lobe, the shadow ray's
//! origin), each waiting on the last. [`LightSampleLanes`] runs the chain in
//! SIMD lanes ([`Vec3Lanes`]), each lane its own receiving point and light
//! point (the camera-sample lanes' points, or one point's samples in the
//! reference's lanes), and [`count_lanes`] counts them as the scalar path
//! counts them one by one. Every lane does the scalar path's operations in its
//! order, bit for bit (the tests compare). The intersection counts of
//! `--stats` are not: tested in lanes, a shape counts one test per ray in the
//! batch.

use crate::ShadingCounters;
use glint_geometry::lanes::{self, F32Lanes, Vec3Lanes};
use glint_lighting::AreaLight;

/// One sample of an area light per lane, seen from each lane's receiving point,
/// before its shadow ray: the light point, the (unnormalised) direction to it,
/// the reflection of a unit light from it, and the lanes (bit k for lane k) it
/// lights, shades (normalisable and above the surface) and needs a shadow ray
/// for (a non-zero reflection). The one kernel of a point's light samples in
/// lanes and of a pixel's camera samples' first hits in lanes.
pub(crate) struct LightSampleLanes {
    pub(crate) position: Vec3Lanes,
    pub(crate) towards: Vec3Lanes,
    pub(crate) reflected: Vec3Lanes,
    pub(crate) lit: u32,
    pub(crate) shaded: u32,
    pub(crate) traced: u32,
}

impl LightSampleLanes {
    /// Lane k: the point `(ux, uy)_k` of `light` seen from `receiver_k`, whose
    /// geometric normal on the viewer's side is `ng_k`; `reflect` gives the
    /// reflection of a unit light from unit directions. Only the lanes `used`.
    #[inline(always)]
    pub(crate) fn new(
        light: &AreaLight,
        (ux, uy): (F32Lanes, F32Lanes),
        receiver: &Vec3Lanes,
        ng: &Vec3Lanes,
        used: u32,
        reflect: impl FnOnce(&Vec3Lanes) -> Vec3Lanes,
    ) -> Self {
        let position = light.sample_points(ux, uy);
        let lit = used & lanes::bits(light.illuminates_lanes(&position, receiver));
        Self::at(position, receiver, ng, lit, reflect)
    }

    /// Lane k: the light point `position_k`, which shines on `receiver_k` in
    /// the lanes `lit` (a point light's position, on all it is asked about).
    #[inline(always)]
    pub(crate) fn at(
        position: Vec3Lanes,
        receiver: &Vec3Lanes,
        ng: &Vec3Lanes,
        lit: u32,
        reflect: impl FnOnce(&Vec3Lanes) -> Vec3Lanes,
    ) -> Self {
        let towards = position - *receiver;
        let (l, normalized) = towards.try_normalize();
        let reflected = reflect(&l);
        let above = lanes::bits(lanes::gt(l.dot(ng), F32Lanes::ZERO));
        let shaded = lit & lanes::bits(normalized) & above;
        let traced = shaded & !lanes::bits(reflected.is_zero());
        Self {
            position,
            towards,
            reflected,
            lit,
            shaded,
            traced,
        }
    }
}

/// Adds one chunk of light samples in lanes to the counts, as the scalar path
/// counts them one by one. Each argument is a set of lanes (bit k for lane k):
/// the lanes `used`, those whose light point shines on the point (`lit`),
/// which are shaded (`shaded`: their direction could be normalised and is
/// above the horizon; a lit lane that is not is counted below the surface, as
/// the scalar path counts a direction of no length), whose shadow ray is
/// traced, and those that evaluate a specular lobe when shaded.
pub(crate) fn count_lanes(
    counters: &mut ShadingCounters,
    used: u32,
    lit: u32,
    shaded: u32,
    traced: u32,
    specular: u32,
) {
    let ones = |bits: u32| u64::from(bits.count_ones());
    counters.light_skips.behind_light += ones(used & !lit);
    counters.light_skips.below_surface += ones(lit & !shaded);
    counters.specular_lobes += ones(shaded & specular);
    counters.light_skips.zero_brdf += ones(shaded & !traced);
    counters.light_shadow_rays += ones(traced);
}
