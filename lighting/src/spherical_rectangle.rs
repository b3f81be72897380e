//! Solid-angle sampling of a rectangle as seen from a point: the area-preserving
//! parametrisation of spherical rectangles of Ureña, Fajardo and King, "An
//! Area-Preserving Parametrization for Spherical Rectangles", EGSR 2013 (Computer
//! Graphics Forum 32(4)). Sampling a rectangular light by solid angle gives the
//! constant pdf `1/Ω` per unit solid angle instead of area sampling's `r²/(A·cosθ')`,
//! which is noisy for lights that are near or large.

use glam::{Vec2, Vec3};

/// The rectangle `corner + s·ex + t·ey`, s,t ∈ [0,1], (ex ⟂ ey) as seen from `reference`.
///
/// It is held in the paper's local frame: `reference` at the origin, x along `ex`, y
/// along `ey`, and the rectangle `[x0,x1]×[y0,y1]` in the plane at distance `z > 0`.
/// (The paper flips its normal so that its `z0 = -z < 0`; only `z` enters the formulas
/// below, so the reference point may be on either side.) All local lengths are divided
/// by the largest of `|x0|,|x1|,|y0|,|y1|,z`: angles are scale-invariant, and squares
/// of the scaled lengths can neither overflow nor underflow.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphericalRectangle {
    corner: Vec3,
    ex: Vec3,
    ey: Vec3,
    x0: f32,
    x1: f32,
    y0: f32,
    y1: f32,
    z: f32,
    /// `θ(x0)` and `θ(x1)` (see [`SphericalRectangle::sample`]).
    theta0: f32,
    theta1: f32,
    /// `Δ = ψ1 − ψ0` and `Σ = ψ0 + ψ1`, with `ψi = atan2(yi, z)`.
    delta: f32,
    sigma: f32,
    solid_angle: f32,
}

/// Smallest argument allowed under a square root that is divided by.
const TINY: f32 = 1e-30;

