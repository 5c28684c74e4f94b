"""Every difference between the Blender versions the add-on supports (3.4
to 4.3, tested on 3.4 and 4.3) handled here, and only here. The rest of the
add-on (and its tests) call these functions instead of testing versions.

  version            what changed                        handled by
  4.0                Mesh polygons' loop_total read-only  set_triangles
  4.0                corner edges stored as an attribute  set_edges
                     (no block copy from foreach_set)
  4.0                Principled BSDF renamed inputs       principled_inputs
                     (Specular -> Specular IOR Level)
  4.1                auto smooth removed (custom normals  set_custom_normals,
                     work without it); calc_normals_split clear_custom_normals,
                     removed (corner_normals instead)     corner_normals
  4.2                add-ons become extensions: the       (nothing to do: the
                     package is bl_ext.<repo>.libblend,   add-on names itself
                     blender_manifest.toml replaces        by __package__;
                     bl_info                               is_extension says)
  4.2                EEVEE is BLENDER_EEVEE_NEXT          eevee_engine
  4.3 (seen)         view_layer.objects yields None for    view_layer_objects
                     objects just removed, until the view
                     layer resyncs
"""
import bpy

VERSION = bpy.app.version


def is_extension():
    """True when the add-on runs as a 4.2+ extension (bl_ext.<repo>.<id>)."""
    return __package__.startswith("bl_ext.")


def view_layer_objects(view_layer):
    """The view layer's objects, without the None entries Blender 4.3 leaves
    for objects removed since its last resync (3.4 resyncs at once)."""
    return [o for o in view_layer.objects if o is not None]


def set_triangles(me, nt):
    """Mark me's polygons as nt triangles whose loops are consecutive."""
    import numpy as np
    # uint32, the properties' own type: foreach_set then copies one block
    me.polygons.foreach_set("loop_start", np.arange(0, 3 * nt, 3, dtype=np.uint32))
    if VERSION < (4, 0, 0):  # later versions derive loop_total from loop_start
        me.polygons.foreach_set("loop_total", np.full(nt, 3, dtype=np.uint32))


def takes_libblend_edges():
    """True where set_edges uses libblend's edges (so the mesher should make
    them): 3.x; 4.x derives its own."""
    return VERSION < (4, 0, 0)


def set_edges(me, edges, corner_edges):
    """The edges of a mesh just given its triangles: libblend's (lb_mesh_edges,
    (e, 2) and (3 t,) uint32) where Blender stores them as one block, else
    Blender derives them. Measured on 85,568 triangles: 3.4 derives them in
    9-11 ms and takes libblend's in 1.2 ms; 4.3 derives them in 7 ms but
    takes the corners' edges element by element (8 ms), so it derives."""
    if edges is None or corner_edges is None or not takes_libblend_edges():
        me.update(calc_edges=True)
        return
    me.edges.add(len(edges))
    me.edges.foreach_set("vertices", edges.ravel())
    me.loops.foreach_set("edge_index", corner_edges)


def set_custom_normals(me, normals):
    """One normal per vertex as the mesh's custom split normals."""
    if VERSION < (4, 1, 0):
        me.use_auto_smooth = True
        me.auto_smooth_angle = 3.14159
    me.normals_split_custom_set_from_vertices(normals)


def set_custom_loop_normals(me, normals):
    """One normal per loop (face corner) as the mesh's custom split normals:
    a corner on a crease takes its own side's normal, so the crease shades
    sharp (libblend's corner normals, mesh(features=True))."""
    if VERSION < (4, 1, 0):
        me.use_auto_smooth = True
        me.auto_smooth_angle = 3.14159
    me.normals_split_custom_set(normals)


def clear_custom_normals(me):
    """Blender's own smooth normals on a mesh just refilled after
    clear_geometry (which drops custom normals in every version)."""
    if VERSION < (4, 1, 0):
        me.use_auto_smooth = False


def corner_normals(me):
    """The shading normal of every loop (face corner), as a flat float32 array."""
    import numpy as np
    out = np.empty(3 * len(me.loops), dtype=np.float32)
    if VERSION < (4, 1, 0):
        me.calc_normals_split()
        me.loops.foreach_get("normal", out)
    else:
        me.corner_normals.foreach_get("vector", out)
    return out


def principled_inputs():
    """Names of the Principled BSDF inputs the render section maps to."""
    if VERSION < (4, 0, 0):
        return {"color": "Base Color", "specular": "Specular", "roughness": "Roughness"}
    return {"color": "Base Color", "specular": "Specular IOR Level", "roughness": "Roughness"}


def eevee_engine():
    return "BLENDER_EEVEE" if VERSION < (4, 2, 0) else "BLENDER_EEVEE_NEXT"
