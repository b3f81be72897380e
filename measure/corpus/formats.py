#!/usr/bin/env python3
"""Saves a render the ways students' ray tracers save images: with Pillow
(libjpeg-turbo, libpng), OpenCV, OpenEXR's Python bindings, stb_image_write
(what most C++ course frameworks call; compiled from Debian's libstb-dev), and
by hand where those write no such file (a 16-bit TGA, PPMs of other maxvals).

    formats.py IN.pfm OUTDIR [--only NAME ...]     # every variant of IN
    formats.py --list                              # the variants

IN is a linear render (PFM, as tracer.py or glint write it); the 8-bit variants
start from its 8-bit sRGB encoding (`tracer.encode_8bit`), the float ones from
the floats. measure_formats.py builds its corpus with `write_variant`.
"""

import argparse
import os
import struct
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import tracer  # noqa: E402


@dataclass(frozen=True)
class Variant:
    name: str
    ext: str
    what: str
    # Takes the linear film (H, W, 3; None where only 8-bit data exists), its
    # 8-bit sRGB codes and the output path.
    write: Callable
    # "float" variants need the linear film; "8-bit" ones only the codes.
    needs: str = "8-bit"
    # What the grader should make of a correct render: "graded" or "unreadable".
    expect: str = "graded"
    # In the grading corpus (colour scenes), or only among the test files.
    corpus: bool = True


def srgb16(film):
    """The exact sRGB curve at 16 bits, rounded: a tracer writing 16 bits itself."""
    c = np.clip(np.nan_to_num(film, nan=0.0), 0.0, 1.0)
    e = np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1 / 2.4) - 0.055)
    return np.floor(e * 65535.0 + 0.5).astype(np.uint16)


def srgb_levels(film, maxval):
    c = np.clip(np.nan_to_num(film, nan=0.0), 0.0, 1.0)
    e = np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1 / 2.4) - 0.055)
    return np.floor(e * maxval + 0.5).astype(np.uint32)


def pil(rgb8):
    from PIL import Image
    return Image.fromarray(np.ascontiguousarray(rgb8, dtype=np.uint8))


def cv2_write(path, image, params=()):
    os.environ.setdefault("OPENCV_IO_MAX_IMAGE_PIXELS", str(1 << 40))
    import cv2
    if image.ndim == 3:
        image = image[..., ::-1]  # OpenCV stores BGR
    if not cv2.imwrite(str(path), np.ascontiguousarray(image), list(params)):
        raise RuntimeError(f"OpenCV could not write {path}")


def stb(kind, rgb8_or_film, path, quality=None):
    """stb_image_write through measure/corpus/stb_write.c (compiled once)."""
    exe = Path(os.environ.get("STB_WRITE", "/tmp/glint-stb-write"))
    if not exe.exists():
        subprocess.run(["gcc", "-O2", "-o", str(exe), str(HERE / "stb_write.c"), "-lm"], check=True)
    tmp = Path(str(path) + (".in.pfm" if kind == "hdr" else ".in.ppm"))
    if kind == "hdr":
        tracer.write_pfm(str(tmp), rgb8_or_film)
    else:
        tracer.write_ppm(str(tmp), rgb8_or_film, False)
    try:
        cmd = [str(exe), kind, str(tmp), str(path)] + ([str(quality)] if quality else [])
        subprocess.run(cmd, check=True, capture_output=True)
    finally:
        tmp.unlink()


def png_with_chunks(rgb8, path):
    """gAMA (1/2.2), sRGB (perceptual) and an sRGB ICC profile, as photo
    software writes them."""
    from PIL import ImageCms, PngImagePlugin
    info = PngImagePlugin.PngInfo()
    info.add(b"gAMA", struct.pack(">I", 45455))
    info.add(b"sRGB", b"\x00")
    profile = ImageCms.ImageCmsProfile(ImageCms.createProfile("sRGB")).tobytes()
    pil(rgb8).save(path, pnginfo=info, icc_profile=profile)


def png_palette(rgb8, path):
    from PIL import Image
    pil(rgb8).quantize(256, method=Image.Quantize.MEDIANCUT).save(path)


def gray(rgb8):
    """Rec. 601 luma of 8-bit codes, as Pillow's convert("L") computes it."""
    return pil(rgb8).convert("L")


