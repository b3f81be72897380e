#!/usr/bin/env python3
"""Writes a displaced grid of about N triangles as an OBJ file, for measuring
what meshes of millions of triangles cost (docs/speed.md, "Memory").

    measure/speed/grid_obj.py 1000000 /tmp/grid1m.obj

The grid spans [-2, 2] in x and z at y = 0.1·sin(7x)·cos(5z): two triangles per
quad, ceil(sqrt(N / 2)) quads a side.
"""
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "meshes"))
from obj_file import write_atomically  # noqa: E402


def main() -> int:
    if len(sys.argv) != 3 or not sys.argv[1].isdigit() or int(sys.argv[1]) < 2:
        print("usage: grid_obj.py TRIANGLES FILE (TRIANGLES at least 2)", file=sys.stderr)
        return 2
    n = max(1, math.ceil(math.sqrt(int(sys.argv[1]) / 2)))
    path = sys.argv[2]
    status = write_atomically(path, lambda partial: write_grid(n, partial), "grid_obj.py")
    if status != 0:
        return status
    print(f"wrote {path}: {2 * n * n} triangles")
    return 0


def write_grid(n: int, path: str) -> None:
    with open(path, "w") as out:
        for j in range(n + 1):
            for i in range(n + 1):
                x, z = i / n * 4 - 2, j / n * 4 - 2
                out.write(f"v {x:.5f} {0.1 * math.sin(7 * x) * math.cos(5 * z):.5f} {z:.5f}\n")
        for j in range(n):
            for i in range(n):
                a = j * (n + 1) + i + 1
                out.write(f"f {a} {a + 1} {a + n + 2}\nf {a} {a + n + 2} {a + n + 1}\n")


if __name__ == "__main__":
    sys.exit(main())
