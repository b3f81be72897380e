#!/usr/bin/env python3
"""Equal-error comparison of Glint and Mitsuba 3: how long each takes to reach the same error.

Run through ``compare.sh --equal-error`` (or ``compare.py --equal-error``). For each
scene, each renderer is measured against its *own* converged reference, over a
ladder of budgets (spp, light/emitter samples, sample patterns or samplers); the
time to reach a relative MSE of 1e-3 and 1e-4 is interpolated along each
configuration's ladder in log–log, each renderer's fastest configuration is
picked, and the ratio Mitsuba time / Glint time is printed as a Markdown table.
See measure/mitsuba/README.md, "Equal-error mode".

Glint does its own rendering (``glint render``), scene export
(``glint export --mitsuba``) and metrics (``glint diff``, whose relMSE is
``(x − r)²/(r + 0.01)²`` over pixels and channels); Mitsuba's images are written
as EXR and measured by ``glint diff`` too.
"""

from __future__ import annotations

import argparse
import gc
import json
import math
import os
import re
import statistics
import subprocess
import sys
import time
import tomllib
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import harness
from harness import REPO, Failure

PROG = "compare.py --equal-error"

DEFAULT_SCENES = ["cornell-physical", "physical-environment", "analytic-area-light", "physical-textured-ground"]
TARGETS = [1e-3, 1e-4]

# Glint's summary line ends with `T s wall (T s rendering)`, printed to 1 ms; the
# --stats-json file has the same phase unrounded, which the cheap rungs need.
RENDER_S = re.compile(r"\((?P<render>[0-9.]+) s rendering\)")


def log(*a):
    print(*a, file=sys.stderr, flush=True)


