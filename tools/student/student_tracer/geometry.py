"""Shapes and ray intersection (scene-format.md): spheres, parallelograms,
infinite planes and boxes, each with its first hit t along a ray and the Hit
there (point, geometric normal, uv, dp/du, dp/dv), and the scene's objects.
"""

import math

from .mistake import mistake
from .vectors import INF, add, cross, dot, length, mul, normalize, sub, vec


class Hit:
    __slots__ = ("t", "obj", "point", "ng", "uv", "dpdu", "dpdv")

    def __init__(self, t, obj, point, ng, uv, dpdu, dpdv):
        self.t, self.obj, self.point, self.ng, self.uv, self.dpdu, self.dpdv = t, obj, point, ng, uv, dpdu, dpdv


class Sphere:
    kind = "sphere"

    def __init__(self, center, radius):
        self.center = center
        self.radius = radius

    def intersect_t(self, o, d, tmax=INF):
        oc = sub(o, self.center)
        a = dot(d, d)
        # Haines et al. (Ray Tracing Gems 7): b' and a discriminant from the
        # distance of the centre to the line, which keeps small spheres precise
        b = -dot(oc, d)
        f = sub(oc, mul(d, -b / a))
        disc = a * (self.radius * self.radius - dot(f, f))
        if disc < 0:
            return None
        sq = math.sqrt(disc)
        q = b + math.copysign(sq, b)
        c = dot(oc, oc) - self.radius * self.radius
        if q == 0:
            return None
        t0, t1 = c / q, q / a
        if t0 > t1:
            t0, t1 = t1, t0
        if 0 < t0 < tmax:
            return t0
        if 0 < t1 < tmax:
            return t1
        return None

    def uv_of_normal(self, n):
        # scene-format.md, sphere uv
        phi = math.atan2(-n[2], n[0])
        if phi < 0 and not mistake("sphere-u-unwrapped"):
            # (MISTAKE sphere-u-unwrapped skips this wrap: u stays in [-0.5, 0.5))
            phi += 2 * math.pi
        theta = math.acos(max(-1.0, min(1.0, n[1])))
        return (phi / (2 * math.pi), 1 - theta / math.pi)

    def derivs(self, uv):
        phi = uv[0] * 2 * math.pi
        theta = math.pi * (1 - uv[1])
        r = self.radius
        dpdu = (-2 * math.pi * r * math.sin(theta) * math.sin(phi), 0.0,
                -2 * math.pi * r * math.sin(theta) * math.cos(phi))
        dpdv = mul((r * math.cos(theta) * math.cos(phi), -r * math.sin(theta),
                    -r * math.cos(theta) * math.sin(phi)), -math.pi)
        return dpdu, dpdv

    def hit(self, o, d, t, obj):
        p = add(o, mul(d, t))
        n = normalize(sub(p, self.center))
        uv = self.uv_of_normal(n)
        dpdu, dpdv = self.derivs(uv)
        return Hit(t, obj, p, n, uv, dpdu, dpdv)

    def jacobian_area(self, uv):
        dpdu, dpdv = self.derivs(uv)
        return length(cross(dpdu, dpdv))


class Parallelogram:
    kind = "parallelogram"

    def __init__(self, origin, e1, e2, normal=None, two_sided=False):
        self.origin, self.e1, self.e2 = origin, e1, e2
        c = cross(e1, e2)
        self.nrm = normalize(c) if normal is None else normalize(normal)
        self.two_sided = two_sided
        # dual basis for (alpha, beta)
        self._c = c
        self._cc = dot(c, c)

    def intersect_t(self, o, d, tmax=INF):
        dn = dot(d, self.nrm)
        if dn == 0 or (not self.two_sided and dn >= 0):
            return None
        t = dot(sub(self.origin, o), self.nrm) / dn
        if not (0 < t < tmax):
            return None
        q = sub(add(o, mul(d, t)), self.origin)
        a = dot(cross(q, self.e2), self._c) / self._cc
        b = dot(cross(self.e1, q), self._c) / self._cc
        if a < 0 or a > 1 or b < 0 or b > 1:
            return None
        return t

    def hit(self, o, d, t, obj):
        p = add(o, mul(d, t))
        q = sub(p, self.origin)
        a = dot(cross(q, self.e2), self._c) / self._cc
        b = dot(cross(self.e1, q), self._c) / self._cc
        return Hit(t, obj, p, self.nrm, (a, b), self.e1, self.e2)

    def jacobian_area(self, uv):
        return length(self._c)


