#!/usr/bin/env python3
"""Do Glint's two checking tools name the same mistake the same way?

For each of the fourteen classic student mistakes that `tracer.py --mistake NAME`
can make, on a scene where it shows:

  1. `glint grade --stages S --write V` (once per scene), the tracer's
     `stages S V A --mistake NAME`, and `glint grade --stages S --answers A
     --format json` (and once more as text): the first failing stage, its first
     failing case, that case's first differing field (grading-stages.md, "The
     report"), and whether the text report shows "how Glint's expected values
     were found" for it;
  2. at a pixel where the mistake shows (the failing case's `from`, or, where
     that case has no pixel or explain agrees there, up to K more cases whose
     answers differ from Glint's raw numbers: 1e-3 of the largest component,
     u not modulo 1, codes exactly), the tracer's `explain` with the
     mistake and the flags of that case's `explain` command (`--stage` left
     out, so that every stage is compared; `--texture-level report` on the
     texture scene, since the texture stage checks the report's level), and
     `glint explain ... --against doc.json --json`: the first difference's
     stage and key path;
  3. a markdown table of both, whether they name the same stage and the same
     quantity (judged by the hand-coded correspondences in CORRESPONDENCES).

Standard library only; it runs `glint` (never cargo) and tracer.py.

  python3 tools/student/mistakes.py [--glint PATH] [--json FILE] [--only NAME ...]
                                    [--workdir DIR] [--candidates K] [--cases N ...]

Where no stage fails at 64 cases per stage, the check is repeated with more
(`--cases 64 400` by default).  Where explain's first difference comes in a
later stage than the grade's (the film, at a camera sample the mistake spares),
the pixel is explained again with `--all-samples`; on the texture scene, also
without `--texture-level report`.  Both are shown after a `;` in the table.
"""

import argparse
import csv
import errno
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
TRACER = os.path.join(HERE, "tracer.py")
STAGES = ("camera", "intersection", "texture", "lighting", "film")

# mistake -> the scene it is tried on (scenes/NAME.toml).  The texture ones on
# the textured spheres (image textures with a MIP pyramid; coffee.png is
# 600 x 400, whose level 4 is 37 x 25); the rest on the Cornell box (Set 1).
MISTAKES = [
    ("up-flipped", "cornell-set1"),
    ("sphere-u-unwrapped", "textured-spheres"),
    ("mip-natural-log", "textured-spheres"),
    ("odd-level-rounded-up", "textured-spheres"),
    ("light-sum-not-divided", "cornell-set1"),
    ("light-blocks-itself", "cornell-set1"),
    ("no-shadow-offset", "cornell-set1"),
    ("blinn", "cornell-set1"),
    ("view-sign", "cornell-set1"),
    ("gamma-22", "cornell-set1"),
    ("no-ambient", "cornell-set1"),  # ambient = 0.1
    ("light-centre", "cornell-set1"),  # one area light, 4 x 4 grid samples
    ("pixel-corner", "cornell-set1"),
    ("fov-not-halved", "cornell-set1"),
]
TEXTURE_SCENES = {"textured-spheres"}  # explained with --texture-level report

# ----------------------------------------------------------------------------
# Which explain key is which stage field: (stage field pattern, explain path
# pattern, how sure).  Paths are matched after their indices are replaced by
# [k] and the leading samples[k].ray. / samples[k]. dropped.  "exact": the same
# quantity by definition; "judged": a related quantity, said so in the table.
# ----------------------------------------------------------------------------

