"""Shared by the add-on tests that run inside Blender (3.4 and 4.x alike).

ADDON, the tests' first argument, says where the add-on under test is:
  a folder        that holds libblend_blender/ (the build tree): the add-on
                  is enabled from sys.path, as on Blender 3.4
  ext:MODULE      an extension installed with `blender --command extension
                  install-file` (Blender 4.2+), e.g. ext:bl_ext.user_default.libblend
The tests reach the add-on's modules through the returned package, never by
a fixed name, so the same test runs against both.
"""
import importlib
import os
import sys

import addon_utils
import bpy


checks = 0  # how many check() calls passed


def check(cond, what):
    """Count a check; raise AssertionError(what) when cond is false."""
    global checks
    checks += 1
    if not cond:
        raise AssertionError(what)
    return cond


def active():
    return bpy.context.view_layer.objects.active


def activate(obj):
    """Make obj the only selected object and the active one."""
    for o in bpy.context.view_layer.objects:
        if o is not None:
            o.select_set(False)
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj


def enable(spec):
    """Enable the add-on named by spec; returns (package, module name)."""
    if spec.startswith("ext:"):
        name = spec[4:]
    else:
        sys.path.insert(0, spec)
        name = "libblend_blender"
    mod = addon_utils.enable(name, default_set=True)
    assert mod is not None, "the add-on %s did not enable" % name
    pkg = importlib.import_module(name)
    for sub in ("bake", "binding", "compat", "live", "render_section", "tree", "ui"):
        importlib.import_module(name + "." + sub)
    return pkg, name


def viewport_simplify_off(pkg):
    """Turn the Viewport Simplify preference off, for the tests that
    compare a viewport mesh with the library's unsimplified mesh; returns
    its value as shipped, which the caller checks."""
    p = pkg.libhandle.prefs()
    shipped = p.viewport_simplify
    p.viewport_simplify = 0.0
    return shipped


def blender_cmd(spec, work):
    """(argv prefix, env) to start another Blender with the same add-on
    enabled, the way a farm starts one: `--addons NAME`."""
    env = dict(os.environ)
    if spec.startswith("ext:"):
        name = spec[4:]  # BLENDER_USER_RESOURCES already points at the installed extension
    else:
        scripts = os.path.join(work, "user-scripts")
        link = os.path.join(scripts, "addons", "libblend_blender")
        os.makedirs(os.path.dirname(link), exist_ok=True)
        if not os.path.islink(link):
            os.symlink(os.path.join(os.path.abspath(spec), "libblend_blender"), link)
        env["BLENDER_USER_SCRIPTS"] = scripts
        name = "libblend_blender"
    env.pop("LIBBLEND_LIBRARY", None)
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    return [bpy.app.binary_path, "-b", "--factory-startup", "--addons", name], env


def image_pixels(path):
    """An image file's RGBA pixels as float32 (height, width, 4), bottom row
    first, read by Blender itself."""
    import numpy as np
    img = bpy.data.images.load(path, check_existing=False)
    try:
        w, h = img.size
        px = np.empty(w * h * 4, dtype=np.float32)
        img.pixels.foreach_get(px)
        return px.reshape(h, w, 4)
    finally:
        bpy.data.images.remove(img)
