"""Ray queries: where rays meet the scene's spheres and parallelograms, the
closest hit of camera rays, and whether a shadow ray is blocked. Vectors are
structures of arrays: x, y, z components as separate arrays.
"""

from __future__ import annotations

import numpy as np

from scene_file import AreaLight, Parallelogram, Scene, Sphere


def dot3(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def sphere_roots(s: Sphere, o, d):
    """Both roots of |o + t d - c|^2 = r^2 (the precision-improved form of
    Haines et al. that geometry/src/shapes/sphere.rs uses), NaN where none."""
    c = s.center
    fx, fy, fz = o[0] - c[0], o[1] - c[1], o[2] - c[2]
    a = dot3(d, d)
    b = fx * d[0] + fy * d[1] + fz * d[2]
    r2 = s.radius * s.radius
    cc = fx * fx + fy * fy + fz * fz - r2
    k = b / a
    px, py, pz = fx - k * d[0], fy - k * d[1], fz - k * d[2]
    disc = a * (r2 - (px * px + py * py + pz * pz))
    with np.errstate(invalid="ignore", divide="ignore"):
        q = -(b + np.copysign(np.sqrt(disc), b))
        t0, t1 = cc / q, q / a
    return np.minimum(t0, t1), np.maximum(t0, t1)  # NaN propagates where disc < 0


def parallelogram_t(p: Parallelogram, o, d, two_sided: bool):
    """Ray parameter of the hit of a parallelogram (one-sided unless two_sided:
    a ray must arrive against its normal, geometry/src/shapes/parallelogram.rs),
    NaN where there is none."""
    n = p.normal
    denom = n[0] * d[0] + n[1] * d[1] + n[2] * d[2]
    no = n[0] * o[0] + n[1] * o[1] + n[2] * o[2]
    with np.errstate(invalid="ignore", divide="ignore"):
        t = (float(n.dot(p.origin)) - no) / denom
    ok = denom != 0 if two_sided else denom < 0
    x, y, z = o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]
    alpha = p.A[0] * x + p.A[1] * y + p.A[2] * z - p.a0
    beta = p.B[0] * x + p.B[1] * y + p.B[2] * z - p.b0
    m = 1e-9  # a rounding margin, so that a ray aimed at a shared edge meets a wall
    ok &= (alpha >= -m) & (alpha <= 1 + m) & (beta >= -m) & (beta <= 1 + m)
    return np.where(ok, t, np.nan)


class Intersector:
    """The scene's shapes as seen by rays, with the mistakes that change what a
    ray hits; `eps` is the tracer's shadow-ray offset, which the culling of
    walls allows for."""

    def __init__(self, scene: Scene, mistakes: frozenset, eps: float):
        self.scene, self.m, self.eps = scene, mistakes, eps

    def closest(self, o, d):
        """Closest hit of each ray, t > 0: (t, kind, index); kind 0 sphere,
        1 parallelogram (walls and light surfaces), -1 none."""
        n = d[0].shape[0]
        best = np.full(n, np.inf)
        kind = np.full(n, -1, dtype=np.int8)
        index = np.full(n, -1, dtype=np.int32)
        for i, s in enumerate(self.scene.spheres):
            t0, t1 = sphere_roots(s, o, d)
            t = np.where(t0 > 0, t0, np.where(t1 > 0, t1, np.inf))
            closer = t < best
            best[closer], kind[closer], index[closer] = t[closer], 0, i
        for i, p in enumerate(self.scene.parallelograms):
            two_sided = p.two_sided
            if p.light >= 0:
                if "invisible-light" in self.m:  # MISTAKE: the light is not an object camera rays can hit
                    continue
                if "two-sided-light" in self.m:  # MISTAKE: the light seen from both sides
                    two_sided = True
            t = parallelogram_t(p, o, d, two_sided)
            closer = t > 0
            closer[closer] = t[closer] < best[closer]
            best[closer], kind[closer], index[closer] = t[closer], 1, i
        return best, kind, index

    def blocked(self, o, d, tmax, own_kind, own_index, light_surface, point_target=None):
        """Whether anything lies on o + t d, 0 < t < tmax. A flat shape cannot
        block rays leaving it (own_kind 1) and the light's surface is not
        reached (the segment ends short of it), as in Glint
        (geometry/src/shape_list/occluders.rs); one-sided walls only block
        rays that arrive at their front. The segments end at the area light
        whose surface is `light_surface` or, when that is -1, at the point
        light at `point_target`."""
        n = d[0].shape[0]
        hit = np.zeros(n, dtype=bool)
        no_offset = "no-shadow-offset" in self.m
        for i, s in enumerate(self.scene.spheres):
            t0, t1 = sphere_roots(s, o, d)
            blocks = ((t0 > 0) & (t0 < tmax)) | ((t1 > 0) & (t1 < tmax))
            if "no-clamp-dots" in self.m:
                # MISTAKE (part of no-clamp-dots): the object a shadow ray leaves
                # is not tested (a common cure for acne), so light from below
                # the horizon reaches the point, with its negative n.l.
                blocks &= ~((own_kind == 0) & (own_index == i))
            hit |= blocks
        for i, p in enumerate(self.scene.parallelograms):
            if p.light >= 0:
                if i != light_surface:
                    pass  # another light's surface blocks like a wall
                elif "light-blocks-shadow" in self.m:
                    # MISTAKE: the light itself is an occluder, and the segment
                    # is tested up to and including the light point (t <= 1).
                    t = parallelogram_t(p, o, d, False)
                    hit |= (t > 0) & (t <= tmax * (1 + 1e-9))
                    continue
                else:
                    continue
            two_sided = p.two_sided or (p.light >= 0 and "two-sided-light" in self.m)
            if not two_sided:
                # Cull (exactly): a one-sided wall only blocks a segment that ends
                # behind it; all segments here end at the light (or a point light).
                if light_surface >= 0:
                    L = self.scene.area_lights[self.scene.parallelograms[light_surface].light]
                    corners = self.light_corners(L)
                else:
                    corners = [point_target]
                if all(p.normal.dot(c - p.origin) > 10 * self.eps for c in corners):
                    continue
            t = parallelogram_t(p, o, d, two_sided)
            own = (own_kind == 1) & (own_index == i)
            if no_offset:
                own = np.zeros_like(own)  # MISTAKE (no-shadow-offset): the own wall is tested too
            hit |= (t > 0) & (t < tmax) & ~own
        return hit

    def light_corners(self, L: AreaLight):
        """The corners of the area the light's samples cover, moved to its front
        as the shadow rays' ends are: where every segment to it ends."""
        h1, h2 = L.edge1, L.edge2
        if "light-twice-size" in self.m:
            h1, h2 = 2 * h1, 2 * h2
        c = L.center + 2 * self.eps * L.normal
        return [c + a * 0.5 * h1 + b * 0.5 * h2 for a in (-1, 1) for b in (-1, 1)]
