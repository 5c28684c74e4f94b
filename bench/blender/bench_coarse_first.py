"""The add-on's live update with Simplify's two methods against none
(bench/run_coarse_first_bench.sh; docs/meshing.md, Coarse first):

    blender -b --factory-startup --python bench_coarse_first.py -- ADDON_PARENT SOURCE_DIR

A scene is imported as a field (normals 'FACES', Blender's own, as for the
largest live meshes; the field's mesh cache on, the add-on's default); the
primitive nearest the region's middle moves by 1 % of the region, back and
forth, and each live update is timed as bench_incremental.py times it (the
field marked dirty, the add-on's timer run until the new mesh is in the
Blender mesh: scene text, compile, mesh through the cache, mesh data). For
each configuration (no Simplify; Simplify 0.25 and 1 cell with Coarse First;
Simplify 0.25 with the collapses) a first update outside the timing (the
cache then holds that configuration's blocks), then ROUNDS timed moves; the
configurations take turns REPS times and each one's median over all its
moves is reported, with the libblend and Blender parts. Prints "BENCH
{json}" lines and a table.
"""
import json
import os
import statistics
import sys
import time

import bpy
import addon_utils
import mathutils

argv = sys.argv[sys.argv.index("--") + 1:]
ADDON_PARENT, SRC = argv[:2]
sys.path.insert(0, ADDON_PARENT)
os.environ.pop("LIBBLEND_LIBRARY", None)
addon_utils.enable("libblend_blender", default_set=True)
from libblend_blender import live, tree  # noqa: E402

for o in list(bpy.data.objects):
    bpy.data.objects.remove(o)
ROUNDS, REPS = 5, 3
SCENES = (("S2", os.path.join(SRC, "scenes", "bench-s2-64-spheres.json")),
          ("S1", os.path.join(SRC, "scenes", "bench-s1-three-spheres.json")),
          ("stool", os.path.join(SRC, "scenes", "hsu-bounded-fig7-stool.json")))
CONFIGS = (("plain", 0.0, "COLLAPSE"), ("coarse 0.25", 0.25, "COARSE"),
           ("coarse 1", 1.0, "COARSE"), ("collapse 0.25", 0.25, "COLLAPSE"))


def moves(out, mover, step, st, n, times, parts):
    for i in range(n):
        t0 = time.perf_counter()
        mover.location.x += step if i % 2 == 0 else -step
        live.mark_dirty(mover)
        wait = live.tick()
        while wait is not None and (st.dirty or st.job is not None):
            time.sleep(wait)
            wait = live.tick()
        times.append(time.perf_counter() - t0)
        assert not st.error, st.status
        parts.append((st.last["mesh"], st.last["apply"]))
        while live.tick() is not None:
            time.sleep(live.TICK)


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
        times = {k: [] for k, _t, _m in CONFIGS}
        parts = {k: [] for k, _t, _m in CONFIGS}
        tris = {}
        for _ in range(REPS):
            for k, tol, method in CONFIGS:
                out.libblend.live = False
                out.libblend.simplify, out.libblend.simplify_method = tol, method
                ok, msg = live.update_now(out)
                assert ok, msg
                out.libblend.live = True
                moves(out, mover, step, live.state_of(out), ROUNDS, times[k], parts[k])
                tris[k] = len(out.data.polygons)
        out.libblend.live = False
        r = {"scene": name, "cells": res}
        for k, _t, _m in CONFIGS:
            r[k] = {"ms": 1000 * statistics.median(times[k]), "triangles": tris[k],
                    "libblend_ms": 1000 * statistics.median(p[0] for p in parts[k]),
                    "blender_ms": 1000 * statistics.median(p[1] for p in parts[k])}
        print("BENCH " + json.dumps(r), flush=True)
        rows.append(r)
    out.libblend.simplify = 0.0
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)

print("\n| scene | cells | " + " | ".join("%s: update (libblend / Blender), triangles" % k
                                          for k, _t, _m in CONFIGS) + " | " +
      " | ".join("%s / plain" % k for k, _t, _m in CONFIGS[1:]) + " |")
print("|---|---|" + "---|" * (2 * len(CONFIGS) - 1))
for r in rows:
    print("| %s | %d | " % (r["scene"], r["cells"]) + " | ".join(
        "%.1f ms (%.1f / %.1f), %d" % (r[k]["ms"], r[k]["libblend_ms"], r[k]["blender_ms"],
                                       r[k]["triangles"]) for k, _t, _m in CONFIGS) + " | " +
        " | ".join("%.2fx" % (r[k]["ms"] / r["plain"]["ms"]) for k, _t, _m in CONFIGS[1:]) +
        " |")
