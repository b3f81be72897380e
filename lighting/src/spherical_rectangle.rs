//! Solid-angle sampling of a rectangle as seen from a point: the area-preserving
//! parametrisation of spherical rectangles of Ureña, Fajardo and King, "An
//! Area-Preserving Parametrization for Spherical Rectangles", EGSR 2013 (Computer
//! Graphics Forum 32(4)). Sampling a rectangular light by solid angle gives the
//! constant pdf `1/Ω` per unit solid angle instead of area sampling's `r²/(A·cosθ')`,
//! which is noisy for lights that are near or large.

use glam::{Vec2, Vec3};
use glint_geometry::lanes::{atan2_approx, sin_cos_approx, Float, Vector3};

/// The rectangle `corner + s·ex + t·ey`, s, t ∈ `[0, 1]`, (ex ⟂ ey) as seen from `reference`,
/// from one point (`F = f32`) or from each lane's (`F` lanes of them): one kernel
/// for both, each lane bit for bit the scalar rectangle. Its angles are the
/// polynomial [`atan2_approx`] and [`sin_cos_approx`] (within 1e-6 rad and 1e-7
/// of libm, and accurate relative to small results), one evaluation for all the
/// lanes where libm would take them one at a time; the accuracy tests below
/// hold as with libm's.
///
/// It is held in the paper's local frame: `reference` at the origin, x along `ex`, y
/// along `ey`, and the rectangle `[x0,x1]×[y0,y1]` in the plane at distance `z > 0`.
/// (The paper flips its normal so that its `z0 = -z < 0`; only `z` enters the formulas
/// below, so the reference point may be on either side.) All local lengths are divided
/// by the largest of `|x0|,|x1|,|y0|,|y1|,z`: angles are scale-invariant, and squares
/// of the scaled lengths can neither overflow nor underflow.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphericalRectangle<F: Float = f32> {
    corner: Vec3,
    ex: Vec3,
    ey: Vec3,
    x0: F,
    x1: F,
    y0: F,
    y1: F,
    z: F,
    /// `θ(x0)` and `θ(x1)` (see [`SphericalRectangle::sample`]).
    theta0: F,
    theta1: F,
    /// `Δ = ψ1 − ψ0` and `Σ = ψ0 + ψ1`, with `ψi = atan2(yi, z)`.
    delta: F,
    sigma: F,
    solid_angle: F,
}

/// Smallest argument allowed under a square root that is divided by.
const TINY: f32 = 1e-30;

impl SphericalRectangle {
    /// None if the edges are not perpendicular (|ex·ey| > 1e-4·|ex||ey|), zero-length,
    /// non-finite, or the reference point lies in the rectangle's plane (no solid angle:
    /// its distance to the plane is at most 1e-6·|corner − reference|, the rounding
    /// noise of f32) or the solid angle is not finite/positive.
    pub fn new(reference: Vec3, corner: Vec3, ex: Vec3, ey: Vec3) -> Option<Self> {
        let reference = Vector3::new(reference.x, reference.y, reference.z);
        Self::seen_from(&reference, corner, ex, ey)
            .and_then(|(rectangle, seen)| seen.then_some(rectangle))
    }

    /// The point on the rectangle for u ∈ `[0, 1]²`, distributed uniformly in solid
    /// angle ([`Self::sample_at`]).
    #[inline]
    pub fn sample(&self, u: Vec2) -> Vec3 {
        self.sample_at(u.x, u.y).into()
    }
}

