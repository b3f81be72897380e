#!/usr/bin/env python3
"""Glint's rendering speed side by side with Mitsuba 3's, on this machine, in one run.

For each case, Glint (a subprocess, ``target/release/glint render``) and Mitsuba 3
(in this process, ``mi.render``) render the same Cornell box with the same numbers
of camera and light samples, taking turns, and the script prints a Markdown table
of pixel samples per second and of the ratio Glint/Mitsuba. With ``--baseline``,
an earlier Glint build takes turns with them too, and a second table gives the
speed-up of Glint over it. The Mitsuba scene is the one ``glint export --mitsuba``
writes, with the case's sample counts. See measure/mitsuba/README.md.

Python 3.11 and the standard library, plus the ``mitsuba`` package (which brings
``drjit``; numpy is not needed).
"""

from __future__ import annotations

import argparse
import json
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

from harness import REPO, Failure, Mitsuba, glint_version, machine_cpu

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
        Case(
            "terrain",
            "scenes/large/terrain.toml",
            (),
            None,
            None,
            "a generated terrain of a million triangles (write it first: measure/meshes/terrain.py; not in the default set)",
        ),
    ]
}

# The cases run without --case: those whose scene is in the repository.
DEFAULT_CASES = ["cornell-set1-random", "cornell-set1-defaults", "bunny-cornell"]


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
# The Glint scene as a Mitsuba scene: `glint export --mitsuba`

# The summary line of `glint export` (docs/command-line.md), on stdout:
# wrote OUT.xml[ and N files in DIR] (Mitsuba 3): WxH, N spp, direct integrator with N emitter and N BSDF samples, ...
EXPORT_SUMMARY = re.compile(
    r"\(Mitsuba 3\): (?P<w>\d+)x(?P<h>\d+), (?P<spp>\d+) spp, direct integrator with "
    r"(?P<emitter>\d+) emitter and (?P<bsdf>\d+) BSDF samples"
)
EXPORT_WARNING = "glint: warning: "


@dataclass
class Exported:
    xml: Path
    emitter_samples: int
    bsdf_samples: int


def export_scene(glint: Path, case: Case, info: SceneInfo, out_dir: Path) -> Exported:
    """Writes the case's scene as a Mitsuba scene, OUT_DIR/CASE.xml (and its
    meshes beside it in CASE-assets/), with the case's sample counts and
    `bsdf_samples = 0`: Glint takes one shadow ray per light sample and no BSDF
    samples, so Mitsuba's `direct` does the same work. What the export cannot
    reproduce like for like (its warnings) goes to the notes."""
    xml = out_dir / f"{case.name}.xml"
    cmd = [
        str(glint), "export", "--mitsuba", str(info.path), "-o", str(xml),
        "--spp", str(info.spp), "--light-samples", str(info.light_samples), "--bsdf-samples", "0",
    ]
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, cwd=REPO)
    except OSError as e:
        raise Failure(f"{case.name}: cannot run glint export ({glint}): {e}")
    if r.returncode != 0:
        err = (r.stderr.strip() or r.stdout.strip() or "(no output)").splitlines()
        raise Failure(
            f"{case.name}: glint export failed with exit status {r.returncode}: " + " | ".join(err[-5:])
            + f"\n  command: {' '.join(cmd)}",
            2 if r.returncode == 2 else 1,
        )
    m = EXPORT_SUMMARY.search(r.stdout)
    if not m:
        raise Failure(f"{case.name}: glint export: no summary line in its output:\n{r.stdout}{r.stderr}")
    got = (int(m["w"]), int(m["h"]), int(m["spp"]))
    if got != (info.width, info.height, info.spp):
        raise Failure(
            f"{case.name}: glint export wrote {got[0]}x{got[1]} at {got[2]} spp, expected "
            f"{info.width}x{info.height} at {info.spp} spp (the scene's defaults changed?)"
        )
    for line in r.stderr.splitlines():
        if line.startswith(EXPORT_WARNING):
            note = f"export: {line[len(EXPORT_WARNING):]}"
            if note not in info.notes:
                info.notes.append(note)
    return Exported(xml, int(m["emitter"]), int(m["bsdf"]))


def timing_notes(info: SceneInfo, exported: Exported):
    """What differs in the work the two renderers do, beyond the export's warnings."""
    doc = info.toml
    info.notes.append(
        "the light seen directly: Glint returns its colour; Mitsuba adds its emission and then also "
        "shades it (a black `diffuse`, still sampling the light: a little extra work on ~1% of the pixels)"
    )
    if doc.get("shading", "phong") == "phong":
        info.notes.append(
            "light transport: Glint's area light sample is a point light without distance falloff "
            "(`L · kd · max(0, n·l)`, the course's model); Mitsuba's `direct` integrator is physically "
            "based (`kd/π`, cosines at both ends, 1/r²), so its image is much darker. Both trace one "
            "shadow ray per light sample"
        )
    if len(doc.get("area_light", [])) > 1:
        info.notes.append(
            "several area lights: Glint takes `light_samples` samples of each light per camera "
            "sample, Mitsuba `emitter_samples` samples in all, each of one light picked at random"
        )
    if doc.get("mesh"):
        info.notes.append(
            "meshes: Mitsuba reads the PLY files the export writes, with Glint's vertex normals; Glint "
            "intersects them with its own BVH, Mitsuba with Embree; both shade either side of a triangle"
        )
    checkers = [t["checkerboard"] for t in doc.get("textures", {}).values() if "checkerboard" in t]
    if any(c.get("filter", "point") != "point" for c in checkers):
        info.notes.append(
            "checkerboards: Glint's `analytic` filter is not reproduced (Mitsuba looks the pattern up at the hit point)"
        )
    if exported.emitter_samples != info.light_samples:
        info.notes.append(
            f"emitter samples: the export wrote {exported.emitter_samples} (point lights), Glint takes "
            f"{info.light_samples} light samples"
        )


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
        help="a case to run (repeat for several; default: all but terrain): " + "; ".join(f"{c.name}: {c.about}" for c in CASES.values()),
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
    reference (measure/mitsuba/equal_error.py, a module of its own)."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import equal_error as mode

    return mode.run(argv)


def main(argv=None) -> int:
    if "--equal-error" in (sys.argv[1:] if argv is None else argv):
        return equal_error(sys.argv[1:] if argv is None else argv)
    args = parse_args(argv)
    cases = [CASES[n] for n in dict.fromkeys(args.case or DEFAULT_CASES)]
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

        exported = export_scene(glint, case, info, out_dir)
        timing_notes(info, exported)
        patterns = glint_patterns(case, info)
        if patterns != ("random", "random"):
            info.notes.append(
                f"samplers ({case.name}): Glint's pixel/light patterns are {patterns[0]}/{patterns[1]} "
                "(Owen-scrambled Sobol hashes per sample), Mitsuba's `independent` sampler draws uniform "
                "random numbers; the sample counts are the same"
            )
        scene = ms.load(exported.xml)
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
                "scene": str(exported.xml),
                "integrator": {
                    "type": "direct",
                    "emitter_samples": exported.emitter_samples,
                    "bsdf_samples": exported.bsdf_samples,
                },
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
