"""The add-on's live update with Simplify's two methods against none
(bench/run_coarse_first_bench.sh; docs/meshing.md, Coarse first):

    blender -b --factory-startup --python bench_coarse_first.py -- ADDON_PARENT SOURCE_DIR

A scene is imported as a field (normals 'FACES', Blender's own, as for the
largest live meshes; the field's mesh cache on, the add-on's default); the
primitive nearest the region's middle moves by 1 % of the region, back and
forth, and each live update is timed as bench_incremental.py times it (the
field marked dirty, the add-on's timer run until the new mesh is in the
Blender mesh: scene text, compile, mesh through the cache, mesh data). For
each configuration (no Simplify; the Viewport Simplify preference at 0.5
cells, Coarse First; the field's Simplify at 0.25 and 1
cell with Coarse First; Simplify 0.25 with the collapses) a first update outside the timing (the
cache then holds that configuration's blocks), then ROUNDS timed moves; the
configurations take turns REPS times and each one's median over all its
moves is reported, with the libblend and Blender parts. Prints "BENCH
{json}" lines and a table.
"""
import json
import os
import statistics
import sys

import bpy
import mathutils

argv = sys.argv[sys.argv.index("--") + 1:]
ADDON_PARENT, SRC = argv[:2]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import addon_bench  # noqa: E402

addon_bench.start(ADDON_PARENT)
from libblend_blender import live, tree  # noqa: E402
ROUNDS, REPS = 5, 3
SCENES = (("S2", os.path.join(SRC, "scenes", "bench-s2-64-spheres.json")),
          ("S1", os.path.join(SRC, "scenes", "bench-s1-three-spheres.json")),
          ("stool", os.path.join(SRC, "scenes", "hsu-bounded-fig7-stool.json")))
# (name, the field's Simplify, its method, the Viewport Simplify preference)
CONFIGS = (("plain", 0.0, "COLLAPSE", 0.0), ("viewport 0.5", 0.0, "COLLAPSE", 0.5),
           ("coarse 0.25", 0.25, "COARSE", 0.0), ("coarse 1", 1.0, "COARSE", 0.0),
           ("collapse 0.25", 0.25, "COLLAPSE", 0.0))
PREFS = bpy.context.preferences.addons["libblend_blender"].preferences


rows = []
for name, path in SCENES:
    bpy.ops.libblend.import_scene(filepath=path, with_render=False)
    out = bpy.context.view_layer.objects.active
    out.libblend.live = False
    out.libblend.normals = "FACES"
    lo, hi = mathutils.Vector(out.libblend.bounds_min), mathutils.Vector(out.libblend.bounds_max)
    prims = [o for o in out.children_recursive if tree.is_node(o) and
             o.libblend.kind == "PRIMITIVE"]
    mover = min(prims, key=lambda o: (o.matrix_world.translation - (lo + hi) / 2).length)
    step = 0.01 * (hi - lo).x
    for res in (64, 128):
        out.libblend.preview_resolution = res
        times = {k: [] for k, *_ in CONFIGS}
        parts = {k: [] for k, *_ in CONFIGS}
        tris = {}
        for _ in range(REPS):
            for k, tol, method, vs in CONFIGS:
                out.libblend.live = False
                out.libblend.simplify, out.libblend.simplify_method = tol, method
                PREFS.viewport_simplify = vs
                ok, msg = live.update_now(out)
                assert ok, msg
                out.libblend.live = True
                for sec, last in addon_bench.live_moves(mover, live.state_of(out), ROUNDS, step):
                    times[k].append(sec)
                    parts[k].append((last["mesh"], last["apply"]))
                tris[k] = len(out.data.polygons)
        out.libblend.live = False
        r = {"scene": name, "cells": res}
        for k, *_ in CONFIGS:
            r[k] = {"ms": 1000 * statistics.median(times[k]), "triangles": tris[k],
                    "libblend_ms": 1000 * statistics.median(p[0] for p in parts[k]),
                    "blender_ms": 1000 * statistics.median(p[1] for p in parts[k])}
        print("BENCH " + json.dumps(r), flush=True)
        rows.append(r)
    out.libblend.simplify = 0.0
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)

print("\n| scene | cells | " + " | ".join("%s: update (libblend / Blender), triangles" % k
                                          for k, *_ in CONFIGS) + " | " +
      " | ".join("%s / plain" % k for k, *_ in CONFIGS[1:]) + " |")
print("|---|---|" + "---|" * (2 * len(CONFIGS) - 1))
for r in rows:
    print("| %s | %d | " % (r["scene"], r["cells"]) + " | ".join(
        "%.1f ms (%.1f / %.1f), %d" % (r[k]["ms"], r[k]["libblend_ms"], r[k]["blender_ms"],
                                       r[k]["triangles"]) for k, *_ in CONFIGS) + " | " +
        " | ".join("%.2fx" % (r[k]["ms"] / r["plain"]["ms"]) for k, *_ in CONFIGS[1:]) +
        " |")