impl<F: Float> SphericalRectangle<F> {
    /// The rectangle as seen from each lane's `reference`, and the lanes that
    /// see it ([`SphericalRectangle::new`] gives `Some` there); `None` if it is
    /// no rectangle (its edges not perpendicular, zero-length or not finite).
    #[inline(always)]
    pub fn seen_from(
        reference: &Vector3<F>,
        corner: Vec3,
        ex: Vec3,
        ey: Vec3,
    ) -> Option<(Self, F::Mask)> {
        let (w, h) = (ex.length(), ey.length());
        if !(w > 0.0 && h > 0.0 && w.is_finite() && h.is_finite()) {
            return None;
        }
        let (xa, ya) = (ex / w, ey / h);
        if xa.dot(ya).abs() > 1e-4 {
            return None;
        }
        let d = Vector3::splat_sub(corner, reference);
        let finite = d.x.is_finite() & d.y.is_finite() & d.z.is_finite();
        let (x0, y0) = (d.dot_splat(xa), d.dot_splat(ya));
        let z = d.dot_splat(xa.cross(ya).normalize()).abs();
        let (x1, y1) = (x0 + F::splat(w), y0 + F::splat(h));
        let off_plane = !z.le(F::splat(1e-6) * d.dot(&d).sqrt());
        let seen = finite & off_plane & x1.is_finite() & y1.is_finite();
        let inv = F::ONE / x0.abs().max(x1.abs()).max(y0.abs()).max(y1.abs()).max(z);
        let (x0, x1, y0, y1, z) = (x0 * inv, x1 * inv, y0 * inv, y1 * inv, z * inv);
        // θ(x) = F(x,y1) − F(x,y0) as one atan2 (the argument of a complex product),
        // with `y1·R0 − y0·R1` rewritten for y0, y1 of one sign, where it would cancel.
        let theta = |x: F| {
            let (rr, yy) = (x * x + z * z, y0 * y1);
            let (r0, r1) = ((rr + y0 * y0).sqrt(), (rr + y1 * y1).sqrt());
            let cross = F::select_with(
                yy.gt(F::ZERO),
                || (y1 - y0) * (y1 + y0) * rr / (y1 * r0 + y0 * r1),
                || y1 * r0 - y0 * r1,
            );
            atan2_approx(x * z * cross, z * z * r0 * r1 + x * x * yy)
        };
        let (theta0, theta1) = (theta(x0), theta(x1));
        let foot_inside = x0.le(F::ZERO) & F::ZERO.le(x1) & y0.le(F::ZERO) & F::ZERO.le(y1);
        let solid_angle = F::select_with(
            foot_inside,
            // The foot of the perpendicular is inside: Ω = θ1 − θ0 is a sum of four
            // corner terms of one sign.
            || theta1 - theta0,
            // Outside, those terms would cancel: two triangles instead, each by Van
            // Oosterom & Strackee (IEEE Trans. Biomed. Eng. 30(2), 1983): tan(Ω_t/2) =
            // |a·(b×c)| / (abc + (a·b)c + (a·c)b + (b·c)a). Both triple products are
            // z·w·h exactly, so small Ω keeps its digits (the paper's Σγ − 2π cancels
            // to nothing in f32 below ~1e-5 sr).
            || {
                let v = |x, y| Vector3::new(x, y, z);
                let (v00, v10, v11, v01) = (v(x0, y0), v(x1, y0), v(x1, y1), v(x0, y1));
                let triple = z * (x1 - x0) * (y1 - y0);
                let triangle = |a: Vector3<F>, b: Vector3<F>, c: Vector3<F>| {
                    let length = |v: &Vector3<F>| v.dot(v).sqrt();
                    let (la, lb, lc) = (length(&a), length(&b), length(&c));
                    let den = la * lb * lc + a.dot(&b) * lc + a.dot(&c) * lb + b.dot(&c) * la;
                    F::splat(2.0) * atan2_approx(triple, den)
                };
                triangle(v00, v10, v11) + triangle(v00, v11, v01)
            },
        );
        let seen = seen & solid_angle.gt(F::ZERO) & solid_angle.is_finite();
        let delta = atan2_approx(z * (y1 - y0), z * z + y0 * y1);
        let sigma = atan2_approx(y0, z) + atan2_approx(y1, z);
        let rectangle = Self {
            corner,
            ex,
            ey,
            x0,
            x1,
            y0,
            y1,
            z,
            theta0,
            theta1,
            delta,
            sigma,
            solid_angle,
        };
        Some((rectangle, seen))
    }

    /// Solid angle Ω subtended (steradians); the sampling pdf is 1/Ω per unit solid angle.
    ///
    /// Ω = F(x1,y1) − F(x0,y1) − F(x1,y0) + F(x0,y0) with the corner terms
    /// `F(x,y) = atan2(x·y, z·√(x²+y²+z²))`, summed directly when they all have one sign
    /// (the foot of the perpendicular from the reference lies inside the rectangle),
    /// otherwise as the two triangles `v00 v10 v11`, `v00 v11 v01` by Van Oosterom and
    /// Strackee's formula. Accurate to ~1e-6 relative from tiny solid angles to near 2π,
    /// given the plane distance `z`; at grazing angles Ω ∝ z also carries the f32
    /// rounding of `z` itself, ~1e-7·|corner − reference|/z relative.
    pub fn solid_angle(&self) -> F {
        self.solid_angle
    }

