#!/usr/bin/env python3
"""Measures `glint grade` on the files students' ray tracers write: the
independent tracer's correct renders saved in every format `formats.py`
knows (false alarms, settings stated and unknown, 1 to 256 spp), its mistakes
saved as PNG, JPEG (quality 85, 75 and 50), BMP and Radiance HDR (what the
lossy formats cost in power), and the time a class of mixed formats takes
per image against one of PNGs.

    measure/corpus/.venv/bin/python measure/corpus/measure_formats.py [--glint target/release/glint]
        [--out target/corpus-formats] [--quick]

Writes OUT/results.json and OUT/table.md (the tables of docs/grading.md,
"Formats"). Renders, files and Glint's reference cache stay in OUT, so a
second run only grades. Glint is called for everything Glint does; the
tracer makes the renders and formats.py the files.
"""

import argparse
import json
import random
import statistics
import subprocess
import sys
from pathlib import Path


HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import formats  # noqa: E402
import measure  # noqa: E402
import tracer  # noqa: E402

SCENES = measure.SCENES
# Mistakes in the 8-bit encoding itself: the tracer writes them as 8-bit
# files only, so they have no float variants.
EIGHT_BIT_MISTAKES = {"no-srgb", "gamma-22", "truncate-8bit"}
MISTAKE_VARIANTS = ["png", "jpeg-q85-420", "jpeg-q85-444", "jpeg-q75-420", "jpeg-q50-420", "bmp", "hdr-stb"]
MISTAKE_SETTINGS = (16, "stratified", 16, "stratified")


class Corpus(measure.Corpus):
    def variants_of(self, render, variants):
        """Each of `variants` of `render` (a .pfm, or an 8-bit .png), made once."""
        film = tracer.read_pfm(str(render)) if render.suffix == ".pfm" else None
        codes = tracer.encode_8bit(film, ()) if film is not None else tracer.read_png(str(render))
        made = []
        for v in variants:
            if v.needs == "float" and film is None:
                continue
            path = self.out / "files" / f"{render.stem}-{v.name}.{v.ext}"
            if not path.exists():
                formats.write_variant(v, film, codes, path)
            made.append((v, path))
        return made

    def add_file(self, kind, scene, res, settings, path, variant, stated=True, mistake=""):
        self.add(kind, scene, res, settings, path, stated=stated, mistake=mistake)
        self.rows[-1].update(variant=variant.name, expect=variant.expect)


def build(corpus, quick):
    rng = random.Random(49)
    seed = iter(range(5000, 100000))
    corpus_variants = [v for v in formats.VARIANTS if v.corpus]
    plan = [(128, 10 if not quick else 2, 1024), (512, 2 if not quick else 1, 256)]
    for res, per_scene, max_paths in plan:
        for scene in SCENES:
            for settings in measure.correct_settings(rng, per_scene, max_paths):
                render = corpus.trace(scene, res, *settings, next(seed), ext="pfm")
                for variant, path in corpus.variants_of(render, corpus_variants):
                    corpus.add_file("correct", scene, res, settings, path, variant)
                    if "grid" not in (settings[1], settings[3]):
                        corpus.add_file("correct", scene, res, settings, path, variant, stated=False)
    mistakes = subprocess.run([corpus.python, str(HERE / "tracer.py"), "--list-mistakes"],
                              check=True, capture_output=True, text=True).stdout.split("\n")
    mistakes = [m.split()[0] for m in mistakes if m.strip()]
    if quick:
        mistakes = mistakes[:3]
    chosen = [formats.BY_NAME[n] for n in MISTAKE_VARIANTS]
    for m in mistakes:
        ext = "png" if m in EIGHT_BIT_MISTAKES else "pfm"
        render = corpus.trace("set1", 512, *MISTAKE_SETTINGS, next(seed), mistakes=(m,), ext=ext)
        for variant, path in corpus.variants_of(render, chosen):
            corpus.add_file("mistake", "set1", 512, MISTAKE_SETTINGS, path, variant, mistake=m)


def grade(corpus):
    graded, elapsed = measure.grade_class(corpus, corpus.rows)
    for r in corpus.rows:
        g = graded[r["student"]]
        r["verdict"] = g["verdict"]
        r["format"] = g.get("format", "")
        r["why"] = (g["rejected"][0]["region"] if g.get("rejected") else g.get("unreadable", g.get("message", "")))
        r["largest_z"] = g.get("largest_accepted_z")
    return elapsed


def class_time(corpus, rows, label):
    """Seconds per image to grade `rows` as one class against cached
    references (which an earlier run made)."""
    rows = [dict(r, student=f"t{i}", stated=True) for i, r in enumerate(rows)]
    _, elapsed = measure.grade_class(corpus, rows, name=f"timing-{label}")
    return elapsed / len(rows)


