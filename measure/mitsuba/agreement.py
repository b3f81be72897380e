#!/usr/bin/env python3
"""Glint against Mitsuba 3 on physical scenes: do the two renderers compute the same image?

For each Glint scene file (``shading = "physical"``), the script renders it K times
with Glint (``glint render SCENE --seed S``) and K times with Mitsuba 3 from
``glint export --mitsuba`` (each render in a process of its own), and prints a
Markdown table per scene:

- the mean of each renderer over the image, per channel and overall, with its
  standard error over the K seeds, and the relative difference of the means;
- relMSE(Glint, Mitsuba) over the image, and the noise floor: relMSE between two
  Glint seeds and between two Mitsuba seeds. For independent renders
  E[(G − M)²] = var_G + var_M + bias², while E[(G₁ − G₂)²] = 2·var_G, so without
  bias the cross relMSE equals the mean of the two within-renderer ones: their
  ratio is printed, and is 1 up to noise when the renderers agree pixel by pixel.

Mitsuba's ``direct`` integrator follows no mirror reflections, renders a partial
mirror's ``blendbsdf`` biased, and shows one-sided surfaces black from behind;
where a scene needs it, the Mitsuba renders use a small Python integrator around
``direct`` that does as Glint does (``--integrator glint``, the default).

Exit status 1 if a scene's means differ by 0.3% or more (overall or in a
channel; ``--mean-tolerance``), or its ratio exceeds ``--ratio-tolerance`` with
the cross relMSE more than ``--excess-tolerance`` above the floor; 2 for bad
input; 0 otherwise. See measure/mitsuba/README.md.

Python 3.11 and the standard library, plus the ``mitsuba`` package (numpy is not
needed).
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib
import xml.etree.ElementTree as ET
from dataclasses import asdict, dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
PROG = "agreement.py"

# commands/metrics' relative MSE: (x − r)² / (r + 0.01)² per channel, averaged
# (REL_MSE_EPSILON in commands/metrics/src/rel_mse.rs). Here r is one fixed
# reference for all three comparisons, the mean of every render of the scene,
# so that they weigh each pixel alike and their expectations add up.
REL_MSE_EPSILON = 0.01


class Failure(Exception):
    """A failure reported as one line, with an exit status."""

    def __init__(self, message: str, status: int = 1):
        super().__init__(message)
        self.status = status


# ----------------------------------------------------------------------------------
# Images


def read_image(mi, path: Path) -> tuple[int, int, list[float]]:
    """(width, height, RGB floats row by row) of an EXR."""
    bitmap = mi.Bitmap(str(path)).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32)
    return bitmap.width(), bitmap.height(), [float(v) for v in mi.TensorXf(bitmap).array]


# ----------------------------------------------------------------------------------
# The renders


@dataclass
class Settings:
    seeds: list[int]
    spp: int
    mitsuba_spp: int
    light_samples: int
    resolution: str | None
    variant: str
    integrator: str


def run(command: list[str], what: str) -> subprocess.CompletedProcess:
    try:
        done = subprocess.run(command, capture_output=True, text=True)
    except OSError as e:
        raise Failure(f"{what}: cannot run {command[0]}: {e}", 2)
    if done.returncode != 0:
        message = (done.stderr.strip().splitlines() or ["(no message)"])[-1]
        status = 2 if done.returncode == 2 else 1
        raise Failure(f"{what} failed (exit status {done.returncode}): {message}", status)
    return done


def glint_render(glint: Path, scene: Path, seed: int, s: Settings, out: Path) -> float:
    command = [str(glint), "render", str(scene), "--seed", str(seed), "--spp", str(s.spp),
               "--light-samples", str(s.light_samples), "-o", str(out)]
    if s.resolution:
        command += ["--resolution", s.resolution]
    start = time.perf_counter()
    run(command, f"{scene.name}: glint render --seed {seed}")
    return time.perf_counter() - start


def glint_export(glint: Path, scene: Path, s: Settings, out: Path) -> list[str]:
    command = [str(glint), "export", "--mitsuba", str(scene), "--spp", str(s.mitsuba_spp),
               "--light-samples", str(s.light_samples), "-o", str(out)]
    if s.resolution:
        command += ["--resolution", s.resolution]
    done = run(command, f"{scene.name}: glint export --mitsuba")
    prefix = "glint: warning: "
    return [line[len(prefix):] for line in done.stderr.splitlines() if line.startswith(prefix)]


def mitsuba_render(xml: Path, seed: int, s: Settings, max_depth: int, out: Path) -> float:
    """Renders in a process of its own: after a render in this one, Mitsuba's
    threads leave this process's Python loops crawling."""
    command = [sys.executable, __file__, "--render-worker", str(xml), str(seed), str(out),
               s.variant, s.integrator, str(max_depth)]
    start = time.perf_counter()
    run(command, f"{xml.stem}: Mitsuba render --seed {seed}")
    return time.perf_counter() - start