def int_list(text: str) -> list[int]:
    try:
        values = [int(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a comma-separated list of integers: {text!r}")
    if not values or min(values) < 1:
        raise argparse.ArgumentTypeError(f"needs integers of at least 1: {text!r}")
    return sorted(set(values))


def name_list(choices):
    def parse(text: str) -> list[str]:
        values = [x.strip() for x in text.split(",") if x.strip()]
        bad = [v for v in values if v not in choices]
        if not values or bad:
            raise argparse.ArgumentTypeError(f"choose from {', '.join(choices)}: {text!r}")
        return list(dict.fromkeys(values))

    return parse


@dataclass(frozen=True)
class Config:
    """One renderer's way of spending samples; its ladder varies only spp."""

    renderer: str  # "glint" or "mitsuba"
    pattern: str  # Glint's pixel, light and environment pattern, or Mitsuba's sampler
    samples: int  # Glint's light and environment samples; Mitsuba's emitter and/or BSDF samples
    # Glint's environment sampling (GLINT_STRATEGIES); Mitsuba's techniques (MITSUBA_STRATEGIES)
    strategy: str

    @property
    def label(self) -> str:
        if self.renderer == "glint":
            by = f", environment by {self.strategy}" if self.strategy != "luminance" else ""
            return f"{self.pattern}, {self.samples} light/env samples{by}"
        what = {"mis": "emitter+BSDF", "emitter": "emitter", "bsdf": "BSDF"}[self.strategy]
        return f"{self.pattern}, {self.samples} {what} samples"

    @property
    def key(self) -> str:
        return f"{self.renderer}-{self.pattern}-{self.samples}-{self.strategy}"

    def mitsuba_samples(self) -> dict[str, int]:
        """The `direct` integrator's emitter_samples and bsdf_samples."""
        n = self.samples
        emitter, bsdf = {"mis": (n, n), "emitter": (n, 0), "bsdf": (0, n)}[self.strategy]
        return {"emitter_samples": emitter, "bsdf_samples": bsdf}


# Glint's environment sampling (`--environment-sampling`), tried on scenes with an environment.
GLINT_STRATEGIES = ["luminance", "cosine"]
# Mitsuba's `direct` integrator: emitter and BSDF samples combined by MIS, or either alone.
MITSUBA_STRATEGIES = ["mis", "emitter", "bsdf"]


@dataclass
class Scene:
    name: str
    path: Path
    width: int
    height: int
    has_environment: bool


def read_scene(name: str, width: int) -> Scene:
    path = REPO / "scenes" / f"{name}.toml"
    if not path.is_file():
        raise Failure(f"no scene {path}", 2)
    with open(path, "rb") as f:
        toml = tomllib.load(f)
    if toml.get("shading") != "physical":
        # Phong scenes have no physical counterpart in Mitsuba: their errors would
        # measure different images.
        raise Failure(f"{name}: not a physical scene (shading = \"physical\"); Mitsuba renders something else", 2)
    w, h = toml.get("render", {}).get("resolution", [512, 512])
    return Scene(
        name=name,
        path=path,
        width=width,
        height=max(1, round(width * h / w)),
        has_environment="environment" in toml,
    )


# ----------------------------------------------------------------------------------
# Glint


class Glint:
    def __init__(self, binary: Path):
        self.binary = binary

    def run(self, args: list[str], what: str) -> subprocess.CompletedProcess:
        cmd = [str(self.binary), *args]
        try:
            r = subprocess.run(cmd, capture_output=True, text=True, cwd=REPO)
        except OSError as e:
            raise Failure(f"cannot run {self.binary}: {e}")
        if r.returncode not in (0, 1) or (r.returncode == 1 and args[0] != "diff"):
            err = (r.stderr.strip() or r.stdout.strip() or "(no output)").splitlines()
            raise Failure(f"{what}: glint exited with {r.returncode}: " + " | ".join(err[-5:]) + f"\n  command: {' '.join(cmd)}")
        return r

    def render(self, scene: Scene, cfg: Config, spp: int, seed: int, out: Path) -> dict:
        stats = out.with_suffix(".stats.json")
        args = [
            "render", str(scene.path), "-o", str(out), "--resolution", f"{scene.width}x{scene.height}",
            "--spp", str(spp), "--seed", str(seed), "--sampler", cfg.pattern,
            "--light-samples", str(cfg.samples), "--light-sampler", cfg.pattern,
            "--stats-json", str(stats),
        ]
        if scene.has_environment:
            args += ["--environment-samples", str(cfg.samples), "--environment-sampler", cfg.pattern,
                     "--environment-sampling", cfg.strategy]
        t0 = time.perf_counter()
        r = self.run(args, f"{scene.name}: glint render")
        wall = time.perf_counter() - t0
        m = RENDER_S.search(r.stdout) or RENDER_S.search(r.stderr)
        if not m:
            raise Failure(f"{scene.name}: no `(T s rendering)` in glint's output:\n{r.stdout}{r.stderr}")
        render_s = float(m["render"])
        precise = stats_render_seconds(stats)
        if precise is not None:
            render_s = precise
        return {"render_s": render_s, "process_wall_s": wall, "summary": r.stdout.strip().splitlines()[0]}

    def rel_mse(self, test: Path, reference: Path) -> float:
        r = self.run(["diff", str(test), str(reference), "--json"], f"glint diff {test.name}")
        try:
            value = json.loads(r.stdout)["rel_mse"]
        except (json.JSONDecodeError, KeyError) as e:
            raise Failure(f"glint diff --json: cannot read rel_mse ({e}): {r.stdout[:300]}")
        # null: not finite (a NaN or infinity in one image only).
        return math.inf if value is None else float(value)

    def export(self, scene: Scene, out: Path) -> list[str]:
        r = self.run(
            ["export", "--mitsuba", str(scene.path), "-o", str(out), "--resolution", f"{scene.width}x{scene.height}",
             "--spp", "1", "--light-samples", "1"],
            f"{scene.name}: glint export --mitsuba",
        )
        return [line for line in r.stderr.splitlines() if line.strip()]


def stats_render_seconds(path: Path) -> float | None:
    try:
        seconds = json.loads(path.read_text())["seconds"]["render"]
        path.unlink()
    except (OSError, json.JSONDecodeError, KeyError, TypeError):
        return None
    return float(seconds)


# ----------------------------------------------------------------------------------
# Mitsuba


class MitsubaScenes:
    """The exported scene with each configuration's sampler and sample counts, loaded
    once per configuration and kept, so that the timed rounds only render."""

    def __init__(self, ms: harness.Mitsuba, xml: Path):
        self.ms = ms
        self.xml = xml
        self.loaded = {}

    def variant_xml(self, cfg: Config) -> Path:
        tree = ET.parse(self.xml)
        root = tree.getroot()
        sampler = root.find(".//sensor/sampler")
        integrator = root.find("integrator")
        if sampler is None or integrator is None:
            raise Failure(f"{self.xml}: no <sampler> in the sensor or no <integrator>")
        sampler.set("type", cfg.pattern)
        # mi.render's spp replaces the count; this one only keeps ldsampler from
        # warning at loading that the export's 1 is not a square power of two.
        count = sampler.find("integer[@name='sample_count']")
        if count is not None:
            count.set("value", "16")
        for name, value in cfg.mitsuba_samples().items():
            e = integrator.find(f"integer[@name='{name}']")
            if e is None:
                e = ET.SubElement(integrator, "integer", name=name)
            e.set("value", str(value))
        # Beside the export, so that its relative asset paths resolve.
        out = self.xml.with_name(f"{self.xml.stem}-{cfg.pattern}-{cfg.samples}-{cfg.strategy}.xml")
        tree.write(out, encoding="utf-8", xml_declaration=True)
        return out

    def scene(self, cfg: Config):
        if cfg not in self.loaded:
            path = self.variant_xml(cfg)
            try:
                self.loaded[cfg] = self.ms.mi.load_file(str(path))
            except Exception as e:  # noqa: BLE001
                raise Failure(f"Mitsuba could not load {path}: {e}")
        return self.loaded[cfg]

    def exact_spp(self, cfg: Config, spp: int) -> bool:
        """Whether the sampler takes `spp` as it is: `ldsampler` rounds up to a square
        power of two (with a warning), and a rounded rung would repeat another."""
        sampler = self.scene(cfg).sensors()[0].sampler()
        if cfg.pattern == "ldsampler":
            return spp >= 4 and (spp & (spp - 1)) == 0 and math.isqrt(spp) ** 2 == spp
        sampler.set_sample_count(spp)
        return sampler.sample_count() == spp

    def render(self, cfg: Config, spp: int, seed: int):
        return self.ms.render(self.scene(cfg), spp, seed)

    def release(self, cfgs: list[Config]):
        """Frees the scenes of configurations no longer rendered. Every loaded
        scene slows each render of the others: 1 spp of one configuration took
        17 ms with 9 loaded and 43 ms with 27 (AMD EPYC)."""
        for cfg in cfgs:
            self.loaded.pop(cfg, None)
        gc.collect()

    def write(self, img, path: Path):
        self.ms.mi.Bitmap(img).write(str(path))


def average_exr(mi, dr, inputs: list[Path], out: Path):
    """The pixel-wise mean of EXRs of one size (Dr.Jit arithmetic, no numpy)."""
    acc = None
    for p in inputs:
        t = mi.TensorXf(mi.Bitmap(str(p)))
        acc = t if acc is None else acc + t
    acc = acc / len(inputs)
    dr.eval(acc)
    mi.Bitmap(acc).write(str(out))


# ----------------------------------------------------------------------------------
# Interpolation and summaries


def interpolate_time(points: list[tuple[float, float]], target: float) -> tuple[float | None, str]:
    """Time at which a ladder's error reaches `target`: log-linear between the two
    rungs that bracket it. `points` are (time, relMSE) in ladder order. Returns
    (seconds, how): how is "" inside the ladder, "<" if even the cheapest rung is
    below the target (the time is then an upper bound), and None beyond the ladder."""
    pts = [(t, e) for t, e in points if t > 0 and e > 0]
    if not pts:
        return None, "no data"
    if pts[0][1] <= target:
        return pts[0][0], "<"
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if e0 >= target >= e1 and e0 != e1:
            f = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0))), ""
    return None, "not reached"