CORRESPONDENCES = [
    # camera
    (r"origin", r"camera\.origin", "exact", ""),
    (r"direction", r"camera\.direction", "exact", ""),
    (r"direction", r"camera\.film_point", "judged", "direction = normalize(film point)"),
    (r"direction", r"camera\.ndc", "judged", "the direction is built from ndc"),
    (r"direction", r"camera\.raster", "judged",
     "the direction is built from the raster position (an input of the stage)"),
    (r"direction", r"camera\.differentials\..*", "judged", "the differentials are offsets of the direction"),
    # intersection
    (r"hit", r"intersect\.hit", "exact", ""),
    (r"t", r"intersect\.hit\.t", "exact", ""),
    (r"point", r"intersect\.hit\.point", "exact", ""),
    (r"geometric_normal", r"intersect\.hit\.geometric_normal", "exact", ""),
    (r"shading_normal", r"intersect\.hit\.shading_normal", "exact", ""),
    (r"uv", r"intersect\.hit\.uv", "exact", ""),
    (r"uv", r"texture\.footprint\.uv", "judged", "the texture's copy of the hit's uv"),
    (r"uv", r"texture\.material_uv", "judged", "uv' = uv*scale + offset"),
    (r"uv", r"texture\.(diffuse|specular)\.st", "judged", "st = (u', 1 - v')"),
    (r"object", r"(intersect\.hit\.)?object", "exact", ""),
    # texture
    (r"l", r"texture\.(diffuse|specular)\.report_l", "exact", ""),
    (r"w", r"texture\.(diffuse|specular)\.report_w", "exact", ""),
    (r"level", r"texture\.(diffuse|specular)\.report_level", "exact", ""),
    (r"level", r"texture\.(diffuse|specular)\.glint_level", "judged",
     "under --texture-level report Glint's level is the report's, clamped"),
    (r"level", r"texture\.(diffuse|specular)\.dst_d[xy]|texture\.footprint\.duvd[xy]", "judged",
     "under --texture-level report the footprint is 2^level/m wide"),
    (r"value", r"texture\.(diffuse|specular)\.value|texture\.k[ds]", "exact", ""),
    (r"value", r"texture\.(diffuse|specular)\.texels\[k\]\..*", "judged",
     "the texels and weights whose sum is the value"),
    # lighting
    (r"ambient_term", r"light\.ambient", "exact", ""),
    (r"s\d+_(verdict|blocker)", r"light\.lights\[k\]\.samples\[k\]\.shadow", "exact", ""),
    (r"s\d+_diffuse", r"light\.lights\[k\]\.samples\[k\]\.diffuse", "exact", ""),
    (r"s\d+_specular", r"light\.lights\[k\]\.samples\[k\]\.specular", "exact", ""),
    (r"s\d+_(verdict|blocker)", r"light\.lights\[k\]\.samples\[k\]\.(value|running_average)", "judged",
     "what a blocked sample adds (0) follows from its verdict"),
    (r"s\d+_(verdict|blocker|diffuse|specular)", r"light\.lights\[k\]\.samples\[k\]\.(position|l|n_dot_l|reflection)",
     "judged", "the sample's position is an input of the stage; its l, terms and verdict follow from it"),
    (r"total", r"light\.lights\[k\]\.total", "exact", "a light's term of the total"),
    (r"total", r"radiance\.(local|value)|radiance", "exact", "the point's local radiance"),
    # film
    (r"srgb8", r"film\.srgb8", "exact", ""),
]


def normalize_path(path):
    p = re.sub(r"\[\d+\]", "[k]", path)
    p = re.sub(r"^samples\[k\]\.(ray\.(reflection\.)*)?", "", p)
    return p


def correspond(field, path):
    """(verdict, note): "yes", "yes (judged: …)" or "no"."""
    if field is None or path is None:
        return "—", ""
    npath = normalize_path(path)
    for fpat, ppat, how, note in CORRESPONDENCES:
        if re.fullmatch(fpat, field) and re.fullmatch(ppat, npath):
            if how == "exact":
                return "yes", note
            return "judged yes", note
    return "no", ""


# ----------------------------------------------------------------------------
# Running things
# ----------------------------------------------------------------------------

def find_glint(given):
    if given:
        return given
    for rel in ("target/release/glint", "target/debug/glint"):
        p = os.path.join(REPO, rel)
        if os.path.exists(p):
            return p
    raise SystemExit("mistakes.py: no glint binary in target/release or target/debug: pass --glint PATH")


def run(cmd, ok=(0,), tries=20):
    """Runs cmd from the repository root; retries while the binary is missing or
    busy (being relinked).  Returns (status, stdout, stderr)."""
    for attempt in range(tries):
        try:
            p = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True)
        except OSError as exc:
            if exc.errno in (errno.ENOENT, errno.ETXTBSY, errno.EACCES) and attempt < tries - 1:
                time.sleep(3)
                continue
            raise
        if p.returncode not in ok:
            raise RuntimeError(f"{' '.join(shlex.quote(c) for c in cmd)}: exit {p.returncode}\n{p.stderr.strip()}")
        return p.returncode, p.stdout, p.stderr
    raise RuntimeError(f"{cmd[0]}: could not be run")


def scene_path(scene):
    return os.path.join("scenes", f"{scene}.toml")


