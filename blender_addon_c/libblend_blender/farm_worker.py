"""The Blender side of `blendtool batch` with outputs.image.renderer
"blender" (docs/batch.md, "Rendering with Blender").

blendtool starts one background Blender per batch process:
    blender -b --factory-startup --python-exit-code 1 --python farm_worker.py
with two inherited pipes: fd 3 carries one JSON request per line, fd 4 one
JSON reply per line. The first reply is a hello with Blender's version.
Each request is one task:
    scene       the task's resolved scene file (sweep values and frame set)
    out         where to write the image (PNG, 8 or 16 bits, RGB or RGBA)
    width, height, engine ("cycles" | "eevee"), samples, seed, threads
    resolution  cells along the region's longest side for the mesh
    bits16, alpha (the PNG's channels), transparent (a background of alpha 0:
                outputs.image.alpha)
    fps, shutter, before, after, dt_frames (motion blur: the resolved scenes
                dt_frames before and after the frame; shutter in frames, 0: off)
The scene is imported as the add-on's Import does (the blend tree, the
render section's camera, lights, floor and materials), meshed at the
task's resolution, rendered, and saved; then everything it made is
removed, so each task starts from the same empty scene. A failed task
replies {"error": ...} and the worker goes on; end of input ends it.

Motion blur: the mesh gets a point attribute `velocity` (scene units per
second), which Cycles uses to blur a mesh whose topology is its own
(Blender 3.4 and 4.3 measured: tests/blender/test_farm.py). The velocity of
a surface point is its normal motion, from the field a sub-frame before and
after (libblend's lb_mesh_velocities: -df/dt / |grad f| along the normal),
times the frame rate.
"""
import importlib
import json
import os
import sys
import time
import traceback


def _package():
    """Enable the add-on this file belongs to; returns its package."""
    import addon_utils
    here = os.path.dirname(os.path.abspath(__file__))
    parent, name = os.path.split(here)
    if parent not in sys.path:
        sys.path.insert(0, parent)
    if addon_utils.enable(name, default_set=True) is None:
        raise RuntimeError("the add-on %s did not enable" % here)
    pkg = importlib.import_module(name)
    for sub in ("binding", "compat", "libhandle", "live", "render_section", "tree"):
        importlib.import_module(name + "." + sub)
    return pkg


def _clear(bpy):
    """Remove what the last task made: objects and their data."""
    for coll in (bpy.data.objects, bpy.data.meshes, bpy.data.cameras, bpy.data.lights,
                 bpy.data.materials):
        for idb in list(coll):
            coll.remove(idb)


def _velocities(pkg, lib, out, req):
    """The point attribute `velocity` on out's mesh from the scenes before and after."""
    import numpy as np
    me = out.data
    n = len(me.vertices)
    if n == 0:
        return 0
    P = np.empty(3 * n, dtype=np.float32)
    me.vertices.foreach_get("co", P)
    P = P.reshape(-1, 3).astype(np.float64)
    M = np.array(out.matrix_world)
    P = P @ M[:3, :3].T + M[:3, 3]  # world = scene coordinates
    evs = []
    try:
        for key in ("scene", "before", "after"):
            if req.get(key):
                with lib.load_scene(req[key]) as s:
                    evs.append(s.compile())
            else:
                evs.append(None)
        here, before, after = evs
        # the scenes dt_frames before and after: units per frame, then per second
        dt = float(req.get("dt_frames", 1.0))
        v = here.velocities(P, before, after, dt=dt, threads=req.get("threads", 0))
        v *= float(req["fps"])
    finally:
        for e in evs:
            if e is not None:
                e.close()
    v = v @ np.linalg.inv(M[:3, :3]).T  # back into the object's frame
    a = me.attributes.get("velocity") or me.attributes.new("velocity", "FLOAT_VECTOR", "POINT")
    a.data.foreach_set("vector", v.astype(np.float32).ravel())
    me["libblend_velocities"] = "given"  # the add-on's render path leaves them as they are
    return float(np.abs(v).max()) if len(v) else 0.0