def timing(corpus):
    """One 512² render as a class of its every graded format against the same
    render as as many PNGs: one reference set, so that what is timed is what
    each file costs (its decoding, a JPEG's encoding of the references),
    alternated, medians with the spread."""
    big = [r for r in corpus.rows if r["kind"] == "correct" and r["res"] == 512 and r["stated"]
           and r["expect"] == "graded"]
    render = Path(big[0]["file"]).stem.rsplit("-", 1)[0]
    stem = lambda r: Path(r["file"]).stem
    mixed = [r for r in big if stem(r).startswith(render + "-")]
    png = [r for r in mixed if r["variant"] == "png"] * len(mixed)
    jpeg = [r for r in mixed if r["variant"] == "jpeg-q85-420"] * len(mixed)
    class_time(corpus, mixed, "mixed")  # the JPEG encodings' references, once
    runs = [(class_time(corpus, png, "png"), class_time(corpus, jpeg, "jpeg"),
             class_time(corpus, mixed, "mixed")) for _ in range(3)]
    return png, mixed, runs


def rate(group, verdicts=("fail",)):
    bad = sum(r["verdict"] in verdicts for r in group)
    return f"{bad} / {len(group)}" if group else "–"


def tables(corpus, elapsed, timed):
    rows = corpus.rows
    lines = ["### False alarms: correct renders in every format", "",
             "| format | how it was written | settings stated: failed | settings unknown: failed |",
             "|---|---|---|---|"]
    correct = [r for r in rows if r["kind"] == "correct"]
    for v in formats.VARIANTS:
        if not v.corpus:
            continue
        group = [r for r in correct if r["variant"] == v.name]
        if v.expect == "unreadable":
            lines.append(f"| `{v.name}` | {v.what} | {rate(group, ('unreadable',))} unreadable for grading, "
                         f"{rate(group)} failed | |")
            continue
        stated = [r for r in group if r["stated"]]
        unknown = [r for r in group if not r["stated"]]
        lines.append(f"| `{v.name}` | {v.what} | {rate(stated, ('fail', 'unreadable', 'error'))} | "
                     f"{rate(unknown, ('fail', 'unreadable', 'error'))} |")
    graded = [r for r in correct if r["expect"] == "graded"]
    lines.append(f"| **all** | | **{rate([r for r in graded if r['stated']], ('fail', 'unreadable', 'error'))}** | "
                 f"**{rate([r for r in graded if not r['stated']], ('fail', 'unreadable', 'error'))}** |")
    lines += ["", "| correct renders, every format graded | 1–4 spp | 16–64 spp | 256 spp |", "|---|---|---|---|"]
    for res in (128, 512):
        cells = []
        for lo, hi in ((1, 4), (16, 64), (256, 256)):
            group = [r for r in graded if r["res"] == res and lo <= r["spp"] <= hi]
            cells.append(rate(group, ("fail", "unreadable", "error")))
        lines.append(f"| {res}² | " + " | ".join(cells) + " |")
    lines += ["", "### Mistakes through lossy formats (512², 16 spp × 16 light samples, stated)", "",
              "| mistake | " + " | ".join(f"`{n}`" for n in MISTAKE_VARIANTS) + " |",
              "|---|" + "---|" * len(MISTAKE_VARIANTS)]
    mistakes = sorted({r["mistake"] for r in rows if r["kind"] == "mistake"})
    for m in mistakes:
        cells = []
        for n in MISTAKE_VARIANTS:
            group = [r for r in rows if r["mistake"] == m and r["variant"] == n]
            if not group:
                cells.append("–")
            else:
                cells.append({"fail": "caught", "pass": "missed"}.get(group[0]["verdict"], group[0]["verdict"]))
        lines.append(f"| `{m}` | " + " | ".join(cells) + " |")
    png, mixed, runs = timed
    spread = lambda k: (f"{statistics.median(r[k] for r in runs):.3f} "
                        f"({min(r[k] for r in runs):.3f}–{max(r[k] for r in runs):.3f})")
    lines += ["", f"Grading a class against cached references, seconds per 512² image (3 alternated runs, "
                  f"median and range): one render as {len(png)} PNGs {spread(0)}; as many JPEGs of "
                  f"quality 85, 4:2:0 {spread(1)}; in its {len(mixed)} graded formats (11 JPEG encodings) "
                  f"{spread(2)}.",
              f"The whole corpus ({len(rows)} gradings, references and JPEG encodings included): {elapsed:.0f} s."]
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--glint", default=str(measure.REPO / "target/release/glint"))
    ap.add_argument("--out", default=str(measure.REPO / "target/corpus-formats"))
    ap.add_argument("--quick", action="store_true", help="a small corpus, to try the script")
    ap.add_argument("--timing-only", action="store_true",
                    help="time again, with the corpus and grades of the last run (results.json)")
    args = ap.parse_args()
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    corpus = Corpus(out, args.glint, sys.executable)
    if args.timing_only:
        corpus.rows = json.loads((out / "results.json").read_text())
        elapsed = float((out / "elapsed.txt").read_text())
    else:
        build(corpus, args.quick)
        print(f"{len(corpus.rows)} gradings; grading", file=sys.stderr)
        elapsed = grade(corpus)
        (out / "results.json").write_text(json.dumps(corpus.rows, indent=1))
        (out / "elapsed.txt").write_text(f"{elapsed}\n")
    timed = timing(corpus)
    text = tables(corpus, elapsed, timed)
    (out / "table.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
