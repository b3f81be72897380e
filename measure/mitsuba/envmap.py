"""Glint's lat-long environment lighting against Mitsuba 3's, on a diffuse sphere.

A white diffuse sphere (reflectance 0.5) alone under a lat-long HDR map, seen
from 4 units away: Glint (``target/release/glint render``) and Mitsuba 3
(``direct`` integrator, ``envmap`` emitter, variant ``scalar_rgb``) each render
it, and the script prints the ratio of their means over a disc inside the
sphere's outline, per colour channel.

The two renderers place a lat-long map's rows at different latitudes. Glint
centres row ``j`` of ``H`` in its band, at ``θ = (j + ½)·π/H`` (as pbrt-v3 does);
Mitsuba puts the first and last rows on the poles, row ``j`` at
``θ = j·π/(H − 1)``, stretching the map away from the equator by ``H/(H − 1)``.
Both centre column ``i`` of ``W`` at ``u = (i + ½)/W``. So the script renders
Mitsuba twice: with the map as it is, and with the map resampled onto Mitsuba's
rows (Glint's bilinear reading of the map, pole continuation included,
evaluated at ``θ = j·π/(H − 1)``), which gives both renderers one radiance
function. Mitsuba's ``u = 0`` looks down −z where Glint's ``u = ½`` does: the
envmap is turned 180° about y to match.

Both renderers read one scene file: Mitsuba renders what ``glint export --mitsuba``
writes for it (4 times Glint's samples per pixel), with the envmap's file
replaced by the map as it is, or resampled onto Mitsuba's rows as above. (The
export's own map, a ``W × (2H + 1)`` image whose bilinear interpolation is
exactly Glint's radiance, is not used here: the point is the two row layouts.)

    path/to/venv/bin/python measure/mitsuba/envmap.py MAP.hdr [MAP.hdr ...] [--spp N]

Needs the ``mitsuba`` package (numpy is not needed) and a release build of
Glint (``cargo build --release -p glint-cli``). docs/environment-lighting.md
gives the measured table.
"""

import argparse
import math
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
RESOLUTION = 128
DISC_RADIUS = 40  # pixels: well inside the sphere's outline (about 45)

GLINT_SCENE = """\
[camera]
position = [0, 0, 4]
look_at = [0, 0, 0]
fov = 40

[render]
resolution = [{res}, {res}]
spp = {spp}
environment_samples = 64
max_depth = 1
seed = {seed}

[environment]
latlong = "{map}"

[materials.white]
diffuse = [0.5, 0.5, 0.5]
specular = [0, 0, 0]

[[sphere]]
center = [0, 0, 0]
radius = 1
material = "white"
"""


def pixels(mi, path):
    """The RGB floats of an image file, row by row."""
    b = mi.Bitmap(str(path)).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32)
    return b.width(), b.height(), [float(v) for v in mi.TensorXf(b).array]


def disc_mean(mi, path):
    w, h, data = pixels(mi, path)
    total, n = [0.0, 0.0, 0.0], 0
    for y in range(h):
        for x in range(w):
            if (x + 0.5 - w / 2) ** 2 + (y + 0.5 - h / 2) ** 2 < DISC_RADIUS**2:
                i = (y * w + x) * 3
                for c in range(3):
                    total[c] += data[i + c]
                n += 1
    return [t / n for t in total]


def pole_rows(mi, source, target):
    """Writes ``source`` resampled onto Mitsuba's rows (row j at θ = jπ/(H−1)),
    read as Glint reads it: bilinear, texel centres at half-integers, longitude
    wrapping, and past a pole the row half a turn away."""
    w, h, d = pixels(mi, source)

    def texel(x, y):
        if y < 0:
            x, y = x + w // 2, -1 - y
        elif y >= h:
            x, y = x + w // 2, 2 * h - 1 - y
        i = (y * w + x % w) * 3
        return d[i : i + 3]

    out = []
    for j in range(h):
        py = j / (h - 1) * h - 0.5  # Glint's continuous row at that latitude
        y0 = math.floor(py)
        fy = py - y0
        for i in range(w):  # columns are centred alike: no resampling across
            a, b = texel(i, y0), texel(i, y0 + 1)
            out.extend(a[k] * (1 - fy) + b[k] * fy for k in range(3))
    mi.Bitmap(mi.TensorXf(out, shape=(h, w, 3))).write(str(target))


