#!/usr/bin/env python3
"""A render from Python against the same render by `glint render`: the render
alone (the time around `Scene.render()`; the CLI's "s rendering"), the two
alternated, and the median and range of their ratio.

    PY -m pip install ./python            # the package under test, into PY's environment
    PY measure/python/render_time.py --glint target/release/glint [--pairs 9]

Prints the CPU, each pair's times and the ratio Python / CLI.
"""

import argparse
import re
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import glint

REPO = Path(__file__).resolve().parents[2]


def cpu():
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return "unknown CPU"


def cli_seconds(binary, scene, spp, light, out):
    text = subprocess.run([binary, "render", str(scene), "--spp", str(spp), "--light-samples", str(light),
                           "-o", str(out)], check=True, capture_output=True, text=True).stdout
    return float(re.search(r"\(([0-9.]+) s rendering\)", text).group(1))


def python_seconds(scene):
    start = time.perf_counter()
    scene.render()
    return time.perf_counter() - start


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--glint", default=str(REPO / "target/release/glint"))
    ap.add_argument("--scene", default=str(REPO / "scenes/cornell-set1.toml"))
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--light-samples", type=int, default=16)
    ap.add_argument("--pairs", type=int, default=9)
    args = ap.parse_args()
    scene = glint.load(args.scene, spp=args.spp, light_samples=args.light_samples)
    out = Path(tempfile.mkdtemp()) / "render.exr"
    python_seconds(scene)  # the thread pool started, the scene prepared
    ratios = []
    for k in range(args.pairs):
        if k % 2:
            p = python_seconds(scene)
            c = cli_seconds(args.glint, args.scene, args.spp, args.light_samples, out)
        else:
            c = cli_seconds(args.glint, args.scene, args.spp, args.light_samples, out)
            p = python_seconds(scene)
        ratios.append(p / c)
        print(f"pair {k + 1}: Python {p:.3f} s, CLI {c:.3f} s, ratio {p / c:.3f}")
    print(f"{cpu()}: Python / CLI median {statistics.median(ratios):.3f} "
          f"({min(ratios):.3f}-{max(ratios):.3f}), {args.pairs} alternated pairs")


if __name__ == "__main__":
    main()
