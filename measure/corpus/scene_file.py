"""Reading a Glint scene file: the subset of the TOML format the course's
Cornell scenes use, into the dataclasses below. Any key it does not know is
refused (InputError), never ignored.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field

import numpy as np


class InputError(Exception):
    """Bad input (scene file or command line): one line, exit status 2."""


# --------------------------------------------------------------------------
# The scene
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


# --------------------------------------------------------------------------
# Reading the TOML
# --------------------------------------------------------------------------
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
