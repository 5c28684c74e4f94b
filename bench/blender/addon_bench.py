"""What the add-on's benchmarks in Blender share: the add-on enabled from a
build (not an installed copy, not $LIBBLEND_LIBRARY) in an empty scene,
and the live path timed as Blender's loop runs it."""
import os
import sys
import time

import addon_utils
import bpy


def start(addon_parent):
    """enable the add-on found under addon_parent, with Viewport Simplify
    off (each benchmark sets the options it compares); remove every object"""
    sys.path.insert(0, addon_parent)
    os.environ.pop("LIBBLEND_LIBRARY", None)
    addon_utils.enable("libblend_blender", default_set=True)
    bpy.context.preferences.addons["libblend_blender"].preferences.viewport_simplify = 0.0
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)


def live_moves(obj, field_state, n, step):
    """n live updates, obj moved by step along x before each (back and
    forth): obj marked dirty (the depsgraph handler's call) and the add-on's
    timer run until the new mesh is in the Blender mesh; the analytic
    normals that follow once the field is idle are not timed. Returns
    [(seconds, the field's last-run parts)]."""
    from libblend_blender import live
    out = []
    for i in range(n):
        t0 = time.perf_counter()
        obj.location.x += step if i % 2 == 0 else -step
        live.mark_dirty(obj)
        wait = live.tick()
        while wait is not None and (field_state.dirty or field_state.job is not None):
            time.sleep(wait)
            wait = live.tick()
        out.append((time.perf_counter() - t0, dict(field_state.last)))
        assert not field_state.error, field_state.status
        while live.tick() is not None:
            time.sleep(live.TICK)
    return out
