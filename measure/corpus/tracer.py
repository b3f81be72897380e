#!/usr/bin/env python3
"""A small, independent ray tracer for Glint's course Cornell scenes.

It reads Glint's TOML scene files itself (the subset the course's scenes use),
renders the course's direct lighting (Phong, area and point lights, shadows,
ambient, checkerboard textures) with numpy, vectorised over camera samples and
light samples, and writes PNG / PPM (8-bit sRGB) or PFM (linear float).

Its correct output has the same expected value as `glint render`; switches
(`--mistake NAME`) reproduce classic student mistakes, to make a corpus of
"student submissions" for `glint grade`. See README.md next to this file for
the conventions and where each comes from in Glint.

This file is the command line; the tracer reads by its stages, each module
importing only those before it:

    mistakes.py      the catalogue of mistakes
    scene_file.py    reading the scene file
    sampling.py      the render's options and the sample patterns
    camera.py        pixel samples and camera rays
    intersect.py     ray queries: closest hit, shadow rays
    shading.py       textures, materials, lights: what a camera ray sees
    render.py        the image, chunk by chunk of pixels
    image_files.py   8-bit encoding, PNG / PPM / PFM

The names other scripts use (read_pfm, read_png, encode_8bit, the writers,
MISTAKES, ENCODING_MISTAKES, ...) are importable from here.

Python 3.11+ and numpy only.
"""

from __future__ import annotations

import argparse
import os
import sys

from image_files import encode_8bit, read_pfm, read_png, srgb8_to_linear, write_pfm, write_png, write_ppm
from mistakes import ENCODING_MISTAKES, MISTAKES
from render import keep_freed_memory, render
from sampling import Options, square_root
from scene_file import InputError, Scene, load_scene

__all__ = [
    "ENCODING_MISTAKES", "EXIT_BAD_INPUT", "MISTAKES", "InputError", "Options", "Scene",
    "encode_8bit", "load_scene", "main", "read_pfm", "read_png", "render", "square_root",
    "srgb8_to_linear", "write_pfm", "write_png", "write_ppm",
]

EXIT_BAD_INPUT = 2


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        description="Render a Glint course scene (Cornell box subset) with an independent numpy ray tracer.")
    ap.add_argument("scene", nargs="?", help="Glint scene file (TOML)")
    ap.add_argument("-o", "--output", help="output image: .png, .ppm (8-bit sRGB) or .pfm (linear float)")
    ap.add_argument("--resolution", help="WxH (default: the scene's [render] resolution, else 512x512)")
    ap.add_argument("--spp", type=int, help="camera samples per pixel (default: the scene's, else 16)")
    ap.add_argument("--sampler", choices=["random", "stratified", "grid"],
                    help="pixel sample pattern (default: the scene's; its sobol becomes stratified, or random for a non-square count)")
    ap.add_argument("--light-samples", type=int, help="samples per area light per camera sample (default: the scene's, else 16)")
    ap.add_argument("--light-sampler", choices=["random", "stratified", "grid"], help="light sample pattern (default as --sampler)")
    ap.add_argument("--seed", type=int, help="RNG seed (default: the scene's, else 0)")
    ap.add_argument("--mistake", action="append", default=[], metavar="NAME", help="a student mistake to make (repeatable; see --list-mistakes)")
    ap.add_argument("--ppm-ascii", action="store_true", help="write PPM as P3 (text) instead of P6")
    ap.add_argument("--list-mistakes", action="store_true", help="list the mistakes and exit")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="worker processes (default: one per CPU); the image does not depend on it")
    args = ap.parse_args(argv)

    if args.list_mistakes:
        width = max(map(len, MISTAKES))
        for name, text in MISTAKES.items():
            print(f"{name:<{width}}  {text}")
        return 0
    try:
        if not args.scene or not args.output:
            raise InputError("a scene and -o OUT are required")
        ext = os.path.splitext(args.output)[1].lower()
        if ext not in (".png", ".ppm", ".pfm"):
            raise InputError(f"{args.output}: unknown output format; expected .png, .ppm or .pfm")
        for name in args.mistake:
            if name not in MISTAKES:
                raise InputError(f"--mistake {name}: unknown (see --list-mistakes)")
        if ext == ".pfm" and ENCODING_MISTAKES & set(args.mistake):
            raise InputError(f"--mistake {sorted(ENCODING_MISTAKES & set(args.mistake))[0]} changes only the 8-bit encoding: write .png or .ppm")
        scene = load_scene(args.scene)
        rs = scene.render
        if args.resolution:
            try:
                w, h = (int(x) for x in args.resolution.lower().split("x"))
                assert 1 <= w <= 16384 and 1 <= h <= 16384
            except (ValueError, AssertionError):
                raise InputError(f"--resolution {args.resolution}: expected WxH, each 1 to 16384")
        else:
            w, h = rs.get("resolution", (512, 512))
        spp = args.spp if args.spp is not None else rs.get("spp", 16)
        ls = args.light_samples if args.light_samples is not None else rs.get("light_samples", 16)
        for flag, value in (("--spp", spp), ("--light-samples", ls)):
            if value < 1:
                raise InputError(f"{flag} {value}: expected at least 1")

        def pattern(given, key, count):
            if given:
                return given
            p = rs.get(key, "sobol")
            if p == "sobol":
                p = "stratified" if square_root(count) else "random"
                print(f"note: the scene's {key} is sobol, which this tracer lacks; using {p}", file=sys.stderr)
            return p

        sampler = pattern(args.sampler, "pixel_sampler", spp)
        light_sampler = pattern(args.light_sampler, "light_sampler", ls)
        for flag, p, count in (("--sampler", sampler, spp), ("--light-sampler", light_sampler, ls)):
            if p in ("grid", "stratified") and not square_root(count):
                raise InputError(f"{flag} {p} needs a perfect-square count (1, 4, 9, 16, ...), got {count}")
        seed = args.seed if args.seed is not None else rs.get("seed", 0)
        if seed < 0:
            raise InputError("--seed: expected an integer >= 0")
        opts = Options(w, h, spp, sampler, ls, light_sampler, seed, frozenset(args.mistake))
        keep_freed_memory()
        film = render(scene, opts, max(1, args.jobs))
    except InputError as e:
        print(f"error: {e}", file=sys.stderr)
        return EXIT_BAD_INPUT
    if ext == ".pfm":
        write_pfm(args.output, film)
    else:
        rgb8 = encode_8bit(film, opts.mistakes)
        if ext == ".png":
            write_png(args.output, rgb8)
        else:
            write_ppm(args.output, rgb8, args.ppm_ascii)
    return 0


if __name__ == "__main__":
    sys.exit(main())