def png_translucent(rgb8, path):
    """RGBA whose left half is half transparent: alpha as coverage."""
    from PIL import Image
    alpha = np.full(rgb8.shape[:2] + (1,), 255, np.uint8)
    alpha[:, : rgb8.shape[1] // 2] = 128
    Image.fromarray(np.concatenate([rgb8, alpha], axis=2)).save(path)


def pgm(rgb8, path, ascii_):
    g = np.asarray(gray(rgb8))
    h, w = g.shape
    with open(path, "wb") as f:
        f.write(f"{'P2' if ascii_ else 'P5'}\n{w} {h}\n255\n".encode())
        if ascii_:
            for y in range(h):
                f.write((" ".join(map(str, g[y].tolist())) + "\n").encode())
        else:
            f.write(g.tobytes())


def png_rgba(rgb8, path):
    alpha = np.full(rgb8.shape[:2] + (1,), 255, np.uint8)
    from PIL import Image
    Image.fromarray(np.concatenate([rgb8, alpha], axis=2)).save(path)


def ppm(codes, maxval, path, ascii_):
    h, w, _ = codes.shape
    with open(path, "wb") as f:
        f.write(f"{'P3' if ascii_ else 'P6'}\n# written by formats.py\n{w} {h}\n{maxval}\n".encode())
        if ascii_:
            for y in range(h):
                f.write((" ".join(map(str, codes[y].ravel().tolist())) + "\n").encode())
        elif maxval > 255:
            f.write(codes.astype(">u2").tobytes())
        else:
            f.write(codes.astype(np.uint8).tobytes())


def tga16(rgb8, path):
    """A 16-bit (5-5-5) uncompressed TGA, bottom row first, as old tools write it."""
    h, w, _ = rgb8.shape
    five = (rgb8.astype(np.uint32) * 31 + 127) // 255
    word = (five[..., 0] << 10) | (five[..., 1] << 5) | five[..., 2]
    with open(path, "wb") as f:
        f.write(struct.pack("<BBBHHBHHHHBB", 0, 0, 2, 0, 0, 0, 0, 0, w, h, 16, 0))
        f.write(word[::-1].astype("<u2").tobytes())


def hdr_flat(film, path):
    """Radiance RGBE with flat (uncompressed) scanlines, each pixel as
    Radiance's float2rgbe makes it: mantissas truncated to 8 bits of the
    largest channel's power of two."""
    film = np.clip(np.nan_to_num(film.astype(np.float64), nan=0.0), 0.0, None)
    h, w, _ = film.shape
    top = film.max(axis=2)
    mantissa, exponent = np.frexp(top)
    scale = np.where(top > 1e-32, mantissa * 256.0 / np.where(top > 0, top, 1), 0.0)
    rgbe = np.zeros((h, w, 4), np.uint8)
    rgbe[..., :3] = np.floor(film * scale[..., None]).clip(0, 255)
    rgbe[..., 3] = np.where(top > 1e-32, exponent + 128, 0)
    with open(path, "wb") as f:
        f.write(f"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {h} +X {w}\n".encode())
        f.write(rgbe.tobytes())


def exr(film, path, half):
    import OpenEXR
    data = np.ascontiguousarray(film.astype(np.float16 if half else np.float32))
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    channels = {"RGB": data}
    with OpenEXR.File(header, channels) as f:
        f.write(str(path))


def jpeg(rgb8, path, quality, subsampling, progressive=False):
    pil(rgb8).save(path, quality=quality, subsampling=subsampling, progressive=progressive)


VARIANTS = [
    Variant("png", "png", "8-bit PNG (the tracer's own writer)", lambda f, c, p: tracer.write_png(str(p), c)),
    Variant("png16-of-8bit", "png", "16-bit PNG of 8-bit codes × 257 (OpenCV)",
            lambda f, c, p: cv2_write(p, c.astype(np.uint16) * 257)),
    Variant("png16", "png", "16-bit PNG from floats (OpenCV)", lambda f, c, p: cv2_write(p, srgb16(f)), needs="float"),
    Variant("png-rgba", "png", "8-bit RGBA PNG, opaque (Pillow)", lambda f, c, p: png_rgba(c, p)),
    Variant("png-chunks", "png", "8-bit PNG with gAMA, sRGB and iCCP (Pillow)", lambda f, c, p: png_with_chunks(c, p)),
    Variant("png-stb", "png", "8-bit PNG (stb_image_write)", lambda f, c, p: stb("png", c, p)),
    Variant("png-palette", "png", "256-colour palette PNG (Pillow, median cut)",
            lambda f, c, p: png_palette(c, p), expect="unreadable"),
    Variant("ppm-p6", "ppm", "binary PPM (the tracer's own writer)", lambda f, c, p: tracer.write_ppm(str(p), c, False)),
    Variant("ppm-p3", "ppm", "ASCII PPM (the tracer's own writer)", lambda f, c, p: tracer.write_ppm(str(p), c, True)),
    Variant("ppm-65535-of-8bit", "ppm", "binary PPM, maxval 65535, of 8-bit codes × 257",
            lambda f, c, p: ppm(c.astype(np.uint32) * 257, 65535, p, False)),
    Variant("ppm-1023", "ppm", "ASCII PPM, maxval 1023, from floats",
            lambda f, c, p: ppm(srgb_levels(f, 1023), 1023, p, True), needs="float"),
    Variant("bmp", "bmp", "24-bit BMP (Pillow)", lambda f, c, p: pil(c).save(p)),
    Variant("bmp-stb", "bmp", "24-bit BMP (stb_image_write)", lambda f, c, p: stb("bmp", c, p)),
    Variant("tga", "tga", "24-bit TGA (Pillow)", lambda f, c, p: pil(c).save(p, compression=None)),
    Variant("tga-rle", "tga", "24-bit RLE TGA (Pillow)", lambda f, c, p: pil(c).save(p, compression="tga_rle")),
    Variant("tga-stb", "tga", "24-bit RLE TGA (stb_image_write)", lambda f, c, p: stb("tga", c, p)),
    Variant("tga16", "tga", "16-bit (5-5-5) TGA", lambda f, c, p: tga16(c, p)),
    *[Variant(f"jpeg-q{q}-{name}", "jpg", f"JPEG quality {q}, {name[0]}:{name[1]}:{name[2]} (Pillow)",
              lambda f, c, p, q=q, s=s: jpeg(c, p, q, s))
      for q in (75, 85, 95, 100) for s, name in ((2, "420"), (0, "444"))],
    Variant("jpeg-q85-progressive", "jpg", "progressive JPEG quality 85, 4:2:0 (Pillow)",
            lambda f, c, p: jpeg(c, p, 85, 2, progressive=True)),
    Variant("jpeg-stb", "jpg", "JPEG quality 90 (stb_image_write)", lambda f, c, p: stb("jpg", c, p, 90)),
    Variant("jpeg-q50-420", "jpg", "JPEG quality 50, 4:2:0 (Pillow)", lambda f, c, p: jpeg(c, p, 50, 2)),
    Variant("jpeg-q30-420", "jpg", "JPEG quality 30, 4:2:0 (Pillow)", lambda f, c, p: jpeg(c, p, 30, 2),
            expect="unreadable"),
    Variant("hdr-stb", "hdr", "Radiance HDR, RLE (stb_image_write)", lambda f, c, p: stb("hdr", f, p), needs="float"),
    Variant("hdr-flat", "hdr", "Radiance HDR, flat scanlines (by hand)", lambda f, c, p: hdr_flat(f, p), needs="float"),
    Variant("hdr-cv", "pic", "Radiance HDR, RLE, named .pic (OpenCV)",
            lambda f, c, p: cv2_write(p, f.astype(np.float32)), needs="float"),
    Variant("exr-half", "exr", "OpenEXR, half (OpenEXR)", lambda f, c, p: exr(f, p, True), needs="float"),
    Variant("exr-float", "exr", "OpenEXR, float (OpenEXR)", lambda f, c, p: exr(f, p, False), needs="float"),
    Variant("pfm", "pfm", "PFM (the tracer's own writer)", lambda f, c, p: tracer.write_pfm(str(p), f), needs="float"),
    # Only among the test files: a colour scene's render is never gray, and
    # translucency is reported, not graded.
    Variant("png-gray", "png", "8-bit gray PNG (Pillow)", lambda f, c, p: gray(c).save(p), corpus=False),
    Variant("png-translucent", "png", "8-bit RGBA PNG, left half alpha 128 (Pillow)",
            lambda f, c, p: png_translucent(c, p), corpus=False),
    Variant("pgm-p5", "pgm", "binary PGM", lambda f, c, p: pgm(c, p, False), corpus=False),
    Variant("pgm-p2", "pgm", "ASCII PGM", lambda f, c, p: pgm(c, p, True), corpus=False),
    Variant("jpeg-gray", "jpg", "gray JPEG quality 90 (Pillow)", lambda f, c, p: gray(c).save(p, quality=90),
            corpus=False),
]
BY_NAME = {v.name: v for v in VARIANTS}


def write_variant(variant, film, codes, path):
    """Writes `variant` of a render to `path`: `film` linear (None if only the
    8-bit codes exist), `codes` its 8-bit sRGB encoding."""
    if variant.needs == "float" and film is None:
        raise ValueError(f"{variant.name} needs the render's floats")
    path.parent.mkdir(parents=True, exist_ok=True)
    variant.write(film, codes, path)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("input", nargs="?")
    ap.add_argument("outdir", nargs="?")
    ap.add_argument("--only", nargs="*")
    ap.add_argument("--list", action="store_true")
    args = ap.parse_args()
    if args.list:
        for v in VARIANTS:
            print(f"{v.name:24} .{v.ext:4} {v.what}")
        return
    if not args.input or not args.outdir:
        ap.error("give IN.pfm and OUTDIR")
    film = tracer.read_pfm(args.input)
    codes = tracer.encode_8bit(film, ())
    stem = Path(args.input).stem
    for v in VARIANTS:
        if args.only and v.name not in args.only:
            continue
        write_variant(v, film, codes, Path(args.outdir) / f"{stem}-{v.name}.{v.ext}")


if __name__ == "__main__":
    main()
