#!/usr/bin/env python3
"""A small, independent ray tracer for Glint's course Cornell scenes.

It reads Glint's TOML scene files itself (the subset the course's scenes use),
renders the course's direct lighting (Phong, area and point lights, shadows,
ambient, checkerboard textures) with numpy, vectorised over camera samples and
light samples, and writes PNG / PPM (8-bit sRGB) or PFM (linear float).

Its correct output has the same expected value as `glint render`; switches
(`--mistake NAME`) reproduce classic student mistakes, to make a corpus of
"student submissions" for `glint grade`. See README.md next to this file for
the conventions and where each comes from in Glint.

Python 3.11+ and numpy only.
"""

from __future__ import annotations

import argparse
import math
import os
import struct
import sys
import tomllib
import zlib
from dataclasses import dataclass, field

import numpy as np

# --------------------------------------------------------------------------
# Mistakes: name -> one-line description. Each is a small, commented branch
# below, found by searching for its name.
# --------------------------------------------------------------------------
MISTAKES: dict[str, str] = {
    "flipped-view": "specular term with the view vector flipped (v = ray direction, not -direction)",
    "sphere-u-sign": "sphere u angle with the wrong sign (phi = atan2(z, x) instead of atan2(-z, x))",
    "no-shadow-offset": "shadow rays start exactly at o + t*d on the surface, test t > 0, no offset/epsilon (acne)",
    "no-shadows": "no shadow rays: every light sample counts as visible",
    "no-srgb": "8-bit output written from linear values without the sRGB curve (8-bit outputs only)",
    "gamma-22": "8-bit output encoded with gamma 1/2.2 instead of the exact sRGB curve (8-bit outputs only)",
    "truncate-8bit": "8-bit quantisation by floor instead of rounding (half a step darker; arguably acceptable)",
    "summed-light-samples": "light samples summed, not averaged (no division by the light-sample count)",
    "horizontal-fov": "fov taken as the horizontal field of view (no effect on square images)",
    "fov-no-half": "film half-height f*tan(fov) instead of f*tan(fov/2) (zoomed out)",
    "pixel-corners": "samples shifted by -0.5 px (grid cell at offset 0 instead of 0.5: pixel corners)",
    "unnormalised-normals": "sphere normal p - c not divided by r in shading (uv still right)",
    "blinn-half-vector": "specular lobe n.h (half vector) in place of r.v, same exponent",
    "checker-doubled": "checkerboard frequency doubled (2N x 2N checks)",
    "sphere-v-from-y": "sphere v = (n.y + 1)/2 (the height) instead of 1 - theta/pi (the polar angle)",
    "no-ambient": "ambient term left out",
    "ambient-per-sample": "ambient*kd added inside the light-sample loop and not averaged (ambient x L; none at L = 1)",
    "ambient-in-shadow-only": "ambient*kd only for occluded light samples (the report's literal reading), averaged",
    "flipped-image": "image rows written upside down",
    "light-centre": "every light sample at the light's centre (a point light)",
    "light-twice-size": "light samples over centre +- edge instead of centre +- edge/2",
    "light-blocks-shadow": "the light's own surface blocks its shadow rays (segment tested up to and including the light point)",
    "invisible-light": "camera rays do not see the area light (they see what is behind it)",
    "two-sided-light": "area light emits (and is seen) on both sides",
    "distance-falloff": "1/r^2 falloff added to every light sample",
    "no-clamp-dots": "n.l and r.v not clamped at 0, no horizon test, shadow rays skip the object they leave (negative diffuse past the terminator)",
    "specular-white": "specular colour ks = 1 (white) instead of the diffuse colour",
    "shared-samples": "every pixel reuses the same pixel jitter and light points (correlated noise; unbiased per pixel)",
}

# Mistakes that only change the 8-bit encoding: refused for PFM output.
ENCODING_MISTAKES = {"no-srgb", "gamma-22", "truncate-8bit"}

EXIT_BAD_INPUT = 2


class InputError(Exception):
    """Bad input (scene file or command line): one line, exit status 2."""


# --------------------------------------------------------------------------
# Scene
# --------------------------------------------------------------------------
@dataclass
class Checker:
    colors: np.ndarray  # (2, 3): even checks, odd checks
    checks: int


@dataclass
class Material:
    diffuse: object  # np.ndarray (3,) or Checker
    specular: object | None  # None: = diffuse (the course's convention)
    shininess: float
    lobe: str  # "phong" | "blinn-phong"
    uv_scale: np.ndarray
    uv_offset: np.ndarray


@dataclass
class Parallelogram:
    origin: np.ndarray
    edge1: np.ndarray
    edge2: np.ndarray
    normal: np.ndarray  # unit, front side
    two_sided: bool
    material: int  # index, or -1 for a light's surface
    light: int  # index of the area light it is the surface of, or -1
    # alpha = A.p - a0, beta = B.p - b0 (edge coordinates of a point in the plane)
    A: np.ndarray = field(default=None)
    B: np.ndarray = field(default=None)
    a0: float = 0.0
    b0: float = 0.0

    def __post_init__(self):
        cross = np.cross(self.edge1, self.edge2)
        w = cross / cross.dot(cross)
        self.A = np.cross(self.edge2, w)
        self.B = np.cross(w, self.edge1)
        self.a0 = float(self.A.dot(self.origin))
        self.b0 = float(self.B.dot(self.origin))


@dataclass
class Sphere:
    center: np.ndarray
    radius: float
    material: int


@dataclass
class AreaLight:
    center: np.ndarray
    edge1: np.ndarray
    edge2: np.ndarray
    normal: np.ndarray  # unit, emitting side
    color: np.ndarray
    surface: int  # index into Scene.parallelograms


@dataclass
class PointLight:
    position: np.ndarray
    color: np.ndarray


@dataclass
class Camera:
    position: np.ndarray
    look_at: np.ndarray
    up: np.ndarray
    fov: float  # degrees, vertical
    focal_length: float


@dataclass
class Scene:
    path: str
    ambient: np.ndarray
    camera: Camera
    render: dict
    materials: list[Material]
    spheres: list[Sphere]
    parallelograms: list[Parallelogram]
    area_lights: list[AreaLight]
    point_lights: list[PointLight]
    scale: float  # a length of the scene's size, for offsets


