"""Shading: what a camera ray sees at its closest hit. The course's direct
lighting (integrator/src/direct.rs): ambient, then each light's Phong
reflection, averaged over the light's samples, with shadow rays; textures and
materials at the hit; a light's own colour where a camera ray sees it.
"""

from __future__ import annotations

import math

import numpy as np

from intersect import Intersector, dot3
from sampling import Options, pattern_points
from scene_file import AreaLight, Checker, PointLight, Scene


class Shader:
    def __init__(self, scene: Scene, opts: Options, hits: Intersector):
        self.scene, self.o, self.hits = scene, opts, hits
        self.m = opts.mistakes
        self.eps = hits.eps  # our shadow-ray offset (Glint's is an error bound)

    def radiance(self, pos, d, t, kind, index, rng, shared_light=None):
        """What each camera ray pos + t d sees at its closest hit (t, kind,
        index from Intersector.closest), as (M, 3): a light's colour on its
        front side, the shaded surface elsewhere, 0 where it hits nothing."""
        scene = self.scene
        radiance = np.zeros((t.shape[0], 3))

        # A camera ray whose first hit is a light's front side sees its colour.
        for i, p in enumerate(scene.parallelograms):
            if p.light >= 0:
                sel = (kind == 1) & (index == i)
                radiance[sel] = scene.area_lights[p.light].color

        surf = np.nonzero(((kind == 0) | ((kind == 1) & (index >= 0))) & ~self._is_light(kind, index))[0]
        if surf.size:
            local_shared = None
            if shared_light is not None:  # MISTAKE (shared-samples): the same light points everywhere
                local_shared = shared_light[surf]
            radiance[surf] = self.shade(pos, [c[surf] for c in d], t[surf], kind[surf], index[surf], rng, local_shared)
        return radiance

    def _is_light(self, kind, index):
        lit = np.zeros(kind.shape, dtype=bool)
        for i, p in enumerate(self.scene.parallelograms):
            if p.light >= 0:
                lit |= (kind == 1) & (index == i)
        return lit

    # -- textures and materials -------------------------------------------
    def texture(self, tex, uv):
        if isinstance(tex, Checker):
            n = tex.checks
            if "checker-doubled" in self.m:  # MISTAKE: twice the frequency
                n *= 2
            # texture/src/checkerboard.rs: check (floor(u N), floor(v N)), first
            # colour when the sum is even (parity of the xor), point-sampled.
            iu = np.floor(uv[0] * n).astype(np.int64)
            iv = np.floor(uv[1] * n).astype(np.int64)
            odd = (iu ^ iv) & 1
            return tex.colors[odd]
        return np.broadcast_to(tex, (uv[0].shape[0], 3))

    # -- a surface point and its lights ------------------------------------
    def shade(self, pos, d, t, kind, index, rng, shared_light):
        scene, m = self.scene, self.m
        n_hits = t.shape[0]
        raw = [pos[i] + t * d[i] for i in range(3)]  # o + t d
        ng = [np.empty(n_hits) for _ in range(3)]
        point = [np.empty(n_hits) for _ in range(3)]
        u = np.empty(n_hits)
        v = np.empty(n_hits)
        mat = np.empty(n_hits, dtype=np.int32)
        shading_scale = np.ones(n_hits)  # 1, or r for unnormalised-normals
        for i, s in enumerate(scene.spheres):
            sel = np.nonzero((kind == 0) & (index == i))[0]
            if not sel.size:
                continue
            q = [raw[k][sel] - s.center[k] for k in range(3)]
            inv = 1.0 / np.sqrt(dot3(q, q))
            nrm = [q[k] * inv for k in range(3)]
            for k in range(3):
                ng[k][sel] = nrm[k]
                # geometry/src/shapes/sphere.rs: the point projected back onto the sphere
                point[k][sel] = s.center[k] + s.radius * nrm[k]
            # sphere.rs `uv_of_normal`: theta = acos(n.y), phi = atan2(-n.z, n.x)
            # in [0, 2 pi), u = phi / 2 pi, v = 1 - theta / pi.
            theta = np.arccos(np.clip(nrm[1], -1.0, 1.0))
            if "sphere-u-sign" in m:  # MISTAKE: phi = atan2(z, x)
                phi = np.arctan2(nrm[2], nrm[0])
            else:
                phi = np.arctan2(-nrm[2], nrm[0])
            phi = np.where(phi < 0, phi + 2 * math.pi, phi)
            u[sel] = phi / (2 * math.pi)
            v[sel] = 1.0 - theta / math.pi
            if "sphere-v-from-y" in m:  # MISTAKE: v linear in the height, not in the angle
                v[sel] = (nrm[1] + 1.0) / 2.0
            mat[sel] = s.material
            if "unnormalised-normals" in m:  # MISTAKE: shading normal p - c, length r
                shading_scale[sel] = s.radius
        for i, p in enumerate(scene.parallelograms):
            sel = np.nonzero((kind == 1) & (index == i))[0]
            if not sel.size:
                continue
            x = [raw[k][sel] for k in range(3)]
            alpha = np.clip(p.A[0] * x[0] + p.A[1] * x[1] + p.A[2] * x[2] - p.a0, 0, 1)
            beta = np.clip(p.B[0] * x[0] + p.B[1] * x[1] + p.B[2] * x[2] - p.b0, 0, 1)
            for k in range(3):
                ng[k][sel] = p.normal[k]
                point[k][sel] = x[k]
            u[sel], v[sel] = alpha, beta  # uv = (alpha, beta) of origin + alpha e1 + beta e2
            mat[sel] = p.material
        if "no-shadow-offset" in m:
            point = raw  # MISTAKE: the shadow ray starts at o + t d, as computed

        # The normal turned to the viewer's side (geometry/src/hit.rs `facing_normal`).
        flip = np.where(dot3(ng, d) > 0, -1.0, 1.0)
        ng = [ng[k] * flip for k in range(3)]
        n = [ng[k] * shading_scale for k in range(3)]
        view = [-d[k] for k in range(3)]
        if "flipped-view" in m:  # MISTAKE: v along the ray instead of towards the viewer
            view = d

        kd = np.empty((n_hits, 3))
        ks = np.empty((n_hits, 3))
        shin = np.empty(n_hits)
        blinn = np.zeros(n_hits, dtype=bool)
        for j, mt in enumerate(scene.materials):
            sel = np.nonzero(mat == j)[0]
            if not sel.size:
                continue
            uv = (u[sel] * mt.uv_scale[0] + mt.uv_offset[0], v[sel] * mt.uv_scale[1] + mt.uv_offset[1])
            kd[sel] = self.texture(mt.diffuse, uv)
            ks[sel] = kd[sel] if mt.specular is None else self.texture(mt.specular, uv)
            if "specular-white" in m:  # MISTAKE: white highlights
                ks[sel] = 1.0
            shin[sel] = mt.shininess
            blinn[sel] = mt.lobe == "blinn-phong"
        if "blinn-half-vector" in m:  # MISTAKE: n.h in place of r.v
            blinn[:] = True

        # integrator/src/direct.rs `shade_with`: ambient * kd once, then each light.
        out = np.zeros((n_hits, 3))
        if "no-ambient" not in m:  # MISTAKE no-ambient: this term left out
            amb = scene.ambient * kd
            if "ambient-per-sample" in m:  # MISTAKE: once per light sample, not averaged
                amb = amb * self.o.light_samples * max(1, len(scene.area_lights))
            if "ambient-in-shadow-only" not in m:
                out += amb
        geo = dict(point=point, ng=ng, n=n, view=view, kd=kd, ks=ks, shin=shin, blinn=blinn, kind=kind, index=index)
        for li, L in enumerate(scene.area_lights):
            out += self.area_light(L, geo, rng, shared_light)
        for P in scene.point_lights:
            out += self.point_light(P, geo)
        return out

    def reflect(self, geo, l, rows=slice(None)):
        """The course's Phong reflection of a unit light along l (lighting/src/
        material.rs `reflect`): kd (n.l) + ks lobe, zero where n.l <= 0; lobe
        max(0, r.v)^s, r = 2 (n.l) n - l (or max(0, n.h)^s, h = normalize(l + v)).
        Returns (n.l, lobe) broadcast over the light samples."""
        n = [c[rows][:, None] for c in geo["n"]]
        view = [c[rows][:, None] for c in geo["view"]]
        s = geo["shin"][rows][:, None]
        ndl = dot3(n, l)
        r = [2 * ndl * n[k] - l[k] for k in range(3)]
        cos = dot3(r, view)
        blinn = geo["blinn"][rows][:, None]
        if blinn.any():
            h = [l[k] + view[k] for k in range(3)]
            with np.errstate(invalid="ignore", divide="ignore"):
                hn = 1.0 / np.sqrt(dot3(h, h))
                cos_h = np.nan_to_num(dot3(n, h) * hn)
            cos = np.where(blinn, cos_h, cos)
        if "no-clamp-dots" in self.m:
            # MISTAKE: neither n.l nor the lobe's cosine clamped at 0
            with np.errstate(invalid="ignore"):
                lobe = np.nan_to_num(cos**s)
            return ndl, lobe, np.ones(ndl.shape, dtype=bool)
        with np.errstate(invalid="ignore"):
            lobe = np.where(cos > 0, np.maximum(cos, 0) ** s, 0.0)
        return ndl, lobe, ndl > 0

    def point_light(self, P: PointLight, geo):
        p = geo["point"]
        w = [P.position[k] - p[k] for k in range(3)]
        dist = np.sqrt(dot3(w, w))
        with np.errstate(invalid="ignore", divide="ignore"):
            l = [(w[k] / dist)[:, None] for k in range(3)]
        contrib = self.light_samples_value(geo, [x[:, None] for x in p], l, dist[:, None], np.ones_like(dist, dtype=bool)[:, None],
                                           [np.full((p[0].shape[0], 1), P.position[k]) for k in range(3)], -1, 1, P.position)
        return P.color * contrib

    def area_light(self, L: AreaLight, geo, rng, shared_light):
        o, m = self.o, self.m
        p = geo["point"]
        N, S = p[0].shape[0], o.light_samples
        if shared_light is not None:
            uv = shared_light
        else:
            uv = pattern_points(o.light_sampler, (N,), S, rng)
        if "light-centre" in m:  # MISTAKE: every sample at the centre
            uv = np.full((N, S, 2), 0.5)
        e1, e2 = L.edge1, L.edge2
        if "light-twice-size" in m:  # MISTAKE: centre +- edge instead of +- edge/2
            e1, e2 = 2 * e1, 2 * e2
        # lighting/src/area_light.rs: origin + u e1 + v e2, origin = centre - (e1 + e2)/2,
        # i.e. centre + (u - 1/2) e1 + (v - 1/2) e2.
        a, b = uv[..., 0] - 0.5, uv[..., 1] - 0.5
        q = [L.center[k] + a * e1[k] + b * e2[k] for k in range(3)]
        pp = [c[:, None] for c in p]
        w = [q[k] - pp[k] for k in range(3)]
        dist = np.sqrt(dot3(w, w))
        with np.errstate(invalid="ignore", divide="ignore"):
            l = [w[k] / dist for k in range(3)]
        # area_light.rs `illuminates`: the receiver must be in front of the light.
        lit = dot3(L.normal, [pp[k] - q[k] for k in range(3)]) > 0
        if "two-sided-light" in m:  # MISTAKE: both sides emit
            lit = np.ones_like(lit)
        # Shadow rays end a little short of the light, on its emitting side.
        side = np.where(dot3(L.normal, [-x for x in w]) >= 0, 1.0, -1.0)
        end = [q[k] + side * 2 * self.eps * L.normal[k] for k in range(3)]
        if "light-blocks-shadow" in m:
            end = q  # MISTAKE (with blocked()): aimed at the light point itself
        contrib = self.light_samples_value(geo, pp, l, dist, lit, end, L.surface, S)
        return L.color * contrib

    def light_samples_value(self, geo, pp, l, dist, lit, end, light_surface, S, point_target=None):
        """Sum over a point's light samples of the visible Phong reflections,
        divided by the sample count: (N, 3) per unit light colour. The shadow
        rays end at `end`, on the area light whose surface is `light_surface`,
        or (light_surface -1) at the point light at `point_target`."""
        m = self.m
        ng = [c[:, None] for c in geo["ng"]]
        ndl, lobe, front = self.reflect(geo, l)
        # direct.rs `above_surface`: the light must be above the geometric surface.
        above = dot3(ng, l) > 0
        if "no-clamp-dots" in m:
            above = np.ones_like(above)  # MISTAKE: no horizon test either
        with np.errstate(invalid="ignore"):
            shaded = lit & above & front & (dist > 0)
        kd, ks = geo["kd"][:, None, :], geo["ks"][:, None, :]
        refl = kd * ndl[..., None] + ks * lobe[..., None]  # (N, S, 3)
        if "distance-falloff" in m:  # MISTAKE: 1/r^2
            refl = refl / (dist * dist)[..., None]
        N = ndl.shape[0]
        visible = shaded.copy()
        rows, cols = np.nonzero(shaded)
        if rows.size and "no-shadows" not in m:  # MISTAKE no-shadows: skip the test
            o = [pp[k][rows, 0] for k in range(3)]
            if "no-shadow-offset" not in m:
                # Leave on the side of the geometric surface the light is on
                # (geometry/src/offset.rs `spawn_ray_to`), by a fixed offset of ours.
                g = [geo["ng"][k][rows] for k in range(3)]
                w = [l[k][rows, cols] for k in range(3)]
                sgn = np.where(dot3(g, w) < 0, -1.0, 1.0) * self.eps
                o = [o[k] + sgn * g[k] for k in range(3)]
            e = [np.broadcast_to(end[k], (N, S))[rows, cols] for k in range(3)]
            d = [e[k] - o[k] for k in range(3)]
            hit = self.hits.blocked(o, d, 1.0, geo["kind"][rows], geo["index"][rows], light_surface, point_target)
            visible[rows, cols] = ~hit
        total = np.where(visible[..., None], refl, 0.0).sum(axis=1)
        if "ambient-in-shadow-only" in m:
            # MISTAKE: the report's literal reading, ambient only when a shadow
            # ray is blocked (per sample, averaged with the Phong terms).
            occluded = (shaded & ~visible).sum(axis=1)
            total = total + self.scene.ambient * geo["kd"] * occluded[:, None]
        if "summed-light-samples" in m:  # MISTAKE: the sum is not divided by S
            return total
        return total / S
