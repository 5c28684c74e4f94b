"""Given to a test's `blender -b FILE --python render_hook.py -a` run: after
each rendered frame, saves the mesh every libblend field rendered with (its
vertex positions and triangles, and its `velocity` attribute when there is
one) to $LB_DUMP_DIR/FIELD_NNNN.npz. It records
only; it changes nothing the render does."""
import os

import bpy
import numpy as np

DUMP = os.environ["LB_DUMP_DIR"]
os.makedirs(DUMP, exist_ok=True)


def dump(scene, *_):
    for obj in scene.objects:
        if obj.libblend.kind != "OUTPUT" or obj.hide_render:
            continue
        me = obj.data
        V = np.empty(3 * len(me.vertices), dtype=np.float32)
        me.vertices.foreach_get("co", V)
        L = np.empty(len(me.loops), dtype=np.int32)
        me.loops.foreach_get("vertex_index", L)
        extra = {}
        vel = me.attributes.get("velocity")
        if vel is not None:  # motion blur's velocities, when the add-on wrote them
            U = np.empty(3 * len(me.vertices), dtype=np.float32)
            vel.data.foreach_get("vector", U)
            extra["U"] = U.reshape(-1, 3)
        np.savez(os.path.join(DUMP, "%s_%04d.npz" % (bpy.path.clean_name(obj.name),
                                                      scene.frame_current)),
                 V=V.reshape(-1, 3), F=L.reshape(-1, 3), **extra)


bpy.app.handlers.render_post.append(dump)
