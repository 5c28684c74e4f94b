"""Baked caches: a field meshed at render resolution for every frame of a
range, one file per frame, so that renders (a farm's `blender -b FILE -a`
among them) and scrubbing read meshes instead of running the library.

Files: FOLDER/frame_NNNNNN.npz (numpy's uncompressed npz), FOLDER is the
field's Bake Folder (default `//libblend_cache/<field name>/`, next to the
.blend). Each holds
  positions  float32 (n, 3)   vertex positions in the field's space
  normals    float32 (n, 3)   libblend's analytic unit normals
  triangles  int32 (t, 3)     counter-clockwise seen from outside
  key        the mesh key: a hash of the frame's scene text, region,
             resolution and boundary mode (live.mesh_key)
  meta       JSON text: format, frame, resolution, field name
A file is written to a temporary name in the same folder and renamed into
place (os.replace), so a reader sees a whole file or none, and an
interrupted bake leaves only whole frames. A frame whose key differs from
the field's state at that frame is stale: it is not used (the field is
meshed instead, and the status says so).
"""
import json
import os

import bpy

from . import atomic, binding

FORMAT = "libblend-bake"
VERSION = 1


class CacheError(Exception):
    """A cache folder or file that cannot be used; the text says which and why."""


def folder(output):
    """The absolute cache folder of an OUTPUT object."""
    d = output.libblend.bake_dir or "//libblend_cache/%s/" % bpy.path.clean_name(output.name)
    if d.startswith("//") and not bpy.data.filepath:
        raise CacheError("field '%s': the bake folder %s is relative to the .blend file, which "
                         "is not saved yet. Fix: save the .blend first, or set an absolute Bake "
                         "Folder" % (output.name, d))
    return os.path.normpath(bpy.path.abspath(d))


def frame_path(folder_, frame):
    return os.path.join(folder_, "frame_%06d.npz" % frame)


class CachedMesh:
    """What the mesher returns (positions, normals, triangles), read from a file."""

    def __init__(self, positions, normals, triangles, resolution, material_index=None,
                 materials=None):
        self.positions, self.normals, self.triangles = positions, normals, triangles
        self.resolution = resolution
        # the nodes' materials, when the scene names any (live.set_materials)
        self.material_index, self.materials = material_index, materials
        # Sharp Features: each corner's normal index and the added normals
        # (binding.Mesh.corner_normals, split_normals)
        self.corner_normals, self.split_normals = None, None

    # each triangle corner's normal, read from the same four arrays
    loop_normals = binding.Mesh.loop_normals


def write(path, mesh, key, frame, resolution, name):
    """Write one frame atomically."""
    import numpy as np
    d = os.path.dirname(path)
    os.makedirs(d, exist_ok=True)
    fd, tmp = atomic.temp_beside(path, ".frame-")
    info = {"format": FORMAT, "version": VERSION, "frame": frame, "resolution": resolution,
            "field": name}
    arrays = {}
    if getattr(mesh, "materials", None):
        info["materials"] = mesh.materials
        arrays["material_index"] = np.asarray(mesh.material_index, dtype=np.uint32)
    if getattr(mesh, "corner_normals", None) is not None:
        arrays["corner_normals"] = np.asarray(mesh.corner_normals, dtype=np.uint32)
        arrays["split_normals"] = np.asarray(mesh.split_normals, dtype=np.float32)
    meta = json.dumps(info)
    try:
        with os.fdopen(fd, "wb") as f:
            np.savez(f, positions=np.asarray(mesh.positions, dtype=np.float32),
                     normals=np.asarray(mesh.normals, dtype=np.float32),
                     triangles=np.asarray(mesh.triangles, dtype=np.int32),
                     key=np.array(key), meta=np.array(meta), **arrays)
        atomic.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def read(path, key=None):
    """The cached mesh of one frame, or None when there is no file or (with
    key) the file is stale. Raises CacheError for a file that is not a cache."""
    import numpy as np
    if not os.path.exists(path):
        return None
    import zipfile
    if not zipfile.is_zipfile(path):
        raise CacheError("%s: not a bake file (not an npz archive). Fix: bake again" % path)
    try:
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["meta"]))
            if meta.get("format") != FORMAT or meta.get("version") != VERSION:
                raise CacheError("%s: not a libblend bake (format %r version %r); allowed: %s "
                                 "version %d. Fix: bake again" % (path, meta.get("format"),
                                                                  meta.get("version"), FORMAT,
                                                                  VERSION))
            if key is not None and str(z["key"]) != key:
                return None
            pos, nrm, tri = z["positions"], z["normals"], z["triangles"]
            mats = meta.get("materials")
            midx = z["material_index"] if mats else None
            cn = z["corner_normals"] if "corner_normals" in z.files else None
            sn = z["split_normals"] if cn is not None else None
    except (OSError, ValueError, KeyError) as e:
        raise CacheError("%s: unreadable bake file (%s). Fix: bake again" % (path, e)) from None
    if pos.ndim != 2 or pos.shape[1:] != (3,) or nrm.shape != pos.shape or tri.ndim != 2 or \
            tri.shape[1:] != (3,) or (len(tri) and (tri.min() < 0 or tri.max() >= len(pos))):
        raise CacheError("%s: damaged bake file (array shapes or indices). Fix: bake again" % path)
    if mats and (midx.shape != (len(tri),) or (len(tri) and int(midx.max()) >= len(mats))):
        raise CacheError("%s: damaged bake file (material indices). Fix: bake again" % path)
    if cn is not None and (cn.shape != tri.shape or sn.ndim != 2 or sn.shape[1:] != (3,) or
                           (len(cn) and int(cn.max()) >= len(pos) + len(sn))):
        raise CacheError("%s: damaged bake file (corner normals). Fix: bake again" % path)
    m = CachedMesh(pos, nrm, tri, meta.get("resolution", 0), midx, mats)
    m.corner_normals, m.split_normals = cn, sn
    return m


def frames(folder_):
    """Frame numbers present in a cache folder, sorted."""
    if not os.path.isdir(folder_):
        return []
    out = []
    for n in os.listdir(folder_):
        if n.startswith("frame_") and n.endswith(".npz") and n[6:-4].lstrip("-").isdigit():
            out.append(int(n[6:-4]))
    return sorted(out)


def clear(folder_):
    """Delete the cache files (and the folder when nothing else is in it)."""
    n = 0
    for f in frames(folder_):
        os.unlink(frame_path(folder_, f))
        n += 1
    try:
        os.rmdir(folder_)
    except OSError:
        pass
    return n