# ----------------------------------------------------------------------------------
# The worker: one Mitsuba render


def mirror_table(xml_path: Path) -> dict[str, tuple[float, list[float]]]:
    """Per shape id of an exported scene, its perfect-mirror part: (reflectivity r,
    tint), from the BSDFs `glint export` writes (a `conductor` is r = 1, a
    `blendbsdf` of a diffuse and a conductor is r = its weight)."""

    def rgb(element, name):
        for child in element.iter("rgb"):
            if child.get("name") == name:
                return [float(x) for x in child.get("value").replace(",", " ").split()]
        return [1.0, 1.0, 1.0]

    def mirror_of(bsdf) -> tuple[float, list[float]] | None:
        kind = bsdf.get("type")
        if kind == "twosided":
            inner = bsdf.find("bsdf")
            return mirror_of(inner) if inner is not None else None
        if kind == "conductor":
            return 1.0, rgb(bsdf, "specular_reflectance")
        if kind == "blendbsdf":
            weight = next(float(f.get("value")) for f in bsdf.findall("float") if f.get("name") == "weight")
            conductor = next((b for b in bsdf.findall("bsdf") if b.get("type") == "conductor"), None)
            if conductor is not None:
                return weight, rgb(conductor, "specular_reflectance")
        return None

    root = ET.parse(xml_path).getroot()
    bsdfs = {b.get("id"): mirror_of(b) for b in root.findall("bsdf") if b.get("id")}
    table = {}
    for shape in root.findall("shape"):
        ref = shape.find("ref")
        found = bsdfs.get(ref.get("id")) if ref is not None else None
        if found:
            table[shape.get("id")] = found
    return table


def see_through_table(xml_path: Path) -> tuple[set[str], bool]:
    """The ids of the exported one-sided rectangles (Glint's one-sided
    parallelograms and planes, and its area lights: invisible from behind),
    and whether the camera sees the back of any of them (it stands behind its
    plane). `glint export` puts a rectangle's unit front normal in the third
    column of its `to_world` and its centre in the fourth."""
    root = ET.parse(xml_path).getroot()
    bsdf_types = {b.get("id"): b.get("type") for b in root.findall("bsdf") if b.get("id")}
    lookat = root.find("sensor/transform/lookat")
    camera = [float(x) for x in lookat.get("origin").replace(",", " ").split()]
    ids, behind = set(), False
    for shape in root.findall("shape"):
        if shape.get("type") != "rectangle":
            continue
        ref, inline = shape.find("ref"), shape.find("bsdf")
        kind = bsdf_types.get(ref.get("id")) if ref is not None else (inline.get("type") if inline is not None else None)
        if kind == "twosided":
            continue
        ids.add(shape.get("id"))
        m = [float(x) for x in shape.find("transform/matrix").get("value").split()]
        normal, centre = (m[2], m[6], m[10]), (m[3], m[7], m[11])
        if sum((camera[i] - centre[i]) * normal[i] for i in range(3)) < 0:
            behind = True
    return ids, behind


def without_mirrors(xml_path: Path) -> Path:
    """A copy of an exported scene (beside it, so that its relative paths still
    resolve) whose perfect mirrors are black diffuse BSDFs: a `conductor`
    becomes black, and a `blendbsdf` of a diffuse and a conductor the diffuse
    part alone, at 1 − r. The mirror chains are then added by the integrator.
    (Mitsuba 3.9's `blendbsdf` of a smooth and a delta lobe is biased under
    MIS: its sampling reports the chosen lobe's density, not the blend's.)"""
    tree = ET.parse(xml_path)
    for parent in tree.getroot().iter():
        for i, child in enumerate(list(parent)):
            if child.tag == "bsdf" and child.get("type") == "conductor":
                black = ET.Element("bsdf", {k: v for k, v in child.attrib.items() if k == "id"})
                black.set("type", "diffuse")
                ET.SubElement(black, "rgb", {"name": "reflectance", "value": "0, 0, 0"})
                parent.remove(child)
                parent.insert(i, black)
    out = xml_path.with_name(xml_path.stem + "-without-mirrors.xml")
    tree.write(out)
    return out


