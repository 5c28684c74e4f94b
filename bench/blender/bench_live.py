"""Blender add-on benchmark, in headless Blender (bench/run_blender_bench.sh):

    blender -b --factory-startup --python bench_live.py -- ADDON_PARENT SOURCE_DIR

1. Parameter change -> updated mesh at viewport resolution (64 cells across
   the region) for S1 (three spheres) and S2 (64 spheres): the blend's r is
   set (its update callback marks the field dirty), then the add-on's own
   timer function runs as Blender's main loop would (again after the
   interval it returns) until the new mesh is in the Blender mesh. The analytic normals that follow once the
   field is idle (0.3 s later) are timed separately. 15 changes each. The
   same with the add-on's Viewport Simplify preference at 0.5 cells (Coarse
   First, as shipped), and both again at 128 cells: a blend parameter
   remeshes every block, the case where Coarse First gains least.
2. Next to it, Blender's own metaballs: the same balls (S1 / S2 placement,
   radii matched as in bench/mesh/blender_metaballs.py), polygonized at the
   same cell size, time of the depsgraph update after changing one ball.
3. Moving a ~1M-triangle libblend mesh into a Blender mesh: foreach_set with
   Blender's smooth normals, with libblend's analytic normals as custom split
   normals, and the plain from_pydata path as the baseline.
Prints one "BENCH {json}" line per measurement.
"""
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
PREFS = bpy.context.preferences.addons["libblend_blender"].preferences
from libblend_blender import libhandle, live  # noqa: E402

for o in list(bpy.data.objects):
    bpy.data.objects.remove(o)
REPEAT = 15


RESULTS = []


def report(**kw):
    RESULTS.append(kw)
    print("BENCH " + json.dumps(kw), flush=True)


def live_update(name, scene_file, viewport_simplify=0.0, cells=64):
    """the live update of name's blend parameter (every block remeshed);
    viewport_simplify: the add-on's Viewport Simplify preference (0: the
    unsimplified mesh; 0.5 as shipped)"""
    for o in list(bpy.data.objects):  # alone: the preference remeshes every field
        bpy.data.objects.remove(o)
    PREFS.viewport_simplify = viewport_simplify
    bpy.ops.libblend.import_scene(filepath=os.path.join(SRC, "scenes", scene_file))
    out = bpy.context.view_layer.objects.active
    out.libblend.preview_resolution = cells
    live.update_now(out)
    root = [c for c in out.children if c.libblend.kind == "BLEND"][0]
    r0 = root.libblend.r
    times, parts = [], []
    for i in range(REPEAT):
        t0 = time.perf_counter()
        root.libblend.r = r0 * (1.0 + 0.04 * ((i % 2) + 1))  # update callback -> dirty
        st = live.state_of(out)
        # Blender calls the timer again after the interval it returns
        wait = live.tick()
        while wait is not None and (st.dirty or st.job is not None):
            time.sleep(wait)
            wait = live.tick()
        times.append(time.perf_counter() - t0)
        while live.tick() is not None:  # the idle normals, not timed here
            time.sleep(live.TICK)
        assert not st.error, st.status
        parts.append(st.last)
    tris = len(out.data.polygons)
    report(what="live update" if not viewport_simplify else "live update, viewport simplify",
           scene=name, cells=cells, triangles=tris,
           median_ms=1000 * statistics.median(times), max_ms=1000 * max(times),
           libblend_ms=1000 * statistics.median(p["mesh"] for p in parts),
           apply_ms=1000 * statistics.median(p["apply"] for p in parts))
    if viewport_simplify or cells != 64:
        return
    job = live.prepare(out, 64)
    job.run()
    t0 = time.perf_counter()
    live.set_normals(out.data, job.mesh)
    out.data.update()
    report(what="idle analytic normals", scene=name, ms=1000 * (time.perf_counter() - t0))
    # the synchronous path (Update button, renders)
    ts = []
    for i in range(5):
        root.libblend.live = False
        t0 = time.perf_counter()
        live.update_now(out)
        ts.append(time.perf_counter() - t0)
    report(what="update_now", scene=name, cells=64, median_ms=1000 * statistics.median(ts))


def metaballs(name, res):
    if name == "S1":
        balls = [((0, 0, 0), 1.0), ((1.2, 0, 0), 1.0), ((0, 1.2, 0), 1.0)]
    else:
        balls = [((-0.25 + 0.5 * i, -0.25 + 0.5 * j, -0.25 + 0.5 * k), 0.3)
                 for k in range(4) for j in range(4) for i in range(4)]
    mb = bpy.data.metaballs.new("mb-" + name)
    mb.threshold = 0.6
    mb.resolution = mb.render_resolution = 5.0 / res  # region [-2, 3]^3, like the scenes
    mb.update_method = "UPDATE_ALWAYS"
    shrink = (1.0 - (mb.threshold / 2.0) ** (1.0 / 3.0)) ** 0.5
    for (c, r) in balls:
        e = mb.elements.new()
        e.co, e.radius, e.stiffness = c, r / shrink, 2.0
    obj = bpy.data.objects.new("mb-" + name, mb)
    bpy.context.scene.collection.objects.link(obj)
    dg = bpy.context.evaluated_depsgraph_get()
    dg.update()
    times = []
    for i in range(REPEAT):
        t0 = time.perf_counter()
        mb.elements[0].radius *= 1.0 + 0.01 * (1 if i % 2 else -1)
        dg.update()
        ev = obj.evaluated_get(dg)
        me = ev.to_mesh()
        n = len(me.polygons)
        ev.to_mesh_clear()
        times.append(time.perf_counter() - t0)
    report(what="metaball update", scene=name, cells=res, faces=n,
           median_ms=1000 * statistics.median(times), max_ms=1000 * max(times))
    bpy.data.objects.remove(obj)