def duff_basis(n):
    """Duff et al., 'Building an Orthonormal Basis, Revisited' (JCGT 2017)."""
    sign = math.copysign(1.0, n[2])
    a = -1.0 / (sign + n[2])
    b = n[0] * n[1] * a
    b1 = (1 + sign * n[0] * n[0] * a, sign * b, -sign * n[0])
    b2 = (b, sign + n[1] * n[1] * a, -n[1])
    return b1, b2


class Plane:
    kind = "plane"

    def __init__(self, point, normal, tile, two_sided=False):
        self.point = point
        self.nrm = normalize(normal)
        self.tile = tile
        self.two_sided = two_sided
        self.b1, self.b2 = duff_basis(self.nrm)

    def intersect_t(self, o, d, tmax=INF):
        dn = dot(d, self.nrm)
        if dn == 0 or (not self.two_sided and dn >= 0):
            return None
        t = dot(sub(self.point, o), self.nrm) / dn
        return t if 0 < t < tmax else None

    def hit(self, o, d, t, obj):
        p = add(o, mul(d, t))
        q = sub(p, self.point)
        uv = (dot(q, self.b1) / self.tile, dot(q, self.b2) / self.tile)
        return Hit(t, obj, p, self.nrm, uv, mul(self.b1, self.tile), mul(self.b2, self.tile))

    def jacobian_area(self, uv):
        return self.tile * self.tile


def box_faces(lo, hi):
    """scene-format.md: px nx py ny pz nz, each upright seen from outside: side
    faces u right and v up; top v towards -z, bottom v towards +z."""
    dx, dy, dz = hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]
    return [
        ((hi[0], lo[1], hi[2]), (0, 0, -dz), (0, dy, 0), (1, 0, 0)),
        ((lo[0], lo[1], lo[2]), (0, 0, dz), (0, dy, 0), (-1, 0, 0)),
        ((lo[0], hi[1], hi[2]), (dx, 0, 0), (0, 0, -dz), (0, 1, 0)),
        ((lo[0], lo[1], lo[2]), (dx, 0, 0), (0, 0, dz), (0, -1, 0)),
        ((lo[0], lo[1], hi[2]), (dx, 0, 0), (0, dy, 0), (0, 0, 1)),
        ((hi[0], lo[1], lo[2]), (-dx, 0, 0), (0, dy, 0), (0, 0, -1)),
    ]


class Box:
    kind = "box"

    def __init__(self, lo, hi):
        self.faces = [Parallelogram(vec(o), vec(a), vec(b), vec(n), True) for o, a, b, n in box_faces(lo, hi)]

    def _nearest(self, o, d, tmax):
        best = None
        for f in self.faces:
            t = f.intersect_t(o, d, tmax)
            if t is not None and (best is None or t < best[0]):
                best = (t, f)
        return best

    def intersect_t(self, o, d, tmax=INF):
        b = self._nearest(o, d, tmax)
        return None if b is None else b[0]

    def hit(self, o, d, t, obj):
        b = self._nearest(o, d, INF)
        return b[1].hit(o, d, t, obj)

    def jacobian_area(self, uv):
        return None


class SceneObject:
    def __init__(self, index, shape, material, name, light=None):
        self.index = index
        self.shape = shape
        self.material = material
        self.name = name
        self.light = light  # an AreaLight for a light's surface

    @property
    def kind(self):
        return self.shape.kind
