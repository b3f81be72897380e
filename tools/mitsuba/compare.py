#!/usr/bin/env python3
"""Glint's rendering speed side by side with Mitsuba 3's, on this machine, in one run.

For each case, Glint (a subprocess, ``target/release/glint render``) and Mitsuba 3
(in this process, ``mi.render``) render the same Cornell box with the same numbers
of camera and light samples, taking turns, and the script prints a Markdown table
of pixel samples per second and of the ratio Glint/Mitsuba. With ``--baseline``,
an earlier Glint build takes turns with them too, and a second table gives the
speed-up of Glint over it. See tools/mitsuba/README.md.

Python 3.11 and the standard library, plus the ``mitsuba`` package (which brings
``drjit``; numpy is not needed).
"""

from __future__ import annotations

import argparse
import glob
import json
import math
import os
import platform
import re
import statistics
import subprocess
import sys
import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
PROG = "compare.py"

# Glint's defaults for `[render]` keys a scene leaves out (docs/scene-format.md).
GLINT_DEFAULT_RESOLUTION = (512, 512)
GLINT_DEFAULT_SPP = 16
GLINT_DEFAULT_LIGHT_SAMPLES = 16

# The summary line of `glint render` (docs/command-line.md), on stdout:
# wrote OUT: WxH, N spp, N light samples[, N environment samples], T s wall (T s rendering), ...
SUMMARY = re.compile(
    r"wrote (?P<out>.+?): (?P<w>\d+)x(?P<h>\d+), (?P<spp>\d+) spp, "
    r"(?P<light>\d+) light samples.*?, (?P<wall>[0-9.]+) s wall "
    r"\((?P<render>[0-9.]+) s rendering\)"
)


class Failure(Exception):
    """A failure reported as one line, with an exit status."""

    def __init__(self, message: str, status: int = 1):
        super().__init__(message)
        self.status = status


@dataclass(frozen=True)
class Case:
    name: str
    scene: str  # relative to the repository
    glint_args: tuple[str, ...]  # flags after `glint render SCENE`
    spp: int | None  # None: the scene's [render] spp
    light_samples: int | None  # None: the scene's [render] light_samples
    about: str


CASES = {
    c.name: c
    for c in [
        Case(
            "cornell-set1-random",
            "scenes/cornell-set1.toml",
            ("--spp", "64", "--light-samples", "1", "--sampler", "random", "--light-sampler", "random"),
            64,
            1,
            "Set1 box, 64 spp x 1 light sample, independent uniform samples in both",
        ),
        Case(
            "cornell-set1-defaults",
            "scenes/cornell-set1.toml",
            (),
            None,
            None,
            "Set1 box at the scene's shipped settings (Glint: Sobol; Mitsuba: independent)",
        ),
        Case(
            "bunny-cornell",
            "scenes/bunny-cornell.toml",
            (),
            None,
            None,
            "the open Stanford bunny (OBJ) in the box, at the scene's shipped settings",
        ),
    ]
}


# ----------------------------------------------------------------------------------
# Reading the Glint scene


@dataclass
class SceneInfo:
    path: Path
    toml: dict
    width: int
    height: int
    spp: int
    light_samples: int
    notes: list[str] = field(default_factory=list)  # what is not like-for-like


def read_scene(case: Case) -> SceneInfo:
    path = REPO / case.scene
    if not path.is_file():
        raise Failure(f"{case.name}: the scene file {path} is missing", 2)
    try:
        with path.open("rb") as f:
            doc = tomllib.load(f)
    except (OSError, tomllib.TOMLDecodeError) as e:
        raise Failure(f"{case.name}: cannot read {path}: {e}", 2)
    render = doc.get("render", {})
    w, h = render.get("resolution", GLINT_DEFAULT_RESOLUTION)
    spp = case.spp if case.spp is not None else render.get("spp", GLINT_DEFAULT_SPP)
    light = (
        case.light_samples
        if case.light_samples is not None
        else render.get("light_samples", GLINT_DEFAULT_LIGHT_SAMPLES)
    )
    return SceneInfo(path, doc, int(w), int(h), int(spp), int(light))


# ----------------------------------------------------------------------------------
# Small vector helpers (no numpy)


def add(a, b):
    return [a[i] + b[i] for i in range(3)]


def scale(a, s):
    return [x * s for x in a]


