"""A student's ray tracer for Glint's course model (Phong shading), written from
Glint's documentation alone (README.md, docs/*.md, the scene files): no Glint
source was read.  Standard library only.

Two commands:

  tracer.py stages SCENE.toml VECTORS_DIR ANSWERS_DIR [--epsilon-fraction F | --epsilon E]
      answers every stage of `glint grade --stages SCENE --write VECTORS_DIR`
      (camera, intersection, texture, lighting, film) into ANSWERS_DIR/STAGE.csv

  tracer.py explain SCENE.toml --pixel X,Y [--spp N] [--sampler grid]
            [--light-samples N] [--light-sampler grid] [--environment-samples 0]
            [--sample K | --all-samples] [--epsilon-fraction F | --epsilon E] -o doc.json
      writes this tracer's glint-explain/1 document for the pixel, to be
      compared with `glint explain SCENE --pixel X,Y ... --against doc.json`

Every rule is cited from the docs it comes from (scene-format.md "How a pixel
is computed" steps 1-13, grading-stages.md, checking-your-ray-tracer.md,
texture-filtering.md, environment-lighting.md).  Arithmetic is in doubles;
Glint's is in 32-bit floats, which the documented tolerances allow for.
"""

import argparse
import os
import sys

from .explain import cmd_explain
from .mistake import MISTAKES, switch_on
from .stages import cmd_stages


def add_mistake_option(p):
    p.add_argument("--mistake", choices=sorted(MISTAKES), default=None, metavar="NAME",
                   help="make one classic student mistake on purpose (for tools/student/mistakes.py): "
                        + "; ".join(f"{k}: {v}" for k, v in MISTAKES.items()))


def add_epsilon_options(p):
    p.add_argument("--epsilon-fraction", type=float, default=1e-4, metavar="F",
                   help="shadow and mirror ray offset as a fraction of the scene's size (scene-format.md step 9: "
                        "1e-5 to 1e-4; default 1e-4)")
    p.add_argument("--epsilon", type=float, default=None, metavar="E",
                   help="an absolute offset, overriding --epsilon-fraction")


def main(argv=None):
    # --help shows this module's docstring, the program's usage
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub_ = ap.add_subparsers(dest="command", required=True)
    a = sub_.add_parser("stages", help="answer glint grade --stages test vectors")
    a.add_argument("scene")
    a.add_argument("vectors")
    a.add_argument("answers")
    add_epsilon_options(a)
    add_mistake_option(a)
    e = sub_.add_parser("explain", help="write a glint-explain/1 document for one pixel")
    e.add_argument("scene")
    e.add_argument("--pixel", required=True)
    e.add_argument("--spp", type=int)
    e.add_argument("--sampler", default="grid")
    e.add_argument("--light-samples", type=int)
    e.add_argument("--light-sampler", default="grid")
    e.add_argument("--environment-samples", type=int, default=0)
    e.add_argument("--texture-level", choices=("footprint", "report"), default="footprint",
                   help="the MIP level image textures are read at: the ray differentials' footprint (default) or "
                        "the course report's log2(L/W) at every camera ray's hit, read trilinearly "
                        "(command-line.md, Textures)")
    g = e.add_mutually_exclusive_group()
    g.add_argument("--sample", type=int, default=0)
    g.add_argument("--all-samples", action="store_true")
    add_epsilon_options(e)
    add_mistake_option(e)
    e.add_argument("-o", "--output", default="-")
    args = ap.parse_args(argv)
    switch_on(args.mistake)
    try:
        if args.command == "stages":
            cmd_stages(args)
        else:
            cmd_explain(args)
    except SystemExit:
        raise
    except Exception as exc:  # one line on stderr, non-zero status (TRACER_DEBUG=1: the traceback)
        if os.environ.get("TRACER_DEBUG"):
            raise
        print(f"tracer.py: error: {type(exc).__name__}: {exc}", file=sys.stderr)
        sys.exit(1)
