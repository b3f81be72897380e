#!/usr/bin/env python3
"""A student's ray tracer for Glint's course model (Phong shading), written from
Glint's documentation alone (README.md, docs/*.md, the scene files): no Glint
source was read.  Standard library only.

Two commands:

  tracer.py stages SCENE.toml VECTORS_DIR ANSWERS_DIR [--epsilon-fraction F | --epsilon E]
      answers every stage of `glint grade --stages SCENE --write VECTORS_DIR`
      (camera, intersection, texture, lighting, film) into ANSWERS_DIR/STAGE.csv

  tracer.py explain SCENE.toml --pixel X,Y [--spp N] [--sampler grid]
            [--light-samples N] [--light-sampler grid] [--environment-samples 0]
            [--sample K | --all-samples] [--epsilon-fraction F | --epsilon E] -o doc.json
      writes this tracer's glint-explain/1 document for the pixel, to be
      compared with `glint explain SCENE --pixel X,Y ... --against doc.json`

Every rule is cited from the docs it comes from (scene-format.md "How a pixel
is computed" steps 1-13, grading-stages.md, checking-your-ray-tracer.md,
texture-filtering.md, environment-lighting.md).  Arithmetic is in doubles;
Glint's is in 32-bit floats, which the documented tolerances allow for.
"""

import argparse
import csv
import json
import math
import os
import struct
import sys
import tomllib
import zlib

INF = float("inf")


# ----------------------------------------------------------------------------
# Deliberate mistakes (--mistake NAME): fourteen classic student slips, each a small
# branch marked "MISTAKE name" where it is made, so that tools/student/mistakes.py
# can see how `glint grade --stages` and `glint explain --against` name them.
# With no --mistake (MISTAKE is None) no branch is taken and nothing changes.
# ----------------------------------------------------------------------------

MISTAKES = {
    "up-flipped": "the camera's up vector flipped (up = forward x right): the image upside down",
    "sphere-u-unwrapped": "sphere u = atan2(-z, x)/2pi left in [-0.5, 0.5) instead of wrapped into [0, 1)",
    "mip-natural-log": "the report's MIP level with the natural log, ln(L/W), instead of log2(L/W)",
    "odd-level-rounded-up": "pyramid levels of odd size rounded up, ceil(side/2) (75x50 -> 38x25), not floor",
    "light-sum-not-divided": "an area light's sum of samples not divided by their number N",
    "light-blocks-itself": "the shadow ray aimed along l from the offset start (the old recipe): the light's "
                           "own surface blocks it where the light is seen at a slant",
    "no-shadow-offset": "shadow rays start exactly at x, blockers at t > 0 (shadow acne)",
    "blinn": "the Phong lobe with the half vector, max(0, n.h)^s, instead of max(0, r.v)^s",
    "view-sign": "the view vector's sign flipped in the specular term (r.(-v))",
    "gamma-22": "8-bit film values with c^(1/2.2) instead of the sRGB curve",
    "no-ambient": "the ambient term (ambient * kd) left out of the local radiance",
    "light-centre": "every area-light sample placed at the light's centre instead of its grid cell's centre",
    "pixel-corner": "camera samples through the grid cells' corners, (i mod k)/k, not their centres (+1/2 left out)",
    "fov-not-halved": "the film's half height f*tan(fov) instead of f*tan(fov/2)",
}
MISTAKE = None


def mistake(name):
    """True where the mistake `name` is switched on (--mistake name)."""
    assert name in MISTAKES, name
    return MISTAKE == name


# ----------------------------------------------------------------------------
# Vectors (plain tuples)
# ----------------------------------------------------------------------------