def dot(a, b):
    return sum(a[i] * b[i] for i in range(3))


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def normalize(a):
    n = math.sqrt(dot(a, a))
    return [x / n for x in a]


def matmul(a, b):
    n, m, p = len(a), len(b), len(b[0])
    return [[sum(a[i][k] * b[k][j] for k in range(m)) for j in range(p)] for i in range(n)]


def affine(columns, translation):
    """The 4x4 matrix with these three columns and this translation."""
    x, y, z = columns
    t = translation
    return [
        [x[0], y[0], z[0], t[0]],
        [x[1], y[1], z[1], t[1]],
        [x[2], y[2], z[2], t[2]],
        [0.0, 0.0, 0.0, 1.0],
    ]


# ----------------------------------------------------------------------------------
# The Glint scene as a Mitsuba scene dictionary


def rgb(value):
    return {"type": "rgb", "value": [float(x) for x in value]}


def rectangle_to_world(center, edge1, edge2, normal):
    """A Mitsuba `rectangle` spans [-1, 1]^2 in its local xy plane, facing +z: map it
    onto center ± edge1/2 ± edge2/2, with +z going to `normal` (the front side).

    Mitsuba's normal is the inverse transpose of the matrix applied to +z, so it is
    perpendicular to both edges and on `normal`'s side. The rectangle is two
    triangles whose winding also gives a normal; keeping the matrix's determinant
    positive (swapping the edges, which spans the same parallelogram) keeps the two
    normals in agreement."""
    a, b = scale(edge1, 0.5), scale(edge2, 0.5)
    n = normalize(normal)
    if dot(cross(a, b), n) < 0:
        a, b = b, a
    return affine((a, b, n), center)


def rotation_xyz(degrees):
    """Glint's mesh `rotate`: about x, then y, then z, i.e. Rz · Ry · Rx."""
    rx, ry, rz = (math.radians(d) for d in degrees)
    cx, sx, cy, sy, cz, sz = math.cos(rx), math.sin(rx), math.cos(ry), math.sin(ry), math.cos(rz), math.sin(rz)
    Rx = [[1, 0, 0], [0, cx, -sx], [0, sx, cx]]
    Ry = [[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]]
    Rz = [[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]]
    return matmul(Rz, matmul(Ry, Rx))