class _Reader:
    """Reads one TOML table, refusing every key it does not know."""

    def __init__(self, path: str, table: dict, where: str):
        if not isinstance(table, dict):
            raise InputError(f"{path}: {where}: expected a table")
        self.path, self.table, self.where = path, table, where
        self.used: set[str] = set()

    def fail(self, key: str, message: str):
        name = f"{self.where}.{key}" if self.where else key
        raise InputError(f"{self.path}: {name}: {message}")

    def get(self, key, kind, default=None, required=False):
        self.used.add(key)
        if key not in self.table:
            if required:
                self.fail(key, "required key missing")
            return default
        value = self.table[key]
        try:
            return kind(value)
        except (TypeError, ValueError) as e:
            self.fail(key, str(e))

    def finish(self, ignored: set[str] = frozenset()):
        unknown = sorted(set(self.table) - self.used - set(ignored))
        if unknown:
            self.fail(unknown[0], "not supported by this tracer (refused rather than ignored)")


def _number(v):
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ValueError(f"expected a number, got {v!r}")
    if not math.isfinite(v) or abs(v) > 1e12:
        raise ValueError(f"expected a finite number of magnitude at most 1e12, got {v!r}")
    return float(v)


def _vec3(v):
    if not isinstance(v, list) or len(v) != 3:
        raise ValueError(f"expected [x, y, z], got {v!r}")
    return np.array([_number(x) for x in v], dtype=np.float64)


def _color(v):
    c = _vec3(v)
    if (c < 0).any():
        raise ValueError(f"expected a color >= 0, got {v!r}")
    return c


def _direction(v):
    d = _vec3(v)
    if not np.any(d):
        raise ValueError("expected a nonzero direction")
    return d


def _positive(v):
    x = _number(v)
    if not x > 0:
        raise ValueError(f"expected a number greater than 0, got {v!r}")
    return x


def _nonneg(v):
    x = _number(v)
    if x < 0:
        raise ValueError(f"expected a number >= 0, got {v!r}")
    return x


def _count(v):
    if isinstance(v, bool) or not isinstance(v, int) or v < 1:
        raise ValueError(f"expected an integer >= 1, got {v!r}")
    return v


def _string(v):
    if not isinstance(v, str):
        raise ValueError(f"expected a string, got {v!r}")
    return v


def _bool(v):
    if not isinstance(v, bool):
        raise ValueError(f"expected true or false, got {v!r}")
    return v


def _pair(v):
    if not isinstance(v, list) or len(v) != 2:
        raise ValueError(f"expected [u, v], got {v!r}")
    return np.array([_number(x) for x in v])


def _edges_and_front(reader, noun):
    """A parallelogram's or light's `edge1`, `edge2` (spanning an area) and
    front normal (`normal`, or edge1 x edge2)."""
    e1 = reader.get("edge1", _vec3, required=True)
    e2 = reader.get("edge2", _vec3, required=True)
    cross = np.cross(e1, e2)
    if cross.dot(cross) <= 1e-12 * e1.dot(e1) * e2.dot(e2):
        reader.fail("edge1", f"edge1 and edge2 are parallel or zero, so {noun} has no area")
    return e1, e2, _front_side(reader, cross, reader.get("normal", _direction, None))


def _front_side(r: _Reader, cross: np.ndarray, normal) -> np.ndarray:
    """Glint's front side: the unit cross product turned to `normal` if given
    (scene/src/build.rs `front_side`, geometry `Parallelogram::facing`)."""
    n = cross / np.linalg.norm(cross)
    if normal is None:
        return n
    given = normal / np.linalg.norm(normal)
    if abs(given.dot(n)) < 0.999:
        r.fail("normal", f"expected a normal perpendicular to edge1 and edge2, i.e. along +-{cross.tolist()}")
    return n if given.dot(n) >= 0 else -n


