"""The integrator (scene-format.md steps 3-11): one ray traced through the scene
(hit, textures, ambient and lights, mirror reflection with its ray
differentials, the environment), recording explain's document as it goes.
"""

import math

from .geometry import Sphere
from .lighting import light_sample_points, sample_light
from .mistake import mistake
from .textures import ImageTexture, footprint_at, lookup, report_level_of, uses_footprint
from .vectors import ZERO, add, cmul, cross, dot, length, mul, neg, normalize, sub


class Tracer:
    def __init__(self, scene, light_samples, eps, env_samples=0, texture_level="footprint"):
        self.scene = scene
        self.texture_level = texture_level
        if texture_level == "report":
            # command-line.md, Textures: "--texture-level report reads every image
            # texture trilinearly" (another --texture-filter is bad input), so every
            # image is a trilinear one, filtered over a footprint; at a camera ray's
            # hit it is read at the report's level, and "a mirror's reflection rays,
            # for which the report gives no level, keep the footprint".
            for m in scene.materials.values():
                for t in (m.diffuse, m.specular):
                    if isinstance(t, ImageTexture):
                        t.filter = "trilinear"
        self.light_samples = light_samples
        self.eps = eps
        if env_samples:
            raise SystemExit("environment samples are not implemented: pass --environment-samples 0")
        self.needs_footprint = any(
            m.diffuse is not None and (uses_footprint(m.diffuse) or (m.specular is not None and uses_footprint(m.specular)))
            for m in scene.materials.values()) or scene.environment is not None

    def trace(self, o, d, depth, rd, shown_from=None):
        """Returns (radiance, the ray's explain dict). rd: ray differentials
        ((rx_origin, rx_dir), (ry_origin, ry_dir)) or None.  shown_from: for a
        reflection ray, the mirror's hit point, which explain shows as the
        origin (checking-your-ray-tracer.md: "its origin usually prints as the
        point"), t then counting from it."""
        sc = self.scene
        rec = {"depth": depth}
        hit = sc.closest_hit(o, d)
        inter = {"origin": o if shown_from is None else shown_from, "direction": d}
        rec["intersect"] = inter
        if hit is None:
            inter["hit"] = None
            if sc.environment is None:
                return ZERO, rec
            width = self.env_width(d, rd)
            rad = sc.environment.lookup(d, width)
            rec["environment"] = {"direction": d, "filter_width": width, "radiance": rad}
            return rad, rec
        obj = sc.objects[hit.obj]
        front = dot(hit.ng, d) < 0
        shown_t = hit.t if shown_from is None else hit.t + dot(sub(o, shown_from), d)
        inter["hit"] = {"object": hit.obj, "kind": obj.kind, "triangle": 0, "t": shown_t, "point": hit.point,
                        "geometric_normal": hit.ng, "shading_normal": hit.ng, "uv": hit.uv,
                        "dpdu": hit.dpdu, "dpdv": hit.dpdv, "front_face": front}
        rec["object"] = hit.obj
        rec["triangle"] = 0
        if obj.light is not None:  # step 4: the light's colour, nothing shaded
            rec["emitter"] = {"radiance": obj.light.color}
            return obj.light.color, rec
        mat = obj.material
        v = neg(d)
        n = hit.ng if front else neg(hit.ng)  # step 5: facing normal
        ng = n
        fp = None
        if rd is not None and self.needs_footprint:
            fp = footprint_at(hit, rd)
        local = ZERO
        if mat.reflectivity < 1:
            kd, ks, tex = self.textures(mat, obj, hit, d, depth, fp)
            rec["texture"] = tex
            rec["shading"] = {"n": n, "ng": ng, "v": v}
            ambient = cmul(sc.ambient, kd)  # step 6
            if mistake("no-ambient"):
                # MISTAKE no-ambient: the ambient term left out (recorded as 0)
                ambient = ZERO
            lights = []
            local = ambient
            for light in sc.lights:  # step 7: point lights, then area lights
                pts = light_sample_points(light, self.light_samples if light.kind == "area" else 1)
                samples = []
                acc = ZERO
                for k, p in enumerate(pts):
                    s, _, _ = sample_light(sc, light, p, hit.point, n, ng, v, kd, ks, mat.shininess, mat.lobe,
                                           self.eps)
                    acc = add(acc, s["value"])
                    s["running_average"] = mul(acc, 1 / (k + 1))
                    samples.append(s)
                total = cmul(light.color, mul(acc, 1 / len(pts)))
                if mistake("light-sum-not-divided"):
                    # MISTAKE light-sum-not-divided: the sum, not the mean (the
                    # running averages above are left as they should be)
                    total = cmul(light.color, acc)
                lights.append({"light": light.index, "kind": light.kind, "samples": samples, "total": total})
                local = add(local, total)
            rec["light"] = {"ambient": ambient, "lights": lights, "environment": None}
        mirror = ZERO
        r = mat.reflectivity
        if r > 0 and depth < sc.max_depth:  # step 11
            wi = sub(mul(n, 2 * dot(v, n)), v)
            # scene-format.md step 11: "A tracer with a fixed offset starts the
            # reflection at x + eps*wi, along the reflected direction".
            o2 = add(hit.point, mul(wi, self.eps))
            # environment-lighting.md, Mirrors: "The offset rays start at the hit
            # point plus dp/dx and dp/dy, not at the main ray's offset origin"
            # (reflect_differentials returns them so).
            rd2 = self.reflect_differentials(hit, n, v, wi, rd, fp, obj)
            rec["mirror"] = {"reflectivity": r, "tint": mat.tint, "direction": wi}
            lr, rrec = self.trace(o2, wi, depth + 1, rd2, shown_from=hit.point)
            rec["reflection"] = rrec
            mirror = cmul(mat.tint, lr)
        value = add(mul(local, 1 - r), mul(mirror, r))
        rec["radiance"] = {"local": local, "mirror": mirror, "value": value}
        return value, rec

    def textures(self, mat, obj, hit, d, depth, fp):
        su, sv = mat.uv_scale
        ou, ov = mat.uv_offset
        uv = hit.uv
        uvm = (uv[0] * su + ou, uv[1] * sv + ov)
        uses = uses_footprint(mat.diffuse) or (mat.specular is not None and uses_footprint(mat.specular))
        if fp is not None and uses:
            duvdx, duvdy = fp[2], fp[3]
        else:
            duvdx, duvdy = (0.0, 0.0), (0.0, 0.0)
        dmx = (duvdx[0] * su, duvdx[1] * sv)
        dmy = (duvdy[0] * su, duvdy[1] * sv)
        report = None
        if depth == 0:
            report = self.report_parts(obj, hit, d, mat)
        # --texture-level report: image textures at the report's level at the
        # camera ray's hit only; a mirror's reflection rays keep the footprint.
        at_report = self.texture_level == "report" and depth == 0
        if at_report and report is not None:
            # checking-your-ray-tracer.md, the texture stage: "At such a hit the
            # lookup's footprint is the square one whose trilinear level is the
            # report's, not the ray differentials': dst/dx = (w, 0), dst/dy =
            # (0, -w) with w = 2^l / m (l the report's level, unclamped), and
            # duv/dx = (w/s_u, 0), duv/dy = (0, w/s_v)".  m is the image's, so the
            # material's first image texture (diffuse, then specular) sets it;
            # where the report gives no finite level the footprint stays.
            img_tex = next((t for t in (mat.diffuse, mat.specular) if isinstance(t, ImageTexture)), None)
            if img_tex is not None:
                L, Wj = report
                m = max(img_tex.image.width, img_tex.image.height)
                level = report_level_of(L, Wj / m) if L > 0 and Wj > 0 else float("nan")
                if math.isfinite(level):
                    w = 2.0 ** level / m
                    duvdx, duvdy = (w / su, 0.0), (0.0, w / sv)
                    dmx, dmy = (w, 0.0), (0.0, w)
        kd, dl = lookup(mat.diffuse, uvm, dmx, dmy, report, at_report)
        tex = {"footprint": {"uv": uv, "duvdx": duvdx, "duvdy": duvdy}, "material_uv": uvm, "diffuse": dl}
        if mat.specular is None:
            ks = kd
            tex["specular"] = "the diffuse texture's (ks = kd)"
        else:
            ks, sl = lookup(mat.specular, uvm, dmx, dmy, report, at_report)
            tex["specular"] = sl
        tex["kd"], tex["ks"] = kd, ks
        return kd, ks, tex

    def report_parts(self, obj, hit, d, mat):
        """checking-your-ray-tracer.md: L = 2 t tan(fov/2) / (r |N.D|), |J_T| =
        sqrt|dpdu x dpdv| / sqrt|su sv|."""
        sc = self.scene
        L = 2 * hit.t * math.tan(math.radians(sc.camera.fov) / 2) / (sc.height * abs(dot(hit.ng, d)))
        J = math.sqrt(length(cross(hit.dpdu, hit.dpdv))) / math.sqrt(abs(mat.uv_scale[0] * mat.uv_scale[1]))
        return L, J

    def reflect_differentials(self, hit, n, v, wi, rd, fp, obj):
        """pbrt-v4's specular-reflection rule for ray differentials."""
        if rd is None or not self.needs_footprint:
            return None
        if fp is None:
            fp = footprint_at(hit, rd)
        dpdx, dpdy, _, _ = fp
        (rxo, rxd), (ryo, ryd) = rd
        shape = obj.shape
        if isinstance(shape, Sphere):
            sgn = 1.0 if dot(n, hit.ng) > 0 else -1.0
            dndx, dndy = mul(dpdx, sgn / shape.radius), mul(dpdy, sgn / shape.radius)
        else:
            dndx = dndy = ZERO
        wo = v
        out = []
        for dp, dd, dn in ((dpdx, rxd, dndx), (dpdy, ryd, dndy)):
            # environment-lighting.md, Mirrors: "each incoming offset direction is
            # normalised first (pbrt-v4 uses them as they come)"
            dd = normalize(dd)
            dwo = sub(neg(dd), wo)
            dwo_n = dot(dwo, n) + dot(wo, dn)
            nd = add(sub(wi, dwo), mul(add(mul(dn, dot(wo, n)), mul(n, dwo_n)), 2))
            # "The offset rays start at the hit point plus dp/dx and dp/dy"
            out.append((add(hit.point, dp), nd))
        return tuple(out)

    def env_width(self, d, rd):
        """environment-lighting.md, Mirrors: filter_width = max(angle(d, d_x),
        angle(d, d_y)), each 2*atan2(|a - b|, |a + b|) of the unit directions."""
        if rd is None:
            return 0.0
        (_, rxd), (_, ryd) = rd
        a = normalize(d)

        def angle(b):
            b = normalize(b)
            return 2 * math.atan2(length(sub(a, b)), length(add(a, b)))

        return max(angle(rxd), angle(ryd))
