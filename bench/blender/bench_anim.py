"""Animation benchmark, in headless Blender (bench/run_blender_anim_bench.sh):

    blender -b --factory-startup --python bench_anim.py -- ADDON SOURCE_DIR WORK_DIR

The S2 lattice (64 spheres of radius 0.3 on a 4x4x4 grid, region [-2, 3]^3) as
a blend of eight blocks of eight: each block is a displacement blend whose m
is keyframed from 1 to 0.3 over 24 frames (m moves each block's reach on the
outer blend, so every frame's surface differs). Render resolution 128 cells.
All in one run, on this machine:

 1. a 24-frame animation render, Cycles 1 sample, 320x240: seconds per frame
    (wall time of render(animation=True) / 24) and, inside it, the add-on's
    own per-frame time (read the tree, mesh in libblend, move the mesh into
    Blender), for threads = 1 and threads = 0 (every CPU);
 2. the same render of a static copy of the mesh (Apply): the Cycles frame
    without any remeshing, the baseline that (1) adds to;
 3. Blender's metaballs, the same 64 balls (radius matched as in
    bench/mesh/blender_metaballs.py), polygonized at the same cell size
    (5 / 128) with each ball's radius keyframed so that every frame changes:
    seconds per frame of the depsgraph update a frame change makes;
 4. baking the 24 frames (render resolution, files written);
 5. the metaballs' own 24-frame Cycles render, animated and not, and of
    their surface converted to a plain mesh (no polygonizing): the frame
    their own update adds to.
Prints one "BENCH {json}" line per measurement and a summary.
"""
import json
import os
import statistics
import sys
import time

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
ADDON, SRC, WORK = argv[:3]
os.makedirs(WORK, exist_ok=True)
sys.path.insert(0, os.path.join(SRC, "tests", "blender"))
import addon_env  # noqa: E402

os.environ.pop("LIBBLEND_LIBRARY", None)
lbb, _name = addon_env.enable(ADDON)
live = lbb.live
FRAMES = 24
RES = 128
W, H = 320, 240


def report(**kw):
    print("BENCH " + json.dumps(kw), flush=True)
    return kw


def clear():
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)


def s2_blocks():
    blocks = []
    for bz in range(2):
        for by in range(2):
            for bx in range(2):
                balls = [{"type": "sphere", "center": [-0.25 + 0.5 * (2 * bx + i),
                                                       -0.25 + 0.5 * (2 * by + j),
                                                       -0.25 + 0.5 * (2 * bz + k)], "radius": 0.3}
                         for k in range(2) for j in range(2) for i in range(2)]
                blocks.append({"type": "displacement", "op": "union", "r": 0.1, "p": 2,
                               "m": 1, "args": balls})
    return {"format": "libblend-scene", "version": 1, "convention": "zero",
            "bounds": {"min": [-2, -2, -2], "max": [3, 3, 3]},
            "root": {"type": "displacement", "op": "union", "r": 0.1, "p": 2, "args": blocks}}


def setup_render(sc):
    cam = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    sc.collection.objects.link(cam)
    cam.location = (0.5, -6.0, 3.5)
    cam.rotation_euler = (1.05, 0, 0)
    sc.camera = cam
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sc.collection.objects.link(sun)
    sun.rotation_euler = (0.6, 0.3, 0)
    sc.render.engine = "CYCLES"
    sc.cycles.samples = 1
    sc.cycles.use_denoising = False
    sc.render.resolution_x, sc.render.resolution_y = W, H
    sc.render.resolution_percentage = 100
    sc.frame_start, sc.frame_end = 1, FRAMES
    sc.render.filepath = os.path.join(WORK, "frames", "f_")


def render_animation(sc, per_frame=None):
    t0 = time.perf_counter()
    bpy.ops.render.render(animation=True)
    return (time.perf_counter() - t0) / FRAMES


sc = bpy.context.scene
clear()
path = os.path.join(WORK, "s2-blocks.json")
with open(path, "w") as f:
    json.dump(s2_blocks(), f)
bpy.ops.libblend.import_scene(filepath=path, with_render=False)
out = bpy.context.view_layer.objects.active
out.libblend.render_resolution = RES
out.libblend.live = False
root = [c for c in out.children if c.libblend.kind == "BLEND"][0]
for blk in [c for c in root.children if c.libblend.kind == "BLEND"]:
    for f, m in ((1, 1.0), (FRAMES, 0.3)):
        blk.libblend.m = m
        blk.keyframe_insert("libblend.m", frame=f)
setup_render(sc)
bpy.ops.wm.save_as_mainfile(filepath=os.path.join(WORK, "bench-anim.blend"))

mesh_times = []


def grab(scene, *_):
    mesh_times.append(dict(live.state_of(out).last))


bpy.app.handlers.render_post.append(grab)
prefs = live.prefs()
results = {}
# analytic normals (the default, Auto, below 250k triangles) on 1 and all
# threads; then Blender's own smooth normals, as the metaballs have
for threads, normals in ((1, "AUTO"), (0, "AUTO"), (0, "FACES")):
    prefs.threads = threads
    out.libblend.normals = normals
    mesh_times.clear()
    sc.frame_set(1)
    per = render_animation(sc)
    tri = len(out.data.polygons)
    libblend = statistics.median(m.get("mesh", 0) for m in mesh_times[1:])
    total = statistics.median(m.get("total", 0) for m in mesh_times[1:])
    results[threads, normals] = report(
        what="render 24 frames, remeshing", threads=threads or os.cpu_count(), normals=normals,
        seconds_per_frame=per, remesh_per_frame=total, libblend_mesh_per_frame=libblend,
        frames=len(mesh_times), triangles_preview=tri)
