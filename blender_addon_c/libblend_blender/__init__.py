"""libblend for Blender: the blend operators of libblend (k-ary blends with
per-primitive range, curvature and subsequent-blend parameters, bounded
blends, bulge elimination, local blends) as a tree of primitives under a field object,
meshed live by the C library through ctypes. See README.md next to this
package."""

bl_info = {
    "name": "libblend",
    "author": "libblend developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Add > libblend, View3D > Sidebar > libblend, File > Import/Export",
    "description": "Implicit-surface blends from recent research, meshed live by libblend",
    "category": "Add Mesh",
}

if "bpy" in locals():  # F8 / script reload
    import importlib
    for _m in ("compat", "binding", "props", "tree", "bake", "render_section", "live", "ops",
               "ui"):
        if _m in locals():
            importlib.reload(locals()[_m])

import bpy  # noqa: E402

from . import bake, binding, compat, libhandle, live, ops, props, render_section, tree, ui  # noqa: E402,F401


def register():
    props.register()
    for c in ops.CLASSES + ui.CLASSES:
        bpy.utils.register_class(c)
    for menu, fn in ui.MENUS:
        getattr(bpy.types, menu).append(fn)
    live.register()


def unregister():
    live.unregister()
    for menu, fn in reversed(ui.MENUS):
        getattr(bpy.types, menu).remove(fn)
    for c in reversed(ops.CLASSES + ui.CLASSES):
        bpy.utils.unregister_class(c)
    props.unregister()