def make_glint_integrator(mi, dr, direct, mirrors: dict, see_through: set, max_depth: int):
    """Glint's direct integrator in Mitsuba, as far as the camera's rays go:

    - `direct` shades each point, with the mirror lobes removed from the scene
      ([`without_mirrors`]); where a camera ray (or a reflected one) meets a
      shape whose material reflects r·tint perfectly, r·tint times the radiance
      along the mirrored ray is added, traced the same way, up to `max_depth`
      reflections, beyond which Glint sees black;
    - a ray that meets a one-sided rectangle (a one-sided parallelogram or
      plane, an area light) from behind goes on through it, as in Glint.

    Scalar variants only: one sample at a time, in Python."""

    class GlintDirect(mi.SamplingIntegrator):
        def __init__(self, props=mi.Properties()):
            mi.SamplingIntegrator.__init__(self, props)

        def trace(self, scene, sampler, ray, depth):
            si = scene.ray_intersect(ray)
            if si.is_valid() and si.shape is not None and si.shape.id() in see_through and dr.dot(si.n, ray.d) > 0:
                return self.trace(scene, sampler, si.spawn_ray(ray.d), depth)
            L, _, _ = direct.sample(scene, sampler, mi.RayDifferential3f(ray))
            if depth >= max_depth or not si.is_valid() or si.shape is None:
                return L
            mirror = mirrors.get(si.shape.id())
            if mirror is None:
                return L
            r, tint = mirror
            n = si.sh_frame.n
            if dr.dot(n, ray.d) > 0:
                n = -n
            reflected = si.spawn_ray(ray.d - 2.0 * dr.dot(ray.d, n) * n)
            return L + mi.Color3f(*tint) * r * self.trace(scene, sampler, reflected, depth + 1)

        def sample(self, scene, sampler, ray, medium=None, active=True):
            return self.trace(scene, sampler, mi.Ray3f(ray), 0), True, []

        def aov_names(self):
            return []

        def to_string(self):
            return "GlintDirect[]"

    return GlintDirect()


def render_worker(argv: list[str]) -> int:
    xml, seed, out, variant, mode, max_depth = argv
    import mitsuba as mi

    if variant.startswith("llvm_") and "DRJIT_LIBLLVM_PATH" not in os.environ:
        sys.path.insert(0, str(Path(__file__).parent))
        from harness import newest_libllvm  # the same lookup as compare.py

        found = newest_libllvm()
        if found:
            os.environ["DRJIT_LIBLLVM_PATH"] = found[1]
    mi.set_variant(variant)
    integrator = None
    mirrors = mirror_table(Path(xml)) if mode == "glint" else {}
    see_through, behind = see_through_table(Path(xml)) if mode == "glint" else (set(), False)
    scene = mi.load_file(str(without_mirrors(Path(xml))) if mirrors else xml)
    if mirrors or behind:
        import drjit as dr

        root = ET.parse(xml).getroot()
        counts = {i.get("name"): int(i.get("value")) for i in root.find("integrator").findall("integer")}
        direct = mi.load_dict({"type": "direct", **counts})
        integrator = make_glint_integrator(mi, dr, direct, mirrors, see_through, int(max_depth))
    image = mi.render(scene, integrator=integrator, seed=int(seed)) if integrator else mi.render(scene, seed=int(seed))
    mi.util.write_bitmap(out, image, write_async=False)
    return 0


# ----------------------------------------------------------------------------------
# One scene

REGIONS = ["surfaces", "mirrors", "background", "edges"]


def regions_of(mi, glint: Path, scene: Path, s: Settings, work: Path) -> list[str]:
    """Each pixel's region, from Glint's depth and reflection-depth AOVs:
    `background` where every camera ray misses, `mirrors` where every path took
    a mirror reflection, `edges` where only some did, `surfaces` otherwise."""
    images = {}
    for aov in ("depth", "reflection-depth"):
        out = work / f"{scene.stem}-{aov}.exr"
        command = [str(glint), "render", str(scene), "--aov", aov, "--spp", "16", "-o", str(out)]
        if s.resolution:
            command += ["--resolution", s.resolution]
        run(command, f"{scene.name}: glint render --aov {aov}")
        images[aov] = read_image(mi, out)[2][0::3]
    regions = []
    for depth, reflections in zip(images["depth"], images["reflection-depth"]):
        if depth == 0:
            regions.append("background")
        elif reflections >= 1:
            regions.append("mirrors")
        elif reflections > 0:
            regions.append("edges")
        else:
            regions.append("surfaces")
    return regions