class Converter:
    """Builds the `mi.load_dict` dictionary of a Glint scene: the same geometry, the
    camera and the area lights, with each material's diffuse colour as a Mitsuba
    `diffuse` BSDF. Whatever is not converted like-for-like is noted in `notes`."""

    def __init__(self, mi, info: SceneInfo, emitter_samples: int):
        self.mi = mi
        self.info = info
        self.doc = info.toml
        self.emitter_samples = emitter_samples
        self.notes = info.notes
        self._noted: set[str] = set()

    def note(self, text: str):
        if text not in self._noted:
            self._noted.add(text)
            self.notes.append(text)

    def fail(self, text: str):
        raise Failure(f"{self.info.path.relative_to(REPO)}: cannot convert for Mitsuba: {text}", 2)

    # -- materials -------------------------------------------------------------

    def texture(self, name: str, for_sphere: bool):
        tex = self.doc.get("textures", {}).get(name)
        if tex is None:
            self.fail(f"unknown texture {name!r}")
        if "checkerboard" not in tex:
            self.fail(f"texture {name!r}: only procedural checkerboards are converted")
        c = tex["checkerboard"]
        n = float(c["checks"])
        if c.get("filter", "point") != "point":
            self.note("checkerboards: Glint's `analytic` filter is not reproduced (Mitsuba looks the pattern up at the hit point)")
        # Mitsuba's checkerboard has 2 x 2 checks over the unit uv square after its
        # `to_uv` transform, color0 where (frac(u) > 1/2) == (frac(v) > 1/2), which is
        # Glint's "first colour where the check's indices sum to an even number" once
        # uv is scaled by N/2. On a sphere Mitsuba's v runs from the top pole down
        # (Glint's from the bottom up), so v is mirrored too.
        h = n / 2
        to_uv = [[h, 0, 0], [0, -h, h], [0, 0, 1]] if for_sphere else [[h, 0, 0], [0, h, 0], [0, 0, 1]]
        return {
            "type": "checkerboard",
            "color0": rgb(c["colors"][0]),
            "color1": rgb(c["colors"][1]),
            "to_uv": self.mi.ScalarTransform3f(to_uv),
        }

    def bsdf(self, name: str, shape_kind: str, two_sided: bool):
        mat = self.doc.get("materials", {}).get(name)
        if mat is None:
            self.fail(f"unknown material {name!r}")
        if "mirror" in mat or mat.get("reflectivity", 0) > 0:
            self.fail(f"material {name!r}: mirrors are not converted")
        if mat.get("uv_scale", [1, 1]) != [1, 1] or mat.get("uv_offset", [0, 0]) != [0, 0]:
            self.fail(f"material {name!r}: uv_scale/uv_offset are not converted")
        kd = mat["diffuse"]
        if isinstance(kd, str):
            reflectance = self.texture(kd, for_sphere=shape_kind == "sphere")
        else:
            reflectance = rgb(kd)
        self.note(
            "materials: Glint shades Phong (diffuse + a specular lobe, `specular` defaulting to the "
            "diffuse colour); Mitsuba gets a Lambertian `diffuse` BSDF with the diffuse colour only"
        )
        bsdf = {"type": "diffuse", "reflectance": reflectance}
        if two_sided:
            bsdf = {"type": "twosided", "material": bsdf}
        return bsdf

    # -- the scene -------------------------------------------------------------

    def scene_dict(self, spp: int):
        doc = self.doc
        for key in ("environment", "plane", "box", "point_light"):
            if key in doc:
                self.fail(f"`{key}` is not converted")
        if any(v != 0 for v in doc.get("ambient", [0, 0, 0])):
            self.note(
                "ambient: Glint adds `ambient · kd` at every shaded point; Mitsuba has no ambient term "
                "(a constant environment would add an emitter to sample, so none is added)"
            )
        cam = doc["camera"]
        info = self.info
        d: dict = {
            "type": "scene",
            "integrator": {
                "type": "direct",
                "emitter_samples": self.emitter_samples,
                "bsdf_samples": 0,
            },
            "sensor": {
                "type": "perspective",
                "fov": float(cam["fov"]),
                "fov_axis": "y",
                "to_world": self.mi.ScalarTransform4f().look_at(
                    origin=[float(x) for x in cam["position"]],
                    target=[float(x) for x in cam["look_at"]],
                    up=[float(x) for x in cam.get("up", [0, 1, 0])],
                ),
                "film": {
                    "type": "hdrfilm",
                    "width": info.width,
                    "height": info.height,
                    "pixel_format": "rgb",
                    "rfilter": {"type": "box"},
                },
                "sampler": {"type": "independent", "sample_count": spp},
            },
        }
        for i, p in enumerate(doc.get("parallelogram", [])):
            e1, e2 = p["edge1"], p["edge2"]
            n = p.get("normal") or cross(e1, e2)
            center = add(p["origin"], scale(add(e1, e2), 0.5))
            two_sided = bool(p.get("two_sided", False))
            d[f"parallelogram-{i}"] = {
                "type": "rectangle",
                "to_world": self.mi.ScalarTransform4f(rectangle_to_world(center, e1, e2, n)),
                "bsdf": self.bsdf(p["material"], "parallelogram", two_sided),
            }
        for i, s in enumerate(doc.get("sphere", [])):
            # Glint's sphere uv: u = atan2(-z, x)/2π around +y, v from the bottom
            # pole. Mitsuba's: u = atan2(y, x)/2π around its local +z, v from the top
            # pole. Local x, y, z -> world x, -z, y makes the u's agree (v is mirrored
            # in the checkerboard's to_uv); the radius is the matrix's scale.
            r = float(s["radius"])
            rot = affine(([r, 0, 0], [0, 0, -r], [0, r, 0]), [float(x) for x in s["center"]])
            d[f"sphere-{i}"] = {
                "type": "sphere",
                "to_world": self.mi.ScalarTransform4f(rot),
                "bsdf": self.bsdf(s["material"], "sphere", False),
            }
        for i, m in enumerate(doc.get("mesh", [])):
            if "material" not in m:
                self.fail(f"mesh[{i}]: meshes with MTL materials are not converted")
            file = (info.path.parent / m["file"]).resolve()
            if not file.is_file():
                raise Failure(f"{info.path.relative_to(REPO)}: mesh[{i}]: {file} is missing", 2)
            sc = m.get("scale", 1)
            sc = [float(sc)] * 3 if isinstance(sc, (int, float)) else [float(x) for x in sc]
            if sc[0] * sc[1] * sc[2] < 0:
                self.fail(f"mesh[{i}]: mirroring scales are not converted")
            R = rotation_xyz(m.get("rotate", [0, 0, 0]))
            cols = [[R[r][c] * sc[c] for r in range(3)] for c in range(3)]
            d[f"mesh-{i}"] = {
                "type": "obj",
                "filename": str(file),
                "to_world": self.mi.ScalarTransform4f(affine(cols, [float(x) for x in m.get("translate", [0, 0, 0])])),
                # Glint shades a triangle on whichever side the viewer is (an open
                # mesh shows its inside lit); Mitsuba's BSDFs are one-sided unless
                # wrapped in `twosided`.
                "bsdf": self.bsdf(m["material"], "mesh", True),
            }
            self.note(
                "meshes: the OBJ has no normals and both compute angle-weighted vertex normals; Glint "
                "intersects them with its own BVH, Mitsuba with Embree; both shade either side of a triangle"
            )
        lights = doc.get("area_light", [])
        if not lights:
            self.fail("no area light")
        for i, a in enumerate(lights):
            e1, e2 = a["edge1"], a["edge2"]
            n = a.get("normal") or cross(e1, e2)
            d[f"area-light-{i}"] = {
                "type": "rectangle",
                "to_world": self.mi.ScalarTransform4f(rectangle_to_world(a["center"], e1, e2, n)),
                # Glint returns the light's colour when a camera ray hits it, without
                # shading it; a black diffuse BSDF makes Mitsuba's shading of it zero
                # (Mitsuba still samples the light there).
                "bsdf": {"type": "diffuse", "reflectance": rgb([0, 0, 0])},
                "emitter": {"type": "area", "radiance": rgb(a.get("color", [1, 1, 1]))},
            }
        self.note(
            "the light seen directly: Glint returns its colour; Mitsuba adds its emission and then also "
            "shades it (a black `diffuse`, still sampling the light: a little extra work on ~1% of the pixels)"
        )
        self.note(
            "light transport: Glint's area light sample is a point light without distance falloff "
            "(`L · kd · max(0, n·l)`, the course's model); Mitsuba's `direct` integrator is physically "
            "based (`kd/π`, cosines at both ends, 1/r²), so its image is much darker. Both trace one "
            "shadow ray per light sample"
        )
        if len(lights) > 1:
            self.note(
                "several area lights: Glint takes `light_samples` samples of each light per camera "
                "sample, Mitsuba `emitter_samples` samples in all, each of one light picked at random"
            )
        return d