def load_scene(path: str) -> Scene:
    try:
        with open(path, "rb") as f:
            doc = tomllib.load(f)
    except OSError as e:
        raise InputError(f"{path}: cannot read: {e.strerror}")
    except tomllib.TOMLDecodeError as e:
        raise InputError(f"{path}: {e}")
    top = _Reader(path, doc, "")
    shading = top.get("shading", _string, "phong")
    if shading != "phong":
        top.fail("shading", f"only the course's \"phong\" model is supported, got {shading!r}")
    ambient = top.get("ambient", _color, np.zeros(3))

    # [camera]
    c = _Reader(path, top.get("camera", dict, required=True), "camera")
    camera = Camera(
        position=c.get("position", _vec3, required=True),
        look_at=c.get("look_at", _vec3, required=True),
        up=c.get("up", _direction, np.array([0.0, 1.0, 0.0])),
        fov=c.get("fov", _number, required=True),
        focal_length=c.get("focal_length", _positive, 1.0),
    )
    c.finish()
    if not 0 < camera.fov < 180:
        c.fail("fov", f"expected strictly between 0 and 180 degrees, got {camera.fov}")

    # [render]: the values this tracer uses as defaults, and the keys that
    # change nothing in a scene without mirrors, environment or physical shading.
    render = {}
    if "render" in doc:
        r = _Reader(path, top.get("render", dict), "render")

        def res(v):
            if not isinstance(v, list) or len(v) != 2 or not all(isinstance(x, int) and 1 <= x <= 16384 for x in v):
                raise ValueError(f"expected [width, height], each 1 to 16384, got {v!r}")
            return tuple(v)

        def pattern(v):
            if v not in ("grid", "random", "stratified", "sobol"):
                raise ValueError(f"expected grid, random, stratified or sobol, got {v!r}")
            return v

        def seed(v):
            if isinstance(v, bool) or not isinstance(v, int) or v < 0:
                raise ValueError(f"expected an integer >= 0, got {v!r}")
            return v

        render = {
            "resolution": r.get("resolution", res, (512, 512)),
            "spp": r.get("spp", _count, 16),
            "pixel_sampler": r.get("pixel_sampler", pattern, "sobol"),
            "light_samples": r.get("light_samples", _count, 16),
            "light_sampler": r.get("light_sampler", pattern, "sobol"),
            "seed": r.get("seed", seed, 0),
        }
        # No effect here: max_depth (no mirrors are supported), environment_*
        # (no environment is supported), area_sampling and mis (physical only).
        r.finish(ignored={"max_depth", "environment_samples", "environment_sampler", "area_sampling", "mis"})

    # [textures.NAME.checkerboard]
    textures: dict[str, Checker] = {}
    for name, t in top.get("textures", dict, {}).items():
        tr = _Reader(path, t, f"textures.{name}")
        if set(t) != {"checkerboard"}:
            kind = next(iter(set(t) - {"checkerboard"}), "?")
            tr.fail(kind, "only checkerboard textures are supported")
        cr = _Reader(path, tr.get("checkerboard", dict), f"textures.{name}.checkerboard")
        colors = cr.get("colors", lambda v: v, required=True)
        if not isinstance(colors, list) or len(colors) != 2:
            cr.fail("colors", "expected two colors")
        try:
            colors = np.array([_color(x) for x in colors])
        except ValueError as e:
            cr.fail("colors", str(e))
        checks = cr.get("checks", _count, required=True)
        flt = cr.get("filter", _string, "point")
        if flt != "point":
            cr.fail("filter", f"only the point-sampled checkerboard (\"point\", the default) is supported, got {flt!r}")
        cr.finish()
        textures[name] = Checker(colors, checks)

    # [materials.NAME]
    materials: list[Material] = []
    material_index: dict[str, int] = {}
    for name, m in top.get("materials", dict, {}).items():
        mr = _Reader(path, m, f"materials.{name}")

        def color_or_texture(v, mr=mr):
            if isinstance(v, str):
                if v not in textures:
                    raise ValueError(f"no texture named {v!r} (defined: {', '.join(sorted(textures)) or 'none'})")
                return textures[v]
            return _color(v)

        diffuse = mr.get("diffuse", color_or_texture, required=True)
        specular = mr.get("specular", color_or_texture, None)
        shininess = mr.get("shininess", _nonneg, 1.0)
        lobe = mr.get("lobe", _string, "phong")
        if lobe not in ("phong", "blinn-phong"):
            mr.fail("lobe", f"expected phong or blinn-phong, got {lobe!r}")
        uv_scale = mr.get("uv_scale", _pair, np.ones(2))
        if not np.all(uv_scale):
            mr.fail("uv_scale", "no zero component")
        uv_offset = mr.get("uv_offset", _pair, np.zeros(2))
        reflectivity = mr.get("reflectivity", _number, 0.0)
        if reflectivity != 0:
            mr.fail("reflectivity", "mirror reflections are not supported (only 0)")
        mr.finish()
        material_index[name] = len(materials)
        materials.append(Material(diffuse, specular, shininess, lobe, uv_scale, uv_offset))

    def material_of(reader: _Reader):
        name = reader.get("material", _string, required=True)
        if name not in material_index:
            reader.fail("material", f"no material named {name!r} (defined: {', '.join(sorted(material_index)) or 'none'})")
        return material_index[name]

    spheres = []
    for i, s in enumerate(top.get("sphere", list, [])):
        sr = _Reader(path, s, f"sphere[{i}]")
        sr.get("name", _string)  # what reports call the object: no effect on the image
        spheres.append(Sphere(sr.get("center", _vec3, required=True), sr.get("radius", _positive, required=True), material_of(sr)))
        sr.finish()

    parallelograms = []
    for i, p in enumerate(top.get("parallelogram", list, [])):
        pr = _Reader(path, p, f"parallelogram[{i}]")
        pr.get("name", _string)
        origin = pr.get("origin", _vec3, required=True)
        e1, e2, normal = _edges_and_front(pr, "the shape")
        two_sided = pr.get("two_sided", _bool, False)
        parallelograms.append(Parallelogram(origin, e1, e2, normal, two_sided, material_of(pr), -1))
        pr.finish()

    area_lights = []
    for i, a in enumerate(top.get("area_light", list, [])):
        ar = _Reader(path, a, f"area_light[{i}]")
        ar.get("name", _string)
        center = ar.get("center", _vec3, required=True)
        e1, e2, normal = _edges_and_front(ar, "the light")
        color = ar.get("color", _color, np.ones(3))
        ar.finish()
        # The light's surface, for camera rays (and, as a mistake, shadow rays).
        surface = Parallelogram(center - 0.5 * (e1 + e2), e1, e2, normal, False, -1, len(area_lights))
        area_lights.append(AreaLight(center, e1, e2, normal, color, len(parallelograms)))
        parallelograms.append(surface)

    point_lights = []
    for i, p in enumerate(top.get("point_light", list, [])):
        plr = _Reader(path, p, f"point_light[{i}]")
        plr.get("name", _string)
        point_lights.append(PointLight(plr.get("position", _vec3, required=True), plr.get("color", _color, np.ones(3))))
        plr.finish()

    top.finish(ignored={"regions"})  # regions: only for `glint bench`, no effect on a render

    extent = [np.abs(camera.position).max()]
    extent += [np.abs(s.center).max() + s.radius for s in spheres]
    extent += [np.abs(p.origin).max() + np.abs(p.edge1).max() + np.abs(p.edge2).max() for p in parallelograms]
    extent += [np.abs(p.position).max() for p in point_lights]
    return Scene(path, ambient, camera, render, materials, spheres, parallelograms, area_lights, point_lights, max(1.0, max(extent)))


# --------------------------------------------------------------------------
# Sampling
# --------------------------------------------------------------------------
def square_root(n: int) -> int | None:
    k = math.isqrt(n)
    return k if k * k == n else None


