#!/usr/bin/env python3
"""Measures how well `glint grade` tells the mistakes of its catalogue apart:
every mistake `glint render --mistake ID` renders, on scenes that have what
each spoils (the Cornell sets, textured spheres, a MIP-mapped ground, a
cube-map environment, a magnified texture: scenes/ here), at other seeds
than the grader's, graded as a class.

    python3 measure/mistakes/catalogue.py [--glint target/release/glint]
        [--out target/mistakes-catalogue] [--settings 4s4s,16r16r,1r1r] [--res 128]

These submissions are Glint's own mutants, so the measurement is of the
statistics (whether one mistake's image can be told from the others' and
from the correct one at these settings), not of how closely a student's
tracer makes the mistake: measure/mistakes/diagnose.py measures that, on an
independent tracer's mistakes. Writes OUT/results.json and prints the table
of docs/grading.md. Images and the reference cache stay in OUT.
"""

import argparse
import csv
import json
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent.parent
SCENES = ["cornell-set1", "cornell-set2", "cornell-set3", "textured-spheres", "ground-mipmap", "environment",
          "texture-closeup"]


def scene_file(name):
    """A shipped scene, or one of this measurement's own (scenes/ here)."""
    shipped = REPO / "scenes" / f"{name}.toml"
    return shipped if shipped.exists() else Path(__file__).resolve().parent / "scenes" / f"{name}.toml"
PATTERN = {"r": "random", "s": "stratified", "g": "grid"}


def parse_settings(text):
    """`4s4s` -> (4, "stratified", 4, "stratified")."""
    import re
    m = re.fullmatch(r"(\d+)([rsg])(\d+)([rsg])", text)
    if not m:
        sys.exit(f"--settings: {text} is not like 4s4s")
    return int(m[1]), PATTERN[m[2]], int(m[3]), PATTERN[m[4]]


def catalogue(glint):
    """The ids of the mistakes Glint renders (not the noise-only ones)."""
    out = subprocess.run([glint, "grade", "--mistakes"], check=True, capture_output=True, text=True).stdout
    return [line.split()[0] for line in out.splitlines() if "noise" not in line.split()[2]]


def render(glint, scene, out, res, settings, seed, mistake=None):
    """Renders `scene` (with `mistake`) to `out` unless it is there; False
    when Glint refuses the mistake for this scene (it changes nothing)."""
    if out.exists():
        return True
    spp, sampler, light, light_sampler = settings
    cmd = [glint, "render", str(scene_file(scene)), "--resolution", f"{res}x{res}",
           "--spp", str(spp), "--sampler", sampler, "--light-samples", str(light),
           "--light-sampler", light_sampler, "--seed", str(seed), "-o", str(out)]
    if mistake:
        cmd += ["--mistake", mistake]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode == 2 and "changes nothing" in r.stderr:
        return False
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed: {r.stderr}")
    return True


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--glint", default=str(REPO / "target/release/glint"))
    ap.add_argument("--out", default=str(REPO / "target/mistakes-catalogue"))
    ap.add_argument("--settings", default="4s4s,16r16r,1r1r")
    ap.add_argument("--res", type=int, default=128)
    ap.add_argument("--scenes", default=",".join(SCENES))
    args = ap.parse_args()
    out = Path(args.out).resolve()  # the manifest names files by absolute paths
    (out / "images").mkdir(parents=True, exist_ok=True)
    mistakes = catalogue(args.glint)
    rows, seed = [], 700000
    start = time.time()
    for scene in args.scenes.split(","):
        for text in args.settings.split(","):
            settings = parse_settings(text)
            for mistake in [None] + mistakes:
                seed += 1
                path = out / "images" / f"{scene}-{args.res}-{text}-{mistake or 'correct'}.png"
                if render(args.glint, scene, path, args.res, settings, seed, mistake):
                    rows.append(dict(student=f"s{len(rows)}", scene=scene, file=str(path),
                                     settings=settings, mistake=mistake or ""))
    made = time.time() - start
    manifest = out / "manifest.csv"
    with open(manifest, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["student", "scene", "file", "spp", "sampler", "light_samples", "light_sampler", "note"])
        for r in rows:
            w.writerow([r["student"], str(scene_file(r["scene"])), r["file"], *r["settings"], r["mistake"]])
    start = time.time()
    g = subprocess.run([args.glint, "grade", "--class", str(manifest), "--format", "json",
                        "--cache", str(out / "cache")], capture_output=True, text=True)
    if g.returncode not in (0, 1):
        sys.exit(f"glint grade failed ({g.returncode}): {g.stderr}")
    graded_in = time.time() - start
    graded = {s["student"]: s for s in json.loads(g.stdout)["submissions"]}

    table = {}
    for r in rows:
        s = graded[r["student"]]
        t = table.setdefault(r["mistake"] or "(correct)", dict(made=0, failed=0, first=0, top3=0, none=0, given=0, wrong=[]))
        t["made"] += 1
        if s["verdict"] != "fail":
            t["given"] += bool(s.get("likely_mistakes"))
            continue
        t["failed"] += 1
        fits = [m["id"] for m in s.get("likely_mistakes", []) if m["consistent"]]
        t["none"] += not fits
        if r["mistake"]:
            t["first"] += fits[:1] == [r["mistake"]]
            t["top3"] += r["mistake"] in fits[:3]
            if fits[:1] != [r["mistake"]]:
                t["wrong"].append(f"{r['scene']} {fits[0] if fits else 'none fits'}")
    (out / "results.json").write_text(json.dumps(dict(table=table, make_seconds=made, grade_seconds=graded_in), indent=1))
    print("| mistake | failing / made | named first | in the first three | not named first: scene, first fit |")
    print("|---|---|---|---|---|")
    for key, t in table.items():
        f = t["failed"]
        pct = lambda k: f"{t[k]} / {f}" if f else "–"
        wrong = "; ".join(sorted(set(t["wrong"])))[:120]
        print(f"| `{key}` | {f} / {t['made']} | {pct('first')} | {pct('top3')} | {wrong} |")
    total_f = sum(t["failed"] for k, t in table.items() if k != "(correct)")
    total_first = sum(t["first"] for k, t in table.items() if k != "(correct)")
    total_top3 = sum(t["top3"] for k, t in table.items() if k != "(correct)")
    print(f"\nall mistakes: named first {total_first} / {total_f}, in the first three {total_top3} / {total_f}; "
          f"passing given a mistake: {sum(t['given'] for t in table.values())}; "
          f"made in {made:.0f} s, graded (mutants included) in {graded_in:.0f} s")


if __name__ == "__main__":
    main()
