"""Anchor (b): Blender's own metaball polygonizer, timed in-process around
the depsgraph evaluation. Run by:

    blender -b --factory-startup --python blender_metaballs.py -- S1|S2 RESOLUTION [STIFFNESS]

Balls are placed like S1 / S2; each ball's radius is set so that, alone, its
surface has the sphere's radius (Blender's field is stiffness (1 - d^2/R^2)^3
against the threshold). The polygonizer's cell size matches libblend's:
5 / RESOLUTION (the region [-2, 3]^3). Prints one JSON line (best of 3).
"""
import json
import resource
import sys
import time

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
name, res = argv[0], int(argv[1])
stiff = float(argv[2]) if len(argv) > 2 else 2.0  # Blender's default stiffness is 2
if name == "S1":
    balls = [((0, 0, 0), 1.0), ((1.2, 0, 0), 1.0), ((0, 1.2, 0), 1.0)]
else:
    balls = [((-0.25 + 0.5 * i, -0.25 + 0.5 * j, -0.25 + 0.5 * k), 0.3)
             for k in range(4) for j in range(4) for i in range(4)]

for o in list(bpy.data.objects):
    bpy.data.objects.remove(o)
mb = bpy.data.metaballs.new("bench")
mb.threshold = 0.6
cell = 5.0 / res
mb.resolution = cell
mb.render_resolution = cell
mb.update_method = "UPDATE_ALWAYS"  # full resolution, every change
# alone: stiff (1 - d^2/R^2)^3 = threshold  ->  d = R sqrt(1 - (threshold/stiff)^(1/3))
shrink = (1.0 - (mb.threshold / stiff) ** (1.0 / 3.0)) ** 0.5
for (c, r) in balls:
    e = mb.elements.new()
    e.co = c
    e.radius = r / shrink
    e.stiffness = stiff
obj = bpy.data.objects.new("bench", mb)
bpy.context.scene.collection.objects.link(obj)
rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss

best, tris, verts = 1e30, 0, 0
for _ in range(3):
    mb.elements[0].co = mb.elements[0].co  # touch the data: re-polygonize
    mb.update_tag()
    t0 = time.perf_counter()
    dg = bpy.context.evaluated_depsgraph_get()
    dg.update()
    ev = obj.evaluated_get(dg)
    me = ev.to_mesh()
    t = time.perf_counter() - t0
    me.calc_loop_triangles()
    tris, verts = len(me.loop_triangles), len(me.vertices)
    ev.to_mesh_clear()
    best = min(best, t)
print("BENCH " + json.dumps({"tool": "blender-metaballs", "resolution": res, "seconds": best,
                             "triangles": tris, "vertices": verts,
                             "peak_rss_kb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss,
                             "rss_before_kb": rss0}))
