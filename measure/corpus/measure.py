#!/usr/bin/env python3
"""Measures `glint grade` on a corpus of student submissions made by the
independent tracer (tracer.py): correct renders at many settings (false
alarms), every mistake at several settings (what is caught), the course's
first step (one ray through each pixel centre) and its pixel-corner twin, the
time to grade one image, and the course's own autograder (SSIM > 0.9 and
RMSE <= 50 against a reference image) on the same submissions.

    measure/corpus/.venv/bin/python measure/corpus/measure.py [--glint target/release/glint]
        [--out target/corpus] [--quick]

Writes OUT/results.json and OUT/table.md (the tables of docs/grading.md).
Images and Glint's reference cache stay in OUT, so a second run only grades.
Glint is called for everything Glint does (rendering references, grading);
the tracer makes the submissions.
"""

import argparse
import csv
import json
import random
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
SCENES = {name: REPO / "scenes" / f"cornell-{name}.toml" for name in ("set1", "set2", "set3")}
PATTERNS = ("random", "stratified", "grid")


def squares_only(pattern, count):
    """Grid and stratified take a square count in the tracer."""
    return pattern == "random" or int(count ** 0.5) ** 2 == count


def correct_settings(rng, count, max_paths):
    """`count` settings drawn over 1-256 spp, 1-64 light samples and the three
    patterns, with at most `max_paths` light-sample paths per pixel."""
    spps, lights = (1, 4, 16, 64, 256), (1, 4, 16, 64)
    combos = [
        (n, p, l, q)
        for n in spps
        for p in PATTERNS
        for l in lights
        for q in PATTERNS
        if n * l <= max_paths and squares_only(p, n) and squares_only(q, l)
    ]
    rng.shuffle(combos)
    # Every pattern pair and the extreme counts first, then the rest.
    combos.sort(key=lambda c: (c[0] * c[2] not in (1, max_paths), rng.random()))
    return combos[:count]


class Corpus:
    def __init__(self, out, glint, python):
        self.out, self.glint, self.python = out, glint, python
        self.rows = []

    def trace(self, scene, res, spp, sampler, light, light_sampler, seed, mistakes=(), ext="png"):
        tag = "-".join(mistakes) if mistakes else "correct"
        name = f"{scene}-{res}-{tag}-{spp}{sampler[0]}-{light}{light_sampler[0]}-{seed}.{ext}"
        path = self.out / "images" / name
        if not path.exists():
            path.parent.mkdir(parents=True, exist_ok=True)
            cmd = [self.python, str(HERE / "tracer.py"), str(SCENES[scene]), "-o", str(path),
                   "--resolution", f"{res}x{res}", "--spp", str(spp), "--sampler", sampler,
                   "--light-samples", str(light), "--light-sampler", light_sampler, "--seed", str(seed)]
            for m in mistakes:
                cmd += ["--mistake", m]
            subprocess.run(cmd, check=True, capture_output=True)
        return path

    def add(self, kind, scene, res, settings, path, stated=True, mistake=""):
        spp, sampler, light, light_sampler = settings
        self.rows.append(dict(
            student=f"s{len(self.rows)}", kind=kind, mistake=mistake, scene=scene, res=res,
            spp=spp, sampler=sampler, light=light, light_sampler=light_sampler,
            stated=stated, file=str(path)))


def build(corpus, quick):
    rng = random.Random(29)
    seed = iter(range(1000, 100000))
    # Correct renders: at 128², up to 4096 paths per pixel; at 512², 256.
    plan = [(128, 90 if not quick else 12, 4096), (512, 12 if not quick else 2, 256)]
    for res, per_scene, max_paths in plan:
        for scene in SCENES:
            for settings in correct_settings(rng, per_scene, max_paths):
                path = corpus.trace(scene, res, *settings, next(seed))
                corpus.add("correct", scene, res, settings, path, stated=True)
                if "grid" not in (settings[1], settings[3]):
                    corpus.add("correct", scene, res, settings, path, stated=False)
    # The course's first step and its pixel-corner twin, stated.
    for scene in SCENES:
        for res in (128, 512):
            first = (1, "grid", 16, "stratified")
            s = next(seed)
            corpus.add("first step", scene, res, first, corpus.trace(scene, res, *first, s))
            corpus.add("mistake", scene, res, first,
                       corpus.trace(scene, res, *first, s, mistakes=("pixel-corners",)),
                       mistake="pixel-corners (first step)")
    # Every mistake: 512² at 16 x 16 (set1), 128² at four settings (all sets).
    mistakes = subprocess.run([corpus.python, str(HERE / "tracer.py"), "--list-mistakes"],
                              check=True, capture_output=True, text=True).stdout.split("\n")
    mistakes = [m.split()[0] for m in mistakes if m.strip()]
    if quick:
        mistakes = mistakes[:4]
    settings_512 = [(16, "stratified", 16, "stratified")]
    settings_128 = [(1, "random", 1, "random"), (4, "stratified", 4, "stratified"),
                    (16, "random", 16, "random"), (64, "stratified", 1, "random")]
    for m in mistakes:
        for settings in settings_512:
            s = next(seed)
            corpus.add("mistake", "set1", 512, settings,
                       corpus.trace("set1", 512, *settings, s, mistakes=(m,)), mistake=m)
        for scene in SCENES:
            for settings in settings_128:
                s = next(seed)
                corpus.add("mistake", scene, 128, settings,
                           corpus.trace(scene, 128, *settings, s, mistakes=(m,)), mistake=m)