def fmt_s(x: float | None) -> str:
    if x is None:
        return "—"
    return f"{x * 1000:.0f} ms" if x < 1 else f"{x:.2f} s"


def fmt_e(x: float) -> str:
    return f"{x:.2e}" if x > 0 else f"{x:.1e}"


# ----------------------------------------------------------------------------------
# One scene


def run_scene(args, scene: Scene, glint: Glint, ms: harness.Mitsuba, out_dir: Path) -> dict:
    mi, dr = ms.mi, ms.dr
    work = out_dir / scene.name
    work.mkdir(parents=True, exist_ok=True)
    log(f"\n== {scene.name}: {scene.path.relative_to(REPO)} at {scene.width}x{scene.height}")

    xml = work / f"{scene.name}.xml"
    warnings = glint.export(scene, xml)
    for w in warnings:
        log(f"export: {w}")
    mscenes = MitsubaScenes(ms, xml)

    gstrategies = args.glint_environment_sampling if scene.has_environment else ["luminance"]
    gcfgs = [Config("glint", p, n, s) for p in args.glint_patterns for n in args.glint_samples for s in gstrategies]
    mcfgs = [Config("mitsuba", p, n, s) for p in args.mitsuba_samplers for n in args.mitsuba_samples
             for s in args.mitsuba_strategies]

    # References: two independent halves each (seeds far from the ladder's), so that
    # their difference estimates the reference's own noise, which adds to every
    # measured relMSE and is subtracted from it.
    refs = {}
    t_ref = time.perf_counter()
    half_spp = args.glint_reference_spp // 2
    gref_cfg = Config("glint", "sobol", args.glint_reference_samples, "luminance")
    halves = []
    for k in range(2):
        p = work / f"glint-reference-{k}.exr"
        r = glint.render(scene, gref_cfg, half_spp, 1_000_001 + k, p)
        log(f"glint reference half {k}: {half_spp} spp x {gref_cfg.samples} (sobol): {r['render_s']:.2f} s")
        halves.append(p)
    gref = work / "glint-reference.exr"
    average_exr(mi, dr, halves, gref)
    refs["glint"] = {"path": gref, "floor": glint.rel_mse(halves[0], halves[1]) / 4}

    half_spp = args.mitsuba_reference_spp // 2
    mref_cfg = Config("mitsuba", args.mitsuba_reference_sampler, args.mitsuba_reference_samples, "mis")
    # One wavefront of W·H·spp lanes holds all of a pass in memory: split the half
    # into equal passes of at most --mitsuba-pass-lanes, each a count the sampler
    # takes as it is.
    fits = [d for d in range(1, half_spp + 1)
            if half_spp % d == 0 and mscenes.exact_spp(mref_cfg, d)
            and scene.width * scene.height * d <= max(args.mitsuba_pass_lanes, scene.width * scene.height)]
    if not fits:
        raise Failure(f"Mitsuba's {mref_cfg.pattern} sampler cannot split {half_spp} spp (half of --reference-spp) into passes", 2)
    pass_spp = max(fits)
    passes = half_spp // pass_spp
    halves = []
    for k in range(2):
        p = work / f"mitsuba-reference-{k}.exr"
        acc, t_sum = None, 0.0
        for i in range(passes):
            t, img = mscenes.render(mref_cfg, pass_spp, 2_000_000 + 1000 * k + i)
            t_sum += t
            acc = img if acc is None else acc + img
            dr.eval(acc)
        mscenes.write(acc / passes, p)
        del acc
        log(f"mitsuba reference half {k}: {passes} x {pass_spp} spp x {mref_cfg.samples} ({mref_cfg.pattern}): {t_sum:.2f} s")
        halves.append(p)
    mref = work / "mitsuba-reference.exr"
    average_exr(mi, dr, halves, mref)
    refs["mitsuba"] = {"path": mref, "floor": glint.rel_mse(halves[0], halves[1]) / 4}
    del mscenes.loaded[mref_cfg]
    # Faithfulness of the export: Mitsuba's converged image judged against Glint's.
    # Each reference's noise adds its floor to this; the rest is the difference of
    # the two images (mean bias², relative).
    cross = glint.rel_mse(mref, gref)
    agreement = {
        "mitsuba_vs_glint_relmse": cross,
        "glint_floor": refs["glint"]["floor"],
        "mitsuba_floor": refs["mitsuba"]["floor"],
        "excess": cross - refs["glint"]["floor"] - refs["mitsuba"]["floor"],
    }
    reference_s = time.perf_counter() - t_ref
    log(
        f"references ({reference_s:.0f} s): floors glint {agreement['glint_floor']:.2e}, mitsuba "
        f"{agreement['mitsuba_floor']:.2e}; Mitsuba's against Glint's: relMSE {cross:.2e} "
        f"(excess over the floors {agreement['excess']:.2e})"
    )

    # The ladders, found by untimed probes: each configuration goes up the spp list
    # until its error is below the smallest target (by --margin, so that the target
    # is bracketed whatever the rounds' noise), or until the next rung would exceed
    # --max-work or --max-rung-seconds, or its last rung already took --screen times
    # as long as another configuration took to get below the goal (it cannot be the
    # fastest at either target then). This spends the timed rounds only where the
    # targets are. Mitsuba's first render of a configuration traces its kernel and
    # compiles it with LLVM (or loads it from Dr.Jit's disk cache, ~/.drjit): it is
    # done before the probes and not timed; every spp and seed uses the same
    # kernel, so nothing after it compiles. Glint's references have already loaded
    # its binary and the scene's files into the page cache.
    goal = min(TARGETS) / args.margin
    rungs_of, probes, first = {}, {}, {}
    goal_time = {"glint": math.inf, "mitsuba": math.inf}  # the fastest probe below the goal so far
    for cfg in gcfgs + mcfgs:
        rungs, pts, last_t, last_spp = [], [], None, None
        if cfg.renderer == "mitsuba":
            spps = [spp for spp in args.spp if mscenes.exact_spp(cfg, spp)]
            if not spps:
                raise Failure(f"Mitsuba's {cfg.pattern} sampler takes none of the spp {args.spp} as they are")
            t, img = mscenes.render(cfg, spps[0], 998)
            del img
            first[cfg] = t
        else:
            spps = args.spp
        for spp in spps:
            if spp * cfg.samples > args.max_work and rungs:
                break
            if last_t is not None:
                expected = last_t * spp / last_spp
                if expected > args.max_rung_seconds or last_t > args.screen * goal_time[cfg.renderer]:
                    break
            img_path = work / f"{cfg.key}-{spp}spp.exr"
            if cfg.renderer == "glint":
                t = glint.render(scene, cfg, spp, 999, img_path)["render_s"]
            else:
                t, img = mscenes.render(cfg, spp, 999)
                mscenes.write(img, img_path)
                del img
            e = glint.rel_mse(img_path, refs[cfg.renderer]["path"]) - refs[cfg.renderer]["floor"]
            rungs.append(spp)
            pts.append((t, e))
            last_t, last_spp = t, spp
            if e < goal:
                goal_time[cfg.renderer] = min(goal_time[cfg.renderer], t)
                break
        rungs_of[cfg], probes[cfg] = rungs, pts
        log(f"probe {cfg.renderer} {cfg.label}: spp {rungs}, last relMSE {pts[-1][1]:.2e} in {pts[-1][0]:.2f} s")
    log(f"mitsuba first renders (tracing + JIT or disk cache, not timed): {sum(first.values()):.1f} s in all, "
        f"at most {max(first.values()):.2f} s")

    # Screening: the timed rounds measure only the configurations within --screen of
    # their renderer's fastest at some target, by the probes' (single, untimed) runs.
    timed = set()
    for renderer, cfgs in (("glint", gcfgs), ("mitsuba", mcfgs)):
        for target in TARGETS:
            at = {c: interpolate_time(probes[c], target)[0] for c in cfgs}
            reached = [t for t in at.values() if t is not None]
            if not reached:
                continue
            timed |= {c for c, t in at.items() if t is not None and t <= args.screen * min(reached)}
        if not any(c in timed for c in cfgs):
            timed |= set(cfgs)  # none reaches a target: time them all, the table says so
    for cfg in gcfgs + mcfgs:
        if cfg not in timed:
            log(f"screened out: {cfg.renderer} {cfg.label}")
    mscenes.release([c for c in mcfgs if c not in timed])

    jobs = {r: [(c, s) for c in cfgs if c in timed for s in rungs_of[c]] for r, cfgs in (("glint", gcfgs), ("mitsuba", mcfgs))}
    runs = {key: [] for key in ((c, s) for r in jobs.values() for c, s in r)}
    order = list(zip_longest_pairs(jobs["glint"], jobs["mitsuba"]))
    for rnd in range(args.pairs):
        seed = rnd + 1
        for g, m in order:
            pair = [("glint", g), ("mitsuba", m)]
            if rnd % 2:
                pair.reverse()
            for renderer, job in pair:
                if job is None:
                    continue
                cfg, spp = job
                img_path = work / f"{cfg.key}-{spp}spp.exr"
                if renderer == "glint":
                    r = glint.render(scene, cfg, spp, seed, img_path)
                    t = r["render_s"]
                    extra = {"process_wall_s": r["process_wall_s"]}
                else:
                    t, img = mscenes.render(cfg, spp, seed)
                    mscenes.write(img, img_path)
                    del img
                    extra = {}
                e = glint.rel_mse(img_path, refs[renderer]["path"])
                runs[(cfg, spp)].append({"round": rnd, "seed": seed, "render_s": t, "relmse": e, **extra})
        log(f"round {rnd + 1}/{args.pairs} done ({time.perf_counter() - t_ref:.0f} s since the references began)")

    # Per rung: the median time (with its range) and the mean relMSE over the
    # rounds' seeds, less the reference's noise.
    ladders = []
    for renderer, cfgs in (("glint", gcfgs), ("mitsuba", mcfgs)):
        for cfg in cfgs:
            rungs = []
            for spp, (pt, pe) in zip(rungs_of[cfg], probes[cfg]):
                rs = runs.get((cfg, spp))
                if not rs:
                    # Screened out: the probe's single untimed run stands in.
                    rungs.append({"spp": spp, "time_median_s": pt, "time_min_s": pt, "time_max_s": pt,
                                  "relmse_raw": pe + refs[renderer]["floor"], "relmse": pe, "runs": []})
                    continue
                times = [r["render_s"] for r in rs]
                raw = statistics.fmean(r["relmse"] for r in rs)
                rungs.append({
                    "spp": spp,
                    "time_median_s": statistics.median(times),
                    "time_min_s": min(times),
                    "time_max_s": max(times),
                    "relmse_raw": raw,
                    "relmse": raw - refs[renderer]["floor"],
                    "probe": {"render_s": pt, "relmse": pe},
                    "runs": rs,
                })
            at = {}
            for target in TARGETS:
                est = {}
                for which in ("median", "min", "max"):
                    pts = [(r[f"time_{which}_s"], r["relmse"]) for r in rungs]
                    est[which] = interpolate_time(pts, target)
                at[str(target)] = {"time_s": est["median"][0], "how": est["median"][1],
                                   "time_min_s": est["min"][0], "time_max_s": est["max"][0]}
            ladders.append({"renderer": renderer, "pattern": cfg.pattern, "samples": cfg.samples,
                            "strategy": cfg.strategy,
                            "label": cfg.label, "timed": cfg in timed, "rungs": rungs, "at": at,
                            "mitsuba_first_render_s": first.get(cfg)})

    best = {}
    for target in TARGETS:
        row = {}
        for renderer in ("glint", "mitsuba"):
            cands = [l for l in ladders if l["renderer"] == renderer and l["timed"] and l["at"][str(target)]["time_s"] is not None]
            # An upper bound ("<", the cheapest rung already below the target) competes
            # with its bound; it is flagged in the table.
            row[renderer] = min(cands, key=lambda l: l["at"][str(target)]["time_s"]) if cands else None
        g, m = row["glint"], row["mitsuba"]
        entry = {"glint": g and g["label"], "mitsuba": m and m["label"]}
        for name, l in (("glint", g), ("mitsuba", m)):
            if l:
                entry[f"{name}_s"], entry[f"{name}_how"] = l["at"][str(target)]["time_s"], l["at"][str(target)]["how"]
        if g and m:
            ga, ma = g["at"][str(target)], m["at"][str(target)]
            entry.update(
                ratio=ma["time_s"] / ga["time_s"],
                ratio_min=(ma["time_min_s"] or ma["time_s"]) / (ga["time_max_s"] or ga["time_s"]),
                ratio_max=(ma["time_max_s"] or ma["time_s"]) / (ga["time_min_s"] or ga["time_s"]),
            )
        best[str(target)] = entry

    return {
        "scene": scene.name,
        "resolution": [scene.width, scene.height],
        "export_warnings": warnings,
        "references": {
            "glint": {"spp": args.glint_reference_spp, "samples": args.glint_reference_samples, "pattern": "sobol",
                      "noise_floor_relmse": refs["glint"]["floor"]},
            "mitsuba": {"spp": args.mitsuba_reference_spp, "samples": args.mitsuba_reference_samples, "sampler": args.mitsuba_reference_sampler,
                        "noise_floor_relmse": refs["mitsuba"]["floor"]},
            "seconds": reference_s,
        },
        "agreement": agreement,
        "mitsuba_first_render_total_s": sum(first.values()),
        "ladders": ladders,
        "best": best,
    }