# ----------------------------------------------------------------------------
# Where a mistake shows in the raw numbers (to pick pixels beyond the first
# failing case): every expected field of every case compared with the answer
# at 1e-3 of the group's largest component, u not taken modulo 1, codes exactly
# ----------------------------------------------------------------------------

def read_answers(path):
    with open(path, newline="") as f:
        return {r["id"]: r for r in csv.DictReader(f)}


def raw_differs(expected_fields, exp, ans):
    for ef in expected_fields:
        cols = ef["columns"]
        if ef["field"] == "name":
            continue
        gl = [exp.get(c) for c in cols]
        if all(v is None for v in gl):
            continue
        yo = [ans.get(c, "") for c in cols]
        if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in gl):
            try:
                yv = [float(v) for v in yo]
            except ValueError:
                return True
            big = max(abs(v) for v in gl)
            if any(abs(a - b) > 1e-3 * big + 1e-6 for a, b in zip(gl, yv)):
                return True
        else:
            if [str(v).strip().lower() for v in gl] != [str(v).strip().lower() for v in yo]:
                return True
    return False


def raw_candidates(vectors, answers, stages):
    out = []
    for st in stages:
        vp, ap = os.path.join(vectors, f"{st}.json"), os.path.join(answers, f"{st}.csv")
        if not (os.path.exists(vp) and os.path.exists(ap)):
            continue
        doc = json.load(open(vp))
        ans = read_answers(ap)
        for case in doc["cases"]:
            if case["from"] is None or case["id"] not in ans:
                continue
            if raw_differs(doc["expected"], case["expected"], ans[case["id"]]):
                out.append((st, case["id"], case["from"]))
    return out


# ----------------------------------------------------------------------------
# One mistake
# ----------------------------------------------------------------------------

def explain_flags(frm):
    """The flags of a case's `glint explain` command, --stage left out."""
    words = shlex.split(frm["explain"])
    assert words[:2] == ["glint", "explain"], frm["explain"]
    flags, i = [], 3
    while i < len(words):
        w = words[i]
        if w == "--stage":
            i += 2
            continue
        if w.startswith("--") and i + 1 < len(words) and not words[i + 1].startswith("--"):
            flags += [w, words[i + 1]]
            i += 2
        else:
            flags.append(w)
            i += 1
    return flags


def how_found_shown(text, stage):
    """Whether the text report's block for `stage`'s first failure shows how
    Glint's expected values were found."""
    m = re.search(rf"^{stage}: \d+ of \d+ answered cases fail.*?(?=^\S|\Z)", text, re.M | re.S)
    return bool(m) and "how Glint's expected values were found" in m.group(0)


def try_explain(glint, scene, mistake, frm, work, tag, texture_report, all_samples=False):
    flags = explain_flags(frm)
    if all_samples:  # every camera sample of the pixel instead of the case's one
        i = flags.index("--sample")
        flags[i:i + 2] = ["--all-samples"]
    if texture_report:
        flags += ["--texture-level", "report"]
    doc = os.path.join(work, f"{tag}.json")
    run([sys.executable, TRACER, "explain", scene_path(scene), *flags, "--mistake", mistake, "-o", doc])
    status, out, _ = run([glint, "explain", scene_path(scene), *flags, "--against", doc, "--json"], ok=(0, 1))
    rep = json.loads(out)
    fd = rep.get("first_difference")
    return {"pixel": frm["pixel"], "sample": frm["sample"], "spp": frm["spp"], "flags": flags,
            "agrees": rep["agrees"], "stage": fd["stage"] if fd else None, "path": fd["path"] if fd else None,
            "yours": fd.get("yours") if fd else None, "glint": fd.get("glint") if fd else None,
            "tolerance": fd.get("tolerance", {}).get("kind") if fd else None}


def vectors_for(glint, work, scene, cases, cache):
    if (scene, cases) not in cache:
        v = os.path.join(work, f"vectors-{scene}-{cases}")
        if not os.path.isdir(v):
            run([glint, "grade", "--stages", scene_path(scene), "--write", v, "--cases", str(cases)])
        cache[(scene, cases)] = v
    return cache[(scene, cases)]


def grade(glint, mistake, scene, work, vectors, cases):
    answers = os.path.join(work, f"answers-{mistake}-{cases}")
    if os.path.isdir(answers):
        shutil.rmtree(answers)
    run([sys.executable, TRACER, "stages", scene_path(scene), vectors, answers, "--mistake", mistake])
    common = [glint, "grade", "--stages", scene_path(scene), "--answers", answers, "--cases", str(cases)]
    _, out, _ = run(common + ["--format", "json"], ok=(0, 1))
    _, text, _ = run(common, ok=(0, 1))
    return answers, json.loads(out), text


