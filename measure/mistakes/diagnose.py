#!/usr/bin/env python3
"""Measures how well `glint grade` names the mistake behind a failing image,
on submissions made by the independent tracer (measure/corpus/tracer.py):
each of its mistakes at several settings, and correct renders.

    measure/corpus/.venv/bin/python measure/mistakes/diagnose.py [--glint target/release/glint]
        [--out target/corpus-mistakes] [--cache target/corpus/cache] [--quick] [--no-512]

For each mistake the tracer makes, the failing submissions' `likely_mistakes`
(glint grade --format json) are read for where the true mistake ranks: first,
among the first three, or "no known mistake fits" for a mistake Glint's
catalogue does not have. Writes OUT/results.json and prints the table of
docs/grading.md. Images and Glint's reference cache stay, so a second run only
grades. The tracer makes the submissions; Glint does all the rest.
"""

import argparse
import json
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "corpus"))
from measure import Corpus, grade_class  # noqa: E402

# The tracer's name for each mistake -> Glint's catalogue id (None: not in it).
IDS = {
    "flipped-view": "view-sign",
    "sphere-u-sign": "sphere-u-sign",
    "no-shadow-offset": "no-shadow-offset",
    "no-shadows": "no-shadows",
    "no-srgb": "no-srgb",
    "gamma-22": "gamma-2.2",
    "truncate-8bit": None,
    "summed-light-samples": "sum-light-samples",
    "horizontal-fov": "fov-horizontal",
    "fov-no-half": "fov-not-halved",
    "pixel-corners": "pixel-corner",
    "unnormalised-normals": "normal-not-normalised",
    "blinn-half-vector": "blinn",
    "checker-doubled": "checker-double",
    "sphere-v-from-y": None,
    "no-ambient": "no-ambient",
    "ambient-per-sample": None,
    "ambient-in-shadow-only": None,
    "flipped-image": "flip-vertical",
    "light-centre": "light-centre",
    "light-twice-size": "light-twice-size",
    "light-blocks-shadow": "light-blocks-itself",
    "invisible-light": "light-invisible",
    "two-sided-light": "two-sided-light",
    "distance-falloff": None,
    "no-clamp-dots": None,
    "specular-white": None,
    "shared-samples": None,
}

# Pairs of the tracer's mistakes, each a combination Glint should name.
PAIRS = [("no-ambient", "light-centre"), ("no-srgb", "blinn-half-vector"),
         ("no-ambient", "two-sided-light"), ("fov-no-half", "no-ambient"),
         ("gamma-22", "checker-doubled"), ("summed-light-samples", "light-twice-size")]

SETTINGS_128 = [(1, "random", 1, "random"), (4, "stratified", 4, "stratified"),
                (16, "random", 16, "random"), (64, "stratified", 1, "random")]
SETTINGS_512 = [(1, "random", 1, "random"), (16, "stratified", 16, "stratified")]


def catalogue(glint):
    """Glint's mistakes: id -> how it is rendered."""
    import subprocess
    out = subprocess.run([glint, "grade", "--mistakes"], check=True, capture_output=True, text=True)
    found = {}
    for line in out.stdout.splitlines():
        parts = line.split()
        how = "not rendered" if "not rendered" in line else "noise only" if "noise only" in line else parts[2]
        found[parts[0]] = how
    return found


def build(corpus, quick, with_512, only=()):
    """The corpus; with `only`, just those mistakes alone, each image with
    the seed it has in the whole corpus."""
    seed = iter(range(500000, 900000))
    mistakes = list(IDS) if not quick else ["no-ambient", "light-centre", "specular-white", "flipped-image"]
    scenes = ("set1", "set2", "set3") if not quick else ("set1",)

    def add(kind, scene, size, settings, mistake_names):
        s = next(seed)
        if only and not (kind == "mistake" and mistake_names[0] in only):
            return
        path = corpus.trace(scene, size, *settings, s, mistakes=mistake_names)
        corpus.add(kind, scene, size, settings, path, mistake="+".join(mistake_names))

    for m in mistakes:
        for scene in scenes:
            for settings in SETTINGS_128 if not quick else SETTINGS_128[1:2]:
                add("mistake", scene, 128, settings, (m,))
        if with_512:
            for settings in SETTINGS_512:
                add("mistake", "set1", 512, settings, (m,))
    for pair in PAIRS if not quick else PAIRS[:1]:
        for scene in scenes:
            add("pair", scene, 128, SETTINGS_128[1], pair)
    for scene in scenes:
        for settings in SETTINGS_128:
            add("correct", scene, 128, settings, ())


