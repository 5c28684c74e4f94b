"""The add-on zip installs the way a user installs it (Preferences > Add-ons >
Install) and works from the installed copy, with its bundled library; undo /
redo restore settings and meshes; settings survive saving and reopening the
.blend file:

    BLENDER_USER_SCRIPTS=DIR blender -b --factory-startup --python-exit-code 1 \
        --python test_install_zip.py -- ZIP

A Blender 4.2+ extension, installed beforehand with `blender --command
extension install-file` (tests/packaging/test_packages.sh), goes through the
same checks when its module is named instead (BLENDER_USER_RESOURCES set):

    ... --python test_install_zip.py -- EXTENSION.zip bl_ext.user_default.libblend
"""
import importlib
import os
import sys

import addon_utils
import bpy

args = sys.argv[sys.argv.index("--") + 1:]
zip_path = args[0]
module = args[1] if len(args) > 1 else "libblend_blender"
os.environ.pop("LIBBLEND_LIBRARY", None)
if module == "libblend_blender":  # the legacy add-on: Preferences > Add-ons > Install
    scripts = os.environ["BLENDER_USER_SCRIPTS"]
    res = bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
    assert res == {"FINISHED"}, res
    installed = os.path.join(scripts, "addons", "libblend_blender")
else:  # an extension, installed by `extension install-file`
    scripts = os.path.join(os.environ["BLENDER_USER_RESOURCES"], "scripts")
    os.makedirs(scripts, exist_ok=True)
    installed = os.path.join(os.environ["BLENDER_USER_RESOURCES"], "extensions",
                             module.split(".")[1], module.split(".")[2])
assert os.path.isfile(os.path.join(installed, "lib", "libblend.so")), "library installed with it"
assert os.path.isfile(os.path.join(installed, "povray", "libblend.inc")), "libblend.inc installed"
mod = addon_utils.enable(module, default_set=True)
assert mod is not None and os.path.dirname(mod.__file__) == installed, mod
live = importlib.import_module(module + ".live")
libhandle = importlib.import_module(module + ".libhandle")

ok, msg = libhandle.library_status()
assert ok and libhandle.library().path.startswith(installed), msg
assert bpy.ops.libblend.add_field() == {"FINISHED"}
out = bpy.context.view_layer.objects.active
assert len(out.data.polygons) > 1000, "the default sphere is meshed"
n_sphere = len(out.data.polygons)
# as shipped the viewport's mesh is simplified (Viewport Simplify 0.5,
# Coarse First), the render's is not
assert libhandle.prefs().viewport_simplify == 0.5, libhandle.prefs().viewport_simplify
assert live.state_of(out).applied_key == live.prepare(out, out.libblend.preview_resolution,
                                                      viewport=True).key, "a viewport mesh"
assert live.prepare(out, 64, viewport=True).coarse_first, "the viewport meshes Coarse First"
assert not live.prepare(out, 64).coarse_first, "the render does not"
tree = importlib.import_module(module + ".tree")

# undo / redo: an edit of a setting, then of the tree
bpy.ops.ed.undo_push(message="field added")
sph = out.children[0]
sph.libblend.radius = 1.5
ok, msg = live.update_now(out)
assert ok and len(out.data.polygons) > n_sphere, msg
bpy.ops.ed.undo_push(message="radius")
out.select_set(False)
sph.select_set(True)
bpy.context.view_layer.objects.active = sph
bpy.ops.libblend.blend_selected(blend_type="displacement", op="union")  # wraps the sphere
assert bpy.context.view_layer.objects.active.libblend.kind == "BLEND"
bpy.ops.ed.undo_push(message="blend")  # what the UNDO flag does after an operator in the UI
n_objects = len(bpy.data.objects)
bpy.ops.ed.undo()
assert len(bpy.data.objects) == n_objects - 1, "undo removes the blend"
bpy.ops.ed.undo()
out = bpy.data.objects["libblend field"]
assert out.children[0].libblend.radius == 1.0, "undo restores the radius"
assert len(out.data.polygons) == n_sphere, "undo restores the mesh with it"
assert live.state_of(out).dirty, "undo marks the field for a remesh"
bpy.ops.ed.redo()
out = bpy.data.objects["libblend field"]
assert out.children[0].libblend.radius == 1.5, "redo"

# settings are saved in the .blend
out.libblend.preview_resolution = 40
out.children[0].libblend.prim_type = "torus"
before = tree.to_json(out)[0]
path = os.path.join(os.path.dirname(scripts), "saved.blend")
bpy.ops.wm.save_as_mainfile(filepath=path)
bpy.ops.wm.read_homefile(use_factory_startup=True)
assert "libblend field" not in bpy.data.objects
bpy.ops.wm.open_mainfile(filepath=path)
out = bpy.data.objects["libblend field"]
assert out.libblend.preview_resolution == 40 and tree.to_json(out)[0] == before, "saved tree"
ok, msg = live.update_now(out)
assert ok, msg

# a final render meshes at render resolution, then the preview comes back
n_preview = len(out.data.polygons)
out.libblend.render_resolution = 96
seen = []
bpy.app.handlers.render_post.append(lambda *a: seen.append(len(out.data.polygons)))
scene = bpy.context.scene
# Cycles on the CPU: Workbench and EEVEE need an OpenGL/EGL context, which
# Blender 4.x in background mode has not without a GPU
scene.render.engine = "CYCLES"
scene.cycles.samples = 1
scene.cycles.device = "CPU"
scene.cycles.use_denoising = False
scene.render.resolution_x, scene.render.resolution_y = 32, 24
scene.render.filepath = os.path.join(os.path.dirname(scripts), "render.png")
cam = bpy.data.objects.new("cam", bpy.data.cameras.new("cam"))
scene.collection.objects.link(cam)
cam.location = (0, -6, 0)
cam.rotation_euler = (1.5708, 0, 0)
scene.camera = cam
bpy.ops.render.render(write_still=True)
assert seen and seen[0] > 2 * n_preview, "rendered at render resolution: %r vs %d" % (seen, n_preview)
assert len(out.data.polygons) == n_preview, "preview mesh restored after the render"
addon_utils.disable(module)
print("test_install_zip: installed from %s; undo, redo, save and reopen hold"
      % os.path.basename(zip_path))