def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def mul(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


def cmul(a, b):
    return (a[0] * b[0], a[1] * b[1], a[2] * b[2])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def length(a):
    return math.sqrt(dot(a, a))


def normalize(a):
    n = length(a)
    return (a[0] / n, a[1] / n, a[2] / n)


def neg(a):
    return (-a[0], -a[1], -a[2])


def vec(x):
    return tuple(float(c) for c in x)


ZERO = (0.0, 0.0, 0.0)


# ----------------------------------------------------------------------------
# Images: PNG (8/16-bit, sRGB -> linear) and Radiance .hdr readers
# ----------------------------------------------------------------------------

class Image:
    """width x height texels, row 0 at the top; data[y*width + x] = (r, g, b) linear."""

    def __init__(self, width, height, data):
        self.width = width
        self.height = height
        self.data = data

    def texel(self, x, y):
        return self.data[y * self.width + x]


def srgb_to_linear(c):
    # IEC 61966-2-1 decoding (scene-format.md: 8- and 16-bit files are decoded
    # from sRGB to linear once at load)
    if c <= 0.04045:
        return c / 12.92
    return ((c + 0.055) / 1.055) ** 2.4


def _paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    if pa <= pb and pa <= pc:
        return a
    if pb <= pc:
        return b
    return c


def read_png(path):
    raw = open(path, "rb").read()
    if raw[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path}: not a PNG file")
    pos = 8
    idat = []
    palette = None
    while pos < len(raw):
        (n,) = struct.unpack(">I", raw[pos:pos + 4])
        kind = raw[pos + 4:pos + 8]
        body = raw[pos + 8:pos + 8 + n]
        pos += 12 + n
        if kind == b"IHDR":
            width, height, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", body)
        elif kind == b"PLTE":
            palette = [tuple(body[i:i + 3]) for i in range(0, len(body), 3)]
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
    if interlace:
        raise ValueError(f"{path}: interlaced PNGs are not supported")
    channels = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}[ctype]
    data = zlib.decompress(b"".join(idat))
    bpp = max(1, channels * depth // 8)
    stride = (width * channels * depth + 7) // 8
    prev = bytearray(stride)
    rows = []
    p = 0
    for _ in range(height):
        ftype = data[p]
        line = bytearray(data[p + 1:p + 1 + stride])
        p += 1 + stride
        if ftype == 1:
            for i in range(bpp, stride):
                line[i] = (line[i] + line[i - bpp]) & 255
        elif ftype == 2:
            line = bytearray((a + b) & 255 for a, b in zip(line, prev))
        elif ftype == 3:
            for i in range(stride):
                left = line[i - bpp] if i >= bpp else 0
                line[i] = (line[i] + ((left + prev[i]) >> 1)) & 255
        elif ftype == 4:
            for i in range(stride):
                left = line[i - bpp] if i >= bpp else 0
                upleft = prev[i - bpp] if i >= bpp else 0
                line[i] = (line[i] + _paeth(left, prev[i], upleft)) & 255
        rows.append(line)
        prev = line
    if depth == 8:
        lut = [srgb_to_linear(i / 255.0) for i in range(256)]
    texels = []
    for line in rows:
        if depth == 16:
            vals = [(line[2 * i] << 8 | line[2 * i + 1]) for i in range(width * channels)]
            conv = [srgb_to_linear(v / 65535.0) for v in vals]
        elif depth == 8:
            vals = line
            conv = None
        else:
            raise ValueError(f"{path}: bit depth {depth} not supported")
        for x in range(width):
            if ctype == 3:
                r, g, b = palette[line[x]]
                texels.append((lut[r], lut[g], lut[b]))
                continue
            base = x * channels
            if conv is None:
                if channels >= 3:
                    texels.append((lut[vals[base]], lut[vals[base + 1]], lut[vals[base + 2]]))
                else:
                    gv = lut[vals[base]]
                    texels.append((gv, gv, gv))
            else:
                if channels >= 3:
                    texels.append((conv[base], conv[base + 1], conv[base + 2]))
                else:
                    texels.append((conv[base], conv[base], conv[base]))
    return Image(width, height, texels)


def read_hdr(path):
    raw = open(path, "rb").read()
    pos = 0
    while True:  # header lines up to a blank line
        end = raw.index(b"\n", pos)
        line = raw[pos:end]
        pos = end + 1
        if line == b"":
            break
    end = raw.index(b"\n", pos)
    res = raw[pos:end].split()
    pos = end + 1
    if res[0] != b"-Y" or res[2] != b"+X":
        raise ValueError(f"{path}: unsupported orientation {res}")
    height, width = int(res[1]), int(res[3])
    texels = []

    def rgbe(r, g, b, e):
        if e == 0:
            return (0.0, 0.0, 0.0)
        f = math.ldexp(1.0, e - 136)
        return (r * f, g * f, b * f)

    for _ in range(height):
        if 8 <= width < 32768 and raw[pos] == 2 and raw[pos + 1] == 2 and raw[pos + 2] < 128:
            pos += 4  # new-style run-length encoded scanline
            comps = []
            for _c in range(4):
                out = bytearray()
                while len(out) < width:
                    count = raw[pos]
                    pos += 1
                    if count > 128:
                        out.extend(bytes([raw[pos]]) * (count - 128))
                        pos += 1
                    else:
                        out.extend(raw[pos:pos + count])
                        pos += count
                comps.append(out)
            for x in range(width):
                texels.append(rgbe(comps[0][x], comps[1][x], comps[2][x], comps[3][x]))
        else:
            for x in range(width):
                r, g, b, e = raw[pos:pos + 4]
                pos += 4
                texels.append(rgbe(r, g, b, e))
    out = []
    for t in texels:  # NaN, infinite and negative values read as 0
        out.append(tuple(c if (c == c and 0 <= c < INF) else 0.0 for c in t))
    return Image(width, height, out)


def read_image(path):
    if path.lower().endswith(".png"):
        return read_png(path)
    if path.lower().endswith(".hdr"):
        return read_hdr(path)
    raise ValueError(f"{path}: only PNG and Radiance HDR are read by this tracer")


def _box_weights(n):
    """texture-filtering.md: level k+1 has side max(1, floor(n/2)); each new texel
    averages the old level over its own footprint, fractional weights at its edges."""
    m = max(1, n // 2)
    if mistake("odd-level-rounded-up"):
        # MISTAKE odd-level-rounded-up: an odd side rounded up, ceil(n/2), with
        # the same area-weighted box (75 -> 38 instead of 37)
        m = max(1, (n + 1) // 2)
    ratio = n / m
    out = []
    for j in range(m):
        start, end = j * ratio, (j + 1) * ratio
        ws = []
        for i in range(int(math.floor(start)), min(n, int(math.ceil(end)))):
            overlap = min(end, i + 1) - max(start, i)
            if overlap > 0:
                ws.append((i, overlap / ratio))
        out.append(ws)
    return m, out


def downsample(img):
    w, h = img.width, img.height
    nw, wx = _box_weights(w)
    nh, wy = _box_weights(h)
    # x pass
    tmp = []
    for y in range(h):
        row = img.data[y * w:(y + 1) * w]
        for ws in wx:
            r = g = b = 0.0
            for i, wt in ws:
                t = row[i]
                r += t[0] * wt
                g += t[1] * wt
                b += t[2] * wt
            tmp.append((r, g, b))
    out = [None] * (nw * nh)
    for j, ws in enumerate(wy):
        for x in range(nw):
            r = g = b = 0.0
            for i, wt in ws:
                t = tmp[i * nw + x]
                r += t[0] * wt
                g += t[1] * wt
                b += t[2] * wt
            out[j * nw + x] = (r, g, b)
    return Image(nw, nh, out)


class Pyramid:
    def __init__(self, img):
        self.levels = [img]
        while img.width > 1 or img.height > 1:
            img = downsample(img)
            self.levels.append(img)


def wrap_index(i, n, mode):
    if mode == "repeat":
        return i % n
    if mode == "clamp":
        return min(max(i, 0), n - 1)
    # mirror: period 2n
    i %= 2 * n
    return i if i < n else 2 * n - 1 - i


def bilinear(img, s, t, wrap):
    """grading-stages.md: blends the four texels around (s*w - 1/2, t*h - 1/2)."""
    x = s * img.width - 0.5
    y = t * img.height - 0.5
    x0 = math.floor(x)
    y0 = math.floor(y)
    fx = x - x0
    fy = y - y0
    out = [0.0, 0.0, 0.0]
    for dy, wy in ((0, 1 - fy), (1, fy)):
        for dx, wx in ((0, 1 - fx), (1, fx)):
            wt = wx * wy
            if wt == 0:
                continue
            tx = img.texel(wrap_index(x0 + dx, img.width, wrap), wrap_index(y0 + dy, img.height, wrap))
            out[0] += wt * tx[0]
            out[1] += wt * tx[1]
            out[2] += wt * tx[2]
    return tuple(out)


def bilinear_texels(img, s, t, level, share):
    """The four texels a bilinear lookup reads, as explain lists them: level,
    x, y before wrapping, weight (times the level's share), value."""
    x = s * img.width - 0.5
    y = t * img.height - 0.5
    x0, y0 = math.floor(x), math.floor(y)
    fx, fy = x - x0, y - y0
    out = []
    for dy, wy in ((0, 1 - fy), (1, fy)):
        for dx, wx in ((0, 1 - fx), (1, fx)):
            tx = img.texel(wrap_index(x0 + dx, img.width, wrap_mode_of[0]), wrap_index(y0 + dy, img.height, wrap_mode_of[0]))
            out.append({"level": level, "x": x0 + dx, "y": y0 + dy, "weight": wx * wy * share, "value": tx})
    return out


wrap_mode_of = ["repeat"]


def trilinear_texels(pyr, s, t, level, wrap):
    wrap_mode_of[0] = wrap
    # checking-your-ray-tracer.md, `texels`: x, y are "of st brought into one
    # period of the wrap (st mod 1 for repeat and clamp, st mod 2 for mirror),
    # before the texel index itself wraps"
    period = 2.0 if wrap == "mirror" else 1.0
    s -= math.floor(s / period) * period
    t -= math.floor(t / period) * period
    last = len(pyr.levels) - 1
    l0 = int(math.floor(level))
    f = level - l0
    out = bilinear_texels(pyr.levels[l0], s, t, l0, 1 - f if l0 < last else 1.0)
    if f > 0 and l0 < last:
        out += bilinear_texels(pyr.levels[l0 + 1], s, t, l0 + 1, f)
    return out


def trilinear_at_level(pyr, s, t, level, wrap):
    """The level clamped to [0, levels - 1]; bilinear in floor(level) and the next,
    blended by the fraction (grading-stages.md, the texture stage)."""
    last = len(pyr.levels) - 1
    if not (level == level) or level < 0:
        level = 0.0
    level = min(level, float(last))
    l0 = int(math.floor(level))
    f = level - l0
    a = bilinear(pyr.levels[l0], s, t, wrap)
    if f == 0 or l0 >= last:
        return a
    b = bilinear(pyr.levels[l0 + 1], s, t, wrap)
    return tuple((1 - f) * x + f * y for x, y in zip(a, b))


# ----------------------------------------------------------------------------
# Textures
# ----------------------------------------------------------------------------

class Constant:
    kind = "constant"

    def __init__(self, color):
        self.color = color


class Checkerboard:
    kind = "checkerboard"

    def __init__(self, colors, checks, filt):
        self.colors = colors
        self.checks = checks
        self.filter = filt

    def point(self, u, v):
        i = math.floor(u * self.checks) + math.floor(v * self.checks)
        return self.colors[i % 2], i % 2


class ImageTexture:
    kind = "image"

    def __init__(self, image_loader, wrap, filt):
        self._loader = image_loader
        self._image = None
        self._pyramid = None
        self.wrap = wrap
        self.filter = filt

    @property
    def image(self):
        if self._image is None:
            self._image = self._loader()
        return self._image

    @property
    def pyramid(self):
        if self._pyramid is None:
            self._pyramid = Pyramid(self.image)
        return self._pyramid


def checker_image(colors, checks, ppc):
    """scene-format.md: the checkerboard rasterised, checks * pixels_per_check a side;
    st = (u, 1 - v), so row 0 is v = 1."""
    side = checks * ppc
    data = []
    for y in range(side):
        cv = checks - 1 - y // ppc
        for x in range(side):
            cu = x // ppc
            data.append(colors[(cu + cv) % 2])
    return Image(side, side, data)


# ----------------------------------------------------------------------------
# Shapes
# ----------------------------------------------------------------------------

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


# ----------------------------------------------------------------------------
# Materials, lights, environment, camera, scene
# ----------------------------------------------------------------------------

class Material:
    def __init__(self, name, table, textures):
        self.name = name
        self.mirror = "mirror" in table
        if self.mirror:
            self.reflectivity = 1.0
            self.tint = vec(table["mirror"])
            self.diffuse = None
            self.specular = None
        else:
            self.reflectivity = float(table.get("reflectivity", 0.0))
            self.tint = vec(table.get("reflection_tint", (1, 1, 1)))
            self.diffuse = self._tex(table["diffuse"], textures)
            self.specular = self._tex(table["specular"], textures) if "specular" in table else None
        self.shininess = float(table.get("shininess", 1.0))
        self.lobe = table.get("lobe", "phong")
        self.uv_scale = tuple(float(x) for x in table.get("uv_scale", (1, 1)))
        self.uv_offset = tuple(float(x) for x in table.get("uv_offset", (0, 0)))

    @staticmethod
    def _tex(value, textures):
        if isinstance(value, str):
            return textures[value]
        return Constant(vec(value))


class AreaLight:
    kind = "area"

    def __init__(self, index, table):
        self.index = index
        self.center = vec(table["center"])
        self.e1 = vec(table["edge1"])
        self.e2 = vec(table["edge2"])
        self.normal = normalize(vec(table["normal"])) if "normal" in table else normalize(cross(self.e1, self.e2))
        self.color = vec(table.get("color", (1, 1, 1)))
        # step 8: origin = center - (edge1 + edge2)/2, p = origin + u.x edge1 + u.y edge2
        self.origin = sub(self.center, mul(add(self.e1, self.e2), 0.5))
        self.name = table.get("name")

    def point_at(self, ux, uy):
        return add(self.origin, add(mul(self.e1, ux), mul(self.e2, uy)))


class PointLight:
    kind = "point"

    def __init__(self, index, table):
        self.index = index
        self.position = vec(table["position"])
        self.color = vec(table.get("color", (1, 1, 1)))
        self.normal = None


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


class Scene:
    def __init__(self, path):
        self.path = path
        base = os.path.dirname(os.path.abspath(path))
        with open(path, "rb") as f:
            doc = tomllib.load(f)
        if doc.get("shading", "phong") != "phong":
            raise SystemExit("this tracer implements the course's Phong model only")
        self.ambient = vec(doc.get("ambient", (0, 0, 0)))
        r = doc.get("render", {})
        self.width, self.height = (int(x) for x in r.get("resolution", (512, 512)))
        self.spp = int(r.get("spp", 16))
        self.light_samples = int(r.get("light_samples", 16))
        self.seed = int(r.get("seed", 0))
        self.max_depth = int(r.get("max_depth", 4))
        self.environment_samples = int(r.get("environment_samples", 16))
        self.camera = Camera(doc["camera"], self.width, self.height)
        self.environment = Environment(doc["environment"], base) if "environment" in doc else None

        self.textures = {}
        for name, table in doc.get("textures", {}).items():
            (kind, t), = table.items()
            if kind == "checkerboard":
                self.textures[name] = Checkerboard([vec(c) for c in t["colors"]], int(t["checks"]),
                                                   t.get("filter", "point"))
            elif kind == "checker_image":
                cols = [vec(c) for c in t["colors"]]
                ch, ppc = int(t["checks"]), int(t.get("pixels_per_check", 32))
                self.textures[name] = ImageTexture(lambda cols=cols, ch=ch, ppc=ppc: checker_image(cols, ch, ppc),
                                                   t.get("wrap", "repeat"), t.get("filter", "trilinear"))
            elif kind == "image":
                p = os.path.join(base, t["file"])
                self.textures[name] = ImageTexture(lambda p=p: read_image(p), t.get("wrap", "repeat"),
                                                   t.get("filter", "trilinear"))
            else:
                raise SystemExit(f"texture kind {kind} not supported")
        self.materials = {n: Material(n, t, self.textures) for n, t in doc.get("materials", {}).items()}

        # objects: spheres, parallelograms, planes, boxes (a box with
        # face_materials is six parallelograms), then the lights' surfaces
        objs = []

        def push(shape, mat, name):
            objs.append(SceneObject(len(objs), shape, mat, name))

        for i, t in enumerate(doc.get("sphere", [])):
            push(Sphere(vec(t["center"]), float(t["radius"])), self.materials[t["material"]],
                 t.get("name", f"sphere[{i}]"))
        for i, t in enumerate(doc.get("parallelogram", [])):
            push(Parallelogram(vec(t["origin"]), vec(t["edge1"]), vec(t["edge2"]),
                               vec(t["normal"]) if "normal" in t else None, bool(t.get("two_sided", False))),
                 self.materials[t["material"]], t.get("name", f"parallelogram[{i}]"))
        for i, t in enumerate(doc.get("plane", [])):
            push(Plane(vec(t["point"]), vec(t["normal"]), float(t.get("tile_size", 1.0)),
                       bool(t.get("two_sided", False))), self.materials[t["material"]], t.get("name", f"plane[{i}]"))
        for i, t in enumerate(doc.get("box", [])):
            lo, hi = vec(t["min"]), vec(t["max"])
            if "face_materials" in t:
                for (o, a, b, n), m, fn in zip(box_faces(lo, hi), t["face_materials"], FACES):
                    push(Parallelogram(vec(o), vec(a), vec(b), vec(n), True), self.materials[m],
                         f"{t.get('name', f'box[{i}]')}.{fn}")
            else:
                push(Box(lo, hi), self.materials[t["material"]], t.get("name", f"box[{i}]"))
        if doc.get("mesh"):
            raise SystemExit("meshes are not supported by this tracer")
        self.point_lights = [PointLight(i, t) for i, t in enumerate(doc.get("point_light", []))]
        self.area_lights = [AreaLight(len(self.point_lights) + i, t) for i, t in enumerate(doc.get("area_light", []))]
        self.lights = self.point_lights + self.area_lights
        for i, L in enumerate(self.area_lights):
            shape = Parallelogram(L.origin, L.e1, L.e2, L.normal, False)
            o = SceneObject(len(objs), shape, None, L.name or f"area_light[{i}]", light=L)
            objs.append(o)
        self.objects = objs
        self.size = self._size()

    def _size(self):
        """scene-format.md step 9: "the scene's size, the longest side of the box
        around its finite shapes, an infinite plane left out".  The lights'
        surfaces are shapes of the scene (objects of the intersection stage), so
        they count."""
        pts = []
        for obj in self.objects:
            sh = obj.shape
            if isinstance(sh, Sphere):
                pts += [sub(sh.center, (sh.radius,) * 3), add(sh.center, (sh.radius,) * 3)]
            elif isinstance(sh, Parallelogram):
                o, a, b = sh.origin, sh.e1, sh.e2
                pts += [o, add(o, a), add(o, b), add(add(o, a), b)]
            elif isinstance(sh, Box):
                for f in sh.faces:
                    o, a, b = f.origin, f.e1, f.e2
                    pts += [o, add(o, a), add(o, b), add(add(o, a), b)]
            # Plane: infinite, left out
        if not pts:
            return 1.0  # the docs give no size to a scene of planes alone
        return max(max(q[i] for q in pts) - min(q[i] for q in pts) for i in range(3))

    # scene-format.md step 3: smallest t > 0, ties to the lowest object
    def closest_hit(self, o, d, tmax=INF):
        best_t, best = tmax, None
        for obj in self.objects:
            t = obj.shape.intersect_t(o, d, best_t)
            if t is not None and t < best_t:
                best_t, best = t, obj
        if best is None:
            return None
        return best.shape.hit(o, d, best_t, best.index)

    def tests(self, o, d):
        return [(obj, obj.shape.intersect_t(o, d)) for obj in self.objects]


# ----------------------------------------------------------------------------
# Shading rules (scene-format.md, "How a pixel is computed", steps 5-11)
# ----------------------------------------------------------------------------

def phong_terms(kd, ks, shininess, lobe, n, v, l):
    """Step 7: diffuse kd*(n.l), specular ks*lobe, both 0 where n.l <= 0."""
    ndl = dot(n, l)
    r = sub(mul(n, 2 * ndl), l)
    if ndl <= 0:
        return ndl, r, ZERO, ZERO
    if mistake("view-sign"):
        # MISTAKE view-sign: the view vector's sign flipped in the specular term
        v = neg(v)
    if lobe == "blinn-phong" or mistake("blinn"):
        # (MISTAKE blinn: the half vector's lobe for a Phong material too)
        h = normalize(add(l, v))
        base = max(0.0, dot(n, h))
    else:
        base = max(0.0, dot(r, v))
    lob = base ** shininess if not (base == 0 and shininess == 0) else 1.0
    return ndl, r, mul(kd, ndl), mul(ks, lob)


def shadow_test(scene, x, ng, p, eps):
    """Step 9, corrected rule: start at o = x + eps*ng (ng turned to the light's
    side), aim at p from o, a blocker only at 0 < t < |p - o| - eps.
    Returns None (unoccluded) or (object index, t as a fraction of |p - o|)."""
    if dot(ng, sub(p, x)) < 0:
        ng = neg(ng)
    o = add(x, mul(ng, eps))
    to = sub(p, o)
    dist = length(to)
    d = mul(to, 1 / dist)
    if mistake("light-blocks-itself"):
        # MISTAKE light-blocks-itself: aimed along the shading's l (from x) out of
        # the offset start, which meets the light's own plane short of the end
        d = normalize(sub(p, x))
    if mistake("no-shadow-offset"):
        # MISTAKE no-shadow-offset: the ray starts exactly at x (any t > 0 blocks),
        # still stopping eps short of the light
        o, d = x, normalize(sub(p, x))
        dist = length(sub(p, x))
    best_t, best = dist - eps, None
    for obj in scene.objects:
        t = obj.shape.intersect_t(o, d, best_t)
        if t is not None and t < best_t:
            best_t, best = t, obj.index
    if best is None:
        return None
    # checking-your-ray-tracer.md, the verdicts table: t is "where it lies as a
    # fraction of the segment from the hit point x to the light sample p ...
    # (a tracer with a fixed offset intersects the blocker along x -> p again,
    # or reports (eps + t')/|p - x| for the t' along its own ray)".  The first.
    full = length(sub(p, x))
    t_x = scene.objects[best].shape.intersect_t(x, normalize(sub(p, x)), full)
    if t_x is not None:
        return best, t_x / full
    return best, (best_t + eps) / full


def light_sample_points(light, n):
    """Step 8: grid cell centres ((i mod k) + 1/2, (i div k) + 1/2)/k."""
    if light.kind == "point":
        return [light.position]
    k = int(round(math.sqrt(n)))
    if k * k != n:
        raise SystemExit("--light-sampler grid needs a perfect square of light samples")
    if mistake("light-centre"):
        # MISTAKE light-centre: all n samples at the light's centre (still n of them)
        return [light.center] * n
    return [light.point_at(((i % k) + 0.5) / k, ((i // k) + 0.5) / k) for i in range(n)]


def sample_light(scene, light, p, x, n, ng, v, kd, ks, mat_shininess, lobe, eps):
    """One light sample (steps 7 and 8). Returns a dict in explain's layout and
    the verdict of grading-stages.md (unlit, blocked, visible) with the blocker."""
    l = normalize(sub(p, x))
    ndl, r, diff, spec = phong_terms(kd, ks, mat_shininess, lobe, n, v, l)
    s = {"position": p, "l": l, "n_dot_l": ndl, "reflection": r, "diffuse": diff, "specular": spec}
    verdict, blocker, t = None, None, None
    if light.kind == "area" and dot(light.normal, sub(x, p)) <= 0:
        verdict, s["shadow"] = "unlit", {"not_traced": "behind the light"}
    elif dot(ng, l) <= 0:
        verdict, s["shadow"] = "unlit", {"not_traced": "below the surface"}
    elif add(diff, spec) == ZERO:
        verdict, s["shadow"] = "unlit", {"not_traced": "zero BRDF"}
    else:
        b = shadow_test(scene, x, ng, p, eps)
        if b is None:
            verdict, s["shadow"] = "visible", "unoccluded"
        else:
            blocker, t = b
            verdict, s["shadow"] = "blocked", {"blocked_by": blocker, "t": t}
    s["value"] = add(diff, spec) if verdict == "visible" else ZERO
    return s, verdict, blocker


# ----------------------------------------------------------------------------
# Ray differentials and texture lookups (texture-filtering.md, pbrt-v4 10.1)
# ----------------------------------------------------------------------------

def report_level_of(L, W):
    """The report's MIP level, log2(L/W) (checking-your-ray-tracer.md)."""
    if mistake("mip-natural-log"):
        # MISTAKE mip-natural-log: the natural log instead of log2
        return math.log(L / W)
    return math.log2(L / W)


def footprint_at(hit, rd):
    """Intersect the offset rays with the tangent plane; least squares for duv."""
    if rd is None:
        return None
    (rxo, rxd), (ryo, ryd) = rd
    n = hit.ng
    dd = dot(n, hit.point)
    tx = (dd - dot(n, rxo)) / dot(n, rxd)
    ty = (dd - dot(n, ryo)) / dot(n, ryd)
    dpdx = sub(add(rxo, mul(rxd, tx)), hit.point)
    dpdy = sub(add(ryo, mul(ryd, ty)), hit.point)
    a00, a01, a11 = dot(hit.dpdu, hit.dpdu), dot(hit.dpdu, hit.dpdv), dot(hit.dpdv, hit.dpdv)
    det = a00 * a11 - a01 * a01
    inv = 1 / det if det != 0 else 0.0

    def solve(dp):
        b0, b1 = dot(hit.dpdu, dp), dot(hit.dpdv, dp)
        return ((a11 * b0 - a01 * b1) * inv, (a00 * b1 - a01 * b0) * inv)

    return dpdx, dpdy, solve(dpdx), solve(dpdy)


def uses_footprint(tex):
    if isinstance(tex, ImageTexture):
        return tex.filter in ("trilinear", "ewa")
    if isinstance(tex, Checkerboard):
        return tex.filter == "analytic"
    return False


def lookup(tex, uv_m, duvdx_m, duvdy_m, report, at_report_level=False):
    """Returns (value, explain dict).  uv_m and its derivatives are after the
    material's uv transform.  at_report_level: --texture-level report at a camera
    ray's hit, where an image is read trilinearly at the report's level instead of
    with its own filter (command-line.md, Textures; checking-your-ray-tracer.md,
    the texture stage: "Glint reads image textures trilinearly at this level at
    every camera ray's hit, so that `Glint's level` below is the report's")."""
    if isinstance(tex, Constant):
        return tex.color, {"kind": "constant", "value": tex.color}
    if isinstance(tex, Checkerboard):
        if tex.filter != "point":
            raise SystemExit("the analytic checkerboard filter is not implemented")
        c, which = tex.point(*uv_m)
        return c, {"kind": "checkerboard", "value": c, "second_color_fraction": float(which)}
    img = tex.image
    st = (uv_m[0], 1 - uv_m[1])
    dst_dx = (duvdx_m[0], -duvdx_m[1])
    dst_dy = (duvdy_m[0], -duvdy_m[1])
    out = {"kind": tex.filter, "st": st, "dst_dx": dst_dx, "dst_dy": dst_dy}
    if report is not None:
        L, Wj = report
        m = max(img.width, img.height)
        W = Wj / m
        out["report_level"] = report_level_of(L, W)
        out["report_l"], out["report_w"], out["report_m"] = L, W, m
    else:
        out["report_level"] = None
    if at_report_level and out["report_level"] is not None and math.isfinite(out["report_level"]):
        # grading-stages.md, the texture stage's filtered value: "trilinear at the
        # report's level, the level clamped to [0, levels - 1] (a level below 0
        # reads the image bilinearly)".  The caller (Tracer.textures) has already
        # put the report's square footprint, 2^level/m wide, in duvdx_m/duvdy_m
        # (checking-your-ray-tracer.md, the texture stage).
        last = len(tex.pyramid.levels) - 1
        glevel = min(max(out["report_level"], 0.0), float(last))
        out["kind"] = "trilinear"
        out["glint_level"] = glevel
        val = trilinear_at_level(tex.pyramid, st[0], st[1], glevel, tex.wrap)
        out["texels"] = trilinear_texels(tex.pyramid, st[0], st[1], glevel, tex.wrap)
    elif tex.filter == "nearest":
        x = wrap_index(math.floor(st[0] * img.width), img.width, tex.wrap)
        y = wrap_index(math.floor(st[1] * img.height), img.height, tex.wrap)
        val = img.texel(x, y)
        out["glint_level"] = 0.0
    elif tex.filter == "bilinear":
        val = bilinear(img, st[0], st[1], tex.wrap)
        out["glint_level"] = 0.0
    elif tex.filter == "trilinear":
        # texture-filtering.md: log2(width * max(w, h)), width = max(longer/2, shorter)
        a, b = math.hypot(*dst_dx), math.hypot(*dst_dy)
        width = max(max(a, b) / 2, min(a, b))
        level = math.log2(width * max(img.width, img.height)) if width > 0 else -INF
        last = len(tex.pyramid.levels) - 1
        glevel = 0.0 if not (level == level) or level < 0 else min(level, float(last))
        out["glint_level"] = glevel
        val = trilinear_at_level(tex.pyramid, st[0], st[1], glevel, tex.wrap)
        out["texels"] = trilinear_texels(tex.pyramid, st[0], st[1], glevel, tex.wrap)
    else:
        raise SystemExit("the ewa filter is not implemented by this tracer")
    out["value"] = val
    return val, out


# ----------------------------------------------------------------------------
# The integrator (steps 3-11), recording explain's document as it goes
# ----------------------------------------------------------------------------

class Tracer:
    def __init__(self, scene, light_samples, eps, env_samples=0, texture_level="footprint"):
        self.scene = scene
        self.texture_level = texture_level
        if texture_level == "report":
            # command-line.md, Textures: "--texture-level report reads every image
            # texture trilinearly" (another --texture-filter is bad input), so every
            # image is a trilinear one, filtered over a footprint; at a camera ray's
            # hit it is read at the report's level, and "a mirror's reflection rays,
            # for which the report gives no level, keep the footprint".
            for m in scene.materials.values():
                for t in (m.diffuse, m.specular):
                    if isinstance(t, ImageTexture):
                        t.filter = "trilinear"
        self.light_samples = light_samples
        self.eps = eps
        if env_samples:
            raise SystemExit("environment samples are not implemented: pass --environment-samples 0")
        self.needs_footprint = any(
            m.diffuse is not None and (uses_footprint(m.diffuse) or (m.specular is not None and uses_footprint(m.specular)))
            for m in scene.materials.values()) or scene.environment is not None

    def trace(self, o, d, depth, rd, shown_from=None):
        """Returns (radiance, the ray's explain dict). rd: ray differentials
        ((rx_origin, rx_dir), (ry_origin, ry_dir)) or None.  shown_from: for a
        reflection ray, the mirror's hit point, which explain shows as the
        origin (checking-your-ray-tracer.md: "its origin usually prints as the
        point"), t then counting from it."""
        sc = self.scene
        rec = {"depth": depth}
        hit = sc.closest_hit(o, d)
        inter = {"origin": o if shown_from is None else shown_from, "direction": d}
        rec["intersect"] = inter
        if hit is None:
            inter["hit"] = None
            if sc.environment is None:
                return ZERO, rec
            width = self.env_width(d, rd)
            rad = sc.environment.lookup(d, width)
            rec["environment"] = {"direction": d, "filter_width": width, "radiance": rad}
            return rad, rec
        obj = sc.objects[hit.obj]
        front = dot(hit.ng, d) < 0
        shown_t = hit.t if shown_from is None else hit.t + dot(sub(o, shown_from), d)
        inter["hit"] = {"object": hit.obj, "kind": obj.kind, "triangle": 0, "t": shown_t, "point": hit.point,
                        "geometric_normal": hit.ng, "shading_normal": hit.ng, "uv": hit.uv,
                        "dpdu": hit.dpdu, "dpdv": hit.dpdv, "front_face": front}
        rec["object"] = hit.obj
        rec["triangle"] = 0
        if obj.light is not None:  # step 4: the light's colour, nothing shaded
            rec["emitter"] = {"radiance": obj.light.color}
            return obj.light.color, rec
        mat = obj.material
        v = neg(d)
        n = hit.ng if front else neg(hit.ng)  # step 5: facing normal
        ng = n
        fp = None
        if rd is not None and self.needs_footprint:
            fp = footprint_at(hit, rd)
        local = ZERO
        if mat.reflectivity < 1:
            kd, ks, tex = self.textures(mat, obj, hit, d, depth, fp)
            rec["texture"] = tex
            rec["shading"] = {"n": n, "ng": ng, "v": v}
            ambient = cmul(sc.ambient, kd)  # step 6
            if mistake("no-ambient"):
                # MISTAKE no-ambient: the ambient term left out (recorded as 0)
                ambient = ZERO
            lights = []
            local = ambient
            for light in sc.lights:  # step 7: point lights, then area lights
                pts = light_sample_points(light, self.light_samples if light.kind == "area" else 1)
                samples = []
                acc = ZERO
                for k, p in enumerate(pts):
                    s, _, _ = sample_light(sc, light, p, hit.point, n, ng, v, kd, ks, mat.shininess, mat.lobe,
                                           self.eps)
                    acc = add(acc, s["value"])
                    s["running_average"] = mul(acc, 1 / (k + 1))
                    samples.append(s)
                total = cmul(light.color, mul(acc, 1 / len(pts)))
                if mistake("light-sum-not-divided"):
                    # MISTAKE light-sum-not-divided: the sum, not the mean (the
                    # running averages above are left as they should be)
                    total = cmul(light.color, acc)
                lights.append({"light": light.index, "kind": light.kind, "samples": samples, "total": total})
                local = add(local, total)
            rec["light"] = {"ambient": ambient, "lights": lights, "environment": None}
        mirror = ZERO
        r = mat.reflectivity
        if r > 0 and depth < sc.max_depth:  # step 11
            wi = sub(mul(n, 2 * dot(v, n)), v)
            # scene-format.md step 11: "A tracer with a fixed offset starts the
            # reflection at x + eps*wi, along the reflected direction".
            o2 = add(hit.point, mul(wi, self.eps))
            # environment-lighting.md, Mirrors: "The offset rays start at the hit
            # point plus dp/dx and dp/dy, not at the main ray's offset origin"
            # (reflect_differentials returns them so).
            rd2 = self.reflect_differentials(hit, n, v, wi, rd, fp, obj)
            rec["mirror"] = {"reflectivity": r, "tint": mat.tint, "direction": wi}
            lr, rrec = self.trace(o2, wi, depth + 1, rd2, shown_from=hit.point)
            rec["reflection"] = rrec
            mirror = cmul(mat.tint, lr)
        value = add(mul(local, 1 - r), mul(mirror, r))
        rec["radiance"] = {"local": local, "mirror": mirror, "value": value}
        return value, rec

    def textures(self, mat, obj, hit, d, depth, fp):
        su, sv = mat.uv_scale
        ou, ov = mat.uv_offset
        uv = hit.uv
        uvm = (uv[0] * su + ou, uv[1] * sv + ov)
        uses = uses_footprint(mat.diffuse) or (mat.specular is not None and uses_footprint(mat.specular))
        if fp is not None and uses:
            duvdx, duvdy = fp[2], fp[3]
        else:
            duvdx, duvdy = (0.0, 0.0), (0.0, 0.0)
        dmx = (duvdx[0] * su, duvdx[1] * sv)
        dmy = (duvdy[0] * su, duvdy[1] * sv)
        report = None
        if depth == 0:
            report = self.report_parts(obj, hit, d, mat)
        # --texture-level report: image textures at the report's level at the
        # camera ray's hit only; a mirror's reflection rays keep the footprint.
        at_report = self.texture_level == "report" and depth == 0
        if at_report and report is not None:
            # checking-your-ray-tracer.md, the texture stage: "At such a hit the
            # lookup's footprint is the square one whose trilinear level is the
            # report's, not the ray differentials': dst/dx = (w, 0), dst/dy =
            # (0, -w) with w = 2^l / m (l the report's level, unclamped), and
            # duv/dx = (w/s_u, 0), duv/dy = (0, w/s_v)".  m is the image's, so the
            # material's first image texture (diffuse, then specular) sets it;
            # where the report gives no finite level the footprint stays.
            img_tex = next((t for t in (mat.diffuse, mat.specular) if isinstance(t, ImageTexture)), None)
            if img_tex is not None:
                L, Wj = report
                m = max(img_tex.image.width, img_tex.image.height)
                level = report_level_of(L, Wj / m) if L > 0 and Wj > 0 else float("nan")
                if math.isfinite(level):
                    w = 2.0 ** level / m
                    duvdx, duvdy = (w / su, 0.0), (0.0, w / sv)
                    dmx, dmy = (w, 0.0), (0.0, w)
        kd, dl = lookup(mat.diffuse, uvm, dmx, dmy, report, at_report)
        tex = {"footprint": {"uv": uv, "duvdx": duvdx, "duvdy": duvdy}, "material_uv": uvm, "diffuse": dl}
        if mat.specular is None:
            ks = kd
            tex["specular"] = "the diffuse texture's (ks = kd)"
        else:
            ks, sl = lookup(mat.specular, uvm, dmx, dmy, report, at_report)
            tex["specular"] = sl
        tex["kd"], tex["ks"] = kd, ks
        return kd, ks, tex

    def report_parts(self, obj, hit, d, mat):
        """checking-your-ray-tracer.md: L = 2 t tan(fov/2) / (r |N.D|), |J_T| =
        sqrt|dpdu x dpdv| / sqrt|su sv|."""
        sc = self.scene
        L = 2 * hit.t * math.tan(math.radians(sc.camera.fov) / 2) / (sc.height * abs(dot(hit.ng, d)))
        J = math.sqrt(length(cross(hit.dpdu, hit.dpdv))) / math.sqrt(abs(mat.uv_scale[0] * mat.uv_scale[1]))
        return L, J

    def reflect_differentials(self, hit, n, v, wi, rd, fp, obj):
        """pbrt-v4's specular-reflection rule for ray differentials."""
        if rd is None or not self.needs_footprint:
            return None
        if fp is None:
            fp = footprint_at(hit, rd)
        dpdx, dpdy, _, _ = fp
        (rxo, rxd), (ryo, ryd) = rd
        shape = obj.shape
        if isinstance(shape, Sphere):
            sgn = 1.0 if dot(n, hit.ng) > 0 else -1.0
            dndx, dndy = mul(dpdx, sgn / shape.radius), mul(dpdy, sgn / shape.radius)
        else:
            dndx = dndy = ZERO
        wo = v
        out = []
        for dp, dd, dn in ((dpdx, rxd, dndx), (dpdy, ryd, dndy)):
            # environment-lighting.md, Mirrors: "each incoming offset direction is
            # normalised first (pbrt-v4 uses them as they come)"
            dd = normalize(dd)
            dwo = sub(neg(dd), wo)
            dwo_n = dot(dwo, n) + dot(wo, dn)
            nd = add(sub(wi, dwo), mul(add(mul(dn, dot(wo, n)), mul(n, dwo_n)), 2))
            # "The offset rays start at the hit point plus dp/dx and dp/dy"
            out.append((add(hit.point, dp), nd))
        return tuple(out)

    def env_width(self, d, rd):
        """environment-lighting.md, Mirrors: filter_width = max(angle(d, d_x),
        angle(d, d_y)), each 2*atan2(|a - b|, |a + b|) of the unit directions."""
        if rd is None:
            return 0.0
        (_, rxd), (_, ryd) = rd
        a = normalize(d)

        def angle(b):
            b = normalize(b)
            return 2 * math.atan2(length(sub(a, b)), length(add(a, b)))

        return max(angle(rxd), angle(ryd))


# ----------------------------------------------------------------------------
# Film (step 13)
# ----------------------------------------------------------------------------

def srgb8(c):
    if not (c == c):
        c = 0.0
    c = min(1.0, max(0.0, c))
    if mistake("gamma-22"):
        # MISTAKE gamma-22: a plain power curve instead of the sRGB curve
        return int(math.floor(255 * c ** (1 / 2.2) + 0.5))
    e = 12.92 * c if c <= 0.0031308 else 1.055 * c ** (1 / 2.4) - 0.055
    return int(math.floor(255 * e + 0.5))


# ----------------------------------------------------------------------------
# explain
# ----------------------------------------------------------------------------

def clean(x):
    """JSON-ready: tuples to lists, non-finite to null."""
    if isinstance(x, dict):
        return {k: clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [clean(v) for v in x]
    if isinstance(x, float):
        return x if math.isfinite(x) else None
    return x


def cmd_explain(args):
    scene = Scene(args.scene)
    spp = args.spp if args.spp is not None else scene.spp
    ls = args.light_samples if args.light_samples is not None else scene.light_samples
    if args.sampler != "grid" or args.light_sampler != "grid":
        raise SystemExit("only the grid patterns are reproducible: pass --sampler grid --light-sampler grid")
    k = int(round(math.sqrt(spp)))
    if k * k != spp:
        raise SystemExit("--sampler grid needs a perfect square spp")
    X, Y = (int(v) for v in args.pixel.split(","))
    tracer = Tracer(scene, ls, epsilon_of(scene, args), args.environment_samples, args.texture_level)
    cam = scene.camera
    s_shrink = max(1 / math.sqrt(spp), 1 / 8)
    follow = range(spp) if args.all_samples else [args.sample]
    samples = []
    total = ZERO
    for i in range(spp):
        x = X + ((i % k) + 0.5) / k  # step 1, grid
        y = Y + ((i // k) + 0.5) / k
        if mistake("pixel-corner"):
            # MISTAKE pixel-corner: the cell's corner, (i mod k)/k, without the + 1/2
            x, y = X + (i % k) / k, Y + (i // k) / k
        ndc, fp = cam.film_point(x, y)
        d = normalize(fp)
        camrec = {"raster": (x, y), "ndc": ndc, "film_point": fp, "origin": cam.eye, "direction": d}
        rd = None
        if tracer.needs_footprint:
            dx = cam.ray(x + 1, y)[1]
            dy = cam.ray(x, y + 1)[1]
            rxd = add(d, mul(sub(dx, d), s_shrink))
            ryd = add(d, mul(sub(dy, d), s_shrink))
            rd = ((cam.eye, rxd), (cam.eye, ryd))
            camrec["differentials"] = {"rx_origin": cam.eye, "rx_direction": rxd, "ry_origin": cam.eye,
                                       "ry_direction": ryd}
        else:
            camrec["differentials"] = None
        rad, rec = tracer.trace(cam.eye, d, 0, rd)
        if all(math.isfinite(c) for c in rad):
            total = add(total, rad)
        if i in follow:
            samples.append({"sample": i, "camera": camrec, "ray": rec, "radiance": rad})
    pix = mul(total, 1 / spp)
    # checking-your-ray-tracer.md, "Settings first": the document records the
    # settings it was made with (spp, sampler, light_samples, light_sampler,
    # environment_samples, texture_level, seed), which --against checks before
    # any number.  --texture-level footprint (Glint's default) reads image
    # textures at the level of the ray differentials' footprint; report reads
    # them trilinearly at the report's log2(L/W) at camera rays' hits.
    doc = {"schema": "glint-explain/1", "pixel": [X, Y], "resolution": [scene.width, scene.height], "spp": spp,
           "sampler": args.sampler, "light_samples": ls, "light_sampler": args.light_sampler,
           "environment_samples": args.environment_samples, "texture_level": args.texture_level, "seed": scene.seed,
           "samples": samples,
           "film": {"radiance": pix, "samples_averaged": spp, "srgb8": [srgb8(c) for c in pix]}}
    text = json.dumps(clean(doc), indent=1)
    if args.output == "-":
        print(text)
    else:
        with open(args.output, "w") as f:
            f.write(text + "\n")


# ----------------------------------------------------------------------------
# stages
# ----------------------------------------------------------------------------

def fnum(s):
    return float(s) if s not in ("", None) else None


def read_inputs(vectors, stage):
    path = os.path.join(vectors, f"{stage}-inputs.csv")
    if not os.path.exists(path):
        return None
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def write_answers(answers, stage, header, rows):
    with open(os.path.join(answers, f"{stage}.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        for r in rows:
            w.writerow(["" if v is None else (repr(v) if isinstance(v, float) else v) for v in r])


def cell_corner(r):
    """For MISTAKE pixel-corner: a case's raster coordinate is a grid cell's centre,
    X + (j + 1/2)/k (grading-stages.md, where the cases come from); its cell's
    corner X + j/k is r less half a cell, 1/(2k), the largest power of 2 whose odd
    multiple the fraction r - X is."""
    f = r - math.floor(r)
    h = 0.5
    while h > 2 ** -20:
        q = f / h
        if q == int(q) and int(q) % 2 == 1:
            return r - h
        h /= 2
    return r


def stage_camera(scene, cases):
    rows = []
    for c in cases:
        x, y = float(c["x"]), float(c["y"])
        if mistake("pixel-corner"):
            # MISTAKE pixel-corner: the student's camera shoots each grid sample
            # through its cell's corner, so it answers the case's raster position
            # (a cell centre) with that cell's corner, the + 1/2 left out
            x, y = cell_corner(x), cell_corner(y)
        o, d = scene.camera.ray(x, y, int(c["width"]), int(c["height"]))
        rows.append([c["id"], *o, *d])
    return ["id", "origin_x", "origin_y", "origin_z", "direction_x", "direction_y", "direction_z"], rows


def stage_intersection(scene, cases):
    header = ["id", "hit", "t", "point_x", "point_y", "point_z", "geometric_normal_x", "geometric_normal_y",
              "geometric_normal_z", "shading_normal_x", "shading_normal_y", "shading_normal_z", "u", "v", "object",
              "name"]
    rows = []
    for c in cases:
        o = (fnum(c["origin_x"]), fnum(c["origin_y"]), fnum(c["origin_z"]))
        d = (fnum(c["direction_x"]), fnum(c["direction_y"]), fnum(c["direction_z"]))
        h = scene.closest_hit(o, d)
        if h is None:
            rows.append([c["id"], "false"] + [None] * 14)
            continue
        rows.append([c["id"], "true", h.t, *h.point, *h.ng, *h.ng, h.uv[0], h.uv[1], h.obj,
                     scene.objects[h.obj].name])
    return header, rows


def stage_texture(scene, cases):
    header = ["id", "l", "jacobian", "w", "level", "value_r", "value_g", "value_b"]
    rows = []
    for c in cases:
        obj = scene.objects[int(c["object"])]
        mat = obj.material
        tex = mat.diffuse if c["texture"] == "diffuse" else mat.specular
        u, v = fnum(c["u"]), fnum(c["v"])
        su, sv, ou, ov = fnum(c["scale_u"]), fnum(c["scale_v"]), fnum(c["offset_u"]), fnum(c["offset_v"])
        um, vm = u * su + ou, v * sv + ov
        t, ndd, r, fov = fnum(c["t"]), fnum(c["n_dot_d"]), fnum(c["r"]), fnum(c["fov"])
        L = 2 * t * math.tan(math.radians(fov) / 2) / (r * abs(ndd))
        area = obj.shape.jacobian_area((u, v))
        J = math.sqrt(area) / math.sqrt(abs(su * sv))
        if isinstance(tex, Checkerboard):
            val, _ = tex.point(um, vm)
            rows.append([c["id"], L, J, None, None, *val])
            continue
        m = max(tex.image.width, tex.image.height)
        W = J / m
        level = report_level_of(L, W)
        val = trilinear_at_level(tex.pyramid, um, 1 - vm, level, tex.wrap)
        rows.append([c["id"], L, J, W, level, *val])
    return header, rows


def stage_lighting(scene, cases, eps):
    rows = []
    header = None
    for c in cases:
        x = (fnum(c["point_x"]), fnum(c["point_y"]), fnum(c["point_z"]))
        n = (fnum(c["n_x"]), fnum(c["n_y"]), fnum(c["n_z"]))
        ng = (fnum(c["ng_x"]), fnum(c["ng_y"]), fnum(c["ng_z"]))
        v = (fnum(c["v_x"]), fnum(c["v_y"]), fnum(c["v_z"]))
        kd = (fnum(c["kd_r"]), fnum(c["kd_g"]), fnum(c["kd_b"]))
        ks = (fnum(c["ks_r"]), fnum(c["ks_g"]), fnum(c["ks_b"]))
        amb = (fnum(c["ambient_r"]), fnum(c["ambient_g"]), fnum(c["ambient_b"]))
        shin, lobe = fnum(c["shininess"]), c["lobe"]
        # the lights, as given, and their samples
        lights = {}
        j = 0
        while f"light{j}_kind" in c:
            kind = c[f"light{j}_kind"]
            col = (fnum(c[f"light{j}_r"]), fnum(c[f"light{j}_g"]), fnum(c[f"light{j}_b"]))
            nrm = None
            if kind == "area":
                nrm = (fnum(c[f"light{j}_normal_x"]), fnum(c[f"light{j}_normal_y"]), fnum(c[f"light{j}_normal_z"]))
            lights[j] = (kind, col, nrm)
            j += 1
        samples = []
        k = 0
        while f"s{k:02d}_light" in c:
            samples.append((int(c[f"s{k:02d}_light"]),
                            (fnum(c[f"s{k:02d}_x"]), fnum(c[f"s{k:02d}_y"]), fnum(c[f"s{k:02d}_z"]))))
            k += 1
        width = 2 if len(samples) <= 100 else 3
        ambient_term = cmul(amb, kd)
        if mistake("no-ambient"):
            # MISTAKE no-ambient: the ambient term left out (answered as 0)
            ambient_term = ZERO
        out = [c["id"], *ambient_term]
        hdr = ["id", "ambient_term_r", "ambient_term_g", "ambient_term_b"]
        sums = {j: ZERO for j in lights}
        counts = {j: 0 for j in lights}
        for k, (j, p) in enumerate(samples):
            kind, col, nrm = lights[j]
            counts[j] += 1
            if mistake("light-centre") and kind == "area":
                # MISTAKE light-centre: the student's own sample points, all at the
                # light's centre, instead of the given sNN_x/y/z (light J is the
                # scene's J-th light: point lights, then area lights, as step 7)
                assert scene.lights[j].kind == "area", (j, scene.lights[j].kind)
                p = scene.lights[j].center

            class _L:
                pass

            L = _L()
            L.kind, L.normal = kind, nrm
            s, verdict, blocker = sample_light(scene, L, p, x, n, ng, v, kd, ks, shin, lobe, eps)
            if verdict == "visible":
                sums[j] = add(sums[j], add(s["diffuse"], s["specular"]))
            tag = f"s{k:0{width}d}"
            hdr += [f"{tag}_verdict", f"{tag}_blocker", f"{tag}_diffuse_r", f"{tag}_diffuse_g", f"{tag}_diffuse_b",
                    f"{tag}_specular_r", f"{tag}_specular_g", f"{tag}_specular_b"]
            out += [verdict, blocker, *s["diffuse"], *s["specular"]]
        total = ambient_term
        for j, (kind, col, nrm) in lights.items():
            if counts[j]:
                if mistake("light-sum-not-divided"):
                    # MISTAKE light-sum-not-divided: the sum of the samples, not divided by N
                    total = add(total, cmul(col, sums[j]))
                    continue
                total = add(total, cmul(col, mul(sums[j], 1 / counts[j])))
        hdr += ["total_r", "total_g", "total_b"]
        out += list(total)
        header = header or hdr
        rows.append(out)
    return header, rows


def stage_film(scene, cases):
    rows = []
    for c in cases:
        rows.append([c["id"]] + [srgb8(fnum(c[f"radiance_{ch}"])) for ch in "rgb"])
    return ["id", "srgb8_r", "srgb8_g", "srgb8_b"], rows


def cmd_stages(args):
    scene = Scene(args.scene)
    if not os.path.isdir(args.vectors):
        raise SystemExit(f"tracer.py: {args.vectors}: no such directory of test vectors")
    eps = epsilon_of(scene, args)
    os.makedirs(args.answers, exist_ok=True)
    for stage, fn in (("camera", stage_camera), ("intersection", stage_intersection), ("texture", stage_texture),
                      ("lighting", lambda s, c: stage_lighting(s, c, eps)), ("film", stage_film)):
        cases = read_inputs(args.vectors, stage)
        if not cases:
            continue
        header, rows = fn(scene, cases)
        write_answers(args.answers, stage, header, rows)


def epsilon_of(scene, args):
    """scene-format.md step 9: "eps may be anything from 1e-5 to 1e-4 of the
    scene's size, the longest side of the box around its finite shapes, an
    infinite plane left out".  --epsilon-fraction F gives eps = F * size;
    --epsilon E, an absolute eps, overrides it."""
    if args.epsilon is not None:
        eps = args.epsilon
    else:
        eps = args.epsilon_fraction * scene.size
    if not (eps > 0 and math.isfinite(eps)):
        raise SystemExit(f"tracer.py: the shadow offset must be a positive number, not {eps}")
    return eps


def add_mistake_option(p):
    p.add_argument("--mistake", choices=sorted(MISTAKES), default=None, metavar="NAME",
                   help="make one classic student mistake on purpose (for tools/student/mistakes.py): "
                        + "; ".join(f"{k}: {v}" for k, v in MISTAKES.items()))


def add_epsilon_options(p):
    p.add_argument("--epsilon-fraction", type=float, default=1e-4, metavar="F",
                   help="shadow and mirror ray offset as a fraction of the scene's size (scene-format.md step 9: "
                        "1e-5 to 1e-4; default 1e-4)")
    p.add_argument("--epsilon", type=float, default=None, metavar="E",
                   help="an absolute offset, overriding --epsilon-fraction")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub_ = ap.add_subparsers(dest="command", required=True)
    a = sub_.add_parser("stages", help="answer glint grade --stages test vectors")
    a.add_argument("scene")
    a.add_argument("vectors")
    a.add_argument("answers")
    add_epsilon_options(a)
    add_mistake_option(a)
    e = sub_.add_parser("explain", help="write a glint-explain/1 document for one pixel")
    e.add_argument("scene")
    e.add_argument("--pixel", required=True)
    e.add_argument("--spp", type=int)
    e.add_argument("--sampler", default="grid")
    e.add_argument("--light-samples", type=int)
    e.add_argument("--light-sampler", default="grid")
    e.add_argument("--environment-samples", type=int, default=0)
    e.add_argument("--texture-level", choices=("footprint", "report"), default="footprint",
                   help="the MIP level image textures are read at: the ray differentials' footprint (default) or "
                        "the course report's log2(L/W) at every camera ray's hit, read trilinearly "
                        "(command-line.md, Textures)")
    g = e.add_mutually_exclusive_group()
    g.add_argument("--sample", type=int, default=0)
    g.add_argument("--all-samples", action="store_true")
    add_epsilon_options(e)
    add_mistake_option(e)
    e.add_argument("-o", "--output", default="-")
    args = ap.parse_args(argv)
    global MISTAKE
    MISTAKE = args.mistake
    try:
        if args.command == "stages":
            cmd_stages(args)
        else:
            cmd_explain(args)
    except SystemExit:
        raise
    except Exception as exc:  # one line on stderr, non-zero status (TRACER_DEBUG=1: the traceback)
        if os.environ.get("TRACER_DEBUG"):
            raise
        print(f"tracer.py: error: {type(exc).__name__}: {exc}", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
