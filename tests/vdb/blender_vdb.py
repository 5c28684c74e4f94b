"""Inside Blender (3.4, or 4.3 in the Debian 13 root): blendtool's .vdb
files as a user opens them. Imports a level set as a Volume object
(File > Import > OpenVDB), checks its grids as Blender reads them, turns it
back into a surface with Blender's own Volume to Mesh modifier at the
grid's resolution and writes that mesh's vertices for the caller to compare
with libblend's mesh; imports an animated job's files as one sequence and
checks Blender steps through its frames.

usage: blender -b --factory-startup --python-exit-code 1 --python blender_vdb.py --
       LEVEL_SET.vdb BLENDER_CENTRED.vdb SEQUENCE_DIR OUT.json
"""
import json
import os
import sys

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
vdb_path, blender_path, seq_dir, out_path = argv
res = {"version": bpy.app.version_string}


def imported(filepath, files):
    before = set(bpy.data.objects)
    bpy.ops.object.volume_import(filepath=filepath, directory=os.path.dirname(filepath),
                                 files=[{"name": f} for f in files])
    new = [o for o in bpy.data.objects if o not in before]
    assert len(new) == 1 and new[0].type == "VOLUME", "one Volume object: %s" % new
    return new[0]


def volume_to_mesh(path):
    """import path as a Volume, then Volume to Mesh at the grid's own
    resolution, isovalue 0 (the level set's surface)"""
    vol_obj = imported(path, [os.path.basename(path)])
    vol = vol_obj.data
    vol.grids.load()
    out = {"grids": [{"name": g.name, "type": g.data_type, "channels": g.channels}
                     for g in vol.grids],
           "load_error": vol.grids.error_message, "is_sequence": vol.is_sequence}
    me = bpy.data.meshes.new("v2m")
    mesh_obj = bpy.data.objects.new("v2m", me)
    bpy.context.scene.collection.objects.link(mesh_obj)
    mod = mesh_obj.modifiers.new("v2m", "VOLUME_TO_MESH")
    mod.object = vol_obj
    mod.grid_name = "surface"
    mod.resolution_mode = "GRID"
    mod.threshold = 0.0
    mod.adaptivity = 0.0
    dg = bpy.context.evaluated_depsgraph_get()
    ev = mesh_obj.evaluated_get(dg)
    m = ev.to_mesh()
    out["vertices"] = [tuple(v.co) for v in m.vertices]
    # closedness as Blender sees it: every edge in exactly two faces
    count = {}
    for p in m.polygons:
        vs = list(p.vertices)
        for a, b in zip(vs, vs[1:] + vs[:1]):
            k = (min(a, b), max(a, b))
            count[k] = count.get(k, 0) + 1
    out["faces"] = len(m.polygons)
    # as triangles (fans), for the distance to the surface
    out["triangles"] = [(p.vertices[0], p.vertices[k], p.vertices[k + 1])
                        for p in m.polygons for k in range(1, len(p.vertices) - 1)]
    out["open_edges"] = sum(1 for c in count.values() if c != 2)
    ev.to_mesh_clear()
    return out


res["openvdb"] = volume_to_mesh(vdb_path)
res["blender"] = volume_to_mesh(blender_path)

# an animated job's files: one Volume object, a sequence of as many frames
files = sorted(f for f in os.listdir(seq_dir) if f.endswith(".vdb"))
seq = imported(os.path.join(seq_dir, files[0]), files)
sv = seq.data
res["sequence"] = {"files": files, "is_sequence": sv.is_sequence,
                   "frame_duration": sv.frame_duration, "frame_start": sv.frame_start,
                   "filepath": sv.filepath}
# the bounding box Blender gives each frame (its grids loaded per frame)
boxes = []
for f in range(sv.frame_start, sv.frame_start + sv.frame_duration):
    bpy.context.scene.frame_set(f)
    dg = bpy.context.evaluated_depsgraph_get()
    e = seq.evaluated_get(dg)
    bb = [tuple(e.matrix_world @ __import__("mathutils").Vector(c)) for c in e.bound_box]
    boxes.append([min(c[i] for c in bb) for i in range(3)] + [max(c[i] for c in bb) for i in range(3)])
res["sequence"]["boxes"] = boxes
with open(out_path, "w") as f:
    json.dump(res, f)
print("blender_vdb: wrote", out_path)
