"""libblend in headless Blender: a script that builds a field, animates it,
renders two frames, exports a frame's scene and bakes the animation.

    blender -b --factory-startup --addons libblend_blender \
        --python headless_render.py -- OUTDIR

(Blender 4.2+ with the add-on installed as an extension: --addons
bl_ext.user_default.libblend.) Writes OUTDIR/example.blend, frame_0001.png,
frame_0003.png, frame_0003.json (the scene at frame 3, for blendtool),
libblend_cache/field/frame_00000N.npz (the bake) and summary.json.

What to know when scripting: in background mode there is no live timer, so
an edit does not remesh by itself. Call bpy.ops.libblend.update_mesh() (with
final=True for render resolution) when the script needs the mesh; renders
(bpy.ops.render.render, blender -b -f / -a) remesh every field for each frame
by themselves, before the frame renders. Only operators and Object.libblend
settings are used here: they are the same in every supported Blender.
"""
import json
import math
import os
import sys

import bpy

# the add-on's package: libblend_blender (the 3.x zip) or bl_ext.<repository>.libblend (4.2+)
lbb = next(m for n, m in list(sys.modules.items())
           if n.endswith(("libblend_blender", ".libblend")) and hasattr(m, "live"))

out_dir = os.path.abspath(sys.argv[sys.argv.index("--") + 1] if "--" in sys.argv else "out")
os.makedirs(out_dir, exist_ok=True)
scene = bpy.context.scene
for o in list(scene.objects):  # an empty scene to start from
    bpy.data.objects.remove(o)


def active():
    return bpy.context.view_layer.objects.active


# the field, its blend and two spheres
bpy.ops.libblend.add_field(convention="zero", with_sphere=False)
field = active()
field.name = "field"
s = field.libblend
# Fit Region is on for a new field: the region follows the spheres; the box
# below is only where it looks for them (and the region when it is off)
s.bounds_min, s.bounds_max = (-1.6, -1.3, -1.3), (2.9, 1.3, 1.3)
s.preview_resolution, s.render_resolution = 32, 64
bpy.ops.libblend.add_blend(blend_type="displacement", op="union")
blend = active()
bpy.ops.libblend.add_primitive(prim_type="sphere")
bpy.ops.libblend.add_primitive(prim_type="sphere", location=(1.4, 0, 0))
moving = active()
moving.libblend.radius = 0.8

# keyframes: the blend's range grows, the second sphere moves away
scene.frame_start, scene.frame_end = 1, 3
for frame, r, x in ((1, 0.1, 1.4), (3, 1.2, 2.0)):
    blend.libblend.r = r
    blend.keyframe_insert("libblend.r", frame=frame)
    moving.location.x = x
    moving.keyframe_insert("location", index=0, frame=frame)

# no live timer here: mesh explicitly when the script wants the mesh now
scene.frame_set(1)
bpy.ops.libblend.update_mesh(final=True)
summary = {"frame 1 triangles (update_mesh)": len(field.data.polygons)}

# camera, light, render settings
cam = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
scene.collection.objects.link(cam)
cam.location = (0.6, -6.5, 1.5)
cam.rotation_euler = (math.radians(78), 0, 0)
scene.camera = cam
sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
scene.collection.objects.link(sun)
sun.rotation_euler = (math.radians(40), math.radians(20), 0)
scene.render.engine = "CYCLES"
scene.cycles.samples = 4
scene.cycles.use_denoising = False
scene.render.resolution_x, scene.render.resolution_y = 160, 100

# two frames: each render remeshes the field at render resolution first, and
# puts the viewport's mesh back afterwards; a render_post handler sees the
# mesh the frame rendered with
def rendered(scn, *_):
    summary["frame %d triangles (render)" % scn.frame_current] = len(field.data.polygons)


bpy.app.handlers.render_post.append(rendered)
for frame in (1, 3):
    scene.frame_set(frame)
    scene.render.filepath = os.path.join(out_dir, "frame_%04d.png" % frame)
    bpy.ops.render.render(write_still=True)
bpy.app.handlers.render_post.remove(rendered)
summary["triangles after the render (viewport mesh)"] = len(field.data.polygons)

# the scene of frame 3, for blendtool (mesh, pov, batch jobs). A new field
# fits its region to itself (Fit Region): the export's bounds are that
# region, and the grid's cell (as `blendtool mesh --cell-size`) is the fifth
# value of scene_text
bpy.ops.libblend.export_scene(filepath=os.path.join(out_dir, "frame_0003.json"))
summary["frame 3 cell (render)"] = lbb.live.scene_text(field)[4]

# bake: saved first (the cache goes next to the .blend), then every frame
bpy.ops.wm.save_as_mainfile(filepath=os.path.join(out_dir, "example.blend"))
bpy.ops.libblend.bake(frame_start=1, frame_end=3)
bpy.ops.wm.save_mainfile()  # the field now renders from its bake
summary["bake"] = field.libblend.bake_info
with open(os.path.join(out_dir, "summary.json"), "w") as f:
    json.dump(summary, f, indent=1)
print("headless_render:", json.dumps(summary))
