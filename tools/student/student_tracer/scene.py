"""Reading a scene file (scene-format.md): materials, lights, camera,
environment, textures and shapes into a Scene, with its size, its closest hit
along a ray (step 3), and the shadow and mirror rays' offset eps (step 9).
"""

import math
import os
import tomllib

from .camera import Camera
from .environment import FACES, Environment
from .geometry import Box, Parallelogram, Plane, SceneObject, Sphere, box_faces
from .images import read_image
from .textures import Checkerboard, Constant, ImageTexture, checker_image
from .vectors import INF, add, cross, mul, normalize, sub, vec


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
