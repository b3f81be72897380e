"""The pinhole camera (scene-format.md, steps 1-2): the basis from position,
look_at and up, the film point of a raster position, and the camera ray.
"""

import math

from .mistake import mistake
from .vectors import add, cross, mul, neg, normalize, sub, vec


class Camera:
    def __init__(self, table, width, height):
        self.eye = vec(table["position"])
        look = vec(table["look_at"])
        up = vec(table.get("up", (0, 1, 0)))
        self.fov = float(table["fov"])
        self.f = float(table.get("focal_length", 1.0))
        self.forward = normalize(sub(look, self.eye))
        self.right = normalize(cross(self.forward, up))
        self.up = cross(self.right, self.forward)
        if mistake("up-flipped"):
            # MISTAKE up-flipped: the basis's up the wrong way round (forward x right)
            self.up = neg(self.up)
        self.width, self.height = width, height
        self.half_h = self.f * math.tan(math.radians(self.fov) / 2)
        if mistake("fov-not-halved"):
            # MISTAKE fov-not-halved: the whole vertical fov, not half of it, in
            # the film's half height (both commands build rays with this camera)
            self.half_h = self.f * math.tan(math.radians(self.fov))

    def film_point(self, x, y, width=None, height=None):
        width = width or self.width
        height = height or self.height
        half_w = width / height * self.half_h
        ndc = (2 * x / width - 1, 1 - 2 * y / height)
        fp = add(mul(self.forward, self.f), add(mul(self.right, ndc[0] * half_w), mul(self.up, ndc[1] * self.half_h)))
        return ndc, fp

    def ray(self, x, y, width=None, height=None):
        ndc, fp = self.film_point(x, y, width, height)
        return self.eye, normalize(fp)