# ----------------------------------------------------------------------------------
# Running and timing


def glint_patterns(case: Case, info: SceneInfo) -> tuple[str, str]:
    """Glint's pixel and light sample patterns in this case (flags over the scene)."""
    render = info.toml.get("render", {})
    pixel, light = render.get("pixel_sampler", "sobol"), render.get("light_sampler", "sobol")
    args = list(case.glint_args)
    for flag, value in zip(args, args[1:]):
        if flag == "--sampler":
            pixel = value
        elif flag == "--light-sampler":
            light = value
    return pixel, light


def machine_cpu() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def glint_version(binary: Path) -> str:
    try:
        r = subprocess.run([str(binary), "--version"], capture_output=True, text=True, timeout=60)
        return r.stdout.strip() or r.stderr.strip()
    except OSError as e:
        return f"unknown ({e})"


def run_glint(binary: Path, label: str, case: Case, info: SceneInfo, out: Path) -> dict:
    cmd = [str(binary), "render", str(info.path), *case.glint_args, "-o", str(out)]
    t0 = time.perf_counter()
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, cwd=REPO)
    except OSError as e:
        raise Failure(f"{case.name}: cannot run {label} ({binary}): {e}")
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        err = (r.stderr.strip() or r.stdout.strip() or "(no output)").splitlines()
        raise Failure(
            f"{case.name}: {label} failed with exit status {r.returncode}: "
            + " | ".join(err[-5:])
            + f"\n  command: {' '.join(cmd)}"
        )
    m = SUMMARY.search(r.stdout) or SUMMARY.search(r.stderr)
    if not m:
        raise Failure(
            f"{case.name}: {label}: no summary line (`wrote ...: ..., X s wall (Y s rendering), ...`) "
            f"in its output:\n{r.stdout}{r.stderr}"
        )
    got = (int(m["w"]), int(m["h"]), int(m["spp"]), int(m["light"]))
    want = (info.width, info.height, info.spp, info.light_samples)
    if got != want:
        raise Failure(
            f"{case.name}: {label} rendered {got[0]}x{got[1]} at {got[2]} spp x {got[3]} light samples, "
            f"expected {want[0]}x{want[1]} at {want[2]} spp x {want[3]} (the scene's defaults changed?)"
        )
    render = float(m["render"])
    if render <= 0:
        raise Failure(f"{case.name}: {label} reported a render time of {m['render']} s")
    return {
        "render_s": render,
        "reported_wall_s": float(m["wall"]),
        "process_wall_s": wall,
        "summary": m.group(0),
    }


