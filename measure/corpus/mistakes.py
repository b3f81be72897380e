"""The student mistakes the tracer can make (`tracer.py --mistake NAME`).

Only the catalogue: each mistake is a small branch, marked `# MISTAKE`, in the
stage it spoils (camera.py, shading.py, intersect.py, render.py,
image_files.py), found by searching for its name.
"""

MISTAKES: dict[str, str] = {
    "flipped-view": "specular term with the view vector flipped (v = ray direction, not -direction)",
    "sphere-u-sign": "sphere u angle with the wrong sign (phi = atan2(z, x) instead of atan2(-z, x))",
    "no-shadow-offset": "shadow rays start exactly at o + t*d on the surface, test t > 0, no offset/epsilon (acne)",
    "no-shadows": "no shadow rays: every light sample counts as visible",
    "no-srgb": "8-bit output written from linear values without the sRGB curve (8-bit outputs only)",
    "gamma-22": "8-bit output encoded with gamma 1/2.2 instead of the exact sRGB curve (8-bit outputs only)",
    "truncate-8bit": "8-bit quantisation by floor instead of rounding (half a step darker; arguably acceptable)",
    "summed-light-samples": "light samples summed, not averaged (no division by the light-sample count)",
    "horizontal-fov": "fov taken as the horizontal field of view (no effect on square images)",
    "fov-no-half": "film half-height f*tan(fov) instead of f*tan(fov/2) (zoomed out)",
    "pixel-corners": "samples shifted by -0.5 px (grid cell at offset 0 instead of 0.5: pixel corners)",
    "unnormalised-normals": "sphere normal p - c not divided by r in shading (uv still right)",
    "blinn-half-vector": "specular lobe n.h (half vector) in place of r.v, same exponent",
    "checker-doubled": "checkerboard frequency doubled (2N x 2N checks)",
    "sphere-v-from-y": "sphere v = (n.y + 1)/2 (the height) instead of 1 - theta/pi (the polar angle)",
    "no-ambient": "ambient term left out",
    "ambient-per-sample": "ambient*kd added inside the light-sample loop and not averaged (ambient x L; none at L = 1)",
    "ambient-in-shadow-only": "ambient*kd only for occluded light samples (the report's literal reading), averaged",
    "flipped-image": "image rows written upside down",
    "light-centre": "every light sample at the light's centre (a point light)",
    "light-twice-size": "light samples over centre +- edge instead of centre +- edge/2",
    "light-blocks-shadow": "the light's own surface blocks its shadow rays (segment tested up to and including the light point)",
    "invisible-light": "camera rays do not see the area light (they see what is behind it)",
    "two-sided-light": "area light emits (and is seen) on both sides",
    "distance-falloff": "1/r^2 falloff added to every light sample",
    "no-clamp-dots": "n.l and r.v not clamped at 0, no horizon test, shadow rays skip the object they leave (negative diffuse past the terminator)",
    "specular-white": "specular colour ks = 1 (white) instead of the diffuse colour",
    "shared-samples": "every pixel reuses the same pixel jitter and light points (correlated noise; unbiased per pixel)",
}

# Mistakes that only change the 8-bit encoding: refused for PFM output.
ENCODING_MISTAKES = {"no-srgb", "gamma-22", "truncate-8bit"}