def grade_class(corpus, rows, name="manifest", cache=None):
    """Grades `rows` as one class with `glint grade --class` (each row's
    settings stated or not) against the corpus's reference cache: each
    submission's JSON by student, and the seconds it took."""
    manifest = corpus.out / f"{name}.csv"
    with open(manifest, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["student", "scene", "file", "spp", "sampler", "light_samples", "light_sampler", "note"])
        for r in rows:
            stated = [r["spp"], r["sampler"], r["light"], r["light_sampler"]] if r["stated"] else ["", "", "", ""]
            w.writerow([r["student"], str(SCENES[r["scene"]]), r["file"], *stated, r["kind"]])
    start = time.time()
    out = subprocess.run([corpus.glint, "grade", "--class", str(manifest), "--format", "json",
                          "--cache", str(cache or corpus.out / "cache")], capture_output=True, text=True)
    if out.returncode not in (0, 1):
        sys.exit(f"glint grade failed ({out.returncode}): {out.stderr}")
    elapsed = time.time() - start
    return {s["student"]: s for s in json.loads(out.stdout)["submissions"]}, elapsed


def grade(corpus):
    graded, elapsed = grade_class(corpus, corpus.rows)
    for r in corpus.rows:
        g = graded[r["student"]]
        r["verdict"] = g["verdict"]
        r["worst"] = g["rejected"][0]["region"] if g.get("rejected") else ""
    return elapsed


def srgb8(path):
    """An 8-bit image as an H x W x 3 float array."""
    from PIL import Image
    return np.asarray(Image.open(path).convert("RGB"), dtype=np.float64)


def ssim(a, b):
    """Mean SSIM of two 8-bit images (Wang et al. 2004; 7 x 7 uniform windows,
    K1 0.01, K2 0.03, as scikit-image's default), over channels."""
    c1, c2 = (0.01 * 255) ** 2, (0.03 * 255) ** 2

    def box(x):
        k = 7
        s = np.cumsum(np.cumsum(np.pad(x, ((1, 0), (1, 0))), 0), 1)
        return (s[k:, k:] - s[:-k, k:] - s[k:, :-k] + s[:-k, :-k]) / (k * k)

    values = []
    for ch in range(3):
        x, y = a[..., ch], b[..., ch]
        mx, my = box(x), box(y)
        vx, vy, cxy = box(x * x) - mx * mx, box(y * y) - my * my, box(x * y) - mx * my
        n = 49
        vx, vy, cxy = vx * n / (n - 1), vy * n / (n - 1), cxy * n / (n - 1)
        s = ((2 * mx * my + c1) * (2 * cxy + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2))
        values.append(s.mean())
    return float(np.mean(values))


def course_autograder(corpus):
    """SSIM > 0.9 and RMSE <= 50 (8-bit) against Glint's converged render."""
    refs = {}
    for r in corpus.rows:
        key = (r["scene"], r["res"])
        if key not in refs:
            path = corpus.out / "images" / f"reference-{r['scene']}-{r['res']}.png"
            if not path.exists():
                subprocess.run([corpus.glint, "render", str(SCENES[r["scene"]]), "--resolution",
                                f"{r['res']}x{r['res']}", "--spp", "256", "--light-samples", "16",
                                "-o", str(path)], check=True, capture_output=True)
            refs[key] = srgb8(path)
        if not r["file"].endswith(".png"):
            continue
        if "ssim" not in r:
            img = srgb8(r["file"])
            r["ssim"] = ssim(img, refs[key])
            r["rmse"] = float(np.sqrt(np.mean((img - refs[key]) ** 2)))
        r["course_pass"] = r["ssim"] > 0.9 and r["rmse"] <= 50


