"""The `explain` command: this tracer's glint-explain/1 document for one pixel
(checking-your-ray-tracer.md), its camera samples traced on the grid.
"""

import json
import math

from .film import srgb8
from .integrator import Tracer
from .mistake import mistake
from .scene import Scene, epsilon_of
from .vectors import ZERO, add, mul, normalize, sub


def clean(x):
    """JSON-ready: tuples to lists, non-finite to null."""
    if isinstance(x, dict):
        return {k: clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [clean(v) for v in x]
    if isinstance(x, float):
        return x if math.isfinite(x) else None
    return x


def cmd_explain(args):
    scene = Scene(args.scene)
    spp = args.spp if args.spp is not None else scene.spp
    ls = args.light_samples if args.light_samples is not None else scene.light_samples
    if args.sampler != "grid" or args.light_sampler != "grid":
        raise SystemExit("only the grid patterns are reproducible: pass --sampler grid --light-sampler grid")
    k = int(round(math.sqrt(spp)))
    if k * k != spp:
        raise SystemExit("--sampler grid needs a perfect square spp")
    X, Y = (int(v) for v in args.pixel.split(","))
    tracer = Tracer(scene, ls, epsilon_of(scene, args), args.environment_samples, args.texture_level)
    cam = scene.camera
    s_shrink = max(1 / math.sqrt(spp), 1 / 8)
    follow = range(spp) if args.all_samples else [args.sample]
    samples = []
    total = ZERO
    for i in range(spp):
        x = X + ((i % k) + 0.5) / k  # step 1, grid
        y = Y + ((i // k) + 0.5) / k
        if mistake("pixel-corner"):
            # MISTAKE pixel-corner: the cell's corner, (i mod k)/k, without the + 1/2
            x, y = X + (i % k) / k, Y + (i // k) / k
        ndc, fp = cam.film_point(x, y)
        d = normalize(fp)
        camrec = {"raster": (x, y), "ndc": ndc, "film_point": fp, "origin": cam.eye, "direction": d}
        rd = None
        if tracer.needs_footprint:
            dx = cam.ray(x + 1, y)[1]
            dy = cam.ray(x, y + 1)[1]
            rxd = add(d, mul(sub(dx, d), s_shrink))
            ryd = add(d, mul(sub(dy, d), s_shrink))
            rd = ((cam.eye, rxd), (cam.eye, ryd))
            camrec["differentials"] = {"rx_origin": cam.eye, "rx_direction": rxd, "ry_origin": cam.eye,
                                       "ry_direction": ryd}
        else:
            camrec["differentials"] = None
        rad, rec = tracer.trace(cam.eye, d, 0, rd)
        if all(math.isfinite(c) for c in rad):
            total = add(total, rad)
        if i in follow:
            samples.append({"sample": i, "camera": camrec, "ray": rec, "radiance": rad})
    pix = mul(total, 1 / spp)
    # checking-your-ray-tracer.md, "Settings first": the document records the
    # settings it was made with (spp, sampler, light_samples, light_sampler,
    # environment_samples, texture_level, seed), which --against checks before
    # any number.  --texture-level footprint (Glint's default) reads image
    # textures at the level of the ray differentials' footprint; report reads
    # them trilinearly at the report's log2(L/W) at camera rays' hits.
    doc = {"schema": "glint-explain/1", "pixel": [X, Y], "resolution": [scene.width, scene.height], "spp": spp,
           "sampler": args.sampler, "light_samples": ls, "light_sampler": args.light_sampler,
           "environment_samples": args.environment_samples, "texture_level": args.texture_level, "seed": scene.seed,
           "samples": samples,
           "film": {"radiance": pix, "samples_averaged": spp, "srgb8": [srgb8(c) for c in pix]}}
    text = json.dumps(clean(doc), indent=1)
    if args.output == "-":
        print(text)
    else:
        with open(args.output, "w") as f:
            f.write(text + "\n")