def zip_longest_pairs(a, b):
    for i in range(max(len(a), len(b))):
        yield (a[i] if i < len(a) else None, b[i] if i < len(b) else None)


# ----------------------------------------------------------------------------------
# Tables


def summary_table(results: list[dict], machine: dict) -> str:
    lines = [
        "| scene | relMSE | Glint: best configuration | Glint time | Mitsuba: best configuration | Mitsuba time | Mitsuba / Glint |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in results:
        for target in TARGETS:
            b = r["best"][str(target)]
            size = f"{r['resolution'][0]}×{r['resolution'][1]}"
            bound = lambda name: "≤ " if b.get(f"{name}_how") == "<" else ""  # noqa: E731
            ratio = f"**{b['ratio']:.2f}×** ({b['ratio_min']:.2f}–{b['ratio_max']:.2f})" if "ratio" in b else "—"
            lines.append(
                f"| `{r['scene']}` {size} | {target:.0e} | {b['glint'] or 'not reached'} | "
                f"{bound('glint')}{fmt_s(b.get('glint_s'))} | {b['mitsuba'] or 'not reached'} | "
                f"{bound('mitsuba')}{fmt_s(b.get('mitsuba_s'))} | {ratio} |"
            )
    lines.append("")
    lines.append(
        f"Machine: {machine['cpu']}, {machine['cores']} cores; Mitsuba {machine['mitsuba']} `{machine['variant']}`. "
        "Times are render times (Glint's render phase, Mitsuba's `mi.render` with its kernel compiled), "
        "medians over the rounds, interpolated in log–log along each configuration's spp ladder; "
        "the ratio's range pairs the fastest and slowest rounds. ≤: the cheapest rung is already below the target."
    )
    return "\n".join(lines)


def agreement_table(results: list[dict]) -> str:
    lines = [
        "| scene | Glint's reference (spp × samples) | its noise (relMSE) | Mitsuba's reference | its noise | "
        "Mitsuba's reference against Glint's (relMSE) | excess over the noise |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in results:
        a, g, m = r["agreement"], r["references"]["glint"], r["references"]["mitsuba"]
        lines.append(
            f"| `{r['scene']}` | {g['spp']} × {g['samples']}, sobol | {fmt_e(a['glint_floor'])} | "
            f"{m['spp']} × {m['samples']}, {m['sampler']} | {fmt_e(a['mitsuba_floor'])} | "
            f"{fmt_e(a['mitsuba_vs_glint_relmse'])} | {fmt_e(a['excess'])} |"
        )
    return "\n".join(lines)


def ladder_table(r: dict) -> str:
    spps = sorted({g["spp"] for l in r["ladders"] for g in l["rungs"]})
    lines = [
        f"`{r['scene']}`: relMSE against the renderer's own reference · median render time",
        "",
        "| renderer | configuration | " + " | ".join(f"{s} spp" for s in spps) + " | t(1e-3) | t(1e-4) |",
        "|---|---|" + "---|" * (len(spps) + 2),
    ]
    for l in r["ladders"]:
        by = {g["spp"]: g for g in l["rungs"]}
        cells = [f"{fmt_e(by[s]['relmse'])} · {fmt_s(by[s]['time_median_s'])}" if s in by else "" for s in spps]
        ats = []
        for target in TARGETS:
            a = l["at"][str(target)]
            ats.append(("≤ " if a["how"] == "<" else "") + fmt_s(a["time_s"]))
        label = l["label"] if l["timed"] else f"{l['label']} (screened out: one untimed probe)"
        lines.append(f"| {l['renderer']} | {label} | " + " | ".join(cells) + " | " + " | ".join(ats) + " |")
    return "\n".join(lines)


# ----------------------------------------------------------------------------------


def parse_args(argv):
    p = argparse.ArgumentParser(
        prog=PROG,
        description="Equal-error comparison: each renderer against its own converged reference over a ladder "
        "of budgets; Mitsuba's time over Glint's at relMSE 1e-3 and 1e-4, as a Markdown table.",
    )
    p.add_argument("--equal-error", action="store_true", help="this mode (compare.py's flag)")
    p.add_argument("--scene", action="append", help=f"a shipped physical scene (repeatable; default: {', '.join(DEFAULT_SCENES)})")
    p.add_argument("--width", type=int, default=256, help="image width; the height keeps the scene's aspect (default 256)")
    p.add_argument("--spp", type=int_list, default=[1, 4, 16, 64, 256, 1024],
                   help="the spp rungs each configuration climbs until it is below the smallest target (default 1,4,16,64,256,1024)")
    p.add_argument("--max-work", type=int, default=1024,
                   help="stop a ladder before spp × samples exceeds this (default 1024)")
    p.add_argument("--max-rung-seconds", type=float, default=15.0,
                   help="stop a ladder before a rung expected to take longer than this (default 15)")
    p.add_argument("--screen", type=float, default=1.5,
                   help="time only configurations whose probe reaches a target within this factor of their "
                   "renderer's fastest (default 1.5)")
    p.add_argument("--margin", type=float, default=1.5,
                   help="climb until the relMSE is this factor below the smallest target (default 1.5)")
    p.add_argument("--glint-patterns", type=name_list(["random", "stratified", "sobol", "grid"]), default=["random", "sobol"],
                   help="Glint's sample patterns, each for pixels, lights and the environment (default random,sobol)")
    p.add_argument("--glint-samples", type=int_list, default=[1, 4, 16],
                   help="Glint's light (and environment) samples per camera sample (default 1,4,16)")
    p.add_argument("--mitsuba-samplers", type=name_list(["independent", "stratified", "multijitter", "ldsampler", "orthogonal"]),
                   default=["independent", "multijitter", "ldsampler"], help="Mitsuba's samplers (default independent,multijitter,ldsampler)")
    p.add_argument("--glint-environment-sampling", type=name_list(GLINT_STRATEGIES), default=GLINT_STRATEGIES,
                   help="Glint's environment sampling on scenes with an environment (default luminance,cosine)")
    p.add_argument("--mitsuba-samples", type=int_list, default=[1, 4, 16],
                   help="the direct integrator's emitter_samples and bsdf_samples (default 1,4,16)")
    p.add_argument("--mitsuba-strategies", type=name_list(MITSUBA_STRATEGIES), default=MITSUBA_STRATEGIES,
                   help="the direct integrator's techniques: mis (emitter_samples = bsdf_samples), emitter "
                        "(bsdf_samples = 0) or bsdf (emitter_samples = 0) (default mis,emitter,bsdf)")
    p.add_argument("--pairs", type=int, default=3, help="alternated rounds per rung (default 3)")
    p.add_argument("--glint-reference-spp", type=int, default=512, help="Glint's reference: spp, in two halves (default 512)")
    p.add_argument("--glint-reference-samples", type=int, default=4,
                   help="Glint's reference: light and environment samples, Sobol points (default 4)")
    p.add_argument("--mitsuba-reference-spp", type=int, default=4096, help="Mitsuba's reference: spp, in two halves (default 4096)")
    p.add_argument("--mitsuba-reference-samples", type=int, default=1,
                   help="Mitsuba's reference: emitter and BSDF samples (default 1)")
    p.add_argument("--mitsuba-reference-sampler", default="ldsampler",
                   help="the sampler of Mitsuba's reference (default ldsampler; Glint's uses Sobol points)")
    p.add_argument("--mitsuba-pass-lanes", type=int, default=1 << 24,
                   help="at most this many samples (W·H·spp) per Mitsuba reference pass, for memory (default 2^24)")
    p.add_argument("--variant", default="llvm_ad_rgb", help="Mitsuba variant (default llvm_ad_rgb)")
    p.add_argument("--glint", default=str(REPO / "target/release/glint"), help="the Glint binary (default target/release/glint)")
    p.add_argument("--json", metavar="FILE", help="write every number to this JSON file")
    p.add_argument("--out-dir", default=str(REPO / "target/mitsuba/equal-error"), help="where the images go")
    a = p.parse_args(argv)
    if a.pairs < 1:
        p.error("--pairs must be at least 1")
    if min(a.glint_reference_spp, a.mitsuba_reference_spp) < 2:
        p.error("the references need at least 2 spp (two halves)")
    if a.width < 8:
        p.error("--width must be at least 8")
    if "grid" in a.glint_patterns and any(math.isqrt(n) ** 2 != n for n in a.glint_samples + a.spp):
        p.error("the grid pattern needs square spp and sample counts")
    return a


def main(argv) -> int:
    args = parse_args(argv)
    scenes = [read_scene(n, args.width) for n in dict.fromkeys(args.scene or DEFAULT_SCENES)]
    glint_bin = Path(args.glint).resolve()
    if not glint_bin.is_file():
        raise Failure(f"no Glint binary at {glint_bin}; build it with `cargo build --release -p glint-cli`", 2)
    out_dir = Path(args.out_dir).resolve()
    out_dir.mkdir(parents=True, exist_ok=True)
    ms = harness.Mitsuba(args.variant)
    glint = Glint(glint_bin)
    machine = {
        "cpu": harness.machine_cpu(),
        "cores": os.cpu_count(),
        "mitsuba": ms.version,
        "drjit": ms.drjit_version,
        "variant": ms.variant,
        "mitsuba_threads": ms.threads,
        "llvm": ms.llvm_version,
        "glint": harness.glint_version(glint_bin),
    }
    log(f"machine: {machine['cpu']}, {machine['cores']} cores; Mitsuba {ms.version} {ms.variant} ({ms.threads} threads)")
    t0 = time.perf_counter()
    results = [run_scene(args, s, glint, ms, out_dir) for s in scenes]
    log(f"\nequal-error run: {time.perf_counter() - t0:.0f} s")

    print(summary_table(results, machine))
    print()
    print(agreement_table(results))
    for r in results:
        print()
        print(ladder_table(r))
    if args.json:
        settings = {k: v for k, v in vars(args).items() if k not in ("json",)}
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps({"machine": machine, "settings": settings, "scenes": results}, indent=1, default=str))
        log(f"wrote {args.json}")
    return 0


def run(argv) -> int:
    """compare.py's entry to this mode; reports failures as compare.py does."""
    try:
        return main(argv)
    except Failure as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return e.status


if __name__ == "__main__":
    sys.exit(run(sys.argv[1:]))