def time_one_grade(corpus):
    """Seconds to grade one 512² image against cached references (median of 5)."""
    row = next(r for r in corpus.rows if r["res"] == 512 and r["kind"] == "correct" and r["stated"])
    args = [corpus.glint, "grade", str(SCENES[row["scene"]]), row["file"], "--cache",
            str(corpus.out / "cache"), "--spp", str(row["spp"]), "--sampler", row["sampler"],
            "--light-samples", str(row["light"]), "--light-sampler", row["light_sampler"]]
    subprocess.run(args, capture_output=True)
    times = []
    for _ in range(5):
        start = time.time()
        subprocess.run(args, capture_output=True)
        times.append(time.time() - start)
    return statistics.median(times), min(times), max(times)


def tables(corpus, timing, elapsed):
    rows = corpus.rows
    lines = []
    correct = [r for r in rows if r["kind"] in ("correct", "first step")]

    def rate(group):
        fails = sum(r["verdict"] != "pass" for r in group)
        return f"{fails} / {len(group)}"

    lines.append("| correct submissions | stated settings | settings unknown (random and stratified only) |")
    lines.append("|---|---|---|")
    for res in (128, 512):
        for spp_range, label in (((1, 4), "1-4 spp"), ((16, 64), "16-64 spp"), ((256, 256), "256 spp")):
            group = [r for r in correct if r["res"] == res and spp_range[0] <= r["spp"] <= spp_range[1]]
            stated = [r for r in group if r["stated"]]
            unknown = [r for r in group if not r["stated"]]
            if stated or unknown:
                lines.append(f"| {res}², {label} | {rate(stated)} fail | {rate(unknown)} fail |")
    stated_all = [r for r in correct if r["stated"]]
    unknown_all = [r for r in correct if not r["stated"]]
    lines.append(f"| **all** | **{rate(stated_all)} fail** | **{rate(unknown_all)} fail** |")
    lines.append("")
    lines.append("| mistake | 512², 16 spp × 16 light (set1) | 128², 1 × 1 | 128², 4 × 4 | 128², 16 × 16 | 128², 64 × 1 |")
    lines.append("|---|---|---|---|---|---|")
    mistakes = sorted({r["mistake"] for r in rows if r["kind"] == "mistake" and "first step" not in r["mistake"]})
    for m in mistakes:
        cells = []
        group = [r for r in rows if r["mistake"] == m and r["res"] == 512]
        cells.append(f"{sum(r['verdict'] == 'fail' for r in group)} / {len(group)} caught")
        for spp, light in ((1, 1), (4, 4), (16, 16), (64, 1)):
            group = [r for r in rows if r["mistake"] == m and r["res"] == 128 and r["spp"] == spp and r["light"] == light]
            cells.append(f"{sum(r['verdict'] == 'fail' for r in group)} / {len(group)}")
        lines.append(f"| `{m}` | " + " | ".join(cells) + " |")
    first = [r for r in rows if r["kind"] == "first step"]
    corners = [r for r in rows if r["mistake"] == "pixel-corners (first step)"]
    lines.append("")
    lines.append(f"First step (1 spp on the grid, stated): {rate(first)} correct ones fail; "
                 f"pixel corners: {sum(r['verdict'] == 'fail' for r in corners)} / {len(corners)} caught.")
    pngs = [r for r in rows if "course_pass" in r]
    ok = [r for r in pngs if r["kind"] != "mistake" and r["stated"]]
    wrong = [r for r in pngs if r["kind"] == "mistake"]
    lines.append("")
    lines.append("| on the same corpus | correct submissions failed | wrong submissions passed |")
    lines.append("|---|---|---|")
    lines.append(f"| `glint grade` | {sum(r['verdict'] != 'pass' for r in ok)} / {len(ok)} | "
                 f"{sum(r['verdict'] == 'pass' for r in wrong)} / {len(wrong)} |")
    lines.append(f"| SSIM > 0.9 and RMSE ≤ 50 | {sum(not r['course_pass'] for r in ok)} / {len(ok)} | "
                 f"{sum(r['course_pass'] for r in wrong)} / {len(wrong)} |")
    lines.append("")
    med, lo, hi = timing
    lines.append(f"Grading one 512² image against cached references: {med:.2f} s (median of 5, "
                 f"{lo:.2f}-{hi:.2f}); the whole corpus ({len(rows)} submissions): {elapsed:.0f} s.")
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--glint", default=str(REPO / "target/release/glint"))
    ap.add_argument("--out", default=str(REPO / "target/corpus"))
    ap.add_argument("--quick", action="store_true", help="a small corpus, to try the script")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    corpus = Corpus(out, args.glint, sys.executable)
    build(corpus, args.quick)
    print(f"{len(corpus.rows)} submissions; grading", file=sys.stderr)
    elapsed = grade(corpus)
    course_autograder(corpus)
    timing = time_one_grade(corpus)
    (out / "results.json").write_text(json.dumps(corpus.rows, indent=1))
    text = tables(corpus, timing, elapsed)
    (out / "table.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
