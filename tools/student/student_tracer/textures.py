"""Textures and MIP levels (texture-filtering.md, grading-stages.md, the texture
stage): the pyramid of box-filtered levels, wrapped bilinear and trilinear
reads and the texels explain lists; the texture kinds (constant,
checkerboard, image); a hit's uv footprint from its ray differentials
(pbrt-v4 10.1), the course report's level log2(L/W), and the lookup that
returns a texture's value with explain's record of it.
"""

import math

from .images import Image
from .mistake import mistake
from .vectors import INF, add, dot, mul, sub


# ----------------------------------------------------------------------------
# The MIP pyramid and its bilinear and trilinear reads
# ----------------------------------------------------------------------------

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
# Texture kinds
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
# Ray differentials' footprints and texture lookups (texture-filtering.md, pbrt-v4 10.1)
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