# Dr.Jit's LLVM backend (the `llvm_*` variants) compiles with the system's libLLVM,
# picking one itself. LLVM 15 aborts the process on Mitsuba's kernels ("LLVM ERROR:
# Cannot select: ... fminimum", x86 has no lowering of llvm.minimum/maximum there:
# llvm/llvm-project#53353); 19 works; 16 was not tried. So prefer the newest libLLVM
# on the machine, and refuse one older than this unless DRJIT_LIBLLVM_PATH names it.
LLVM_MIN = 17
LIBLLVM_DIRS = ["/usr/lib/x86_64-linux-gnu", "/usr/lib/aarch64-linux-gnu", "/usr/lib64", "/usr/lib", "/usr/local/lib"]


def newest_libllvm() -> tuple[int, str] | None:
    found = []
    dirs = LIBLLVM_DIRS + sorted(glob.glob("/usr/lib/llvm-*/lib"))
    for d in dirs:
        for f in glob.glob(os.path.join(d, "libLLVM*.so*")):
            m = re.match(r"libLLVM(?:-(\d+)|\.so\.(\d+))", os.path.basename(f))
            if m and os.path.isfile(f):
                found.append((int(m[1] or m[2]), f))
    return max(found) if found else None


class Mitsuba:
    def __init__(self, variant: str):
        self.libllvm = None
        explicit_llvm = "DRJIT_LIBLLVM_PATH" in os.environ
        if variant.startswith("llvm_") and not explicit_llvm:
            newest = newest_libllvm()
            if newest is None or newest[0] < LLVM_MIN:
                have = f"the newest found is LLVM {newest[0]} ({newest[1]})" if newest else "none was found"
                raise Failure(
                    f"the Mitsuba variant {variant!r} needs libLLVM {LLVM_MIN} or newer ({have}; LLVM 15 "
                    "aborts on Mitsuba's kernels). Install one (Debian 12: `apt-get install libllvm19`), set "
                    "DRJIT_LIBLLVM_PATH to one, or use --variant scalar_rgb",
                    2,
                )
            os.environ["DRJIT_LIBLLVM_PATH"] = newest[1]
        self.libllvm = os.environ.get("DRJIT_LIBLLVM_PATH") if variant.startswith("llvm_") else None
        try:
            import drjit as dr
            import mitsuba as mi
        except ImportError as e:
            raise Failure(
                f"cannot import mitsuba ({e}); run tools/mitsuba/compare.sh, which installs it in a "
                f"virtual environment, or `pip install mitsuba` for {sys.executable}",
                2,
            )
        if variant not in mi.variants():
            raise Failure(
                f"the Mitsuba variant {variant!r} is not available; this build has: {', '.join(mi.variants())}", 2
            )
        try:
            mi.set_variant(variant)
        except Exception as e:  # noqa: BLE001 (e.g. LLVM missing)
            raise Failure(f"cannot set the Mitsuba variant {variant!r}: {e}", 2)
        self.mi, self.dr, self.variant = mi, dr, variant
        self.llvm_version = None
        if variant.startswith("llvm_") and hasattr(dr.detail, "llvm_version"):
            self.llvm_version = ".".join(str(x) for x in dr.detail.llvm_version())
            major = int(dr.detail.llvm_version()[0])
            if major < LLVM_MIN:
                if not explicit_llvm:
                    raise Failure(
                        f"Dr.Jit loaded LLVM {self.llvm_version}, older than {LLVM_MIN}, which aborts on "
                        "Mitsuba's kernels; set DRJIT_LIBLLVM_PATH to a newer libLLVM or use --variant scalar_rgb",
                        2,
                    )
                print(
                    f"{PROG}: warning: DRJIT_LIBLLVM_PATH gives LLVM {self.llvm_version}; LLVM 15 is known to "
                    "abort on Mitsuba's kernels",
                    file=sys.stderr,
                )
        self.version = mi.__version__
        self.drjit_version = dr.__version__
        try:
            self.threads = int(dr.thread_count())
        except Exception:  # noqa: BLE001
            self.threads = os.cpu_count() or 0

    def load(self, scene_dict: dict):
        try:
            return self.mi.load_dict(scene_dict)
        except Exception as e:  # noqa: BLE001
            raise Failure(f"Mitsuba could not load the converted scene: {e}")

    def render(self, scene, spp: int, seed: int):
        """Renders and waits for the result; returns (seconds, image)."""
        dr = self.dr
        t0 = time.perf_counter()
        img = self.mi.render(scene, spp=spp, seed=seed)
        dr.eval(img)
        dr.sync_thread()
        return time.perf_counter() - t0, img

    def check_and_write(self, img, path: Path) -> list[float]:
        """Writes the image (EXR) and returns its channel means; fails unless they are
        finite and some are above 0."""
        path.parent.mkdir(parents=True, exist_ok=True)
        self.mi.Bitmap(img).write(str(path))
        means = [float(x) for x in self.dr.mean(img, axis=(0, 1)).array]
        if not all(math.isfinite(m) for m in means) or max(means) <= 0:
            raise Failure(f"Mitsuba's image {path} is implausible: channel means {means}")
        return means


