"""The add-on's live update with and without Simplify, in headless Blender
(bench/run_simplify_bench.sh):

    blender -b --factory-startup --python bench_simplify.py -- ADDON_PARENT SOURCE_DIR

For a CSG scene (two overlapping boxes, with Sharp Features), the stool of
the bounded-blending paper (with Sharp Features) and S2 (64 spheres), at 64
and 128 cells: the synchronous update (live.update_now: mesh, then the
Blender mesh data, Blender's own normals) plain, with Merge Flat, and with
Simplify 0.1 cells, alternating, 7 rounds; medians, and of each the libblend and Blender parts.
Then the floor of any edge-collapse simplifier: meshoptimizer's
meshopt_simplify (Debian's libmeshoptimizer-dev, through ctypes; a
benchmark dependency only) on the plain mesh Blender holds, to 0.1 cells
of its quadric error and with no field to check, best of 7 in this
process, against what Blender saves on the triangles it removes (its own
intake time per triangle in this run). And the floor of any
simplification checked against the field: one evaluation of the field at
points a cell apart over the simplified mesh's triangles (the simplifier's
own lattice, corners left out), on the add-on's threads, best of 7.
And the floor of a coarse-first adaptive mesher (bench/mesh/coarse_floor.py:
the uniform mesher at half the resolution, the field once a cell apart
over its triangles, the fine mesher only where a coarse cell fails the
tolerance, seams free), at 0.1, 0.25, 0.5 and 1 cells, with Blender's intake
per triangle of this run. Prints one "BENCH {json}" line per
configuration, then tables."""
import json
import os
import statistics
import sys
import time

import bpy
import addon_utils
import numpy as np

argv = sys.argv[sys.argv.index("--") + 1:]
ADDON_PARENT, SRC = argv[:2]
sys.path.insert(0, ADDON_PARENT)
os.environ.pop("LIBBLEND_LIBRARY", None)
addon_utils.enable("libblend_blender", default_set=True)
# Viewport Simplify off: the configurations below say what they simplify
bpy.context.preferences.addons["libblend_blender"].preferences.viewport_simplify = 0.0
from libblend_blender import libhandle, live  # noqa: E402

for o in list(bpy.data.objects):
    bpy.data.objects.remove(o)
ROUNDS = 7
SCENES = (("two boxes (CSG)", os.path.join(SRC, "tests", "data", "features", "two-boxes.json"),
           True),
          ("stool", os.path.join(SRC, "scenes", "hsu-bounded-fig7-stool.json"), True),
          ("S2", os.path.join(SRC, "scenes", "bench-s2-64-spheres.json"), False))
CONFIGS = (("plain", 0.0, False), ("merge_flat", 0.0, True), ("simplified", 0.1, False))
sys.path.insert(0, os.path.join(SRC, "bench", "mesh"))
import coarse_floor  # noqa: E402
import meshopt_floor  # noqa: E402

MESHOPT = meshopt_floor.load()
if MESHOPT is None:
    print("meshoptimizer not found (apt-get install libmeshoptimizer-dev): its floor is left out")


def meshopt_floor_ms(out, res, tol=0.1):
    """meshopt_simplify on the mesh Blender holds: (best milliseconds, triangles)."""
    me = out.data
    pos = np.empty(3 * len(me.vertices), np.float32)
    me.vertices.foreach_get("co", pos)
    idx = np.empty(3 * len(me.polygons), np.uint32)
    me.polygons.foreach_get("vertices", idx)  # triangles only: the add-on makes no others
    bmin, bmax = live.region_of(out)
    h = max(b - a for a, b in zip(bmin, bmax)) / res
    F, _own, ms = meshopt_floor.simplify(MESHOPT, pos.reshape(-1, 3), idx.reshape(-1, 3),
                                         tol * h, ROUNDS)
    return ms, len(F)


def check_floor(path, res, feat, tol=0.1):
    """(best milliseconds, points): the field once at points a cell apart
    over the simplified mesh's triangles, corners left out, as a check of
    that mesh would need"""
    sc = libhandle.library().load_scene(path)
    with sc:
        with sc.compile() as ev:
            lo, hi = sc.bounds
            h = max(b - a for a, b in zip(lo, hi)) / res
            m = ev.mesh(lo, hi, resolution=res, threads=libhandle.threads(), features=feat,
                        simplify=tol)
            P = meshopt_floor.lattice(m.positions, m.triangles, h, corners=False)
            ms, _ = meshopt_floor.best_ms(lambda: ev.eval(P, threads=libhandle.threads()),
                                          ROUNDS)
    return {"ms": ms, "points": len(P)}


COARSE_TOLERANCES = (0.1, 0.25, 0.5, 1.0)


def coarse_first_floor(path, res, feat, plain):
    """coarse_floor.measure on the add-on's threads, and for each tolerance
    the modelled update: that floor's libblend part plus Blender's intake of
    its triangles at this run's rate, against the uniform mesher's time plus
    Blender's intake of the plain mesh"""
    sc = libhandle.library().load_scene(path)
    with sc:
        with sc.compile() as ev:
            lo, hi = sc.bounds
            r = coarse_floor.measure(ev, lo, hi, res, COARSE_TOLERANCES,
                                     threads=libhandle.threads(), features=feat, rounds=ROUNDS)
    per_tri = plain["blender_ms"] / plain["triangles"]
    r["uniform_update_ms"] = r["fine_ms"] + plain["blender_ms"]
    for t in r["tolerances"].values():
        t["update_ms"] = (r["coarse_ms"] + r["check_ms"] + (1 - t["skipped"]) * r["fine_ms"]
                          + per_tri * t["triangles"])
    return r