def pattern_points(pattern: str, shape: tuple, n: int, rng: np.random.Generator) -> np.ndarray:
    """`shape + (n, 2)` points in [0, 1)^2, n per set.

    grid: the sqrt(n) x sqrt(n) cell centres, cell index k at column k % s,
    row k // s (integrator/src/sampling/pattern.rs `fill_grid`); stratified: one
    uniform point per cell of that grid; random: n uniform points."""
    if pattern == "random":
        return rng.random(shape + (n, 2))
    s = square_root(n)
    k = np.arange(n)
    cells = np.stack([k % s, k // s], axis=-1).astype(np.float64)
    if pattern == "grid":
        return np.broadcast_to((cells + 0.5) / s, shape + (n, 2))
    return (cells + rng.random(shape + (n, 2))) / s  # stratified


# --------------------------------------------------------------------------
# Ray queries (structure of arrays: x, y, z components as separate arrays)
# --------------------------------------------------------------------------
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


# --------------------------------------------------------------------------
# The renderer
# --------------------------------------------------------------------------
@dataclass
class Options:
    width: int
    height: int
    spp: int
    sampler: str
    light_samples: int
    light_sampler: str
    seed: int
    mistakes: frozenset


class Renderer:
    def __init__(self, scene: Scene, opts: Options):
        self.scene, self.o = scene, opts
        self.m = opts.mistakes
        cam = scene.camera
        forward = cam.look_at - cam.position
        if not np.linalg.norm(forward) > 0:
            raise InputError(f"{scene.path}: camera.look_at: the camera position and the look-at point coincide")
        forward /= np.linalg.norm(forward)
        right = np.cross(forward, cam.up / np.linalg.norm(cam.up))
        if np.linalg.norm(right) <= 1e-3:
            raise InputError(f"{scene.path}: camera.up: parallel to the viewing direction")
        right /= np.linalg.norm(right)
        up = np.cross(right, forward)
        aspect = opts.width / opts.height
        # camera/src/camera.rs: half height f*tan(fov/2) (fov vertical), half width aspect*that.
        half_angle = math.radians(cam.fov) / 2
        if "fov-no-half" in self.m:  # MISTAKE: tan(fov) instead of tan(fov/2)
            half_angle = math.radians(cam.fov)
            if half_angle >= math.pi / 2:
                raise InputError("fov-no-half needs fov < 90 degrees")
        half_height = cam.focal_length * math.tan(half_angle)
        half_width = aspect * half_height
        if "horizontal-fov" in self.m:  # MISTAKE: the fov spans the width, not the height
            half_width = cam.focal_length * math.tan(half_angle)
            half_height = half_width / aspect
        self.cam = (cam.position, forward * cam.focal_length, right * half_width, up * half_height)
        self.eps = 1e-7 * scene.scale  # our shadow-ray offset (Glint's is an error bound)
        self._point_target = None  # the point light being shaded (for culling walls)

    # -- camera rays -----------------------------------------------------
    def camera_rays(self, rx, ry):
        """Raster (rx, ry), (0, 0) the top-left corner, pixel centres at +0.5
        (camera/src/camera.rs `film_point`): NDC x = 2 rx / W - 1,
        y = 1 - 2 ry / H; direction = normalize(f forward + x hw right + y hh up)."""
        pos, fwd, right, up = self.cam
        nx = 2.0 * rx / self.o.width - 1.0
        ny = 1.0 - 2.0 * ry / self.o.height
        d = [fwd[i] + nx * right[i] + ny * up[i] for i in range(3)]
        inv = 1.0 / np.sqrt(dot3(d, d))
        return [d[i] * inv for i in range(3)]

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

    def blocked(self, o, d, tmax, own_kind, own_index, light_surface):
        """Whether anything lies on o + t d, 0 < t < tmax. A flat shape cannot
        block rays leaving it (own_kind 1) and the light's surface is not
        reached (the segment ends short of it), as in Glint
        (geometry/src/shape_list/occluders.rs); one-sided walls only block
        rays that arrive at their front."""
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
                    corners = [self._point_target]
                if all(p.normal.dot(c - p.origin) > 10 * self.eps for c in corners):
                    continue
            t = parallelogram_t(p, o, d, two_sided)
            own = (own_kind == 1) & (own_index == i)
            if no_offset:
                own = np.zeros_like(own)  # MISTAKE (no-shadow-offset): the own wall is tested too
            hit |= (t > 0) & (t < tmax) & ~own
        return hit

    def light_corners(self, L: AreaLight):
        h1, h2 = L.edge1, L.edge2
        if "light-twice-size" in self.m:
            h1, h2 = 2 * h1, 2 * h2
        c = L.center + 2 * self.eps * L.normal
        return [c + a * 0.5 * h1 + b * 0.5 * h2 for a in (-1, 1) for b in (-1, 1)]

    # -- textures and materials -------------------------------------------
    def texture(self, tex, uv):
        if isinstance(tex, Checker):
            n = tex.checks
            if "checker-doubled" in self.m:  # MISTAKE: twice the frequency
                n *= 2
            # texture/src/checkerboard.rs: check (floor(u N), floor(v N)), first
            # colour when the sum is even (parity of the xor), point-sampled.
            iu = np.floor(uv[0] * n).astype(np.int64)
            iv = np.floor(uv[1] * n).astype(np.int64)
            odd = (iu ^ iv) & 1
            return tex.colors[odd]
        return np.broadcast_to(tex, (uv[0].shape[0], 3))

    # -- one chunk of pixels ----------------------------------------------
    def render_chunk(self, pix0: int, pix1: int, rng: np.random.Generator, shared=None):
        o, scene, m = self.o, self.scene, self.m
        W = o.width
        P = pix1 - pix0
        pix = np.arange(pix0, pix1)
        px, py = (pix % W).astype(np.float64), (pix // W).astype(np.float64)
        if shared is not None:  # MISTAKE (shared-samples): the same jitter in every pixel
            jitter = np.broadcast_to(shared[0], (P, o.spp, 2))
        else:
            jitter = pattern_points(o.sampler, (P,), o.spp, rng)
        rx = (px[:, None] + jitter[..., 0]).ravel()
        ry = (py[:, None] + jitter[..., 1]).ravel()
        if "pixel-corners" in m:  # MISTAKE: every sample half a pixel up and left
            rx, ry = rx - 0.5, ry - 0.5
        M = rx.shape[0]
        d = self.camera_rays(rx, ry)
        pos = scene.camera.position
        t, kind, index = self.closest(pos, d)
        radiance = np.zeros((M, 3))

        # A camera ray whose first hit is a light's front side sees its colour.
        for i, p in enumerate(scene.parallelograms):
            if p.light >= 0:
                sel = (kind == 1) & (index == i)
                radiance[sel] = scene.area_lights[p.light].color

        surf = np.nonzero(((kind == 0) | ((kind == 1) & (index >= 0))) & ~self._is_light(kind, index))[0]
        if surf.size:
            local_shared = None
            if shared is not None:
                local_shared = np.broadcast_to(shared[1], (P, o.spp, o.light_samples, 2)).reshape(M, o.light_samples, 2)[surf]
            radiance[surf] = self.shade(pos, [c[surf] for c in d], t[surf], kind[surf], index[surf], rng, local_shared)
        return radiance.reshape(P, o.spp, 3).mean(axis=1)

    def _is_light(self, kind, index):
        lit = np.zeros(kind.shape, dtype=bool)
        for i, p in enumerate(self.scene.parallelograms):
            if p.light >= 0:
                lit |= (kind == 1) & (index == i)
        return lit

    def shade(self, pos, d, t, kind, index, rng, shared_light):
        scene, m = self.scene, self.m
        n_hits = t.shape[0]
        raw = [pos[i] + t * d[i] for i in range(3)]  # o + t d
        ng = [np.empty(n_hits) for _ in range(3)]
        point = [np.empty(n_hits) for _ in range(3)]
        u = np.empty(n_hits)
        v = np.empty(n_hits)
        mat = np.empty(n_hits, dtype=np.int32)
        shading_scale = np.ones(n_hits)  # 1, or r for unnormalised-normals
        for i, s in enumerate(scene.spheres):
            sel = np.nonzero((kind == 0) & (index == i))[0]
            if not sel.size:
                continue
            q = [raw[k][sel] - s.center[k] for k in range(3)]
            inv = 1.0 / np.sqrt(dot3(q, q))
            nrm = [q[k] * inv for k in range(3)]
            for k in range(3):
                ng[k][sel] = nrm[k]
                # geometry/src/shapes/sphere.rs: the point projected back onto the sphere
                point[k][sel] = s.center[k] + s.radius * nrm[k]
            # sphere.rs `uv_of_normal`: theta = acos(n.y), phi = atan2(-n.z, n.x)
            # in [0, 2 pi), u = phi / 2 pi, v = 1 - theta / pi.
            theta = np.arccos(np.clip(nrm[1], -1.0, 1.0))
            if "sphere-u-sign" in m:  # MISTAKE: phi = atan2(z, x)
                phi = np.arctan2(nrm[2], nrm[0])
            else:
                phi = np.arctan2(-nrm[2], nrm[0])
            phi = np.where(phi < 0, phi + 2 * math.pi, phi)
            u[sel] = phi / (2 * math.pi)
            v[sel] = 1.0 - theta / math.pi
            if "sphere-v-from-y" in m:  # MISTAKE: v linear in the height, not in the angle
                v[sel] = (nrm[1] + 1.0) / 2.0
            mat[sel] = s.material
            if "unnormalised-normals" in m:  # MISTAKE: shading normal p - c, length r
                shading_scale[sel] = s.radius
        for i, p in enumerate(scene.parallelograms):
            sel = np.nonzero((kind == 1) & (index == i))[0]
            if not sel.size:
                continue
            x = [raw[k][sel] for k in range(3)]
            alpha = np.clip(p.A[0] * x[0] + p.A[1] * x[1] + p.A[2] * x[2] - p.a0, 0, 1)
            beta = np.clip(p.B[0] * x[0] + p.B[1] * x[1] + p.B[2] * x[2] - p.b0, 0, 1)
            for k in range(3):
                ng[k][sel] = p.normal[k]
                point[k][sel] = x[k]
            u[sel], v[sel] = alpha, beta  # uv = (alpha, beta) of origin + alpha e1 + beta e2
            mat[sel] = p.material
        if "no-shadow-offset" in m:
            point = raw  # MISTAKE: the shadow ray starts at o + t d, as computed

        # The normal turned to the viewer's side (geometry/src/hit.rs `facing_normal`).
        flip = np.where(dot3(ng, d) > 0, -1.0, 1.0)
        ng = [ng[k] * flip for k in range(3)]
        n = [ng[k] * shading_scale for k in range(3)]
        view = [-d[k] for k in range(3)]
        if "flipped-view" in m:  # MISTAKE: v along the ray instead of towards the viewer
            view = d

        kd = np.empty((n_hits, 3))
        ks = np.empty((n_hits, 3))
        shin = np.empty(n_hits)
        blinn = np.zeros(n_hits, dtype=bool)
        for j, mt in enumerate(scene.materials):
            sel = np.nonzero(mat == j)[0]
            if not sel.size:
                continue
            uv = (u[sel] * mt.uv_scale[0] + mt.uv_offset[0], v[sel] * mt.uv_scale[1] + mt.uv_offset[1])
            kd[sel] = self.texture(mt.diffuse, uv)
            ks[sel] = kd[sel] if mt.specular is None else self.texture(mt.specular, uv)
            if "specular-white" in m:  # MISTAKE: white highlights
                ks[sel] = 1.0
            shin[sel] = mt.shininess
            blinn[sel] = mt.lobe == "blinn-phong"
        if "blinn-half-vector" in m:  # MISTAKE: n.h in place of r.v
            blinn[:] = True

        # integrator/src/direct.rs `shade_with`: ambient * kd once, then each light.
        out = np.zeros((n_hits, 3))
        if "no-ambient" not in m:  # MISTAKE no-ambient: this term left out
            amb = scene.ambient * kd
            if "ambient-per-sample" in m:  # MISTAKE: once per light sample, not averaged
                amb = amb * self.o.light_samples * max(1, len(scene.area_lights))
            if "ambient-in-shadow-only" not in m:
                out += amb
        geo = dict(point=point, ng=ng, n=n, view=view, kd=kd, ks=ks, shin=shin, blinn=blinn, kind=kind, index=index)
        for li, L in enumerate(scene.area_lights):
            out += self.area_light(L, geo, rng, shared_light)
        for P in scene.point_lights:
            out += self.point_light(P, geo)
        return out

    def reflect(self, geo, l, rows=slice(None)):
        """The course's Phong reflection of a unit light along l (lighting/src/
        material.rs `reflect`): kd (n.l) + ks lobe, zero where n.l <= 0; lobe
        max(0, r.v)^s, r = 2 (n.l) n - l (or max(0, n.h)^s, h = normalize(l + v)).
        Returns (n.l, lobe) broadcast over the light samples."""
        n = [c[rows][:, None] for c in geo["n"]]
        view = [c[rows][:, None] for c in geo["view"]]
        s = geo["shin"][rows][:, None]
        ndl = dot3(n, l)
        r = [2 * ndl * n[k] - l[k] for k in range(3)]
        cos = dot3(r, view)
        blinn = geo["blinn"][rows][:, None]
        if blinn.any():
            h = [l[k] + view[k] for k in range(3)]
            with np.errstate(invalid="ignore", divide="ignore"):
                hn = 1.0 / np.sqrt(dot3(h, h))
                cos_h = np.nan_to_num(dot3(n, h) * hn)
            cos = np.where(blinn, cos_h, cos)
        if "no-clamp-dots" in self.m:
            # MISTAKE: neither n.l nor the lobe's cosine clamped at 0
            with np.errstate(invalid="ignore"):
                lobe = np.nan_to_num(cos**s)
            return ndl, lobe, np.ones(ndl.shape, dtype=bool)
        with np.errstate(invalid="ignore"):
            lobe = np.where(cos > 0, np.maximum(cos, 0) ** s, 0.0)
        return ndl, lobe, ndl > 0

    def point_light(self, P: PointLight, geo):
        p, ng = geo["point"], geo["ng"]
        w = [P.position[k] - p[k] for k in range(3)]
        dist = np.sqrt(dot3(w, w))
        with np.errstate(invalid="ignore", divide="ignore"):
            l = [(w[k] / dist)[:, None] for k in range(3)]
        self._point_target = P.position
        contrib = self.light_samples_value(geo, [x[:, None] for x in p], l, dist[:, None], np.ones_like(dist, dtype=bool)[:, None],
                                           [np.full((p[0].shape[0], 1), P.position[k]) for k in range(3)], -1, 1)
        return P.color * contrib

    def area_light(self, L: AreaLight, geo, rng, shared_light):
        o, m = self.o, self.m
        p = geo["point"]
        N, S = p[0].shape[0], o.light_samples
        if shared_light is not None:
            uv = shared_light
        else:
            uv = pattern_points(o.light_sampler, (N,), S, rng)
        if "light-centre" in m:  # MISTAKE: every sample at the centre
            uv = np.full((N, S, 2), 0.5)
        e1, e2 = L.edge1, L.edge2
        if "light-twice-size" in m:  # MISTAKE: centre +- edge instead of +- edge/2
            e1, e2 = 2 * e1, 2 * e2
        # lighting/src/area_light.rs: origin + u e1 + v e2, origin = centre - (e1 + e2)/2,
        # i.e. centre + (u - 1/2) e1 + (v - 1/2) e2.
        a, b = uv[..., 0] - 0.5, uv[..., 1] - 0.5
        q = [L.center[k] + a * e1[k] + b * e2[k] for k in range(3)]
        pp = [c[:, None] for c in p]
        w = [q[k] - pp[k] for k in range(3)]
        dist = np.sqrt(dot3(w, w))
        with np.errstate(invalid="ignore", divide="ignore"):
            l = [w[k] / dist for k in range(3)]
        # area_light.rs `illuminates`: the receiver must be in front of the light.
        lit = dot3(L.normal, [pp[k] - q[k] for k in range(3)]) > 0
        if "two-sided-light" in m:  # MISTAKE: both sides emit
            lit = np.ones_like(lit)
        # Shadow rays end a little short of the light, on its emitting side.
        side = np.where(dot3(L.normal, [-x for x in w]) >= 0, 1.0, -1.0)
        end = [q[k] + side * 2 * self.eps * L.normal[k] for k in range(3)]
        if "light-blocks-shadow" in m:
            end = q  # MISTAKE (with blocked()): aimed at the light point itself
        contrib = self.light_samples_value(geo, pp, l, dist, lit, end, L.surface, S)
        return L.color * contrib

    def light_samples_value(self, geo, pp, l, dist, lit, end, light_surface, S):
        """Sum over a point's light samples of the visible Phong reflections,
        divided by the sample count: (N, 3) per unit light colour."""
        m = self.m
        ng = [c[:, None] for c in geo["ng"]]
        ndl, lobe, front = self.reflect(geo, l)
        # direct.rs `above_surface`: the light must be above the geometric surface.
        above = dot3(ng, l) > 0
        if "no-clamp-dots" in m:
            above = np.ones_like(above)  # MISTAKE: no horizon test either
        with np.errstate(invalid="ignore"):
            shaded = lit & above & front & (dist > 0)
        kd, ks = geo["kd"][:, None, :], geo["ks"][:, None, :]
        refl = kd * ndl[..., None] + ks * lobe[..., None]  # (N, S, 3)
        if "distance-falloff" in m:  # MISTAKE: 1/r^2
            refl = refl / (dist * dist)[..., None]
        N = ndl.shape[0]
        visible = shaded.copy()
        rows, cols = np.nonzero(shaded)
        if rows.size and "no-shadows" not in m:  # MISTAKE no-shadows: skip the test
            o = [pp[k][rows, 0] for k in range(3)]
            if "no-shadow-offset" not in m:
                # Leave on the side of the geometric surface the light is on
                # (geometry/src/offset.rs `spawn_ray_to`), by a fixed offset of ours.
                g = [geo["ng"][k][rows] for k in range(3)]
                w = [l[k][rows, cols] for k in range(3)]
                sgn = np.where(dot3(g, w) < 0, -1.0, 1.0) * self.eps
                o = [o[k] + sgn * g[k] for k in range(3)]
            e = [np.broadcast_to(end[k], (N, S))[rows, cols] for k in range(3)]
            d = [e[k] - o[k] for k in range(3)]
            hit = self.blocked(o, d, 1.0, geo["kind"][rows], geo["index"][rows], light_surface)
            visible[rows, cols] = ~hit
        total = np.where(visible[..., None], refl, 0.0).sum(axis=1)
        if "ambient-in-shadow-only" in m:
            # MISTAKE: the report's literal reading, ambient only when a shadow
            # ray is blocked (per sample, averaged with the Phong terms).
            occluded = (shaded & ~visible).sum(axis=1)
            total = total + self.scene.ambient * geo["kd"] * occluded[:, None]
        if "summed-light-samples" in m:  # MISTAKE: the sum is not divided by S
            return total
        return total / S


# --------------------------------------------------------------------------
# Output
# --------------------------------------------------------------------------
def encode_8bit(film: np.ndarray, mistakes) -> np.ndarray:
    """camera/src/film.rs `linear_to_srgb8`: NaN -> 0, clamp to [0, 1], the
    exact sRGB curve, then (x * 255 + 0.5) truncated (round half up)."""
    c = np.clip(np.nan_to_num(film, nan=0.0), 0.0, 1.0).astype(np.float32).astype(np.float64)
    if "no-srgb" in mistakes:  # MISTAKE: linear values written as they are
        e = c
    elif "gamma-22" in mistakes:  # MISTAKE: a plain gamma of 2.2
        e = c ** (1 / 2.2)
    else:
        e = np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1 / 2.4) - 0.055)
    if "truncate-8bit" in mistakes:  # MISTAKE: floor instead of rounding
        return np.floor(e * 255.0).astype(np.uint8)
    return np.floor(e * 255.0 + 0.5).astype(np.uint8)


def write_png(path: str, rgb8: np.ndarray):
    h, w, _ = rgb8.shape
    raw = b"".join(b"\x00" + rgb8[y].tobytes() for y in range(h))

    def chunk(tag, data):
        body = tag + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw, 6)))
        f.write(chunk(b"IEND", b""))