# ----------------------------------------------------------------------------------
# Statistics and the tables


def summary(values: list[float]) -> dict:
    return {"median": statistics.median(values), "min": min(values), "max": max(values)}


def fmt_rate(s: dict) -> str:
    """Samples per second as M/s with three significant digits."""
    def f(x):
        m = x / 1e6
        return f"{m:.0f}" if m >= 100 else f"{m:#.3g}"

    return f"{f(s['median'])} ({f(s['min'])}–{f(s['max'])})"


def fmt_ratio(s: dict) -> str:
    return f"{s['median']:.2f}× ({s['min']:.2f}–{s['max']:.2f})"


def parse_args(argv):
    p = argparse.ArgumentParser(
        prog=PROG,
        description="Measure Glint's speed side by side with Mitsuba 3 (alternating runs) and print a Markdown table.",
    )
    p.add_argument(
        "--case",
        action="append",
        choices=list(CASES),
        help="a case to run (repeat for several; default: all): " + "; ".join(f"{c.name}: {c.about}" for c in CASES.values()),
    )
    p.add_argument("--pairs", type=int, default=5, help="timed runs of each renderer per case (default 5)")
    p.add_argument("--variant", default="llvm_ad_rgb", help="Mitsuba variant (default llvm_ad_rgb; e.g. scalar_rgb)")
    p.add_argument("--glint", default=str(REPO / "target/release/glint"), help="the Glint binary (default target/release/glint)")
    p.add_argument("--baseline", metavar="GLINT_BINARY", help="an earlier Glint build to time against as well")
    p.add_argument("--json", metavar="FILE", help="write every raw timing to this JSON file")
    p.add_argument("--out-dir", default=str(REPO / "target/mitsuba"), help="where the images go (default target/mitsuba)")
    p.add_argument("--equal-error", action="store_true", help="time to equal error instead (its own options: --equal-error --help)")
    a = p.parse_args(argv)
    if a.pairs < 1:
        p.error("--pairs must be at least 1")
    return a


