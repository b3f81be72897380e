#!/usr/bin/env python3
"""Writes the terrain of scenes/large/terrain.toml: a heightfield of about N
triangles (default 1,000,000) as an OBJ file, generated rather than committed.

    measure/meshes/terrain.py                                  # scenes/large/terrain.obj
    measure/meshes/terrain.py 4000000 /tmp/terrain-4m.obj

The ground spans [-10, 10] in x and z; its height is a sum of seven octaves of
sine ridges at fixed directions and phases (each octave 1.9 times the frequency
and 0.42 times the amplitude of the one before), so the file is the same on
every run.
Two triangles per grid quad, ceil(sqrt(N / 2)) quads a side; no normals (Glint
computes angle-weighted vertex normals).
"""
import math
import os
import sys

from obj_file import write_atomically

HALF = 10.0
OCTAVES = [
    # (direction angle, phase, frequency, amplitude)
    (0.3 + 1.7 * k, 0.9 * k * k + 0.4, 0.3 * 1.9**k, 1.9 * 0.42**k)
    for k in range(7)
]


def height(x, z):
    h = 0.0
    for angle, phase, frequency, amplitude in OCTAVES:
        u = math.cos(angle) * x + math.sin(angle) * z
        w = -math.sin(angle) * x + math.cos(angle) * z
        h += amplitude * math.sin(frequency * u + phase) * math.cos(0.7 * frequency * w - phase)
    return h


def write_terrain(n, path):
    with open(path, "w") as out:
        out.write(f"# A generated terrain: {n} x {n} quads, {2 * n * n} triangles (measure/meshes/terrain.py)\n")
        for j in range(n + 1):
            z = -HALF + 2.0 * HALF * j / n
            out.write("".join(
                f"v {x:.6f} {height(x, z):.6f} {z:.6f}\n"
                for x in (-HALF + 2.0 * HALF * i / n for i in range(n + 1))
            ))
        row = n + 1
        for j in range(n):
            out.write("".join(
                f"f {a} {a + row} {a + 1}\nf {a + 1} {a + row} {a + row + 1}\n"
                for a in (j * row + i + 1 for i in range(n))
            ))


def main():
    args = sys.argv[1:]
    if len(args) > 2 or (args and not args[0].isdigit()) or (args and int(args[0]) < 2):
        print("usage: terrain.py [TRIANGLES [FILE]] (TRIANGLES at least 2)", file=sys.stderr)
        return 2
    triangles = int(args[0]) if args else 1_000_000
    here = os.path.dirname(os.path.abspath(__file__))
    default = os.path.join(here, "..", "..", "scenes", "large", "terrain.obj")
    path = os.path.normpath(args[1] if len(args) == 2 else default)
    n = max(1, math.ceil(math.sqrt(triangles / 2)))
    status = write_atomically(path, lambda partial: write_terrain(n, partial), "terrain.py")
    if status != 0:
        return status
    print(f"wrote {path}: {2 * n * n} triangles")
    return 0


if __name__ == "__main__":
    sys.exit(main())