def _engine(bpy, pkg, sc, req):
    if req["engine"] == "cycles":
        sc.render.engine = "CYCLES"
        sc.cycles.device = "CPU"
        sc.cycles.samples = int(req["samples"])
        sc.cycles.seed = int(req["seed"])
        sc.cycles.use_animated_seed = False
        sc.cycles.use_denoising = False  # OpenImageDenoise is not on every node
        if hasattr(sc.cycles, "use_adaptive_sampling"):
            sc.cycles.use_adaptive_sampling = False  # the same samples in every pixel
        # tiles of 128 pixels: Blender reports "Rendered T/N Tiles" as it goes,
        # which blendtool turns into progress events (in one tile Cycles
        # reports its samples only at the start and the end)
        sc.cycles.use_auto_tile, sc.cycles.tile_size = True, 128
    else:
        sc.render.engine = pkg.compat.eevee_engine()
        eevee = sc.eevee
        if hasattr(eevee, "taa_render_samples"):
            eevee.taa_render_samples = int(req["samples"])
    threads = int(req.get("threads", 0))
    sc.render.threads_mode = "FIXED" if threads > 0 else "AUTO"
    if threads > 0:
        sc.render.threads = threads


def render(bpy, pkg, req):
    """One task (the request's fields: the module's docstring); returns the
    reply: the mesh's status line, the largest velocity, the seconds in
    Blender's render and in the whole task."""
    t_start = time.perf_counter()
    _clear(bpy)
    lib = pkg.libhandle.library()
    path = req["scene"]
    lib.load_scene(path).close()  # libblend's own messages for a bad scene
    with open(path, encoding="utf-8") as f:
        scene = json.load(f)
    section = scene.get("render") or {}
    if not section.get("camera"):
        raise ValueError("%s: the scene has no render.camera; allowed: a scene with a camera "
                         "(docs/scene-format.md, render)" % req.get("name", path))
    sc = bpy.context.scene
    name = scene.get("title") or req.get("name") or "libblend field"
    out = pkg.tree.from_scene(scene, sc.collection, name)
    pkg.render_section.create(out, section, sc.collection, sc)
    s = out.libblend
    s.render_resolution = s.preview_resolution = int(req["resolution"])
    ok, msg = pkg.live.update_now(out, final=True)
    if not ok:
        raise ValueError(msg)
    sc.render.resolution_x, sc.render.resolution_y = int(req["width"]), int(req["height"])
    sc.render.resolution_percentage = 100
    sc.render.film_transparent = bool(req.get("transparent"))
    _engine(bpy, pkg, sc, req)
    sc.render.fps, sc.render.fps_base = int(req.get("fps", 24)), 1.0
    vmax = 0.0
    shutter = float(req.get("shutter") or 0)
    sc.render.use_motion_blur = shutter > 0
    if shutter > 0:
        sc.render.motion_blur_shutter = shutter
        vmax = _velocities(pkg, lib, out, req)
    im = sc.render.image_settings
    im.file_format = "PNG"
    im.color_mode = "RGBA" if req["alpha"] else "RGB"
    im.color_depth = "16" if req["bits16"] else "8"
    im.compression = 15
    sc.render.use_stamp = False
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=False)
    t_render = time.perf_counter() - t0
    tmp = req["out"] + ".part.png"
    bpy.data.images["Render Result"].save_render(filepath=tmp, scene=sc)
    os.replace(tmp, req["out"])
    return {"ok": True, "mesh": msg, "max_velocity": vmax, "render_seconds": t_render,
            "seconds": time.perf_counter() - t_start}


def main():
    import bpy
    requests = os.fdopen(3, "r", encoding="utf-8")
    replies = os.fdopen(4, "w", encoding="utf-8")

    def reply(obj):
        replies.write(json.dumps(obj) + "\n")
        replies.flush()

    try:
        pkg = _package()
    except Exception as e:  # noqa: BLE001 (any failure to start is the worker's answer)
        reply({"error": "the add-on could not be enabled: %s" % e})
        return 1
    reply({"blender": bpy.app.version_string})
    for line in requests:
        try:
            req = json.loads(line)
            reply(render(bpy, pkg, req))
        except Exception as e:  # noqa: BLE001 (a failed task is reported, the worker goes on)
            traceback.print_exc()
            reply({"error": str(e) or type(e).__name__})
    return 0


if __name__ == "__main__":
    main()
