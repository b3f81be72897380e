"""The deliberate mistakes (--mistake NAME): fourteen classic student slips, each
a small branch marked "MISTAKE name" where it is made (in camera, geometry,
textures, lighting, integrator, film, explain and stages), so that
tools/student/mistakes.py can see how `glint grade --stages` and
`glint explain --against` name them.  With no --mistake (MISTAKE is None) no
branch is taken and nothing changes.
"""


MISTAKES = {
    "up-flipped": "the camera's up vector flipped (up = forward x right): the image upside down",
    "sphere-u-unwrapped": "sphere u = atan2(-z, x)/2pi left in [-0.5, 0.5) instead of wrapped into [0, 1)",
    "mip-natural-log": "the report's MIP level with the natural log, ln(L/W), instead of log2(L/W)",
    "odd-level-rounded-up": "pyramid levels of odd size rounded up, ceil(side/2) (75x50 -> 38x25), not floor",
    "light-sum-not-divided": "an area light's sum of samples not divided by their number N",
    "light-blocks-itself": "the shadow ray aimed along l from the offset start (the old recipe): the light's "
                           "own surface blocks it where the light is seen at a slant",
    "no-shadow-offset": "shadow rays start exactly at x, blockers at t > 0 (shadow acne)",
    "blinn": "the Phong lobe with the half vector, max(0, n.h)^s, instead of max(0, r.v)^s",
    "view-sign": "the view vector's sign flipped in the specular term (r.(-v))",
    "gamma-22": "8-bit film values with c^(1/2.2) instead of the sRGB curve",
    "no-ambient": "the ambient term (ambient * kd) left out of the local radiance",
    "light-centre": "every area-light sample placed at the light's centre instead of its grid cell's centre",
    "pixel-corner": "camera samples through the grid cells' corners, (i mod k)/k, not their centres (+1/2 left out)",
    "fov-not-halved": "the film's half height f*tan(fov) instead of f*tan(fov/2)",
}
MISTAKE = None


def mistake(name):
    """True where the mistake `name` is switched on (--mistake name)."""
    assert name in MISTAKES, name
    return MISTAKE == name


def switch_on(name):
    """--mistake NAME: make the mistake `name` from now on (None: none)."""
    global MISTAKE
    assert name is None or name in MISTAKES, name
    MISTAKE = name