    /// The point on the rectangle for `(ux, uy)` ∈ `[0, 1]²`, distributed uniformly
    /// in solid angle; the map is continuous and area preserving (strata of
    /// `[0, 1]²` map to equal solid angles).
    ///
    /// `ux` moves along `ex` and `uy` along `ey`, both monotonically: `(0,0)` maps to
    /// `corner`, `(1,0)` to `corner + ex`, `(0,1)` to `corner + ey` and `(1,1)` to the
    /// opposite corner; the columns `ux = const` are the segments `s = const`.
    ///
    /// In the paper's frame, the part `[x0,x]×[y0,y1]` subtends `θ(x) − θ(x0)` with
    /// `θ(x) = F(x,y1) − F(x,y0)` (see [`Self::solid_angle`]); θ is the paper's
    /// `au − π = γ0' + γ1' − π`, the angles at the moving edge, and with its
    /// `cu = x/√(x²+z²)`, `b0 = −y0/√(y0²+z²)`, `b1 = y1/√(y1²+z²)`,
    /// `θ = asin(cu·b0) + asin(cu·b1)`.
    /// 1. `θ = θ0 + ux·(θ1 − θ0)`. The paper inverts this as `cu = sign(fu)/√(fu²+b0²)`,
    ///    `fu = (cos(au)·b0 − b1)/sin(au)`, i.e. `cu = sinθ / √(b0² + b1² + 2b0b1·cosθ)`,
    ///    then `x = z·cu/√(1 − cu²)`. With `ψi = atan2(yi, z)`, `Δ = ψ1 − ψ0` and
    ///    `Σ = ψ0 + ψ1` that is, without the cancellation in `1 − cu²` at grazing
    ///    angles nor the division by `sin(au)`:
    ///    `x/z = sinθ / (2·√(sin((Δ−θ)/2)·sin((Δ+θ)/2)·cos((θ+Σ)/2)·cos((θ−Σ)/2)))`,
    ///    every factor positive for `|θ| < Δ`.
    /// 2. Along the line at `x`, at distance `d = √(x²+z²)`, the angle subtended from
    ///    `y0` to `y` grows as `h(y) = y/√(y²+d²)`, so `h` is the lerp of `h0`, `h1` by
    ///    `uy` and `y = d·h/√((1−h)(1+h))`; `1 ∓ h` are lerped from end values computed
    ///    without cancellation, so `y` keeps its digits where `h → ±1`.
    ///
    /// Square roots are guarded and `x`, `y` clamped to the rectangle, so the result is
    /// always a finite point of the rectangle (in the lanes that see it).
    #[inline(always)]
    pub fn sample_at(&self, ux: F, uy: F) -> Vector3<F> {
        let (x0, x1, y0, y1, z) = (self.x0, self.x1, self.y0, self.y1, self.z);
        // Unlike `clamp`, also turns NaN into a bound (0).
        let unit = |t: F| F::select(t.gt(F::ZERO), t.min(F::ONE), F::ZERO);
        let (ux, uy) = (unit(ux), unit(uy));
        let theta = self.theta0 + ux * (self.theta1 - self.theta0);
        let (dl, sg, half) = (self.delta, self.sigma, F::splat(0.5));
        let (sin, cos) = (|a| sin_cos_approx(a).0, |a| sin_cos_approx(a).1);
        let prod = sin(half * (dl - theta))
            * sin(half * (dl + theta))
            * cos(half * (theta + sg))
            * cos(half * (theta - sg));
        let tiny = F::splat(TINY);
        let x = (z * sin(theta) / (F::splat(2.0) * prod.max(tiny).sqrt()))
            .max(x0)
            .min(x1);
        let d2 = x * x + z * z;
        // h(y) = y/√(y²+d²) is lerped for its digits near 0, and 1 ∓ h (computed
        // without cancellation) for theirs near ±1.
        let (m0, m1) = ((y0 * y0 + d2).sqrt(), (y1 * y1 + d2).sqrt());
        let one_minus_h =
            |y: F, m: F| F::select_with(y.gt(F::ZERO), || d2 / (m * (m + y)), || F::ONE - y / m);
        let lerp = |a: F, b: F| (F::ONE - uy) * a + uy * b;
        let h = y0 / m0 + uy * (y1 / m1 - y0 / m0);
        let p = lerp(one_minus_h(y0, m0), one_minus_h(y1, m1)); // 1 − h
        let q = lerp(one_minus_h(-y0, m0), one_minus_h(-y1, m1)); // 1 + h
        let y = (h * d2.sqrt() / (p * q).max(tiny).sqrt()).max(y0).min(y1);
        let s = unit((x - x0) / (x1 - x0));
        let t = unit((y - y0) / (y1 - y0));
        Vector3::splat(self.corner)
            + Vector3::scaled_splat(self.ex, s)
            + Vector3::scaled_splat(self.ey, t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{DVec3, EulerRot, Quat};

    /// `(reference, corner, ex, ey)`.
    type Case = (Vec3, Vec3, Vec3, Vec3);
    /// The rectangle `[x0,x0+w]×[y0,y0+h]` at height `z` in the frame centred at `r`
    /// and rotated by the Euler angles `rot`.
    fn case(r: [f32; 3], rot: [f32; 3], [x0, y0, w, h, z]: [f32; 5]) -> Case {
        let (r, q) = (
            Vec3::from(r),
            Quat::from_euler(EulerRot::XYZ, rot[0], rot[1], rot[2]),
        );
        (
            r,
            r + q * Vec3::new(x0, y0, z),
            q * (w * Vec3::X),
            q * (h * Vec3::Y),
        )
    }
    fn moderate() -> Vec<Case> {
        vec![
            case(
                [0.1, 0.2, 0.3],
                [0.3, -0.5, 1.1],
                [-0.4, -0.3, 1.5, 0.8, 0.7],
            ), // above
            case(
                [-1.0, 0.5, 2.0],
                [1.2, 0.4, -0.2],
                [-0.5, -0.5, 1.0, 1.0, 0.15],
            ), // close
            case(
                [0.0, -1.0, 0.5],
                [-0.7, 2.0, 0.1],
                [0.3, -1.2, 0.6, 2.0, -0.5],
            ), // behind
        ]
    }
    fn extreme() -> Vec<Case> {
        let (o, r) = ([0.0; 3], [0.9, -0.1, 0.5]);
        vec![
            case(o, [0.2, 0.3, 0.4], [30.0, -20.0, 2.0, 1.0, 40.0]), // far, 5e-4 sr
            case(o, r, [-5e-4, 2e-4, 1e-3, 1e-3, 1.0]),              // tiny, 1e-6 sr
            case(o, r, [-5e-4, 2e-4, 1e-3, 1e-3, -30.0]),            // 1e-9 sr
            case(
                [2.0, 1.0, 0.0],
                [0.1, 0.0, 0.0],
                [0.5, -0.5, 1.0, 1.0, 1e-3],
            ), // grazing
            case(
                [2.0, 1.0, 0.0],
                [0.1, 0.0, 0.0],
                [0.5, -0.5, 1.0, 1.0, 1e-5],
            ),
            case(o, [0.2, 0.3, 0.4], [800.0, 1000.0, 2.0, 1.0, 3.0]), // grazing, far
            case(o, [0.0; 3], [100.0, -0.5, 1.0, 1.0, 1e-2]),         // grazing, 1e-8 sr
            case(
                [0.5, 0.5, 0.0],
                [0.0, 0.3, 0.0],
                [-0.5, -0.5, 1.0, 1.0, 1e-3],
            ), // ≈ 2π
            case(
                [0.5, 0.5, 0.0],
                [0.0, 0.3, 0.0],
                [-0.5, -0.5, 1.0, 1.0, 1e-5],
            ),
            case(o, [0.0; 3], [-500.0, -1e-3, 1e3, 2e-3, 1e-2]), // long thin strip
            case([1e4; 3], [0.4, 0.5, 0.6], [-0.3, -0.2, 1.0, 0.5, 0.2]),
            case([1.0; 3], r, [-0.3e15, -0.2e15, 1e15, 0.5e15, 0.2e15]),
            case(o, r, [-0.3e-15, -0.2e-15, 1e-15, 0.5e-15, 0.2e-15]),
        ]
    }
    fn rect(c @ &(r, corner, ex, ey): &Case) -> SphericalRectangle {
        SphericalRectangle::new(r, corner, ex, ey).unwrap_or_else(|| panic!("{c:?} rejected"))
    }
    fn dv(v: Vec3) -> DVec3 {
        v.as_dvec3()
    }
    /// f64 local coordinates `[x, y, |z|]` of `p` in the frame of `ex`, `ey`.
    fn local(&(r, _, ex, ey): &Case, p: Vec3) -> [f64; 3] {
        let (xa, ya, d) = (dv(ex).normalize(), dv(ey).normalize(), dv(p) - dv(r));
        [d.dot(xa), d.dot(ya), d.dot(xa.cross(ya)).abs()]
    }
    /// `F(x,y)`: the solid angle of `[0,x]×[0,y]` at height `z`, signed by `xy`.
    fn f(x: f64, y: f64, z: f64) -> f64 {
        (x * y / (z * (x * x + y * y + z * z).sqrt())).atan()
    }

    /// Ω = F(x1,y1) − F(x0,y1) − F(x1,y0) + F(x0,y0), in f64 from the f32 inputs.
    fn closed_form(c: &Case) -> f64 {
        let [x0, y0, z] = local(c, c.1);
        let (x1, y1) = (x0 + dv(c.2).length(), y0 + dv(c.3).length());
        f(x1, y1, z) - f(x0, y1, z) - f(x1, y0, z) + f(x0, y0, z)
    }

    #[test]
    fn solid_angle_matches_closed_form() {
        for c in moderate().iter().chain(&extreme()) {
            let (got, want) = (rect(c).solid_angle() as f64, closed_form(c));
            let rel = (got - want).abs() / want;
            // Near the plane Ω ∝ z, whose f32 rounding is ~1e-7·|corner − reference|.
            let tol = 1e-5 + 1e-7 * (dv(c.1) - dv(c.0)).length() / local(c, c.1)[2];
            assert!(
                rel < tol,
                "{c:?}: Ω {got} vs closed form {want} (rel {rel:e})"
            );
        }
    }

    /// Midpoint quadrature over the rectangle of (∫ g dω, Ω), dω = |n·r|/|r|³ dA.
    fn quadrature(&(r, c, ex, ey): &Case, g: impl Fn(DVec3) -> f64) -> (f64, f64) {
        let (k, n) = (1000, dv(ex).cross(dv(ey)));
        let (mut sum, mut omega) = (0.0, 0.0);
        for i in 0..k * k {
            let (s, t) = (
                ((i / k) as f64 + 0.5) / k as f64,
                ((i % k) as f64 + 0.5) / k as f64,
            );
            let d = dv(c) + s * dv(ex) + t * dv(ey) - dv(r);
            let dw = n.dot(d).abs() / d.length().powi(3) / (k * k) as f64;
            (sum, omega) = (sum + g(d.normalize()) * dw, omega + dw);
        }
        (sum, omega)
    }

    #[test]
    fn stratified_samples_average_to_the_solid_angle_mean() {
        let g = |w: DVec3| 1.0 + w.x + 0.5 * w.y * w.y + 0.3 * (4.0 * w.z).sin();
        for c in &moderate() {
            let sr = rect(c);
            let (integral, omega) = quadrature(c, g);
            let rel = (sr.solid_angle() as f64 - omega).abs() / omega;
            assert!(
                rel < 1e-4,
                "{c:?}: Ω {} vs quadrature {omega}",
                sr.solid_angle()
            );
            let (want, k) = (integral / omega, 256);
            let (mut solid, mut area) = (0.0, 0.0);
            for i in 0..k * k {
                let u = (Vec2::new((i / k) as f32, (i % k) as f32) + 0.5) / k as f32;
                solid += g((dv(sr.sample(u)) - dv(c.0)).normalize()) / (k * k) as f64;
                let by_area = c.1 + u.x * c.2 + u.y * c.3;
                area += g((dv(by_area) - dv(c.0)).normalize()) / (k * k) as f64;
            }
            let rel = (solid - want).abs() / want.abs();
            assert!(rel < 2e-4, "{c:?}: mean {solid} vs {want} (rel {rel:e})");
            // The test can tell: sampling by area misses by far more than the tolerance.
            assert!(
                (area - want).abs() / want.abs() > 1e-2,
                "{c:?}: {area} vs {want}"
            );
        }
    }

    #[test]
    fn jacobian_is_constant() {
        // Solid angle of the spherical quad `p` (two Van Oosterom–Strackee triangles).
        let quad = |p: [DVec3; 4]| {
            let tri = |a: DVec3, b: DVec3, c: DVec3| {
                let den = 1.0 + a.dot(b) + a.dot(c) + b.dot(c);
                2.0 * a.dot(b.cross(c)).abs().atan2(den)
            };
            tri(p[0], p[1], p[2]) + tri(p[0], p[2], p[3])
        };
        for c in &moderate() {
            let (sr, k) = (rect(c), 32);
            let want = sr.solid_angle() as f64 / (k * k) as f64;
            let dir = |i: usize, j: usize| {
                let u = Vec2::new(i as f32, j as f32) / k as f32;
                (dv(sr.sample(u)) - dv(c.0)).normalize()
            };
            for (i, j) in (1..k - 1).flat_map(|i| (1..k - 1).map(move |j| (i, j))) {
                let cell = quad([dir(i, j), dir(i + 1, j), dir(i + 1, j + 1), dir(i, j + 1)]);
                let rel = (cell - want).abs() / want;
                assert!(rel < 1e-2, "{c:?}: cell ({i}, {j}) is off by {rel:e}");
            }
        }
    }

    /// The stronger check, at grazing angles too: the exact conditional CDFs, in f64,
    /// of the sampled point give back `u`: `u.x = (θ(x) − θ(x0))/Ω` with
    /// `θ(x) = F(x,y1) − F(x,y0)`, and `u.y = (h(y) − h(y0))/(h(y1) − h(y0))`.
    #[test]
    fn exact_cdfs_invert_the_map() {
        // Extreme cases: within 1e-5·|x| of the foot at z = 1e-5, or at x = 500 along a
        // strip at z = 1e-2, the CDFs move by ~1e-3 between neighbouring f32 positions.
        let cases = moderate().into_iter().map(|c| (c, 1e-5));
        for (c, tol) in cases.chain(extreme().into_iter().map(|c| (c, 5e-3))) {
            let sr = rect(&c);
            let [x0, y0, z] = local(&c, c.1);
            let (x1, y1) = (x0 + dv(c.2).length(), y0 + dv(c.3).length());
            let theta = |x| f(x, y1, z) - f(x, y0, z);
            // Below ~3e-4 sr the f32 resolution of θ limits u.x; at 1e4 from the origin,
            // f32 positions are 1e-3 apart, too coarse for a unit rectangle.
            if sr.solid_angle() < 3e-4 || c.0.length() > 1e3 {
                continue;
            }
            for i in 0..17 * 17 {
                let u = Vec2::new((i / 17) as f32, (i % 17) as f32) / 16.0;
                let [x, y, _] = local(&c, sr.sample(u));
                let h = |y: f64| y / (y * y + x * x + z * z).sqrt();
                let ux = (theta(x) - theta(x0)) / (theta(x1) - theta(x0));
                let uy = (h(y) - h(y0)) / (h(y1) - h(y0));
                let err = (ux - u.x as f64).abs().max((uy - u.y as f64).abs());
                assert!(err < tol, "{c:?}: sample({u}) has CDFs ({ux}, {uy})");
            }
        }
    }

    #[test]
    fn samples_lie_on_the_rectangle() {
        let mut seed = 0x9E37_79B9_7F4A_7C15_u64; // xorshift64*
        let mut rng = || {
            seed ^= seed >> 12;
            seed ^= seed << 25;
            seed ^= seed >> 27;
            (seed.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 40) as f32 / (1u64 << 24) as f32
        };
        for c @ &(_, corner, ex, ey) in moderate().iter().chain(&extreme()) {
            let sr = rect(c);
            let omega = sr.solid_angle();
            assert!(
                omega > 0.0 && omega < 2.0 * std::f32::consts::PI + 1e-5,
                "{c:?}"
            );
            let (ex, ey) = (dv(ex), dv(ey));
            let tol = 1e-6 * (dv(corner).length() + ex.length() + ey.length());
            let n = ex.cross(ey).normalize();
            let mut us = vec![
                Vec2::ZERO,
                Vec2::ONE,
                Vec2::X,
                Vec2::Y,
                Vec2::NAN,
                -Vec2::ONE,
            ];
            us.extend((0..2000).map(|_| Vec2::new(rng(), rng())));
            for u in us {
                let p = sr.sample(u);
                assert!(p.is_finite(), "{c:?}: sample({u}) = {p}");
                let d = dv(p) - dv(corner);
                let (s, t) = (
                    d.dot(ex) / ex.length_squared(),
                    d.dot(ey) / ey.length_squared(),
                );
                let (ts, tt) = (tol / ex.length(), tol / ey.length());
                assert!(
                    n.dot(d).abs() <= tol,
                    "{c:?}: sample({u}) = {p} is off the plane"
                );
                let inside = (-ts..=1.0 + ts).contains(&s) && (-tt..=1.0 + tt).contains(&t);
                assert!(inside, "{c:?}: sample({u}) = {p} at ({s}, {t}) is outside");
            }
        }
    }

    #[test]
    fn degenerate_rectangles_are_rejected() {
        let new = |r, ex, ey| SphericalRectangle::new(r, Vec3::ZERO, ex, ey);
        let r = Vec3::new(0.2, 0.3, 1.0);
        assert!(new(r, Vec3::X, Vec3::Y).is_some());
        assert!(new(r, Vec3::X, Vec3::new(5e-5, 1.0, 0.0)).is_some()); // within 1e-4
        assert!(new(r, Vec3::X, Vec3::new(1e-2, 1.0, 0.0)).is_none()); // not perpendicular
        assert!(new(r, Vec3::ZERO, Vec3::Y).is_none());
        assert!(new(r, Vec3::X, Vec3::ZERO).is_none());
        assert!(new(r, Vec3::X, Vec3::new(0.0, f32::NAN, 0.0)).is_none());
        assert!(new(Vec3::new(f32::INFINITY, 0.0, 1.0), Vec3::X, Vec3::Y).is_none());
        for r in [
            Vec3::new(0.5, 0.5, 0.0),
            Vec3::new(3.0, -2.0, 0.0),
            Vec3::ZERO,
        ] {
            assert!(new(r, Vec3::X, Vec3::Y).is_none(), "{r} is in the plane");
        }
        // In the plane of a rotated rectangle, up to f32 rounding.
        let (_, c, ex, ey) = moderate()[0];
        assert!(SphericalRectangle::new(c + 0.3 * ex + 2.5 * ey, c, ex, ey).is_none());
    }

    #[test]
    fn corners_map_to_corners_monotonically() {
        for c @ &(_, corner, ex, ey) in &moderate() {
            let sr = rect(c);
            let tol = 1e-5 * (ex.length() + ey.length());
            let (x, y, xy) = (corner + ex, corner + ey, corner + ex + ey);
            for (u, p) in [
                (Vec2::ZERO, corner),
                (Vec2::X, x),
                (Vec2::Y, y),
                (Vec2::ONE, xy),
            ] {
                let q = sr.sample(u);
                assert!(q.distance(p) <= tol, "{c:?}: sample({u}) = {q}, not {p}");
            }
            let st = |u| {
                let d = sr.sample(u) - corner;
                Vec2::new(
                    d.dot(ex) / ex.length_squared(),
                    d.dot(ey) / ey.length_squared(),
                )
            };
            let k = 64;
            for (i, j) in (0..=k).flat_map(|i| (0..=k).map(move |j| (i, j))) {
                let u = Vec2::new(i as f32, j as f32) / k as f32;
                let p = st(u);
                assert!(
                    (p.x - st(Vec2::new(u.x, 0.0)).x).abs() < 1e-5,
                    "{c:?}: column {u}"
                );
                assert!(
                    i == 0 || p.x > st(u - Vec2::X / k as f32).x,
                    "{c:?}: s at {u}"
                );
                assert!(
                    j == 0 || p.y > st(u - Vec2::Y / k as f32).y,
                    "{c:?}: t at {u}"
                );
            }
        }
    }
}
