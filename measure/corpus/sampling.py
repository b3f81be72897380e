"""What to render and how to sample it: the options of one render, and the
sample patterns in the unit square that both the pixels' camera samples and
the area lights' samples take.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass
class Options:
    width: int
    height: int
    spp: int
    sampler: str
    light_samples: int
    light_sampler: str
    seed: int
    mistakes: frozenset


def square_root(n: int) -> int | None:
    k = math.isqrt(n)
    return k if k * k == n else None


def pattern_points(pattern: str, shape: tuple, n: int, rng: np.random.Generator) -> np.ndarray:
    """`shape + (n, 2)` points in [0, 1)^2, n per set.

    grid: the sqrt(n) x sqrt(n) cell centres, cell index k at column k % s,
    row k // s (integrator/src/sampling/pattern.rs `fill_grid`); stratified: one
    uniform point per cell of that grid; random: n uniform points."""
    if pattern == "random":
        return rng.random(shape + (n, 2))
    s = square_root(n)
    k = np.arange(n)
    cells = np.stack([k % s, k // s], axis=-1).astype(np.float64)
    if pattern == "grid":
        return np.broadcast_to((cells + 0.5) / s, shape + (n, 2))
    return (cells + rng.random(shape + (n, 2))) / s  # stratified
