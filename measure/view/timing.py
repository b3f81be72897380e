"""How quickly `glint view` shows a scene and answers a click, through its API
as the page uses it (docs/view.md's table):

    python3 measure/view/timing.py [--runs 9] [--glint target/release/glint] [SCENE]

Per run: starts `glint view SCENE --no-open`, then asks /api/render as the
page does (every 20 ms) and notes when the first image arrives (1 spp) and
when the scene's own count is done; then asks /api/explain for 20 pixels
and notes each answer's time. Prints medians with their spread and the CPU."""

from __future__ import annotations

import argparse
import pathlib
import random
import statistics
import subprocess
import sys
import time
import urllib.error
import urllib.request

REPO = pathlib.Path(__file__).resolve().parents[2]


def get(url: str):
    try:
        with urllib.request.urlopen(url, timeout=60) as answer:
            return answer.status, dict(answer.headers), answer.read()
    except urllib.error.HTTPError as e:
        return e.code, dict(e.headers), e.read()


def one_run(glint: str, scene: str):
    start = time.perf_counter()
    view = subprocess.Popen([glint, "view", scene, "--no-open"], stdout=subprocess.PIPE,
                            stderr=subprocess.DEVNULL, text=True)
    try:
        url = view.stdout.readline().strip()
        base, token = url.split("/?token=")
        first = done = None
        while done is None:
            status, headers, _ = get(f"{base}/api/render?token={token}")
            now = time.perf_counter() - start
            if status == 200:
                first = first if first is not None else now
                if headers["X-Spp"] == headers["X-Target-Spp"]:
                    done = now
            elif status != 202:
                sys.exit(f"/api/render answered {status}")
            time.sleep(0.02)
        clicks = []
        rng = random.Random(7)
        for _ in range(20):
            x, y = rng.randrange(512), rng.randrange(512)
            t = time.perf_counter()
            status, _, _ = get(f"{base}/api/explain?token={token}&pixel={x},{y}")
            clicks.append(time.perf_counter() - t)
            assert status == 200
        return first, done, clicks
    finally:
        view.terminate()
        view.wait()


def cpu() -> str:
    for line in open("/proc/cpuinfo"):
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return "unknown CPU"


def spread(values):
    return f"{statistics.median(values):.3f} s ({min(values):.3f}–{max(values):.3f})"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("scene", nargs="?", default=str(REPO / "scenes" / "cornell-set1.toml"))
    parser.add_argument("--runs", type=int, default=9)
    parser.add_argument("--glint", default=str(REPO / "target" / "release" / "glint"))
    args = parser.parse_args()
    runs = [one_run(args.glint, args.scene) for _ in range(args.runs)]
    clicks = [c for _, _, cs in runs for c in cs]
    print(f"{pathlib.Path(args.scene).name}, {args.runs} runs, {cpu()}, {len(__import__('os').sched_getaffinity(0))} cores")
    print(f"first image shown:      {spread([r[0] for r in runs])}")
    print(f"scene's count done:     {spread([r[1] for r in runs])}")
    print(f"a click's explain:      {1000 * statistics.median(clicks):.1f} ms median, "
          f"{1000 * sorted(clicks)[int(0.95 * len(clicks))]:.1f} ms 95th percentile, {len(clicks)} clicks")
    return 0


if __name__ == "__main__":
    sys.exit(main())