def equal_error(argv: list[str]) -> int:
    """`--equal-error`: time to reach equal error, each renderer against its own
    reference (tools/mitsuba/equal_error.py, a module of its own)."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import equal_error as mode

    return mode.run(argv)


def main(argv=None) -> int:
    if "--equal-error" in (sys.argv[1:] if argv is None else argv):
        return equal_error(sys.argv[1:] if argv is None else argv)
    args = parse_args(argv)
    cases = [CASES[n] for n in dict.fromkeys(args.case or list(CASES))]
    out_dir = Path(args.out_dir).resolve()

    # Check what can be checked before spending time.
    infos = {c.name: read_scene(c) for c in cases}
    glint = Path(args.glint).resolve()
    if not glint.is_file():
        raise Failure(f"no Glint binary at {glint}; build it with `cargo build --release -p glint-cli`", 2)
    binaries = [("glint", glint)]
    if args.baseline:
        base = Path(args.baseline).resolve()
        if not base.is_file():
            raise Failure(f"--baseline: no such file {base}", 2)
        binaries.append(("baseline", base))
    ms = Mitsuba(args.variant)
    out_dir.mkdir(parents=True, exist_ok=True)

    machine = {
        "cpu": machine_cpu(),
        "cores": os.cpu_count(),
        "os": f"{platform.system()} {platform.release()} {platform.machine()}",
        "python": platform.python_version(),
        "mitsuba": ms.version,
        "drjit": ms.drjit_version,
        "variant": ms.variant,
        "mitsuba_threads": ms.threads,
        "llvm": ms.llvm_version,
        "libllvm": ms.libllvm,
        "glint": glint_version(glint),
        "glint_binary": str(glint),
        "baseline_binary": str(binaries[1][1]) if len(binaries) > 1 else None,
    }
    log = lambda *a: print(*a, file=sys.stderr, flush=True)  # noqa: E731
    llvm = f", LLVM {ms.llvm_version} ({ms.libllvm})" if ms.llvm_version else ""
    log(f"machine: {machine['cpu']}, {machine['cores']} cores; Mitsuba {ms.version} {ms.variant} ({ms.threads} threads{llvm})")

    results = []
    for case in cases:
        info = infos[case.name]
        spp, light = info.spp, info.light_samples
        pixels = info.width * info.height
        samples = pixels * spp  # pixel (camera) samples of one render
        log(f"\n== {case.name}: {info.path.relative_to(REPO)}, {info.width}x{info.height}, {spp} spp x {light} light samples")

        conv = Converter(ms.mi, info, emitter_samples=light)
        patterns = glint_patterns(case, info)
        if patterns != ("random", "random"):
            info.notes.append(
                f"samplers ({case.name}): Glint's pixel/light patterns are {patterns[0]}/{patterns[1]} "
                "(Owen-scrambled Sobol hashes per sample), Mitsuba's `independent` sampler draws uniform "
                "random numbers; the sample counts are the same"
            )
        scene = ms.load(conv.scene_dict(spp))
        png = lambda label: out_dir / f"{label}-{case.name}.png"  # noqa: E731

        # Warm-ups, not timed: Mitsuba's compiles its kernels (LLVM JIT, cached on disk
        # by Dr.Jit), each Glint's loads its binary and the scene files into the page cache.
        warm_s, img = ms.render(scene, spp, seed=1_000_000)
        exr = out_dir / f"{case.name}.exr"
        means = ms.check_and_write(img, exr)
        del img
        log(f"mitsuba warm-up (not timed): {warm_s:.2f} s; wrote {exr}, channel means {[round(m, 5) for m in means]}")
        for label, binary in binaries:
            w = run_glint(binary, label, case, info, png(label))
            log(f"{label} warm-up (not timed): {w['render_s']:.2f} s rendering")

        tools = [b[0] for b in binaries] + ["mitsuba"]
        runs = []
        for i in range(args.pairs):
            if len(tools) == 2:
                order = tools if i % 2 == 0 else tools[::-1]
            else:
                k = i % len(tools)
                order = tools[k:] + tools[:k]
            for pos, tool in enumerate(order):
                run = {"case": case.name, "round": i, "position": pos, "tool": tool}
                if tool == "mitsuba":
                    t, img = ms.render(scene, spp, seed=i)
                    del img
                    run.update(render_s=t, seed=i)
                else:
                    run.update(run_glint(dict(binaries)[tool], tool, case, info, png(tool)))
                run["pixel_samples_per_s"] = samples / run["render_s"]
                run["shadow_ray_samples_per_s"] = samples * light / run["render_s"]
                if "process_wall_s" in run:
                    run["pixel_samples_per_s_process_wall"] = samples / run["process_wall_s"]
                runs.append(run)
                log(f"round {i + 1}/{args.pairs} {tool:8s} {run['render_s']:7.3f} s  {run['pixel_samples_per_s'] / 1e6:7.3f} M pixel samples/s")
        del scene

        by = {t: [r for r in runs if r["tool"] == t] for t in tools}
        rate = {t: [r["pixel_samples_per_s"] for r in by[t]] for t in tools}
        res = {
            "case": case.name,
            "scene": case.scene,
            "resolution": [info.width, info.height],
            "spp": spp,
            "light_samples": light,
            "glint_args": list(case.glint_args),
            "mitsuba": {
                "sampler": "independent",
                "integrator": {"type": "direct", "emitter_samples": light, "bsdf_samples": 0},
                "warmup_s": warm_s,
                "image": str(exr),
                "channel_means": means,
            },
            "not_like_for_like": info.notes,
            "runs": runs,
            "pixel_samples_per_s": {t: summary(rate[t]) for t in tools},
            "shadow_ray_samples_per_s": {t: summary([x * light for x in rate[t]]) for t in tools},
            "render_s": {t: summary([r["render_s"] for r in by[t]]) for t in tools},
            "glint_over_mitsuba": summary([g / m for g, m in zip(rate["glint"], rate["mitsuba"])]),
        }
        for label, _ in binaries:
            res["render_s"][label + "_process_wall"] = summary([r["process_wall_s"] for r in by[label]])
        if len(binaries) > 1:
            res["glint_over_baseline"] = summary([g / b for g, b in zip(rate["glint"], rate["baseline"])])
        results.append(res)

    cpu = f"{machine['cpu']}, {machine['cores']} cores; Mitsuba {ms.version} `{ms.variant}`"
    lines = [
        "| case | spp × light samples | Glint M pixel samples/s | Mitsuba M pixel samples/s | Glint/Mitsuba | "
        "Glint M shadow-ray samples/s | Mitsuba M shadow-ray samples/s | machine |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        ps, sr = r["pixel_samples_per_s"], r["shadow_ray_samples_per_s"]
        lines.append(
            f"| {r['case']} | {r['spp']} × {r['light_samples']} | {fmt_rate(ps['glint'])} | {fmt_rate(ps['mitsuba'])} | "
            f"{fmt_ratio(r['glint_over_mitsuba'])} | {fmt_rate(sr['glint'])} | {fmt_rate(sr['mitsuba'])} | {cpu} |"
        )
    lines += [
        "",
        f"Median (min–max) over {args.pairs} runs each, alternating; rates are W·H·spp (pixel samples) and "
        "W·H·spp·light samples (shadow-ray samples) over the render time: Glint's render phase from its summary "
        "line, Mitsuba's `mi.render` + evaluation after one untimed warm-up (JIT compilation). "
        "Glint/Mitsuba is the median (min–max) of the per-round ratios.",
        "",
        "| case | Glint render s | Glint process wall s | Mitsuba render s |" + (" baseline render s | baseline process wall s |" if len(binaries) > 1 else ""),
        "|---|---|---|---|" + ("---|---|" if len(binaries) > 1 else ""),
    ]
    f3 = lambda s: f"{s['median']:.3f} ({s['min']:.3f}–{s['max']:.3f})"  # noqa: E731
    for r in results:
        t = r["render_s"]
        row = f"| {r['case']} | {f3(t['glint'])} | {f3(t['glint_process_wall'])} | {f3(t['mitsuba'])} |"
        if len(binaries) > 1:
            row += f" {f3(t['baseline'])} | {f3(t['baseline_process_wall'])} |"
        lines.append(row)
    if len(binaries) > 1:
        lines += [
            "",
            f"Glint ({glint}) against the baseline ({binaries[1][1]}):",
            "",
            "| case | Glint M pixel samples/s | baseline M pixel samples/s | speed-up Glint/baseline |",
            "|---|---|---|---|",
        ]
        for r in results:
            ps = r["pixel_samples_per_s"]
            lines.append(
                f"| {r['case']} | {fmt_rate(ps['glint'])} | {fmt_rate(ps['baseline'])} | {fmt_ratio(r['glint_over_baseline'])} |"
            )
    notes = list(dict.fromkeys(n for r in results for n in r["not_like_for_like"]))
    if notes:
        lines += ["", "Not like-for-like:", ""] + [f"- {n}" for n in notes]
    print("\n".join(lines))

    if args.json:
        path = Path(args.json)
        doc = {"machine": machine, "pairs": args.pairs, "argv": sys.argv, "cases": results}
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            tmp = path.with_name(path.name + ".tmp")
            tmp.write_text(json.dumps(doc, indent=2) + "\n")
            tmp.replace(path)
        except OSError as e:
            raise Failure(f"cannot write {path}: {e}")
        log(f"wrote {path}")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except Failure as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        sys.exit(e.status)
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        sys.exit(130)
