"""The `stages` command: answers to every stage of `glint grade --stages`'s test
vectors (grading-stages.md): camera, intersection, texture, lighting and film,
one STAGE.csv each.
"""

import csv
import math
import os

from .film import srgb8
from .lighting import sample_light
from .mistake import mistake
from .scene import Scene, epsilon_of
from .textures import Checkerboard, report_level_of, trilinear_at_level
from .vectors import ZERO, add, cmul, mul


def fnum(s):
    return float(s) if s not in ("", None) else None


def read_inputs(vectors, stage):
    path = os.path.join(vectors, f"{stage}-inputs.csv")
    if not os.path.exists(path):
        return None
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def write_answers(answers, stage, header, rows):
    with open(os.path.join(answers, f"{stage}.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        for r in rows:
            w.writerow(["" if v is None else (repr(v) if isinstance(v, float) else v) for v in r])


def cell_corner(r):
    """For MISTAKE pixel-corner: a case's raster coordinate is a grid cell's centre,
    X + (j + 1/2)/k (grading-stages.md, where the cases come from); its cell's
    corner X + j/k is r less half a cell, 1/(2k), the largest power of 2 whose odd
    multiple the fraction r - X is."""
    f = r - math.floor(r)
    h = 0.5
    while h > 2 ** -20:
        q = f / h
        if q == int(q) and int(q) % 2 == 1:
            return r - h
        h /= 2
    return r


def stage_camera(scene, cases):
    rows = []
    for c in cases:
        x, y = float(c["x"]), float(c["y"])
        if mistake("pixel-corner"):
            # MISTAKE pixel-corner: the student's camera shoots each grid sample
            # through its cell's corner, so it answers the case's raster position
            # (a cell centre) with that cell's corner, the + 1/2 left out
            x, y = cell_corner(x), cell_corner(y)
        o, d = scene.camera.ray(x, y, int(c["width"]), int(c["height"]))
        rows.append([c["id"], *o, *d])
    return ["id", "origin_x", "origin_y", "origin_z", "direction_x", "direction_y", "direction_z"], rows


def stage_intersection(scene, cases):
    header = ["id", "hit", "t", "point_x", "point_y", "point_z", "geometric_normal_x", "geometric_normal_y",
              "geometric_normal_z", "shading_normal_x", "shading_normal_y", "shading_normal_z", "u", "v", "object",
              "name"]
    rows = []
    for c in cases:
        o = (fnum(c["origin_x"]), fnum(c["origin_y"]), fnum(c["origin_z"]))
        d = (fnum(c["direction_x"]), fnum(c["direction_y"]), fnum(c["direction_z"]))
        h = scene.closest_hit(o, d)
        if h is None:
            rows.append([c["id"], "false"] + [None] * 14)
            continue
        rows.append([c["id"], "true", h.t, *h.point, *h.ng, *h.ng, h.uv[0], h.uv[1], h.obj,
                     scene.objects[h.obj].name])
    return header, rows


def stage_texture(scene, cases):
    header = ["id", "l", "jacobian", "w", "level", "value_r", "value_g", "value_b"]
    rows = []
    for c in cases:
        obj = scene.objects[int(c["object"])]
        mat = obj.material
        tex = mat.diffuse if c["texture"] == "diffuse" else mat.specular
        u, v = fnum(c["u"]), fnum(c["v"])
        su, sv, ou, ov = fnum(c["scale_u"]), fnum(c["scale_v"]), fnum(c["offset_u"]), fnum(c["offset_v"])
        um, vm = u * su + ou, v * sv + ov
        t, ndd, r, fov = fnum(c["t"]), fnum(c["n_dot_d"]), fnum(c["r"]), fnum(c["fov"])
        L = 2 * t * math.tan(math.radians(fov) / 2) / (r * abs(ndd))
        area = obj.shape.jacobian_area((u, v))
        J = math.sqrt(area) / math.sqrt(abs(su * sv))
        if isinstance(tex, Checkerboard):
            val, _ = tex.point(um, vm)
            rows.append([c["id"], L, J, None, None, *val])
            continue
        m = max(tex.image.width, tex.image.height)
        W = J / m
        level = report_level_of(L, W)
        val = trilinear_at_level(tex.pyramid, um, 1 - vm, level, tex.wrap)
        rows.append([c["id"], L, J, W, level, *val])
    return header, rows


def stage_lighting(scene, cases, eps):
    rows = []
    header = None
    for c in cases:
        x = (fnum(c["point_x"]), fnum(c["point_y"]), fnum(c["point_z"]))
        n = (fnum(c["n_x"]), fnum(c["n_y"]), fnum(c["n_z"]))
        ng = (fnum(c["ng_x"]), fnum(c["ng_y"]), fnum(c["ng_z"]))
        v = (fnum(c["v_x"]), fnum(c["v_y"]), fnum(c["v_z"]))
        kd = (fnum(c["kd_r"]), fnum(c["kd_g"]), fnum(c["kd_b"]))
        ks = (fnum(c["ks_r"]), fnum(c["ks_g"]), fnum(c["ks_b"]))
        amb = (fnum(c["ambient_r"]), fnum(c["ambient_g"]), fnum(c["ambient_b"]))
        shin, lobe = fnum(c["shininess"]), c["lobe"]
        # the lights, as given, and their samples
        lights = {}
        j = 0
        while f"light{j}_kind" in c:
            kind = c[f"light{j}_kind"]
            col = (fnum(c[f"light{j}_r"]), fnum(c[f"light{j}_g"]), fnum(c[f"light{j}_b"]))
            nrm = None
            if kind == "area":
                nrm = (fnum(c[f"light{j}_normal_x"]), fnum(c[f"light{j}_normal_y"]), fnum(c[f"light{j}_normal_z"]))
            lights[j] = (kind, col, nrm)
            j += 1
        samples = []
        k = 0
        while f"s{k:02d}_light" in c:
            samples.append((int(c[f"s{k:02d}_light"]),
                            (fnum(c[f"s{k:02d}_x"]), fnum(c[f"s{k:02d}_y"]), fnum(c[f"s{k:02d}_z"]))))
            k += 1
        width = 2 if len(samples) <= 100 else 3
        ambient_term = cmul(amb, kd)
        if mistake("no-ambient"):
            # MISTAKE no-ambient: the ambient term left out (answered as 0)
            ambient_term = ZERO
        out = [c["id"], *ambient_term]
        hdr = ["id", "ambient_term_r", "ambient_term_g", "ambient_term_b"]
        sums = {j: ZERO for j in lights}
        counts = {j: 0 for j in lights}
        for k, (j, p) in enumerate(samples):
            kind, col, nrm = lights[j]
            counts[j] += 1
            if mistake("light-centre") and kind == "area":
                # MISTAKE light-centre: the student's own sample points, all at the
                # light's centre, instead of the given sNN_x/y/z (light J is the
                # scene's J-th light: point lights, then area lights, as step 7)
                assert scene.lights[j].kind == "area", (j, scene.lights[j].kind)
                p = scene.lights[j].center

            class _L:
                pass

            L = _L()
            L.kind, L.normal = kind, nrm
            s, verdict, blocker = sample_light(scene, L, p, x, n, ng, v, kd, ks, shin, lobe, eps)
            if verdict == "visible":
                sums[j] = add(sums[j], add(s["diffuse"], s["specular"]))
            tag = f"s{k:0{width}d}"
            hdr += [f"{tag}_verdict", f"{tag}_blocker", f"{tag}_diffuse_r", f"{tag}_diffuse_g", f"{tag}_diffuse_b",
                    f"{tag}_specular_r", f"{tag}_specular_g", f"{tag}_specular_b"]
            out += [verdict, blocker, *s["diffuse"], *s["specular"]]
        total = ambient_term
        for j, (kind, col, nrm) in lights.items():
            if counts[j]:
                if mistake("light-sum-not-divided"):
                    # MISTAKE light-sum-not-divided: the sum of the samples, not divided by N
                    total = add(total, cmul(col, sums[j]))
                    continue
                total = add(total, cmul(col, mul(sums[j], 1 / counts[j])))
        hdr += ["total_r", "total_g", "total_b"]
        out += list(total)
        header = header or hdr
        rows.append(out)
    return header, rows


def stage_film(scene, cases):
    rows = []
    for c in cases:
        rows.append([c["id"]] + [srgb8(fnum(c[f"radiance_{ch}"])) for ch in "rgb"])
    return ["id", "srgb8_r", "srgb8_g", "srgb8_b"], rows


def cmd_stages(args):
    scene = Scene(args.scene)
    if not os.path.isdir(args.vectors):
        raise SystemExit(f"tracer.py: {args.vectors}: no such directory of test vectors")
    eps = epsilon_of(scene, args)
    os.makedirs(args.answers, exist_ok=True)
    for stage, fn in (("camera", stage_camera), ("intersection", stage_intersection), ("texture", stage_texture),
                      ("lighting", lambda s, c: stage_lighting(s, c, eps)), ("film", stage_film)):
        cases = read_inputs(args.vectors, stage)
        if not cases:
            continue
        header, rows = fn(scene, cases)
        write_answers(args.answers, stage, header, rows)