def true_id_of(mistake):
    """Glint's id for the tracer's mistake or pair of them (None: not in the catalogue)."""
    ids = [IDS.get(m) for m in mistake.split("+")]
    return "+".join(ids) if all(ids) else None


def rank_of(true_id, likely):
    """1-based rank of `true_id` (a pair in either order) among the consistent
    mistakes, or None."""
    want = set(true_id.split("+"))
    consistent = [set(m["id"].split("+")) for m in likely if m["consistent"]]
    return consistent.index(want) + 1 if want in consistent else None


def summarise(corpus, rendered):
    rows = {}
    for r in corpus.rows:
        key = r["mistake"] or "(correct)"
        s = rows.setdefault(key, dict(n=0, failed=0, first=0, top3=0, none_fits=0, given=0, wrong_first=[]))
        s["n"] += 1
        g = r["graded"]
        if g["verdict"] != "fail":
            s["given"] += bool(g.get("likely_mistakes"))
            continue
        s["failed"] += 1
        likely = g.get("likely_mistakes", [])
        true_id = true_id_of(r["mistake"]) if r["mistake"] else None
        rank = rank_of(true_id, likely) if true_id else None
        s["first"] += rank == 1
        s["top3"] += rank is not None and rank <= 3
        fits = [m["id"] for m in likely if m["consistent"]]
        s["none_fits"] += not fits
        if fits and rank != 1:
            s["wrong_first"].append(fits[0])
    for key, s in rows.items():
        true_id = true_id_of(key) if key != "(correct)" else None
        s["id"] = true_id
        how = [rendered.get(i, "") for i in true_id.split("+")] if true_id else []
        s["rendered"] = " + ".join(how) if true_id else "not in the catalogue"
    return rows


def table(rows):
    lines = ["| tracer's mistake | Glint's id (rendered as) | failing / made | ranked first | in the first three | no known mistake fits |",
             "|---|---|---|---|---|---|"]
    for key, s in rows.items():
        f = s["failed"] or 1
        pct = lambda k: f"{100 * s[k] / f:.0f}%" if s["failed"] else "–"
        ident = f"`{s['id']}` ({s['rendered']})" if s["id"] else s["rendered"]
        lines.append(f"| `{key}` | {ident} | {s['failed']} / {s['n']} | {pct('first')} | {pct('top3')} | {pct('none_fits')} |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    repo = HERE.parent.parent
    ap.add_argument("--glint", default=str(repo / "target/release/glint"))
    ap.add_argument("--out", default=str(repo / "target/corpus-mistakes"))
    ap.add_argument("--cache", default=str(repo / "target/corpus/cache"))
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--no-512", action="store_true", help="only the 128² submissions")
    ap.add_argument("--only", action="append", default=[], metavar="NAME",
                    help="only this mistake of the tracer's, alone (repeatable): a quick look, not the table")
    args = ap.parse_args()
    out = Path(args.out).resolve()  # the manifest names files by absolute paths
    out.mkdir(parents=True, exist_ok=True)
    corpus = Corpus(out, args.glint, sys.executable)
    start = time.time()
    build(corpus, args.quick, not args.no_512, args.only)
    made = time.time() - start
    graded, elapsed = grade_class(corpus, corpus.rows, cache=Path(args.cache))
    for r in corpus.rows:
        r["graded"] = graded[r["student"]]
    rows = summarise(corpus, catalogue(args.glint))
    name = "results-only.json" if args.only else "results.json"
    (out / name).write_text(json.dumps(dict(rows=rows, grade_seconds=elapsed, trace_seconds=made), indent=1))
    print(table(rows))
    print(f"\n{len(corpus.rows)} submissions; grading (mutants included) took {elapsed:.0f} s")


if __name__ == "__main__":
    main()