def write_ppm(path: str, rgb8: np.ndarray, ascii_: bool):
    h, w, _ = rgb8.shape
    with open(path, "wb") as f:
        if ascii_:
            f.write(f"P3\n{w} {h}\n255\n".encode())
            for y in range(h):
                f.write((" ".join(map(str, rgb8[y].ravel().tolist())) + "\n").encode())
        else:
            f.write(f"P6\n{w} {h}\n255\n".encode())
            f.write(rgb8.tobytes())


def write_pfm(path: str, film: np.ndarray):
    """camera/src/film.rs `write_pfm`: `PF\\nW H\\n-1.0\\n`, little-endian f32,
    bottom row first."""
    h, w, _ = film.shape
    with open(path, "wb") as f:
        f.write(f"PF\n{w} {h}\n-1.0\n".encode())
        f.write(np.ascontiguousarray(film[::-1], dtype="<f4").tobytes())


def read_pfm(path: str) -> np.ndarray:
    """A PFM as Glint and write_pfm write it, as an (H, W, 3) array, top row first."""
    with open(path, "rb") as f:
        data = f.read()
    parts = data.split(b"\n", 3)
    if parts[0] != b"PF":
        raise ValueError(f"{path}: not an RGB PFM")
    w, h = map(int, parts[1].split())
    scale = float(parts[2])
    dtype = "<f4" if scale < 0 else ">f4"
    img = np.frombuffer(parts[3][: w * h * 12], dtype=dtype).reshape(h, w, 3)
    return img[::-1].astype(np.float64) * abs(scale)