@dataclass
class Comparison:
    """The two renderers over a set of pixels."""

    pixels: int
    glint_means: list[list[float]]  # per seed: R, G, B, their mean
    mitsuba_means: list[list[float]]
    mean_difference: list[float]  # Glint / Mitsuba − 1: R, G, B, mean
    mean_difference_se: list[float]
    rel_mse_glint: float
    rel_mse_mitsuba: float
    rel_mse_cross: float
    ratio: float | None  # None: no noise and no difference (0/0)
    ratio_se: float  # jackknife over the seeds


@dataclass
class Result:
    scene: str
    resolution: list[int]
    judged: Comparison  # over the pixels not excluded
    by_region: dict  # region → Comparison
    excluded: list[str]
    passed: bool
    failures: list[str] = field(default_factory=list)
    export_warnings: list[str] = field(default_factory=list)
    seconds: dict = field(default_factory=dict)


def two_digits(x: float) -> str:
    """`x` to two significant digits, without an exponent."""
    if not math.isfinite(x) or x == 0:
        return f"{x:g}"
    decimals = max(0, 1 - math.floor(math.log10(abs(x))))
    return f"{x:.{decimals}f}"


def mean_and_se(values: list[float]) -> tuple[float, float]:
    m = statistics.fmean(values)
    se = statistics.stdev(values) / math.sqrt(len(values)) if len(values) > 1 else float("nan")
    return m, se


def compare(glint_images, mitsuba_images, reference, pixels: list[int]) -> Comparison:
    """Means, relMSEs and their ratio over `pixels` (indices)."""
    k = len(glint_images)

    def means(img):
        n = len(pixels)
        rgb = [sum(img[3 * p + c] for p in pixels) / n for c in range(3)]
        return rgb + [sum(rgb) / 3]

    g_means = [means(img) for img in glint_images]
    m_means = [means(img) for img in mitsuba_images]
    differences, differences_se = [], []
    for c in range(4):
        g, g_se = mean_and_se([m[c] for m in g_means])
        mm, m_se = mean_and_se([m[c] for m in m_means])
        differences.append(g / mm - 1 if mm else float("nan"))
        differences_se.append(math.hypot(g_se / mm, g * m_se / mm**2) if mm else float("nan"))

    weights = [1 / (reference[3 * p + c] + REL_MSE_EPSILON) ** 2 for p in pixels for c in range(3)]
    values = [3 * p + c for p in pixels for c in range(3)]

    def rel_mse(a, b):
        return sum(w * (a[i] - b[i]) ** 2 for i, w in zip(values, weights)) / len(values)

    # Every pair once: Glint–Glint, Mitsuba–Mitsuba (i < j), Glint–Mitsuba (all).
    gg = {(i, j): rel_mse(glint_images[i], glint_images[j]) for i, j in itertools.combinations(range(k), 2)}
    mm_ = {(i, j): rel_mse(mitsuba_images[i], mitsuba_images[j]) for i, j in itertools.combinations(range(k), 2)}
    gm = {(i, j): rel_mse(glint_images[i], mitsuba_images[j]) for i in range(k) for j in range(k)}

    def statistics_without(left_out):
        keep = lambda pair: left_out not in pair
        within_g = statistics.fmean(v for p, v in gg.items() if keep(p))
        within_m = statistics.fmean(v for p, v in mm_.items() if keep(p))
        cross = statistics.fmean(v for p, v in gm.items() if keep(p))
        floor = (within_g + within_m) / 2
        if floor > 0:
            ratio = cross / floor
        else:  # no noise: identical images (0/0) have no ratio; any difference is infinite
            ratio = None if cross == 0 else float("inf")
        return within_g, within_m, cross, ratio

    within_g, within_m, cross, ratio = statistics_without(None)
    if k > 2 and ratio is not None:
        leave_one_out = [statistics_without(i)[3] for i in range(k)]
        mean = statistics.fmean(leave_one_out)
        ratio_se = math.sqrt((k - 1) / k * sum((r - mean) ** 2 for r in leave_one_out))
    else:
        ratio_se = float("nan")
    return Comparison(len(pixels), g_means, m_means, differences, differences_se,
                      within_g, within_m, cross, ratio, ratio_se)


