"""Lighting and shading (scene-format.md, "How a pixel is computed", steps 7-9):
the Phong terms, the area lights' grid of samples, the shadow ray and its
verdict (unlit, blocked, visible), one light sample as explain records it.
"""

import math

from .mistake import mistake
from .vectors import ZERO, add, dot, length, mul, neg, normalize, sub


def phong_terms(kd, ks, shininess, lobe, n, v, l):
    """Step 7: diffuse kd*(n.l), specular ks*lobe, both 0 where n.l <= 0."""
    ndl = dot(n, l)
    r = sub(mul(n, 2 * ndl), l)
    if ndl <= 0:
        return ndl, r, ZERO, ZERO
    if mistake("view-sign"):
        # MISTAKE view-sign: the view vector's sign flipped in the specular term
        v = neg(v)
    if lobe == "blinn-phong" or mistake("blinn"):
        # (MISTAKE blinn: the half vector's lobe for a Phong material too)
        h = normalize(add(l, v))
        base = max(0.0, dot(n, h))
    else:
        base = max(0.0, dot(r, v))
    lob = base ** shininess if not (base == 0 and shininess == 0) else 1.0
    return ndl, r, mul(kd, ndl), mul(ks, lob)


def shadow_test(scene, x, ng, p, eps):
    """Step 9, corrected rule: start at o = x + eps*ng (ng turned to the light's
    side), aim at p from o, a blocker only at 0 < t < |p - o| - eps.
    Returns None (unoccluded) or (object index, t as a fraction of |p - o|)."""
    if dot(ng, sub(p, x)) < 0:
        ng = neg(ng)
    o = add(x, mul(ng, eps))
    to = sub(p, o)
    dist = length(to)
    d = mul(to, 1 / dist)
    if mistake("light-blocks-itself"):
        # MISTAKE light-blocks-itself: aimed along the shading's l (from x) out of
        # the offset start, which meets the light's own plane short of the end
        d = normalize(sub(p, x))
    if mistake("no-shadow-offset"):
        # MISTAKE no-shadow-offset: the ray starts exactly at x (any t > 0 blocks),
        # still stopping eps short of the light
        o, d = x, normalize(sub(p, x))
        dist = length(sub(p, x))
    best_t, best = dist - eps, None
    for obj in scene.objects:
        t = obj.shape.intersect_t(o, d, best_t)
        if t is not None and t < best_t:
            best_t, best = t, obj.index
    if best is None:
        return None
    # checking-your-ray-tracer.md, the verdicts table: t is "where it lies as a
    # fraction of the segment from the hit point x to the light sample p ...
    # (a tracer with a fixed offset intersects the blocker along x -> p again,
    # or reports (eps + t')/|p - x| for the t' along its own ray)".  The first.
    full = length(sub(p, x))
    t_x = scene.objects[best].shape.intersect_t(x, normalize(sub(p, x)), full)
    if t_x is not None:
        return best, t_x / full
    return best, (best_t + eps) / full


def light_sample_points(light, n):
    """Step 8: grid cell centres ((i mod k) + 1/2, (i div k) + 1/2)/k."""
    if light.kind == "point":
        return [light.position]
    k = int(round(math.sqrt(n)))
    if k * k != n:
        raise SystemExit("--light-sampler grid needs a perfect square of light samples")
    if mistake("light-centre"):
        # MISTAKE light-centre: all n samples at the light's centre (still n of them)
        return [light.center] * n
    return [light.point_at(((i % k) + 0.5) / k, ((i // k) + 0.5) / k) for i in range(n)]


def sample_light(scene, light, p, x, n, ng, v, kd, ks, mat_shininess, lobe, eps):
    """One light sample (steps 7 and 8). Returns a dict in explain's layout and
    the verdict of grading-stages.md (unlit, blocked, visible) with the blocker."""
    l = normalize(sub(p, x))
    ndl, r, diff, spec = phong_terms(kd, ks, mat_shininess, lobe, n, v, l)
    s = {"position": p, "l": l, "n_dot_l": ndl, "reflection": r, "diffuse": diff, "specular": spec}
    verdict, blocker, t = None, None, None
    if light.kind == "area" and dot(light.normal, sub(x, p)) <= 0:
        verdict, s["shadow"] = "unlit", {"not_traced": "behind the light"}
    elif dot(ng, l) <= 0:
        verdict, s["shadow"] = "unlit", {"not_traced": "below the surface"}
    elif add(diff, spec) == ZERO:
        verdict, s["shadow"] = "unlit", {"not_traced": "zero BRDF"}
    else:
        b = shadow_test(scene, x, ng, p, eps)
        if b is None:
            verdict, s["shadow"] = "visible", "unoccluded"
        else:
            blocker, t = b
            verdict, s["shadow"] = "blocked", {"blocked_by": blocker, "t": t}
    s["value"] = add(diff, spec) if verdict == "visible" else ZERO
    return s, verdict, blocker
