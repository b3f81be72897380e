#!/usr/bin/env python3
"""Measures how well tracer.py agrees with Glint, and how far each mistake is from it.

For each scene and setting it renders the tracer's image with several seeds
(PFM) and Glint's converged reference (a few seeds, so that the reference's
own noise is known), and compares them per 8x8 block and channel:

    z = (mean over tracer seeds - mean over reference seeds) / se,
    se^2 = var(tracer block means)/n + var(reference block means)/m

(variances over seeds, ddof 1). Unbiased renders give z ~ t-distributed
around 0; it reports the largest |z|, the mean |z|, the mean z^2 and the
share of |z| > 4, next to a null control: the same statistics for
Glint itself rendered at the same settings with as many seeds (the same
estimator, so the same distribution of z if the tracer is right: rare events,
such as a block's only lit samples, and the heavy tails of a variance taken
from few seeds included), and a z of the whole image's mean. Two more
views of the same images: the variance pooled over the tracer's and Glint's
seeds (equal under the null, and not fooled by a block whose rare lit samples
one set of seeds missed), and the tracer against Glint at the same settings
directly.

What the reference converges is only what the setting leaves random: a grid
pixel pattern (or grid light pattern) is deterministic and changes the
expected image (a pixel-centre render is not a box-filtered one), so the
reference uses the same grid for that part and converges the rest.

  agree.py                  # every scene, every setting, the grid check, all mistakes
  agree.py --quick          # fewer seeds, one scene
  agree.py --only correct|grid|mistakes

Requires a Glint binary (--glint, default /tmp/glint-corpus, a copy of
target/release/glint). Results go to stdout and, as JSON, to --json.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import tracer  # noqa: E402

REPO = os.path.dirname(os.path.dirname(HERE))
SCENES = [os.path.join(REPO, "scenes", f"cornell-set{k}.toml") for k in (1, 2, 3)]

# (name, spp, pixel sampler, light samples, light sampler)
SETTINGS = [
    ("1spp-random-1ls-random", 1, "random", 1, "random"),
    ("16spp-random-16ls-random", 16, "random", 16, "random"),
    ("16spp-stratified-16ls-stratified", 16, "stratified", 16, "stratified"),
    ("1spp-grid-16ls-random", 1, "grid", 16, "random"),
    ("16spp-grid-1ls-stratified", 16, "grid", 1, "stratified"),
    ("16spp-random-16ls-grid", 16, "random", 16, "grid"),
    ("1spp-stratified-16ls-grid", 1, "stratified", 16, "grid"),
]

BLOCK = 8


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"failed ({r.returncode}): {' '.join(cmd)}\n{r.stderr}")
    return r


class Work:
    def __init__(self, args):
        self.args = args
        self.dir = args.workdir
        os.makedirs(self.dir, exist_ok=True)
        self.tracer_seconds = 0.0

    def path(self, *parts):
        return os.path.join(self.dir, "-".join(str(p) for p in parts))

    def glint(self, scene, res, spp, sampler, ls, lsampler, seed, ext="pfm"):
        name = os.path.splitext(os.path.basename(scene))[0]
        out = self.path("glint", name, res, spp, sampler, ls, lsampler, seed) + "." + ext
        if not os.path.exists(out):
            run([self.args.glint, "render", scene, "-o", out, "--resolution", res, "--spp", str(spp),
                 "--sampler", sampler, "--light-samples", str(ls), "--light-sampler", lsampler, "--seed", str(seed)])
        return out

    def trace(self, scene, res, spp, sampler, ls, lsampler, seed, mistakes=(), ext="pfm"):
        name = os.path.splitext(os.path.basename(scene))[0]
        tag = "+".join(mistakes) or "correct"
        out = self.path("tracer", name, res, spp, sampler, ls, lsampler, tag, seed) + "." + ext
        if not os.path.exists(out):
            cmd = [sys.executable, os.path.join(HERE, "tracer.py"), scene, "-o", out, "--resolution", res,
                   "--spp", str(spp), "--sampler", sampler, "--light-samples", str(ls), "--light-sampler", lsampler,
                   "--seed", str(seed), "--jobs", str(self.args.jobs)]
            for m in mistakes:
                cmd += ["--mistake", m]
            t0 = time.perf_counter()
            run(cmd)
            self.tracer_seconds += time.perf_counter() - t0
        return out

    def reference(self, scene, res, spp, sampler, ls, lsampler):
        """Glint's expected image for a setting: the grid parts kept, the random
        parts converged (about `budget` samples per pixel, sobol), and a list of
        seeds' images (one if it is deterministic)."""
        budget = self.args.budget
        if sampler == "grid" and lsampler == "grid":
            return [read(self.glint(scene, res, spp, "grid", ls, "grid", 0))]
        if sampler == "grid":
            rspp, rs = spp, "grid"
            rls, rl = max(1, budget // spp), "sobol"
        elif lsampler == "grid":
            rls, rl = ls, "grid"
            rspp, rs = max(1, budget // ls), "sobol"
        else:
            rspp, rs = self.args.ref_spp, "sobol"
            rls, rl = max(1, budget // rspp), "sobol"
        return [read(self.glint(scene, res, rspp, rs, rls, rl, 1000 + k)) for k in range(self.args.ref_seeds)]


def read(path):
    return tracer.read_pfm(path)


def blocks(img):
    h, w, c = img.shape
    hb, wb = h // BLOCK, w // BLOCK
    return img[: hb * BLOCK, : wb * BLOCK].reshape(hb, BLOCK, wb, BLOCK, c).mean(axis=(1, 3))


def block_stats(imgs):
    """Per block and channel: the mean over seeds, and the variance of that
    mean (0 for a single image, taken as exact)."""
    b = np.stack([blocks(x) for x in imgs])
    var = b.var(0, ddof=1) / len(b) if len(b) > 1 else np.zeros(b.shape[1:])
    return b.mean(0), var, b


def z_from(diff, var):
    se = np.sqrt(var)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(se > 0, diff / se, np.where(np.abs(diff) <= 1e-5, 0.0, np.inf * np.sign(diff)))


def z_scores(a_imgs, b_imgs, floor=0.0):
    """Per block and channel: (mean a - mean b) / se, se from the spread over
    seeds (a list of one image counts as exact). `floor` adds a variance (for
    8-bit quantisation)."""
    ma, va, _ = block_stats(a_imgs)
    mb, vb, _ = block_stats(b_imgs)
    diff = ma - mb
    return z_from(diff, va + vb + floor), diff


def summary(z):
    az = np.abs(z).ravel()
    finite = az[np.isfinite(az)]
    return {
        "max_abs_z": float(az.max()),
        "median_abs_z": float(np.median(az)),
        "mean_abs_z": float(finite.mean()) if finite.size else float("inf"),
        "mean_z2": float((finite**2).mean()) if finite.size else float("inf"),
        "share_abs_z_gt_4": float((az > 4).mean()),
        "blocks": int(az.size),
    }


def fmt(s):
    return (f"max|z| {s['max_abs_z']:6.2f}  median|z| {s['median_abs_z']:5.3f}  mean|z| {s['mean_abs_z']:5.3f}  mean z² {s['mean_z2']:7.2f}  "
            f"|z|>4 {100 * s['share_abs_z_gt_4']:5.2f}%")


def global_z(a_imgs, b_imgs):
    """The whole image's mean: (mean a - mean b) / se, and mean a / mean b - 1."""
    a = np.array([x.mean() for x in a_imgs])
    b = np.array([x.mean() for x in b_imgs])
    var = (a.var(ddof=1) / len(a) if len(a) > 1 else 0) + (b.var(ddof=1) / len(b) if len(b) > 1 else 0)
    diff = a.mean() - b.mean()
    z = diff / np.sqrt(var) if var > 0 else (0.0 if abs(diff) < 1e-7 else float("inf"))
    return float(z), float(a.mean() / b.mean() - 1)


def correct(work: Work, scenes, out):
    """The tracer against the reference, and, as the null it should match,
    Glint itself at the same settings (the same estimator, so the same
    distribution of z, rare events and heavy tails included) against the same
    reference."""
    a = work.args
    res = a.resolution
    results = []
    for scene in scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        for label, spp, smp, ls, lsmp in SETTINGS:
            n = a.seeds
            imgs = [read(work.trace(scene, res, spp, smp, ls, lsmp, s)) for s in range(n)]
            same = [read(work.glint(scene, res, spp, smp, ls, lsmp, 2000 + s)) for s in range(n)]
            ref = work.reference(scene, res, spp, smp, ls, lsmp)
            z, _ = z_scores(imgs, ref)
            s = summary(z)
            zc, _ = z_scores(same, ref)
            c = summary(zc)
            # The variance of a block's mean over n seeds is the same for the
            # tracer and for Glint at the same settings if the tracer is right:
            # pooled over both (2n seeds), it is not fooled by a block whose
            # rare events (a few lit samples) one set of n seeds happens to miss.
            mt, vt, _ = block_stats(imgs)
            mg, vg, _ = block_stats(same)
            mr, vr, _ = block_stats(ref)
            pooled = (vt + vg) / 2
            zp = summary(z_from(mt - mr, pooled + vr))
            zpc = summary(z_from(mg - mr, pooled + vr))
            # The tracer against Glint at the same settings, directly.
            z2 = summary(z_from(mt - mg, vt + vg))
            zg, ratio = global_z(imgs, ref)
            zgc, ratio_c = global_z(same, ref)
            row = {"scene": name, "setting": label, "seeds": n, "ref_seeds": len(ref), "tracer": s,
                   "glint_same_settings": c, "tracer_pooled": zp, "glint_pooled": zpc, "tracer_vs_glint_same": z2,
                   "global_z": zg, "mean_ratio_minus_1": ratio, "glint_global_z": zgc, "glint_mean_ratio_minus_1": ratio_c}
            results.append(row)
            print(f"{name} {label}\n"
                  f"   tracer vs ref, own variance:    {fmt(s)}   global z {zg:+5.2f} (mean {ratio:+.1e})\n"
                  f"   Glint  vs ref, own variance:    {fmt(c)}   global z {zgc:+5.2f} (mean {ratio_c:+.1e})\n"
                  f"   tracer vs ref, pooled variance: {fmt(zp)}\n"
                  f"   Glint  vs ref, pooled variance: {fmt(zpc)}\n"
                  f"   tracer vs Glint, same settings: {fmt(z2)}", flush=True)
    out["correct"] = results


def grid_check(work: Work, scenes, out):
    res = work.args.resolution
    results = []
    for scene in scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        t_pfm = read(work.trace(scene, res, 1, "grid", 16, "grid", 0))
        g_pfm = read(work.glint(scene, res, 1, "grid", 16, "grid", 0))
        t_png = tracer.read_png(work.trace(scene, res, 1, "grid", 16, "grid", 0, ext="png"))
        g_png = tracer.read_png(work.glint(scene, res, 1, "grid", 16, "grid", 0, ext="png"))
        d = np.abs(t_pfm - g_pfm)
        d8 = np.abs(t_png.astype(int) - g_png.astype(int))
        row = {"scene": name, "max_abs_linear": float(d.max()), "max_rel_linear": float((d / np.maximum(np.abs(g_pfm), 1e-3)).max()),
               "png_values_differing": int((d8 > 0).sum()), "png_pixels_differing": int((d8.max(2) > 0).sum()),
               "png_max_difference": int(d8.max()), "pixels": int(d8.shape[0] * d8.shape[1])}
        results.append(row)
        print(f"{name} grid 1spp x grid 16ls: max |linear diff| {row['max_abs_linear']:.2e} (rel {row['max_rel_linear']:.1e}); "
              f"8-bit: {row['png_pixels_differing']} of {row['pixels']} pixels differ, by at most {row['png_max_difference']}", flush=True)
    out["grid"] = results


def mistakes(work: Work, scenes, out):
    """Each mistake against Glint's reference, in 8-bit codes (what a PNG
    holds: the primary "does it visibly differ" measure) and, for the
    mistakes that are not in the encoding, in linear values. The correct
    tracer, rendered the same way, is the control."""
    a = work.args
    res = a.mistake_resolution
    spp, smp, ls, lsmp = 16, "stratified", 16, "stratified"
    results = []
    names = a.mistake_list or list(tracer.MISTAKES)
    for scene in scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        ref = work.reference(scene, res, spp, smp, ls, lsmp)
        ref_mean = np.mean(ref, axis=0)
        # 8-bit codes of the reference, before rounding.
        ref_codes = [srgb_code(r) for r in ref]
        ref_code_mean = np.mean(ref_codes, axis=0)
        for m in ["(correct)"] + names:
            mm = () if m == "(correct)" else (m,)
            n = a.mistake_seeds
            row = {"scene": name, "mistake": m}
            if m in tracer.ENCODING_MISTAKES:
                films = None
                codes = [tracer.read_png(work.trace(scene, res, spp, smp, ls, lsmp, s, mm, ext="png")).astype(float)
                         for s in range(n)]
            else:
                films = [read(work.trace(scene, res, spp, smp, ls, lsmp, s, mm)) for s in range(n)]
                codes = [tracer.encode_8bit(f, set()).astype(float) for f in films]
            # Rounding to 8 bits: up to half a code per block even without noise.
            z8, _ = z_scores(codes, ref_codes, floor=1 / 12)
            d8 = np.mean(codes, axis=0) - ref_code_mean
            row["codes"] = {**summary(z8), "mean_code_diff": float(d8.mean()), "mean_abs_code_diff": float(np.abs(d8).mean()),
                            "pixels_off_by_2_or_more": float((np.abs(d8).max(axis=2) >= 2).mean())}
            line = (f"{name} {m:24s} 8-bit  {fmt(row['codes'])}  code diff {row['codes']['mean_code_diff']:+7.3f} "
                    f"(mean |.| {row['codes']['mean_abs_code_diff']:6.3f}, {100 * row['codes']['pixels_off_by_2_or_more']:5.1f}% px >= 2)")
            if films is not None:
                nonfinite = int(sum((~np.isfinite(f)).any(axis=2).sum() for f in films))
                films = [np.clip(np.nan_to_num(f, nan=0.0, posinf=1e3, neginf=-1e3), -1e3, 1e3) for f in films]
                z, _ = z_scores(films, ref)
                mad = float(np.mean(np.abs(np.mean(films, axis=0) - ref_mean)))
                # Correlation of neighbouring pixels' errors (each seed's image
                # minus the reference): about 0 for independent pixels.
                res_ = [f - ref_mean for f in films]
                num = sum(float((r[:, 1:] * r[:, :-1]).sum()) for r in res_)
                den = sum(float((r * r).sum()) for r in res_)
                neighbour = num / den if den > 0 else 0.0
                row["linear"] = {**summary(z), "mean_abs_diff": mad, "mean_abs_diff_rel": mad / float(np.mean(np.abs(ref_mean))),
                                 "nonfinite_pixels": nonfinite, "neighbour_error_correlation": neighbour}
                line += (f"\n{'':34s} linear {fmt(row['linear'])}  mean|diff| {mad:.4f} "
                         f"({100 * row['linear']['mean_abs_diff_rel']:.1f}% of the mean), neighbour corr. {neighbour:+.3f}"
                         + (f", {nonfinite} non-finite pixels (as 1e3)" if nonfinite else ""))
            results.append(row)
            print(line, flush=True)
    out["mistakes"] = results


def srgb_code(img):
    c = np.clip(img, 0, 1)
    return 255 * np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1 / 2.4) - 0.055)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--glint", default="/tmp/glint-corpus")
    ap.add_argument("--workdir", default="/tmp/corpus-agree")
    ap.add_argument("--scenes", nargs="*", default=SCENES)
    ap.add_argument("--resolution", default="128x128")
    ap.add_argument("--seeds", type=int, default=16, help="tracer seeds per setting")
    ap.add_argument("--ref-seeds", type=int, default=4, help="Glint reference seeds")
    ap.add_argument("--ref-spp", type=int, default=1024, help="reference spp where the pixel pattern is random")
    ap.add_argument("--budget", type=int, default=65536, help="reference samples per pixel (spp x light samples)")
    ap.add_argument("--mistake-resolution", default="160x120", help="non-square, so that horizontal-fov shows")
    ap.add_argument("--mistake-seeds", type=int, default=4)
    ap.add_argument("--mistake-list", nargs="*")
    ap.add_argument("--only", choices=["correct", "grid", "mistakes"], action="append")
    ap.add_argument("--quick", action="store_true", help="one scene, 6 seeds, 2 reference seeds")
    ap.add_argument("--jobs", type=int, default=1, help="tracer worker processes per render")
    ap.add_argument("--json", default=None, help="write the results here as JSON")
    args = ap.parse_args()
    if args.quick:
        args.scenes, args.seeds, args.ref_seeds, args.mistake_seeds = args.scenes[:1], 6, 2, 2
    work = Work(args)
    out = {"date": time.strftime("%Y-%m-%d"), "resolution": args.resolution, "seeds": args.seeds,
           "ref_seeds": args.ref_seeds, "budget": args.budget}
    t0 = time.perf_counter()
    only = set(args.only or ["correct", "grid", "mistakes"])
    if "grid" in only:
        grid_check(work, args.scenes, out)
    if "correct" in only:
        correct(work, args.scenes, out)
    if "mistakes" in only:
        mistakes(work, args.scenes, out)
    out["seconds"] = time.perf_counter() - t0
    out["tracer_seconds"] = work.tracer_seconds
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)
    print(f"done in {out['seconds']:.0f} s (tracer {work.tracer_seconds:.0f} s)")


if __name__ == "__main__":
    main()