def compare_scene(mi, scene: Path, glint: Path, s: Settings, work: Path, tolerances, excluded) -> Result:
    try:
        with scene.open("rb") as f:
            doc = tomllib.load(f)
    except (OSError, tomllib.TOMLDecodeError) as e:
        raise Failure(f"{scene}: cannot read: {e}", 2)
    if doc.get("shading", "phong") != "physical":
        print(f"{PROG}: warning: {scene.name} is not shading = \"physical\": the two renderers compute "
              "different things, so they are not expected to agree", file=sys.stderr)
    max_depth = int(doc.get("render", {}).get("max_depth", 4))
    name = scene.stem
    xml = work / f"{name}.xml"
    warnings = glint_export(glint, scene, s, xml)
    seconds = {"glint": [], "mitsuba": []}
    glint_images, mitsuba_images = [], []
    size = None
    for seed in s.seeds:
        out = work / f"{name}-glint-{seed}.exr"
        seconds["glint"].append(glint_render(glint, scene, seed, s, out))
        w, h, pixels = read_image(mi, out)
        glint_images.append(pixels)
        size = (w, h)
        print(f"{name}: Glint seed {seed}: {seconds['glint'][-1]:.1f} s", file=sys.stderr)
    for seed in s.seeds:
        out = work / f"{name}-mitsuba-{seed}.exr"
        seconds["mitsuba"].append(mitsuba_render(xml, seed, s, max_depth, out))
        w, h, pixels = read_image(mi, out)
        if (w, h) != size:
            raise Failure(f"{name}: Mitsuba's image is {w}x{h}, Glint's {size[0]}x{size[1]}")
        mitsuba_images.append(pixels)
        print(f"{name}: Mitsuba seed {seed}: {seconds['mitsuba'][-1]:.1f} s", file=sys.stderr)
    for label, images in (("Glint", glint_images), ("Mitsuba", mitsuba_images)):
        bad = sum(1 for img in images for v in img if not math.isfinite(v))
        if bad:
            raise Failure(f"{name}: {label}'s images hold {bad} values that are not finite")
    regions = regions_of(mi, glint, scene, s, work)

    everything = glint_images + mitsuba_images
    reference = [sum(values) / len(everything) for values in zip(*everything)]
    by_region = {}
    for region in REGIONS:
        pixels = [p for p, r in enumerate(regions) if r == region]
        if pixels:
            by_region[region] = compare(glint_images, mitsuba_images, reference, pixels)
    judged_pixels = [p for p, r in enumerate(regions) if r not in excluded]
    if not judged_pixels:
        raise Failure(f"{name}: --exclude leaves no pixel to judge", 2)
    judged = compare(glint_images, mitsuba_images, reference, judged_pixels)

    mean_tolerance, ratio_tolerance, excess_tolerance = tolerances
    failures = []
    for c, label in enumerate(["R", "G", "B", "mean"]):
        if not abs(judged.mean_difference[c]) < mean_tolerance:
            failures.append(f"{label} differs by {100 * judged.mean_difference[c]:+.3f}%")
    excess = judged.rel_mse_cross - (judged.rel_mse_glint + judged.rel_mse_mitsuba) / 2
    if judged.ratio is not None and not judged.ratio <= ratio_tolerance and excess > excess_tolerance:
        failures.append(f"relMSE ratio {judged.ratio:.3f} > {ratio_tolerance} (excess {excess:.2e} > {excess_tolerance:g})")
    return Result(
        scene=str(scene),
        resolution=list(size),
        judged=judged,
        by_region=by_region,
        excluded=sorted(excluded),
        passed=not failures,
        failures=failures,
        export_warnings=warnings,
        seconds=seconds,
    )


def ratio_text(c: Comparison) -> str:
    if c.ratio is None:
        return "– (identical, no noise)"
    if math.isnan(c.ratio_se):
        return f"{c.ratio:.3f}"
    return f"{c.ratio:.3f} ± {c.ratio_se:.3f}"