live_update("S1", "bench-s1-three-spheres.json")
live_update("S1", "bench-s1-three-spheres.json", 0.5)
metaballs("S1", 64)
live_update("S2", "bench-s2-64-spheres.json")
live_update("S2", "bench-s2-64-spheres.json", 0.5)
metaballs("S2", 64)
for vs in (0.0, 0.5):  # the same at 128 cells
    live_update("S1", "bench-s1-three-spheres.json", vs, 128)
    live_update("S2", "bench-s2-64-spheres.json", vs, 128)
PREFS.viewport_simplify = 0.0

# ---- 1M triangles into a Blender mesh
lib = libhandle.library()
with lib.load_scene(os.path.join(SRC, "scenes", "bench-s2-64-spheres.json")) as sc, \
        sc.compile() as ev:
    big = ev.mesh(*sc.bounds, resolution=260)
nt = len(big.triangles)
for normals in ("FACES", "ANALYTIC"):
    ts = []
    for _ in range(3):
        me = bpy.data.meshes.new("big")
        t0 = time.perf_counter()
        live.set_mesh_data(me, big, normals)
        ts.append(time.perf_counter() - t0)
        assert len(me.polygons) == nt
        bpy.data.meshes.remove(me)
    report(what="1M transfer", normals=normals, triangles=nt, vertices=len(big.positions),
           best_s=min(ts), median_s=statistics.median(ts))
me = bpy.data.meshes.new("big")
t0 = time.perf_counter()
me.from_pydata(big.positions.tolist(), [], big.triangles.tolist())
me.update()
report(what="1M transfer", normals="from_pydata baseline", triangles=nt, best_s=time.perf_counter() - t0)
metaballs("S2", 260)

# ---- the table (docs/blender.md)
R = {(r["what"], r.get("scene"), r.get("normals"), r.get("cells")): r for r in RESULTS}
print("\n| scene (64 cells) | libblend live update: median / max | of which libblend / Blender mesh "
      "data | idle analytic normals | with Viewport Simplify 0.5: median / max | "
      "Blender metaballs update | ratio (without / with Viewport Simplify) |")
print("|---|---|---|---|---|---|---|")
for sc in ("S1", "S2"):
    lu, mb = R[("live update", sc, None, 64)], R[("metaball update", sc, None, 64)]
    dv = R[("live update, viewport simplify", sc, None, 64)]
    nm = R[("idle analytic normals", sc, None, None)]
    print("| %s | %.0f / %.0f ms (%d triangles) | %.0f / %.0f ms | %.0f ms | %.0f / %.0f ms (%d "
          "triangles) | %.1f ms (%d quads) | %.1fx / %.1fx |"
          % (sc, lu["median_ms"], lu["max_ms"], lu["triangles"], lu["libblend_ms"], lu["apply_ms"],
             nm["ms"], dv["median_ms"], dv["max_ms"], dv["triangles"], mb["median_ms"], mb["faces"],
             lu["median_ms"] / mb["median_ms"], dv["median_ms"] / mb["median_ms"]))
print("\n| scene (128 cells) | live update: median / max | with Viewport Simplify 0.5 | ratio |")
print("|---|---|---|---|")
for sc in ("S1", "S2"):
    lu, dv = R[("live update", sc, None, 128)], R[("live update, viewport simplify", sc, None, 128)]
    print("| %s | %.0f / %.0f ms (%d triangles) | %.0f / %.0f ms (%d triangles) | %.2fx |"
          % (sc, lu["median_ms"], lu["max_ms"], lu["triangles"], dv["median_ms"], dv["max_ms"],
             dv["triangles"], dv["median_ms"] / lu["median_ms"]))
print("\n| moving %d triangles into a Blender mesh | seconds |" % nt)
print("|---|---|")
for k in ("FACES", "ANALYTIC", "from_pydata baseline"):
    r = R[("1M transfer", None, k, None)]
    print("| %s | %.2f |" % ({"FACES": "foreach_set, Blender's smooth normals (Auto above 250k)",
                              "ANALYTIC": "foreach_set + libblend's normals as custom normals",
                              "from_pydata baseline": "from_pydata (the plain Python way)"}[k],
                             r["best_s"]))
mb = R[("metaball update", "S2", None, 260)]
print("| Blender metaballs, S2 at 260 cells (%d quads), one update | %.2f |"
      % (mb["faces"], mb["median_ms"] / 1000))
