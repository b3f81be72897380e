"""The film (scene-format.md step 13): a linear value to its 8-bit sRGB code.
"""

import math

from .mistake import mistake


def srgb8(c):
    if not (c == c):
        c = 0.0
    c = min(1.0, max(0.0, c))
    if mistake("gamma-22"):
        # MISTAKE gamma-22: a plain power curve instead of the sRGB curve
        return int(math.floor(255 * c ** (1 / 2.2) + 0.5))
    e = 12.92 * c if c <= 0.0031308 else 1.055 * c ** (1 / 2.4) - 0.055
    return int(math.floor(255 * e + 0.5))