bpy.app.handlers.render_post.remove(grab)
prefs.threads = 0
out.libblend.normals = "AUTO"

# bake 24 frames
t0 = time.perf_counter()
n, secs = live.bake_frames(out, sc, range(1, FRAMES + 1))
bake_s = report(what="bake 24 frames", seconds=secs, per_frame=secs / FRAMES,
                folder_mb=sum(os.path.getsize(os.path.join(dp, f)) for dp, _d, fs in
                              os.walk(os.path.join(WORK, "libblend_cache")) for f in fs) / 1e6)
out.libblend.use_bake = False

# the baselines: the same render of a static mesh (Apply at render resolution),
# with Blender's smooth normals, then with the analytic ones (the default)
bases = {}
for normals in ("FACES", "AUTO"):
    out.libblend.normals = normals
    bpy.context.view_layer.objects.active = out
    out.select_set(True)
    bpy.ops.libblend.apply(resolution=RES, keep_field=True)
    static = bpy.context.view_layer.objects.active
    out.hide_render = True  # the field itself is not rendered (nor remeshed)
    sc.frame_set(1)
    bases[normals] = report(what="render 24 frames, static mesh (no remeshing)", normals=normals,
                            seconds_per_frame=render_animation(sc),
                            triangles=len(static.data.polygons))
    bpy.data.objects.remove(static)
    out.hide_render = False
base, base_b = bases["AUTO"], bases["FACES"]

# Blender's metaballs: the same balls, each radius keyed so that every frame changes
clear()
mb = bpy.data.metaballs.new("balls")
mb.threshold = 0.6
mb.resolution = mb.render_resolution = 5.0 / RES
mb.update_method = "UPDATE_ALWAYS"
shrink = (1.0 - (mb.threshold / 2.0) ** (1.0 / 3.0)) ** 0.5
mobj = bpy.data.objects.new("balls", mb)
sc.collection.objects.link(mobj)
for k in range(4):
    for j in range(4):
        for i in range(4):
            e = mb.elements.new()
            e.co = (-0.25 + 0.5 * i, -0.25 + 0.5 * j, -0.25 + 0.5 * k)
            e.radius = 0.3 / shrink
for idx in range(len(mb.elements)):
    for f, s in ((1, 1.0), (FRAMES, 1.08)):
        mb.elements[idx].radius = 0.3 / shrink * s
        mb.keyframe_insert('elements[%d].radius' % idx, frame=f)
times = []
sc.frame_set(FRAMES)
for f in range(1, FRAMES + 1):
    t0 = time.perf_counter()
    sc.frame_set(f)
    dg = bpy.context.evaluated_depsgraph_get()
    me = mobj.evaluated_get(dg).to_mesh()
    nq = len(me.polygons)
    mobj.evaluated_get(dg).to_mesh_clear()
    times.append(time.perf_counter() - t0)
meta = report(what="metaballs, frame change (depsgraph + polygonize)", seconds_per_frame=statistics.median(times),
              quads=nq)
# what the metaballs add to the same Cycles frame: their animation rendered, then the same
# balls without animation (polygonized once per frame all the same: Blender re-evaluates them)
setup_render(sc)
sc.frame_set(1)
meta_anim = render_animation(sc)
mb.animation_data_clear()
sc.frame_set(1)
meta_static = render_animation(sc)
# the metaballs' surface as a plain mesh: their Cycles frame without any
# polygonizing, the baseline their own update adds to
dg = bpy.context.evaluated_depsgraph_get()
mesh_copy = bpy.data.objects.new("balls mesh", bpy.data.meshes.new_from_object(mobj.evaluated_get(dg)))
sc.collection.objects.link(mesh_copy)
mobj.hide_render = True
sc.frame_set(1)
meta_mesh = render_animation(sc)
metar = report(what="metaballs, render 24 frames", animated_seconds_per_frame=meta_anim,
               static_seconds_per_frame=meta_static, as_plain_mesh_seconds_per_frame=meta_mesh)

r1, r0, rb = results[1, "AUTO"], results[0, "AUTO"], results[0, "FACES"]
summary = {
    "cycles_frame_static_s": base["seconds_per_frame"],
    "cycles_frame_remeshing_s": {"1 thread": r1["seconds_per_frame"], "all": r0["seconds_per_frame"],
                                 "all, Blender normals": rb["seconds_per_frame"]},
    "remesh_per_frame_s": {"1 thread": r1["remesh_per_frame"], "all": r0["remesh_per_frame"],
                           "all, Blender normals": rb["remesh_per_frame"]},
    "cycles_frame_static_blender_normals_s": base_b["seconds_per_frame"],
    "remesh_share_of_static_frame": {"1 thread": r1["remesh_per_frame"] / base["seconds_per_frame"],
                                     "all": r0["remesh_per_frame"] / base["seconds_per_frame"],
                                     "all, Blender normals (its own static frame)":
                                     rb["remesh_per_frame"] / base_b["seconds_per_frame"]},
    "metaballs_per_frame_s": meta["seconds_per_frame"],
    "metaballs_share_of_static_frame": meta["seconds_per_frame"] / base["seconds_per_frame"],
    "metaballs_cycles_frame_s": {"animated": metar["animated_seconds_per_frame"],
                                 "static": metar["static_seconds_per_frame"],
                                 "as a plain mesh": meta_mesh},
    "metaballs_share_of_their_plain_mesh_frame": meta["seconds_per_frame"] / meta_mesh,
    "remesh_vs_metaballs": {k: r["remesh_per_frame"] / meta["seconds_per_frame"]
                            for k, r in (("1 thread", r1), ("all", r0),
                                         ("all, Blender normals", rb))},
    "bake_24_frames_s": bake_s["seconds"],
}
report(what="summary", **summary)