def table(r: Result, s: Settings) -> str:
    w, h = r.resolution
    k = len(s.seeds)
    j = r.judged
    judged = "the whole image" if not r.excluded else "the image without " + " and ".join(r.excluded)
    lines = [
        f"### {Path(r.scene).stem}",
        "",
        f"{w}x{h}; Glint {s.spp} spp, Mitsuba {s.mitsuba_spp} spp, {s.light_samples} light samples; "
        f"{k} seeds each ({', '.join(map(str, s.seeds))}); Mitsuba `{s.variant}`"
        + (", Glint's mirror chains and see-through backs where needed" if s.integrator == "glint" else ", Mitsuba's `direct` as exported")
        + f"; judged over {judged} ({j.pixels} pixels)",
        "",
        "| | Glint (± s.e.) | Mitsuba (± s.e.) | Glint / Mitsuba − 1 (± s.e.) |",
        "|---|---|---|---|",
    ]
    for c, label in enumerate(["R", "G", "B", "mean"]):
        g, g_se = mean_and_se([m[c] for m in j.glint_means])
        m, m_se = mean_and_se([m[c] for m in j.mitsuba_means])
        lines.append(
            f"| {label} | {g:.5g} ± {two_digits(g_se)} | {m:.5g} ± {two_digits(m_se)} | "
            f"{100 * j.mean_difference[c]:+.3f}% ± {100 * j.mean_difference_se[c]:.3f}% |"
        )
    lines += [
        "",
        "| relMSE Glint–Glint | relMSE Mitsuba–Mitsuba | noise floor (their mean) | relMSE Glint–Mitsuba | excess over the floor | ratio to the floor (± s.e.) | verdict |",
        "|---|---|---|---|---|---|---|",
        f"| {j.rel_mse_glint:.4e} | {j.rel_mse_mitsuba:.4e} | {(j.rel_mse_glint + j.rel_mse_mitsuba) / 2:.4e} "
        f"| {j.rel_mse_cross:.4e} | {j.rel_mse_cross - (j.rel_mse_glint + j.rel_mse_mitsuba) / 2:+.2e} | {ratio_text(j)} | "
        f"{'agree' if r.passed else 'DIFFER: ' + '; '.join(r.failures)} |",
    ]
    if len(r.by_region) > 1:
        lines += [
            "",
            "| region (from Glint's AOVs) | pixels | Glint / Mitsuba − 1 (± s.e.) | relMSE ratio to the floor (± s.e.) |",
            "|---|---|---|---|",
        ]
        for region, c in r.by_region.items():
            lines.append(
                f"| {region}{' (excluded)' if region in r.excluded else ''} | {c.pixels} | "
                f"{100 * c.mean_difference[3]:+.3f}% ± {100 * c.mean_difference_se[3]:.3f}% | "
                f"{ratio_text(c)} |"
            )
    if r.export_warnings:
        lines += ["", "Export warnings: " + " / ".join(r.export_warnings)]
    return "\n".join(lines) + "\n"


# ----------------------------------------------------------------------------------