rows = []
for name, path, feat in SCENES:
    bpy.ops.libblend.import_scene(filepath=path, with_render=False)
    out = bpy.context.view_layer.objects.active
    out.libblend.live = False
    out.libblend.sharp_features = feat
    out.libblend.normals = "FACES"
    for res in (64, 128):
        out.libblend.preview_resolution = res
        t = {k: [] for k, _s, _m in CONFIGS}
        parts = {k: [] for k, _s, _m in CONFIGS}
        tris = {}
        for _ in range(ROUNDS):
            for k, simp, flat in CONFIGS:
                out.libblend.simplify = simp
                out.libblend.merge_flat = flat
                t0 = time.perf_counter()
                ok, msg = live.update_now(out)
                t[k].append(time.perf_counter() - t0)
                assert ok, msg
                parts[k].append(live.state_of(out).last)
                tris[k] = len(out.data.polygons)
        r = {"scene": name, "cells": res, "features": feat}
        for k, _s, _m in CONFIGS:
            r[k] = {"ms": 1000 * statistics.median(t[k]), "triangles": tris[k],
                    "libblend_ms": 1000 * statistics.median(p["mesh"] for p in parts[k]),
                    "blender_ms": 1000 * statistics.median(p["apply"] for p in parts[k])}
        if MESHOPT is not None:
            out.libblend.simplify, out.libblend.merge_flat = 0.0, False
            ok, msg = live.update_now(out)
            assert ok, msg
            ms, n = meshopt_floor_ms(out, res)
            a = r["plain"]
            r["meshopt"] = {"ms": ms, "triangles": n,
                            "blender_saves_ms": a["blender_ms"] * (1 - n / a["triangles"])}
        r["check"] = check_floor(path, res, feat)
        r["coarse_first"] = coarse_first_floor(path, res, feat, r["plain"])
        print("BENCH " + json.dumps(r), flush=True)
        rows.append(r)

print("\n| scene | cells | update without (libblend / Blender) | with Merge Flat (libblend / "
      "Blender) | with Simplify 0.1 (libblend / Blender) | triangles without / merged / "
      "simplified | merged / without | simplified / without |")
print("|---|---|---|---|---|---|---|---|")
for r in rows:
    a, m, b = r["plain"], r["merge_flat"], r["simplified"]
    print("| %s | %d | %.0f ms (%.0f / %.0f) | %.0f ms (%.0f / %.0f) | %.0f ms (%.0f / %.0f) | "
          "%d / %d / %d | %.2fx | %.1fx |" %
          (r["scene"], r["cells"], a["ms"], a["libblend_ms"], a["blender_ms"], m["ms"],
           m["libblend_ms"], m["blender_ms"], b["ms"], b["libblend_ms"], b["blender_ms"],
           a["triangles"], m["triangles"], b["triangles"], m["ms"] / a["ms"], b["ms"] / a["ms"]))
if MESHOPT is not None:
    print("\n| scene | cells | triangles | meshoptimizer, 0.1 cells, no field check | "
          "triangles left | Blender saves on them | floor / saving |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        o = r["meshopt"]
        print("| %s | %d | %d | %.1f ms | %d | %.1f ms | %.1fx |" %
              (r["scene"], r["cells"], r["plain"]["triangles"], o["ms"], o["triangles"],
               o["blender_saves_ms"], o["ms"] / o["blender_saves_ms"]))
print("\n| scene | cells | simplified triangles | Blender saves on them | the field once at "
      "their points (points) | check / saving |")
print("|---|---|---|---|---|---|")
for r in rows:
    a, b, c = r["plain"], r["simplified"], r["check"]
    saves = a["blender_ms"] - b["blender_ms"]
    print("| %s | %d | %d | %.1f ms | %.1f ms (%d) | %s |" %
          (r["scene"], r["cells"], b["triangles"], saves, c["ms"], c["points"],
           "%.1fx" % (c["ms"] / saves) if saves > 0 else "-"))
print("\n| scene | cells | uniform mesher / half resolution / check (points) | Blender, plain "
      "| uniform update | " + " | ".join("coarse-first floor, %g cells: triangles, update, "
                                        "/ uniform" % t for t in COARSE_TOLERANCES) + " |")
print("|---|---|---|---|---|" + "---|" * len(COARSE_TOLERANCES))
for r in rows:
    c = r["coarse_first"]
    print("| %s | %d | %.1f / %.1f / %.1f ms (%d) | %.1f ms | %.1f ms | " % (
        r["scene"], r["cells"], c["fine_ms"], c["coarse_ms"], c["check_ms"], c["check_points"],
        r["plain"]["blender_ms"], c["uniform_update_ms"]) + " | ".join(
        "%d, %.1f ms, %.2fx" % (t["triangles"], t["update_ms"],
                                t["update_ms"] / c["uniform_update_ms"])
        for t in (c["tolerances"][k] for k in COARSE_TOLERANCES)) + " |")