def read_png(path: str) -> np.ndarray:
    """An 8-bit RGB, non-interlaced PNG (as write_png and Glint write them)
    as an (H, W, 3) uint8 array."""
    with open(path, "rb") as f:
        data = f.read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat = 8, b""
    w = h = bpp = None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos : pos + 4])
        tag = data[pos + 4 : pos + 8]
        body = data[pos + 8 : pos + 8 + length]
        if tag == b"IHDR":
            w, h, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or ctype not in (2, 6) or interlace:
                raise ValueError(f"{path}: only 8-bit RGB(A) non-interlaced PNGs are read")
            bpp = 3 if ctype == 2 else 4
        elif tag == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = w * bpp
    out = np.zeros((h, stride), dtype=np.int32)
    prev = np.zeros(stride, dtype=np.int32)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = np.frombuffer(raw, dtype=np.uint8, count=stride, offset=y * (stride + 1) + 1).astype(np.int32)
        if f == 0:
            cur = line
        elif f == 2:
            cur = (line + prev) & 255
        else:  # 1 (sub), 3 (average), 4 (Paeth): byte by byte
            cur = np.zeros(stride, dtype=np.int32)
            for i in range(stride):
                a = cur[i - bpp] if i >= bpp else 0
                b = prev[i]
                c = prev[i - bpp] if i >= bpp else 0
                if f == 1:
                    pred = a
                elif f == 3:
                    pred = (a + b) // 2
                else:
                    pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                    pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                cur[i] = (line[i] + pred) & 255
        out[y] = cur
        prev = cur
    return out.reshape(h, w, bpp)[..., :3].astype(np.uint8)