impl SphericalRectangle {
    /// None if the edges are not perpendicular (|ex·ey| > 1e-4·|ex||ey|), zero-length,
    /// non-finite, or the reference point lies in the rectangle's plane (no solid angle:
    /// its distance to the plane is at most 1e-6·|corner − reference|, the rounding
    /// noise of f32) or the solid angle is not finite/positive.
    pub fn new(reference: Vec3, corner: Vec3, ex: Vec3, ey: Vec3) -> Option<Self> {
        let (w, h) = (ex.length(), ey.length());
        if !(w > 0.0 && h > 0.0 && w.is_finite() && h.is_finite()) {
            return None;
        }
        let (xa, ya) = (ex / w, ey / h);
        let d = corner - reference;
        if xa.dot(ya).abs() > 1e-4 || !d.is_finite() {
            return None;
        }
        let (x0, y0, z) = (d.dot(xa), d.dot(ya), d.dot(xa.cross(ya).normalize()).abs());
        let (x1, y1) = (x0 + w, y0 + h);
        if z <= 1e-6 * d.length() || !x1.is_finite() || !y1.is_finite() {
            return None;
        }
        let inv = 1.0 / x0.abs().max(x1.abs()).max(y0.abs()).max(y1.abs()).max(z);
        let (x0, x1, y0, y1, z) = (x0 * inv, x1 * inv, y0 * inv, y1 * inv, z * inv);
        // θ(x) = F(x,y1) − F(x,y0) as one atan2 (the argument of a complex product),
        // with `y1·R0 − y0·R1` rewritten for y0, y1 of one sign, where it would cancel.
        let theta = |x: f32| {
            let (rr, yy) = (x * x + z * z, y0 * y1);
            let (r0, r1) = ((rr + y0 * y0).sqrt(), (rr + y1 * y1).sqrt());
            let cross = if yy > 0.0 {
                (y1 - y0) * (y1 + y0) * rr / (y1 * r0 + y0 * r1)
            } else {
                y1 * r0 - y0 * r1
            };
            (x * z * cross).atan2(z * z * r0 * r1 + x * x * yy)
        };
        let (theta0, theta1) = (theta(x0), theta(x1));
        let solid_angle = if x0 <= 0.0 && 0.0 <= x1 && y0 <= 0.0 && 0.0 <= y1 {
            // The foot of the perpendicular is inside: Ω = θ1 − θ0 is a sum of four
            // corner terms of one sign.
            theta1 - theta0
        } else {
            // Outside, those terms would cancel: two triangles instead, each by Van
            // Oosterom & Strackee (IEEE Trans. Biomed. Eng. 30(2), 1983): tan(Ω_t/2) =
            // |a·(b×c)| / (abc + (a·b)c + (a·c)b + (b·c)a). Both triple products are
            // z·w·h exactly, so small Ω keeps its digits (the paper's Σγ − 2π cancels
            // to nothing in f32 below ~1e-5 sr).
            let v = |x, y| Vec3::new(x, y, z);
            let (v00, v10, v11, v01) = (v(x0, y0), v(x1, y0), v(x1, y1), v(x0, y1));
            let triple = z * (x1 - x0) * (y1 - y0);
            let triangle = |a: Vec3, b: Vec3, c: Vec3| {
                let (la, lb, lc) = (a.length(), b.length(), c.length());
                let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
                2.0 * triple.atan2(den)
            };
            triangle(v00, v10, v11) + triangle(v00, v11, v01)
        };
        if !(solid_angle > 0.0 && solid_angle.is_finite()) {
            return None;
        }
        let delta = (z * (y1 - y0)).atan2(z * z + y0 * y1);
        let sigma = y0.atan2(z) + y1.atan2(z);
        Some(Self {
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
        })
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
    pub fn solid_angle(&self) -> f32 {
        self.solid_angle
    }

    /// The point on the rectangle for u ∈ [0,1]², distributed uniformly in solid angle;
    /// the map is continuous and area preserving (strata of [0,1]² map to equal solid angles).
    ///
    /// `u.x` moves along `ex` and `u.y` along `ey`, both monotonically: `(0,0)` maps to
    /// `corner`, `(1,0)` to `corner + ex`, `(0,1)` to `corner + ey` and `(1,1)` to the
    /// opposite corner; the columns `u.x = const` are the segments `s = const`.
    ///
    /// In the paper's frame, the part `[x0,x]×[y0,y1]` subtends `θ(x) − θ(x0)` with
    /// `θ(x) = F(x,y1) − F(x,y0)` (see [`Self::solid_angle`]); θ is the paper's
    /// `au − π = γ0' + γ1' − π`, the angles at the moving edge, and with its
    /// `cu = x/√(x²+z²)`, `b0 = −y0/√(y0²+z²)`, `b1 = y1/√(y1²+z²)`,
    /// `θ = asin(cu·b0) + asin(cu·b1)`.
    /// 1. `θ = θ0 + u.x·(θ1 − θ0)`. The paper inverts this as `cu = sign(fu)/√(fu²+b0²)`,
    ///    `fu = (cos(au)·b0 − b1)/sin(au)`, i.e. `cu = sinθ / √(b0² + b1² + 2b0b1·cosθ)`,
    ///    then `x = z·cu/√(1 − cu²)`. With `ψi = atan2(yi, z)`, `Δ = ψ1 − ψ0` and
    ///    `Σ = ψ0 + ψ1` that is, without the cancellation in `1 − cu²` at grazing
    ///    angles nor the division by `sin(au)`:
    ///    `x/z = sinθ / (2·√(sin((Δ−θ)/2)·sin((Δ+θ)/2)·cos((θ+Σ)/2)·cos((θ−Σ)/2)))`,
    ///    every factor positive for `|θ| < Δ`.
    /// 2. Along the line at `x`, at distance `d = √(x²+z²)`, the angle subtended from
    ///    `y0` to `y` grows as `h(y) = y/√(y²+d²)`, so `h` is the lerp of `h0`, `h1` by
    ///    `u.y` and `y = d·h/√((1−h)(1+h))`; `1 ∓ h` are lerped from end values computed
    ///    without cancellation, so `y` keeps its digits where `h → ±1`.
    ///
    /// Square roots are guarded and `x`, `y` clamped to the rectangle, so the result is
    /// always a finite point of the rectangle.
    pub fn sample(&self, u: Vec2) -> Vec3 {
        let (x0, x1, y0, y1, z) = (self.x0, self.x1, self.y0, self.y1, self.z);
        // Unlike `clamp`, also turns NaN into a bound (0).
        let unit = |t: f32| if t > 0.0 { t.min(1.0) } else { 0.0 };
        let (ux, uy) = (unit(u.x), unit(u.y));
        let theta = self.theta0 + ux * (self.theta1 - self.theta0);
        let (dl, sg) = (self.delta, self.sigma);
        let prod = (0.5 * (dl - theta)).sin()
            * (0.5 * (dl + theta)).sin()
            * (0.5 * (theta + sg)).cos()
            * (0.5 * (theta - sg)).cos();
        let x = (z * theta.sin() / (2.0 * prod.max(TINY).sqrt()))
            .max(x0)
            .min(x1);
        let d2 = x * x + z * z;
        // h(y) = y/√(y²+d²) is lerped for its digits near 0, and 1 ∓ h (computed
        // without cancellation) for theirs near ±1.
        let (m0, m1) = ((y0 * y0 + d2).sqrt(), (y1 * y1 + d2).sqrt());
        let one_minus_h = |y: f32, m: f32| {
            if y > 0.0 {
                d2 / (m * (m + y))
            } else {
                1.0 - y / m
            }
        };
        let lerp = |a: f32, b: f32| (1.0 - uy) * a + uy * b;
        let h = y0 / m0 + uy * (y1 / m1 - y0 / m0);
        let p = lerp(one_minus_h(y0, m0), one_minus_h(y1, m1)); // 1 − h
        let q = lerp(one_minus_h(-y0, m0), one_minus_h(-y1, m1)); // 1 + h
        let y = (h * d2.sqrt() / (p * q).max(TINY).sqrt()).max(y0).min(y1);
        let s = unit((x - x0) / (x1 - x0));
        let t = unit((y - y0) / (y1 - y0));
        self.corner + s * self.ex + t * self.ey
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
