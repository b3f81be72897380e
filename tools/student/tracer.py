#!/usr/bin/env python3
"""A student's ray tracer for Glint's course model (Phong shading), written from
Glint's documentation alone: the command line.  `python3 tracer.py --help` shows
the two commands, `stages` and `explain`.

The tracer itself is the package `student_tracer/` beside this file, one module
a stage of the ray tracer (images, textures, geometry, camera, scene reading,
lighting, film, the integrator, the two commands).  `student_tracer/__init__.py`
and README.md list them from the bottom up: each imports only modules listed
before it, and only this file imports the last, cli.py.
"""

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
if HERE not in sys.path:  # e.g. under `python3 -I`, which leaves the script's folder out
    sys.path.insert(0, HERE)

from student_tracer.cli import main  # noqa: E402

if __name__ == "__main__":
    main()
