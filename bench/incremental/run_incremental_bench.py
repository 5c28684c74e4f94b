#!/usr/bin/python3
"""Incremental remeshing (lb_mesh_cache): one primitive moved by 1 % of the
region, the mesh through the cache against a full remesh, one thread, in the
same process and alternating (bench/bench_incremental.c). Scenes: a lattice
of 512 spheres (8 x 8 x 8, one displacement union) and the local-blending
paper's five-capsule figure (scenes/bernhardt-figure.json: body, head and
four limbs in a fold of local unions), at 128 and 256 cells. The issue's
bar: at most 0.1 at 256 cells for the lattice. "incr. ms" gives the
previous mesh back to the cache (lb_mesh_cache_recycle, as the add-on's
live update does); "freed" frees it instead.

usage: run_incremental_bench.py BENCH_INCREMENTAL SOURCE_DIR WORK_DIR
"""
import copy
import json
import os
import subprocess
import sys

BIN, SRC, WORK = sys.argv[1:4]
os.makedirs(WORK, exist_ok=True)


def lattice(moved=None, d=0.0):
    args = []
    for q in range(512):
        c = [-1.75 + 0.5 * (q % 8), -1.75 + 0.5 * (q // 8 % 8), -1.75 + 0.5 * (q // 64)]
        if q == moved:
            c[0] += d
        args.append({"type": "sphere", "center": c, "radius": 0.2})
    return {"format": "libblend-scene", "version": 1, "convention": "zero",
            "bounds": {"min": [-2, -2, -2], "max": [2, 2, 2]},
            "root": {"type": "displacement", "op": "union", "r": 0.1, "p": 2, "m": 1,
                     "args": args}}


def write(name, s):
    p = os.path.join(WORK, name)
    with open(p, "w") as f:
        json.dump(s, f)
    return p


# the sphere nearest the middle (4, 4, 4), moved by 1 % of the 4-unit region
mid = 4 + 4 * 8 + 4 * 64
cases = [("lattice of 512 spheres", write("lattice-0.json", lattice()),
          write("lattice-1.json", lattice(mid, 0.04)))]
fig = json.load(open(os.path.join(SRC, "scenes", "bernhardt-figure.json")))
fig2 = copy.deepcopy(fig)
arm = fig2["root"]["args"][2]  # the left arm's capsule
size = max(b - a for a, b in zip(fig["bounds"]["min"], fig["bounds"]["max"]))
for key in ("start", "end"):
    arm[key][0] -= 0.01 * size
cases.append(("five-capsule figure (left arm moved)", write("figure-0.json", fig),
              write("figure-1.json", fig2)))
print("%-38s %5s %9s %9s %6s %9s %6s %14s %9s %8s %17s %5s" % (
    "scene", "cells", "full ms", "incr. ms", "ratio", "freed ms", "ratio", "blocks reused",
    "cache MiB", "compile", "reusing (copied)", "same"))
for name, before, after in cases:
    for res in (128, 256):
        out = subprocess.run([BIN, before, after, str(res), "1"], capture_output=True, text=True,
                             check=True).stdout
        r = json.loads(out)
        print("%-38s %5d %9.1f %9.1f %6.3f %9.1f %6.3f %7d/%-6d %9.1f %6.1fms %9.1fms (%2d) %5s" % (
            name, res, 1000 * r["full_s"], 1000 * r["incremental_s"], r["ratio"],
            1000 * r["incremental_freed_s"], r["ratio_freed"], r["reused"], r["blocks"], r["cache_mib"], 1000 * r["compile_s"], 1000 * r["compile_reusing_s"],
            r["curves_copied"], r["same"]))
        print("BENCH " + json.dumps(dict(r, scene=name, cells=res)), flush=True)