def study(glint, mistake, scene, work, cache, ladder, k_candidates):
    rec = {"mistake": mistake, "scene": scene}
    # 64 cases per stage (the default); where nothing fails, more cases (a
    # mistake may show only in a few, rare cases, such as a deep MIP level)
    for cases in ladder:
        vectors = vectors_for(glint, work, scene, cases, cache)
        answers, rep, text = grade(glint, mistake, scene, work, vectors, cases)
        if not rep["passed"]:
            break
    rec["cases"] = cases
    rec["ladder"] = list(ladder)
    rec["stages_failing"] = [s["stage"] for s in rep["stages"] if s["passes"] is False]
    rec["stage_counts"] = {s["stage"]: [s["passed"], s["answered"]] for s in rep["stages"]}
    first = next((s for s in rep["stages"] if s["passes"] is False), None)
    frm0 = None
    if first is None:
        rec.update(grade_stage=None, grade_case=None, grade_field=None, grade_columns=None, how_found=None,
                   grade_steps=0)
    else:
        ff = first["first_failure"]
        d0 = ff["differences"][0]
        rec.update(grade_stage=first["stage"], grade_case=ff["id"], grade_field=d0["field"],
                   grade_columns=d0["columns"], grade_glint=d0["glint"], grade_yours=d0["yours"],
                   grade_fields=[d["field"] for d in ff["differences"]],
                   grade_from=ff["from"], grade_steps=len(ff.get("steps") or []),
                   how_found=how_found_shown(text, first["stage"]))
        frm0 = ff["from"]
    # pixels to explain: the failing case's, then cases whose answers differ
    # from Glint's raw numbers (in the failing stage, or in every stage if none fails)
    cands = []
    if frm0 is not None:
        cands.append(("first failing case", rec["grade_case"], frm0))
    stages = [rec["grade_stage"]] if rec["grade_stage"] else list(STAGES)
    for st, cid, frm in raw_candidates(vectors, answers, stages):
        cands.append(("raw difference", cid, frm))
    seen, tried = set(), []
    for why, cid, frm in cands:
        key = (tuple(frm["pixel"]), frm["sample"], frm["spp"])
        if key in seen:
            continue
        seen.add(key)
        r = try_explain(glint, scene, mistake, frm, work, f"doc-{mistake}-{len(tried)}", scene in TEXTURE_SCENES)
        r.update(why=why, case=cid)
        tried.append(r)
        if not r["agrees"] or len(tried) >= k_candidates:
            break
    rec["explain_tried"] = tried
    shown = next((r for r in tried if not r["agrees"]), None)
    rec["explain_all_samples"] = None
    if (shown is not None and rec["grade_stage"] is not None and "--sample" in shown["flags"]
            and STAGES.index(shown["stage"]) > STAGES.index(rec["grade_stage"])):
        # the difference shows only in a later stage at the case's camera
        # sample: follow every sample of the pixel, to see where it starts
        frm = next(c[2] for c in cands if tuple(c[2]["pixel"]) == tuple(shown["pixel"])
                   and c[2]["sample"] == shown["sample"] and c[2]["spp"] == shown["spp"])
        rec["explain_all_samples"] = try_explain(glint, scene, mistake, frm, work, f"doc-{mistake}-all",
                                                 scene in TEXTURE_SCENES, all_samples=True)
    rec["explain_footprint"] = None
    if shown is not None and scene in TEXTURE_SCENES and shown["stage"] == "texture":
        # the same pixel with Glint's default --texture-level footprint
        frm = next(c[2] for c in cands if tuple(c[2]["pixel"]) == tuple(shown["pixel"])
                   and c[2]["sample"] == shown["sample"] and c[2]["spp"] == shown["spp"])
        rec["explain_footprint"] = try_explain(glint, scene, mistake, frm, work, f"doc-{mistake}-fp", False)
    rec["explain"] = shown
    rec["explain_stage"] = shown["stage"] if shown else None
    rec["explain_path"] = shown["path"] if shown else None
    rec["same_stage"] = (None if rec["grade_stage"] is None or shown is None
                         else rec["grade_stage"] == shown["stage"])
    q, note = correspond(rec["grade_field"], rec["explain_path"])
    rec["same_quantity"], rec["quantity_note"] = q, note
    return rec


