#!/usr/bin/env python3
"""Glint's BVH against Embree 3, ray for ray: the same meshes and rays traced by
Glint (`cargo bench -p glint-tests --bench peer`) and by `measure/embree/peer.cpp`,
the two taking turns, on one thread and on all of them.

    measure/embree/compare.py                       # 70k, 1M and 4M triangles
    measure/embree/compare.py --rounds 3 1000000    # one size

Installs Embree 3 first if it is missing (measure/embree/install.sh, as root).
Prints a Markdown table per mesh size and thread count: each query's rays per
second for Glint's best way of tracing those rays and Embree's, with the ratio,
medians over the rounds with their range. Writes its inputs under
target/embree/ (about 90 MB for the three sizes).
"""
import argparse
import os
import re
import statistics
import subprocess
import sys

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
WORK = os.path.join(ROOT, "target", "embree")
PEER = os.path.join(WORK, "peer")


class Failure(Exception):
    """A failure reported as one line."""


def run(cmd, **kw):
    try:
        return subprocess.run(cmd, check=True, text=True, **kw)
    except FileNotFoundError:
        raise Failure(f"{cmd[0]} is not installed")
    except subprocess.CalledProcessError as e:
        raise Failure(f"`{' '.join(map(str, cmd))}` failed (exit status {e.returncode})")


def prepare(sizes):
    if not os.path.exists("/usr/include/embree3/rtcore.h"):
        run([os.path.join(ROOT, "measure", "embree", "install.sh")])
    os.makedirs(WORK, exist_ok=True)
    run(["g++", "-O3", "-march=native", "-std=c++17", os.path.join(ROOT, "measure", "embree", "peer.cpp"),
         "-o", PEER, "-lembree3", "-lpthread"])
    run(["cargo", "bench", "-q", "-p", "glint-tests", "--bench", "peer", "--", "write", WORK]
        + [str(s) for s in sizes], cwd=ROOT, stdout=subprocess.DEVNULL)


def measure(cmd):
    """The lines `name<TAB>value unit` a peer prints, as {name: value}."""
    out = run(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL).stdout
    values = {}
    for line in out.splitlines():
        name, _, value = line.partition("\t")
        number = re.match(r"[0-9.]+", value)
        if number:
            values[name] = float(number.group())
    return values


def best(values, kind_query):
    """The largest rate among the lines that start with `kind_query`, and its way."""
    rates = {k: v for k, v in values.items() if k.startswith(kind_query)}
    way = max(rates, key=rates.get)
    return rates[way], way[len(kind_query) + 2:]


ROWS = [
    ("coherent closest", "camera rays, closest hit"),
    ("incoherent closest", "random rays, closest hit"),
    ("incoherent any", "random rays, any hit within 1"),
    ("shadow any", "shadow rays to an area light"),
]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sizes", nargs="*", type=int, default=[70_000, 1_000_000, 4_000_000])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--threads", default=f"1,{os.cpu_count()}")
    args = parser.parse_args()
    prepare(args.sizes)
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
    print(f"machine: {cpu}, {os.cpu_count()} cores; Embree 3 (Debian's libembree-dev)\n")
    for size in args.sizes:
        for threads in sorted({int(t) for t in args.threads.split(",")}):
            glint, embree = [], []
            for _ in range(args.rounds):
                glint.append(measure(["cargo", "bench", "-q", "-p", "glint-tests", "--bench", "peer", "--",
                                      "run", WORK, str(size), str(threads)]))
                embree.append(measure([PEER, WORK, str(size), str(threads)]))
            print(f"### {size:,} triangles, {threads} thread{'s' if threads > 1 else ''}\n")
            print("| rays | Glint M rays/s | Embree M rays/s | Glint / Embree |")
            print("|---|---|---|---|")
            for key, label in ROWS:
                g = [best(v, key) for v in glint]
                e = [best(v, key) for v in embree]
                ratios = [a[0] / b[0] for a, b in zip(g, e)]
                gm, em = statistics.median(x[0] for x in g), statistics.median(x[0] for x in e)
                print(f"| {label} | {gm:.2f} ({g[0][1]}) | {em:.2f} ({e[0][1]}) | "
                      f"**{statistics.median(ratios):.2f}×** ({min(ratios):.2f}–{max(ratios):.2f}) |")
            gb = statistics.median(v["build"] for v in glint)
            eb = statistics.median(v["build"] for v in embree)
            print(f"| BVH build, ms | {gb:.0f} | {eb:.0f} | {gb / eb:.2f}× Embree's time |")
            gbytes = statistics.median(v["bytes per triangle"] for v in glint)
            ebytes = statistics.median(v["bytes per triangle"] for v in embree)
            print(f"| bytes per triangle (mesh and BVH) | {gbytes:.0f} | {ebytes:.0f} | |\n")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except Failure as e:
        print(f"compare.py: error: {e}", file=sys.stderr)
        sys.exit(1)
    except KeyboardInterrupt:
        sys.exit(130)