def srgb8_to_linear(rgb8: np.ndarray) -> np.ndarray:
    e = rgb8.astype(np.float64) / 255.0
    return np.where(e <= 0.04045, e / 12.92, ((e + 0.055) / 1.055) ** 2.4)


# --------------------------------------------------------------------------
# Driver
# --------------------------------------------------------------------------
def _render_range(args):
    renderer, chunks, base_seed, shared = args
    out = []
    for ci, (p0, p1) in chunks:
        rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence([base_seed, ci])))
        out.append((p0, p1, renderer.render_chunk(p0, p1, rng, shared)))
    return out


def render(scene: Scene, opts: Options, jobs: int = 1) -> np.ndarray:
    r = Renderer(scene, opts)
    npix = opts.width * opts.height
    per_pixel = opts.spp * max(1, opts.light_samples)
    pixels_per_chunk = max(1, min(4096, (1 << 18) // per_pixel))
    chunks = list(enumerate((p, min(npix, p + pixels_per_chunk)) for p in range(0, npix, pixels_per_chunk)))
    shared = None
    if "shared-samples" in opts.mistakes:
        # MISTAKE: one pixel pattern and one set of light points, reused everywhere.
        g = np.random.Generator(np.random.PCG64(np.random.SeedSequence([opts.seed, 1 << 40])))
        shared = (pattern_points(opts.sampler, (), opts.spp, g),
                  pattern_points(opts.light_sampler, (opts.spp,), opts.light_samples, g))
    film = np.zeros((npix, 3))
    if jobs <= 1 or len(chunks) == 1:
        results = [_render_range((r, chunks, opts.seed, shared))]
    else:
        import multiprocessing as mp

        groups = [chunks[i::jobs] for i in range(jobs)]
        with mp.get_context("fork").Pool(jobs) as pool:
            results = pool.map(_render_range, [(r, g, opts.seed, shared) for g in groups])
    for result in results:
        for p0, p1, values in result:
            film[p0:p1] = values
    film = film.reshape(opts.height, opts.width, 3)
    if "flipped-image" in opts.mistakes:  # MISTAKE: rows upside down
        film = film[::-1]
    return film


def _keep_freed_memory():
    """Each chunk allocates and frees temporaries of a few MB; by default glibc
    returns them to the kernel (mmap / trim) and page-faults them back in,
    which costs as much system time as the arithmetic. Keep them instead
    (glibc only; elsewhere nothing changes but the speed)."""
    try:
        import ctypes

        libc = ctypes.CDLL(None)
        libc.mallopt(-3, 32 << 20)  # M_MMAP_THRESHOLD: blocks up to 32 MB from the heap
        libc.mallopt(-1, 1 << 30)  # M_TRIM_THRESHOLD: keep up to 1 GB of freed heap
    except (OSError, AttributeError):
        pass


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        description="Render a Glint course scene (Cornell box subset) with an independent numpy ray tracer.")
    ap.add_argument("scene", nargs="?", help="Glint scene file (TOML)")
    ap.add_argument("-o", "--output", help="output image: .png, .ppm (8-bit sRGB) or .pfm (linear float)")
    ap.add_argument("--resolution", help="WxH (default: the scene's [render] resolution, else 512x512)")
    ap.add_argument("--spp", type=int, help="camera samples per pixel (default: the scene's, else 16)")
    ap.add_argument("--sampler", choices=["random", "stratified", "grid"],
                    help="pixel sample pattern (default: the scene's; its sobol becomes stratified, or random for a non-square count)")
    ap.add_argument("--light-samples", type=int, help="samples per area light per camera sample (default: the scene's, else 16)")
    ap.add_argument("--light-sampler", choices=["random", "stratified", "grid"], help="light sample pattern (default as --sampler)")
    ap.add_argument("--seed", type=int, help="RNG seed (default: the scene's, else 0)")
    ap.add_argument("--mistake", action="append", default=[], metavar="NAME", help="a student mistake to make (repeatable; see --list-mistakes)")
    ap.add_argument("--ppm-ascii", action="store_true", help="write PPM as P3 (text) instead of P6")
    ap.add_argument("--list-mistakes", action="store_true", help="list the mistakes and exit")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="worker processes (default: one per CPU); the image does not depend on it")
    args = ap.parse_args(argv)

    if args.list_mistakes:
        width = max(map(len, MISTAKES))
        for name, text in MISTAKES.items():
            print(f"{name:<{width}}  {text}")
        return 0
    try:
        if not args.scene or not args.output:
            raise InputError("a scene and -o OUT are required")
        ext = os.path.splitext(args.output)[1].lower()
        if ext not in (".png", ".ppm", ".pfm"):
            raise InputError(f"{args.output}: unknown output format; expected .png, .ppm or .pfm")
        for name in args.mistake:
            if name not in MISTAKES:
                raise InputError(f"--mistake {name}: unknown (see --list-mistakes)")
        if ext == ".pfm" and ENCODING_MISTAKES & set(args.mistake):
            raise InputError(f"--mistake {sorted(ENCODING_MISTAKES & set(args.mistake))[0]} changes only the 8-bit encoding: write .png or .ppm")
        scene = load_scene(args.scene)
        rs = scene.render
        if args.resolution:
            try:
                w, h = (int(x) for x in args.resolution.lower().split("x"))
                assert 1 <= w <= 16384 and 1 <= h <= 16384
            except (ValueError, AssertionError):
                raise InputError(f"--resolution {args.resolution}: expected WxH, each 1 to 16384")
        else:
            w, h = rs.get("resolution", (512, 512))
        spp = args.spp if args.spp is not None else rs.get("spp", 16)
        ls = args.light_samples if args.light_samples is not None else rs.get("light_samples", 16)
        for flag, value in (("--spp", spp), ("--light-samples", ls)):
            if value < 1:
                raise InputError(f"{flag} {value}: expected at least 1")

        def pattern(given, key, count):
            if given:
                return given
            p = rs.get(key, "sobol")
            if p == "sobol":
                p = "stratified" if square_root(count) else "random"
                print(f"note: the scene's {key} is sobol, which this tracer lacks; using {p}", file=sys.stderr)
            return p

        sampler = pattern(args.sampler, "pixel_sampler", spp)
        light_sampler = pattern(args.light_sampler, "light_sampler", ls)
        for flag, p, count in (("--sampler", sampler, spp), ("--light-sampler", light_sampler, ls)):
            if p in ("grid", "stratified") and not square_root(count):
                raise InputError(f"{flag} {p} needs a perfect-square count (1, 4, 9, 16, ...), got {count}")
        seed = args.seed if args.seed is not None else rs.get("seed", 0)
        if seed < 0:
            raise InputError("--seed: expected an integer >= 0")
        opts = Options(w, h, spp, sampler, ls, light_sampler, seed, frozenset(args.mistake))
        _keep_freed_memory()
        film = render(scene, opts, max(1, args.jobs))
    except InputError as e:
        print(f"error: {e}", file=sys.stderr)
        return EXIT_BAD_INPUT
    if ext == ".pfm":
        write_pfm(args.output, film)
    else:
        rgb8 = encode_8bit(film, opts.mistakes)
        if ext == ".png":
            write_png(args.output, rgb8)
        else:
            write_ppm(args.output, rgb8, args.ppm_ascii)
    return 0


if __name__ == "__main__":
    sys.exit(main())