def parse_args(argv):
    p = argparse.ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0])
    p.add_argument("scenes", nargs="+", type=Path, help="Glint scene files (shading = \"physical\")")
    p.add_argument("--seeds", type=int, default=8, metavar="K",
                   help="renders per renderer, seeds S..S+K-1 (default 8; at least 2, 3 for the ratio's standard error)")
    p.add_argument("--first-seed", type=int, default=0, metavar="S", help="the first seed (default 0)")
    p.add_argument("--spp", type=int, default=64, metavar="N", help="Glint's samples per pixel (default 64)")
    p.add_argument("--mitsuba-spp", type=int, metavar="N",
                   help="Mitsuba's samples per pixel (default: 4 × --spp: its independent sampler is noisier than Glint's Sobol points)")
    p.add_argument("--light-samples", type=int, default=4, metavar="N",
                   help="Glint's light samples per camera sample, Mitsuba's emitter and BSDF samples (default 4)")
    p.add_argument("--resolution", metavar="WxH", default="128x128", help="both renders' size (default 128x128; 'scene': the scene's own)")
    p.add_argument("--variant", default="scalar_rgb", help="Mitsuba variant (default scalar_rgb)")
    p.add_argument("--integrator", choices=["glint", "direct"], default="glint",
                   help="glint: where the scene has mirrors, or the camera sees the back of a one-sided surface or light, "
                        "a Python integrator adds Glint's mirror chains and sees through those backs (scalar variants only); "
                        "direct: Mitsuba's `direct` as exported")
    p.add_argument("--mean-tolerance", type=float, default=0.003, metavar="T",
                   help="largest relative difference of the means, overall and per channel (default 0.003: 0.3%%)")
    p.add_argument("--ratio-tolerance", type=float, default=1.1, metavar="R",
                   help="largest relMSE(Glint, Mitsuba) / noise floor (default 1.1)")
    p.add_argument("--excess-tolerance", type=float, default=1e-5, metavar="E",
                   help="a ratio above --ratio-tolerance fails only if the cross relMSE exceeds the floor by more than E "
                        "(default 1e-5: a per-pixel bias of about 0.3%% rms), so that nearly noiseless scenes are not "
                        "failed for rounding-sized differences")
    p.add_argument("--exclude", action="append", default=[], choices=REGIONS, metavar="REGION",
                   help="leave a region out of the verdict (surfaces, mirrors, background, edges; repeatable): "
                        "every region is still reported")
    p.add_argument("--glint", type=Path, default=REPO / "target/release/glint", help="the glint binary (default target/release/glint)")
    p.add_argument("--json", type=Path, metavar="FILE", help="write every number to FILE")
    p.add_argument("--keep", type=Path, metavar="DIR", help="keep the images and the exported scenes in DIR")
    args = p.parse_args(argv)
    if args.seeds < 2:
        p.error("--seeds must be at least 2 (the noise floor compares two seeds)")
    if args.spp < 1 or args.light_samples < 1 or (args.mitsuba_spp is not None and args.mitsuba_spp < 1):
        p.error("sample counts must be at least 1")
    if args.integrator == "glint" and not args.variant.startswith("scalar_"):
        p.error("--integrator glint may run a Python integrator, which needs a scalar variant (or use --integrator direct)")
    return args


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["--render-worker"]:
        return render_worker(argv[1:])
    args = parse_args(argv)
    try:
        import mitsuba as mi
    except ImportError:
        print(f"{PROG}: error: the mitsuba package is not installed (pip install mitsuba; see measure/mitsuba/README.md)", file=sys.stderr)
        return 2
    try:
        mi.set_variant("scalar_rgb")  # for reading images in this process
        if not args.glint.is_file():
            raise Failure(f"no {args.glint}; build it: cargo build --release -p glint-cli", 2)
        for scene in args.scenes:
            if not scene.is_file():
                raise Failure(f"{scene}: no such scene file", 2)
        if args.variant not in mi.variants():
            raise Failure(f"Mitsuba has no variant {args.variant!r} (it has {', '.join(mi.variants())})", 2)
        settings = Settings(
            seeds=list(range(args.first_seed, args.first_seed + args.seeds)),
            spp=args.spp,
            mitsuba_spp=args.mitsuba_spp or 4 * args.spp,
            light_samples=args.light_samples,
            resolution=None if args.resolution == "scene" else args.resolution,
            variant=args.variant,
            integrator=args.integrator,
        )
        results = []
        with tempfile.TemporaryDirectory(prefix="glint-agreement-") as tmp:
            work = args.keep or Path(tmp)
            work.mkdir(parents=True, exist_ok=True)
            for scene in args.scenes:
                result = compare_scene(mi, scene, args.glint, settings, work,
                                       (args.mean_tolerance, args.ratio_tolerance, args.excess_tolerance),
                                       set(args.exclude))
                results.append(result)
                print(table(result, settings))
                sys.stdout.flush()
        if args.json:
            document = {
                "settings": asdict(settings),
                "tolerances": {"mean": args.mean_tolerance, "ratio": args.ratio_tolerance,
                               "excess": args.excess_tolerance},
                "glint": str(args.glint),
                "mitsuba": mi.__version__,
                "machine": {"cpu": platform.processor() or platform.machine(), "cores": os.cpu_count()},
                "scenes": [asdict(r) for r in results],
            }
            args.json.write_text(json.dumps(document, indent=2) + "\n")
        failed = [Path(r.scene).stem for r in results if not r.passed]
        if failed:
            print(f"{PROG}: {len(failed)} of {len(results)} scenes differ: {', '.join(failed)}", file=sys.stderr)
            return 1
        print(f"{PROG}: all {len(results)} scenes agree", file=sys.stderr)
        return 0
    except Failure as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return e.status


if __name__ == "__main__":
    sys.exit(main())
