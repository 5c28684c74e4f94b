"""The add-on's live update of a moved primitive with incremental remeshing,
against the same update without the cache and against Blender's metaballs
with the same number of balls (bench/run_incremental_bench.sh):

    blender -b --factory-startup --python bench_incremental.py -- ADDON_PARENT SOURCE_DIR WORK

A lattice of 512 spheres (8 x 8 x 8, one displacement union, as in
bench/incremental/run_incremental_bench.py) is imported as a field; the
sphere object nearest the middle moves by 1 % of the region, back and forth,
and the live update is timed as in bench_live.py (the field marked dirty,
the add-on's timer run until the new mesh is in the Blender mesh: scene
text, compile, mesh, mesh data; the analytic normals follow when idle), 9
rounds, at 64 and 128 cells: with the field's cache (the add-on's default)
and without it. Then 512 metaballs placed alike (radii matched as in
bench_live.py), polygonized at the same cell size, one ball moved as much:
the depsgraph update and the evaluated mesh. Prints "BENCH {json}" lines and
a table (docs/blender.md).
"""
import json
import os
import statistics
import sys
import time

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
ADDON_PARENT, SRC, WORK = argv[:3]
os.makedirs(WORK, exist_ok=True)
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import addon_bench  # noqa: E402

addon_bench.start(ADDON_PARENT)
from libblend_blender import live, tree  # noqa: E402
ROUNDS = 9
CENTRES = [(-1.75 + 0.5 * (q % 8), -1.75 + 0.5 * (q // 8 % 8), -1.75 + 0.5 * (q // 64))
           for q in range(512)]
RESULTS = []


def report(**kw):
    RESULTS.append(kw)
    print("BENCH " + json.dumps(kw), flush=True)


path = os.path.join(WORK, "lattice-512.json")
with open(path, "w") as f:
    json.dump({"format": "libblend-scene", "version": 1, "convention": "zero",
               "bounds": {"min": [-2, -2, -2], "max": [2, 2, 2]},
               "root": {"type": "displacement", "op": "union", "r": 0.1, "p": 2, "m": 1,
                        "args": [{"type": "sphere", "center": list(c), "radius": 0.2}
                                 for c in CENTRES]}}, f)
bpy.ops.libblend.import_scene(filepath=path, with_render=False)
out = bpy.context.view_layer.objects.active
out.libblend.live = False
spheres = [o for o in out.children_recursive if tree.is_node(o) and
           o.libblend.kind == "PRIMITIVE"]
mid = min(spheres, key=lambda o: (o.matrix_world.translation -
                                  __import__("mathutils").Vector((0.25, 0.25, 0.25))).length)
with_cache = live._State.mesh_cache


def timed(res, cached):
    """the live path, as Blender's loop runs it: the object moves, its field
    is marked dirty (the depsgraph handler's call), and the add-on's timer
    runs until the new mesh is in the Blender mesh (the analytic normals
    follow once the field is idle: not timed, as in bench_live.py)"""
    live._State.mesh_cache = with_cache if cached else (lambda self, lib: (None, None))
    out.libblend.preview_resolution = res
    out.libblend.live = False
    live.update_now(out)
    out.libblend.live = True
    st = live.state_of(out)
    runs = addon_bench.live_moves(mid, st, ROUNDS, 0.04)
    ts, meshes = [r[0] for r in runs], [r[1]["mesh"] for r in runs]
    out.libblend.live = False
    live._State.mesh_cache = with_cache
    cs = st.cache.stats if cached else (0, 0, 0, 0)
    report(what="live update", cells=res, cached=cached, median_ms=1000 * statistics.median(ts),
           mesh_ms=1000 * statistics.median(meshes), triangles=len(out.data.polygons),
           blocks=cs[0], reused=cs[1])


def metaballs(res):
    mb = bpy.data.metaballs.new("mb")
    mb.threshold = 0.6
    mb.resolution = mb.render_resolution = 4.0 / res  # the region [-2, 2]^3
    mb.update_method = "UPDATE_ALWAYS"
    shrink = (1.0 - (mb.threshold / 2.0) ** (1.0 / 3.0)) ** 0.5
    for c in CENTRES:
        e = mb.elements.new()
        e.co, e.radius, e.stiffness = c, 0.2 / shrink, 2.0
    obj = bpy.data.objects.new("mb", mb)
    bpy.context.scene.collection.objects.link(obj)
    dg = bpy.context.evaluated_depsgraph_get()
    dg.update()
    k = min(range(512), key=lambda q: sum((a - 0.25) ** 2 for a in CENTRES[q]))
    ts = []
    for i in range(ROUNDS):
        t0 = time.perf_counter()
        mb.elements[k].co.x += 0.04 if i % 2 == 0 else -0.04
        dg.update()
        ev = obj.evaluated_get(dg)
        me = ev.to_mesh()
        n = len(me.polygons)
        ev.to_mesh_clear()
        ts.append(time.perf_counter() - t0)
    report(what="metaball update", cells=res, median_ms=1000 * statistics.median(ts), faces=n)
    bpy.data.objects.remove(obj)
    bpy.data.metaballs.remove(mb)


for res in (64, 128):
    timed(res, True)
    timed(res, False)
    metaballs(res)

R = {(r["what"], r["cells"], r.get("cached")): r for r in RESULTS}
print("\n| 512 spheres, one moved | libblend live update, cached (libblend part) | without the "
      "cache | Blender metaballs (512 balls) | cached / metaballs |")
print("|---|---|---|---|---|")
for res in (64, 128):
    c, f, m = R[("live update", res, True)], R[("live update", res, False)], \
        R[("metaball update", res, None)]
    print("| %d cells (%d triangles; %d of %d blocks reused) | %.0f ms (%.0f) | %.0f ms (%.0f) | "
          "%.0f ms (%d quads) | %.2fx |" % (
              res, c["triangles"], c["reused"], c["blocks"], c["median_ms"], c["mesh_ms"],
              f["median_ms"], f["mesh_ms"], m["median_ms"], m["faces"],
              c["median_ms"] / m["median_ms"]))
