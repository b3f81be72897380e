"""The environment seen where a ray hits nothing (environment-lighting.md): a
constant colour, a cube map (faces px nx py ny pz nz, read across the edges,
trilinear at the mirror's filter width) or a lat-long map.
"""

import math
import os

from .images import read_image
from .textures import Pyramid, trilinear_at_level
from .vectors import ZERO, mul, vec


FACES = ("px", "nx", "py", "ny", "pz", "nz")


def cube_face_coords(d):
    """The OpenGL major-axis rule, with scenes/environments/README.md's faces:
    px (1,-t,-s), nx (-1,-t,s), py (s,1,t), ny (s,-1,-t), pz (s,-t,1), nz (-s,-t,-1)."""
    ax, ay, az = abs(d[0]), abs(d[1]), abs(d[2])
    if ax >= ay and ax >= az:
        if d[0] > 0:
            return 0, -d[2] / ax, -d[1] / ax
        return 1, d[2] / ax, -d[1] / ax
    if ay >= az:
        if d[1] > 0:
            return 2, d[0] / ay, d[2] / ay
        return 3, d[0] / ay, -d[2] / ay
    if d[2] > 0:
        return 4, d[0] / az, -d[1] / az
    return 5, -d[0] / az, -d[1] / az


def cube_face_dir(face, s, t):
    return [(1, -t, -s), (-1, -t, s), (s, 1, t), (s, -1, -t), (s, -t, 1), (-s, -t, -1)][face]


class Environment:
    def __init__(self, table, base):
        self.intensity = float(table.get("intensity", 1.0))
        self.rotation = float(table.get("rotation", 0.0))
        self.color = vec(table["color"]) if "color" in table else None
        self.latlong = None
        self.faces = None
        if "cube_map" in table:
            tmpl = table["cube_map"]
            self.faces = [Pyramid(read_image(os.path.join(base, tmpl.replace("{face}", f)))) for f in FACES]
        elif "latlong" in table:
            self.latlong = Pyramid(read_image(os.path.join(base, table["latlong"])))

    def _rotate(self, d):
        # the map turns about +y by `rotation`: look the direction up turned back
        a = math.radians(-self.rotation)
        c, s = math.cos(a), math.sin(a)
        return (c * d[0] + s * d[2], d[1], -s * d[0] + c * d[2])

    def _cube_texel(self, level, face, i, j):
        img = self.faces[face].levels[level]
        n = img.width
        if 0 <= i < n and 0 <= j < n:
            return img.texel(i, j)
        # environment-lighting.md: a texel past an edge is fetched from the face
        # its direction points into
        s = 2 * (i + 0.5) / n - 1
        t = 2 * (j + 0.5) / n - 1
        f2, s2, t2 = cube_face_coords(cube_face_dir(face, s, t))
        i2 = min(n - 1, max(0, int(math.floor((s2 + 1) / 2 * n))))
        j2 = min(n - 1, max(0, int(math.floor((t2 + 1) / 2 * n))))
        return self.faces[f2].levels[level].texel(i2, j2)

    def _cube_bilinear(self, level, face, s, t):
        n = self.faces[face].levels[level].width
        x = (s + 1) / 2 * n - 0.5
        y = (t + 1) / 2 * n - 0.5
        x0, y0 = math.floor(x), math.floor(y)
        fx, fy = x - x0, y - y0
        block = {}
        for dy in (0, 1):
            for dx in (0, 1):
                i, j = x0 + dx, y0 + dy
                if (i < 0 or i >= n) and (j < 0 or j >= n):
                    block[(dx, dy)] = None  # diagonally past a corner
                else:
                    block[(dx, dy)] = self._cube_texel(level, face, i, j)
        for key, val in block.items():
            if val is None:
                others = [v for k, v in block.items() if k != key and v is not None]
                block[key] = tuple(sum(c) / len(others) for c in zip(*others)) if others else ZERO
        out = [0.0, 0.0, 0.0]
        for (dx, dy), tx in block.items():
            wt = (fx if dx else 1 - fx) * (fy if dy else 1 - fy)
            for c in range(3):
                out[c] += wt * tx[c]
        return tuple(out)

    def lookup(self, d, width):
        if self.color is not None:
            return mul(self.color, self.intensity)
        d = self._rotate(d)
        if self.faces is not None:
            face, s, t = cube_face_coords(d)
            n = self.faces[0].levels[0].width
            last = len(self.faces[0].levels) - 1
            # environment-lighting.md: log2(width*N/2) + 3/4 log2(1 + s^2 + t^2)
            if width > 0:
                level = math.log2(width * n / 2) + 0.75 * math.log2(1 + s * s + t * t)
            else:
                level = 0.0
            if not (level == level) or level < 0:
                level = 0.0
            level = min(level, float(last))
            l0 = int(math.floor(level))
            f = level - l0
            a = self._cube_bilinear(l0, face, s, t)
            if f > 0 and l0 < last:
                b = self._cube_bilinear(l0 + 1, face, s, t)
                a = tuple((1 - f) * x + f * y for x, y in zip(a, b))
            return mul(a, self.intensity)
        # lat-long: u = 1/2 + atan2(d.x, -d.z)/2pi, v = acos(d.y)/pi
        u = 0.5 + math.atan2(d[0], -d[2]) / (2 * math.pi)
        v = math.acos(max(-1.0, min(1.0, d[1]))) / math.pi
        img = self.latlong.levels[0]
        hgt = img.height
        level = math.log2(width * hgt / math.pi) if width > 0 else 0.0
        return mul(trilinear_at_level(self.latlong, u, v, level, "repeat"), self.intensity)