def render_mitsuba(xml, envmap, seed, out):
    """Renders the exported scene `xml` with its envmap's file replaced by
    `envmap`, in a process of its own: after a render in this one, Mitsuba's
    threads leave this process's Python loops crawling."""
    command = [sys.executable, __file__, "--mitsuba-render", str(xml), str(envmap), str(seed), str(out)]
    subprocess.run(command, check=True)


def mitsuba_render_here(mi, xml, envmap, seed, out):
    tree = ET.parse(xml)
    emitters = [e for e in tree.getroot().iter("emitter") if e.get("type") == "envmap"]
    if len(emitters) != 1:
        sys.exit(f"envmap.py: error: {xml} has {len(emitters)} envmap emitters, expected 1")
    for s in emitters[0].iter("string"):
        if s.get("name") == "filename":
            s.set("value", str(Path(envmap).resolve()))
    patched = Path(xml).with_name("envmap-" + Path(xml).name)
    tree.write(patched, encoding="utf-8", xml_declaration=True)
    mi.util.write_bitmap(str(out), mi.render(mi.load_file(str(patched)), seed=seed))


def export_scene(binary, scene, spp, out):
    """The Glint scene as Mitsuba's, at `spp` samples per pixel and 4 emitter and
    4 BSDF samples (Mitsuba's sampler is noisier than Glint's)."""
    command = [str(binary), "export", "--mitsuba", str(scene), "--spp", str(spp), "--light-samples", "4", "-o", str(out)]
    subprocess.run(command, check=True, capture_output=True)


def write_scene(work, envmap, spp, seed):
    scene = work / "sphere.toml"
    scene.write_text(GLINT_SCENE.format(res=RESOLUTION, spp=spp, seed=seed, map=envmap.resolve().as_posix()))
    return scene


def render_glint(binary, scene, out):
    subprocess.run([str(binary), "render", str(scene), "-o", str(out)], check=True, capture_output=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("maps", nargs="+", type=Path, help="lat-long HDR or EXR maps")
    parser.add_argument("--spp", type=int, default=64, help="Glint's samples per pixel (Mitsuba: 4 times as many)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--glint", type=Path, default=REPO / "target/release/glint")
    parser.add_argument("--mitsuba-render", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    try:
        import mitsuba as mi
    except ImportError:
        sys.exit("envmap.py: error: the mitsuba package is not installed (pip install mitsuba)")
    mi.set_variant("scalar_rgb")
    if args.mitsuba_render:  # xml envmap seed out, from render_mitsuba
        xml, envmap, seed, out = args.maps
        return mitsuba_render_here(mi, xml, envmap, int(str(seed)), out)
    if not args.glint.is_file():
        sys.exit(f"envmap.py: error: no {args.glint}; build it: cargo build --release -p glint-cli")
    print("| map | Glint / Mitsuba, map as is (R, G, B) | Glint / Mitsuba, rows resampled (R, G, B) |")
    print("|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for envmap in args.maps:
            scene = write_scene(work, envmap, args.spp, args.seed)
            render_glint(args.glint, scene, work / "glint.exr")
            export_scene(args.glint, scene, 4 * args.spp, work / "sphere.xml")
            render_mitsuba(work / "sphere.xml", envmap, args.seed, work / "raw.exr")
            pole_rows(mi, envmap, work / "rows.exr")
            render_mitsuba(work / "sphere.xml", work / "rows.exr", args.seed, work / "resampled.exr")
            g = disc_mean(mi, work / "glint.exr")
            ratios = [
                ", ".join(f"{a / b:.4f}" for a, b in zip(g, disc_mean(mi, work / name)))
                for name in ("raw.exr", "resampled.exr")
            ]
            print(f"| {envmap.name} | {ratios[0]} | {ratios[1]} |")


if __name__ == "__main__":
    main()