# ----------------------------------------------------------------------------
# The table
# ----------------------------------------------------------------------------

def yn(v):
    return "—" if v is None else ("yes" if v else "**no**")


def row(rec):
    if rec["grade_stage"] is None:
        g = f"**nothing fails** at `--cases` {' and '.join(str(c) for c in rec['ladder'])} (" + ", ".join(
            f"{s} {p}/{a}" for s, (p, a) in rec["stage_counts"].items() if a) + " pass)"
        how = "—"
    else:
        p, a = rec["stage_counts"][rec["grade_stage"]]
        frm = rec["grade_from"]
        at = f", pixel {frm['pixel'][0]},{frm['pixel'][1]}" if frm else ", a chosen value (no pixel)"
        g = f"{rec['grade_stage']} ({a - p}/{a} fail): {rec['grade_case']}{at}, `{rec['grade_field']}`"
        if rec["cases"] != 64:
            g += f" (`--cases {rec['cases']}`; nothing fails at 64)"
        how = "yes" if rec["how_found"] else "no"
    tried = rec["explain_tried"]
    e = rec["explain"]
    if e is None:
        e_cell = f"**agrees** at {len(tried)} pixel(s) tried" if tried else "— (no pixel shows it)"
    else:
        where = f"pixel {e['pixel'][0]},{e['pixel'][1]} spp {e['spp']} sample {e['sample']}"
        if e["why"] != "first failing case":
            where += f", {e['case']}"
        if len(tried) > 1:
            where += f"; agreed at {len(tried) - 1} pixel(s) before"
        e_cell = f"{e['stage']}: `{e['path']}` ({where})"
        for key, label in (("explain_all_samples", "with `--all-samples`"),
                           ("explain_footprint", "without `--texture-level report`")):
            x = rec.get(key)
            if x is not None:
                e_cell += (f"; {label}: agrees" if x["agrees"] else f"; {label}: {x['stage']}: `{x['path']}`")
    q = rec["same_quantity"]
    if rec["quantity_note"] and q != "no":
        q = f"{q} ({rec['quantity_note']})"
    if q == "no":
        q = "**no**"
    return (f"| {rec['mistake']} | {rec['scene']} | {g} | {how} | {e_cell} | {yn(rec['same_stage'])} | {q} |")


def table(recs):
    lines = ["| mistake | scene | `grade --stages`: first failing stage, case, field | report shows how "
             "Glint's values were found? | `explain --against`: first stage, key path | same stage? | "
             "same quantity? |",
             "|---|---|---|---|---|---|---|"]
    lines += [row(r) for r in recs]
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--glint", help="the glint binary (default: target/release/glint, else target/debug/glint)")
    ap.add_argument("--json", metavar="FILE", help="also write the results as JSON")
    ap.add_argument("--only", nargs="+", metavar="NAME", help="only these mistakes")
    ap.add_argument("--workdir", help="keep the vectors, answers and documents here (default: a temporary folder)")
    ap.add_argument("--candidates", type=int, default=8,
                    help="pixels to try with explain before saying it agrees (default 8)")
    ap.add_argument("--cases", type=int, nargs="+", default=[64, 400], metavar="N",
                    help="cases per stage, tried in turn until a stage fails (default: 64 400)")
    args = ap.parse_args(argv)
    glint = find_glint(args.glint)
    if not os.path.isabs(glint):
        glint = os.path.abspath(glint)
    start = time.time()
    work = args.workdir or tempfile.mkdtemp(prefix="glint-mistakes-")
    os.makedirs(work, exist_ok=True)
    todo = [(m, s) for m, s in MISTAKES if not args.only or m in args.only]
    cache = {}
    recs = []
    for m, s in todo:
        t0 = time.time()
        rec = study(glint, m, s, work, cache, args.cases, args.candidates)
        rec["seconds"] = round(time.time() - t0, 2)
        recs.append(rec)
        print(f"{m}: {rec['seconds']} s", file=sys.stderr)
    elapsed = time.time() - start
    print(table(recs))
    print(f"\n{len(recs)} mistakes in {elapsed:.1f} s with {os.path.relpath(glint, REPO)}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"glint": glint, "seconds": round(elapsed, 1), "mistakes": recs}, f, indent=1)
            f.write("\n")
    if not args.workdir:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
