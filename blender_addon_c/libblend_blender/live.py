"""Meshing fields into Blender meshes: live (debounced, on a worker thread)
and on demand (synchronously).

Flow of a live update: a setting's update callback or a transform change
seen by the depsgraph handler calls mark_dirty(); a timer on Blender's main
loop reads the tree into scene JSON (main thread: bpy data is only touched
there) and starts a worker thread that parses, compiles and meshes it in
libblend (ctypes releases the GIL, so Blender stays responsive); a field
whose last run took under SYNC_BELOW is meshed in the timer itself, as
Blender updates its own metaballs, so a small edit waits for no thread
hand-off or poll. While a run is in flight the timer polls again when the
run is expected to end (the last run's length). Edits made
while a run is in flight are coalesced into one next run with the newest
state (so dragging a slider remeshes at the mesher's pace, never queues);
a run older than CANCEL_AFTER with newer edits waiting is cancelled
(CancelToken, polled by the C mesher). The timer moves a finished mesh into
the Blender mesh with foreach_set (no per-vertex Python), with Blender's
smooth normals; libblend's analytic normals (custom split normals, the
costly part) follow once the field has been idle for NORMALS_IDLE. The
library never calls back into Python.
"""
import hashlib
import json
import math
import os
import threading
import time

import bpy

from . import bake, binding, compat, libhandle, tree

TICK = 0.005          # longest timer period while work is pending
MIN_TICK = 0.0005     # shortest: while a run is expected to end any moment
SYNC_BELOW = 0.02     # a field whose last run took less is meshed in the timer
                      # itself (as Blender's metaballs are): no thread hand-off
CANCEL_AFTER = 0.2    # a run this old is cancelled when newer edits wait
NORMALS_IDLE = 0.3    # seconds without edits before analytic normals are set
AUTO_ANALYTIC = 250000  # "Auto" normals: analytic below this many triangles
FIT_SEARCH = 64       # Fit Region looks for the solid within this many times the box
FIT_MARGIN = 0.02     # and grows its extent by this much of its longest side
FIT_MAX_CELLS = 4     # cells along a fitted side: at most this many times the resolution

_states = {}   # output name -> _State
_timer_on = False


class _State:
    def __init__(self):
        self.dirty = False
        self.t_edit = 0.0
        self.job = None
        self.status = ""
        self.error = False
        self.last = {}  # timings of the last update (seconds)
        self.normals = None  # the mesh whose analytic normals wait to be set (live updates)
        self.t_applied = 0.0
        self.applied_key = None  # mesh_key of the mesh in the Blender mesh now
        self.expect = None  # how long the last run took (predicts the next one)
        self.region = None  # (bmin, bmax) the last mesh was made in (Fit Region: the fitted box)
        self.clip_warning = ""  # why the surface is cut flat at the region, if it is
        # the last mesh's blocks (lb_mesh_cache): the next run of this field
        # (an edit, the next frame) recomputes only the blocks that changed,
        # with the same result; one run at a time uses it (the lock: a
        # cancelled run still on its thread finishes first)
        self.cache = None
        self.cache_lock = threading.Lock()

    def mesh_cache(self, lib):
        """(cache, lock) for runs of this field with library lib"""
        if self.cache is None or self.cache.lib is not lib:
            self.cache = lib.mesh_cache()
        return self.cache, self.cache_lock


class _Job:
    """One mesh run. Everything it needs is read on the main thread when it
    is made (the library included: loading it reads the preferences), so
    run() touches no Blender data and may run on a worker thread."""

    def __init__(self, lib, text, name, bmin, bmax, resolution, open_boundary, threads, paths,
                 fit=False, features=False, simplify=0.0, cache=(None, None), merge_flat=False,
                 coarse_first=False):
        self.lib, self.text, self.name = lib, text, name
        self.bmin, self.bmax, self.resolution = bmin, bmax, resolution
        self.open_boundary, self.threads, self.paths = open_boundary, threads, paths
        self.fit, self.features, self.simplify = fit, features, simplify
        self.merge_flat = merge_flat
        # Simplify's method: coarse first (LB_MESH_COARSE_FIRST) or the collapses
        self.coarse_first = bool(coarse_first) and simplify > 0.0
        self.cache, self.cache_lock = cache
        self.key = mesh_key(text, "fit" if fit else bmin, "fit" if fit else bmax, resolution,
                            open_boundary, features, simplify, merge_flat, self.coarse_first)
        self.cell = 0.0        # Fit Region's cell size (0: not fitted)
        self.region_note = ""  # why the fit fell back to the box, if it did
        self.clipped = ""      # the region faces the surface reaches ("+z -x"), if any
        self.cancel = binding.CancelToken()
        self.mesh = None
        self.error = None
        self.seconds = 0.0
        self.t_start = time.perf_counter()
        self.t_run = self.t_start  # when its thread started
        self.done = threading.Event()

    def run(self):
        t0 = time.perf_counter()
        try:
            if self.cache is None:
                self._run()
            else:  # one run of this field at a time uses its cache and kept evaluators
                with self.cache_lock:
                    self._run()
        except binding.Cancelled:
            self.error = None
        except binding.LibblendError as e:
            self.error = tree.explain(str(e), self.paths)
        except Exception as e:  # a bug: keep Blender alive and say so
            self.error = "internal error: %r" % (e,)
        self.seconds = time.perf_counter() - t0
        self.done.set()

    def _run(self):
        with self.lib.parse_scene(self.text, self.name) as scene:
            ev = self._compile(scene, "probe" if self.fit else "mesh")
            try:
                text = self._fit(ev, self.text) if self.fit else self.text
                if text is self.text:  # the compiled scene is the one to mesh
                    self._mesh(scene, ev)
            finally:
                self._keep("probe" if self.fit else "mesh", ev)
        if text is not self.text:  # a local union: its curves inside the fitted bounds
            with self.lib.parse_scene(text, self.name) as scene:
                ev = self._compile(scene, "mesh")
                try:
                    self._mesh(scene, ev)
                finally:
                    self._keep("mesh", ev)

    def _compile(self, scene, role):
        """the scene's evaluator; with a cache, compiled against the one this
        field's last run kept for the same role (the same result, the local
        unions whose children did not change keep their curves)"""
        kept = getattr(self.cache, "evaluators", {}) if self.cache is not None else {}
        return scene.compile(previous=kept.get(role))

    def _keep(self, role, ev):
        """keep ev for the next run's compile (with a cache), else free it"""
        if self.cache is None:
            ev.close()
            return
        kept = self.cache.__dict__.setdefault("evaluators", {})
        old = kept.get(role)
        kept[role] = ev
        if old is not None and old is not ev:
            old.close()

    def _mesh(self, scene, ev):
        import numpy as np
        self.mesh = self._mesh_with(ev, self.cache)
        self.clipped = clipped_faces(self.mesh.positions, self.bmin, self.bmax)
        mats = scene.materials()
        if len(mats) > 1 and len(self.mesh.triangles):
            # each triangle takes the material at its centroid
            P = self.mesh.positions[self.mesh.triangles.astype(np.int64)].mean(axis=1)
            self.mesh.material_index = scene.material_index(ev, P)
            self.mesh.materials = mats

    def _mesh_with(self, ev, cache):
        return ev.mesh(self.bmin, self.bmax, resolution=self.resolution, cell_size=self.cell,
                       open_boundary=self.open_boundary, threads=self.threads, cancel=self.cancel,
                       edges=compat.takes_libblend_edges(), features=self.features,
                       simplify=self.simplify, cache=cache, merge_flat=self.merge_flat,
                       coarse_first=self.coarse_first)

    def _fit(self, ev, text):
        # only local unions read the bounds when meshing: other scenes keep
        # their text (no JSON round trip on a live update)
        text, self.bmin, self.bmax, self.cell, self.region_note = fit_text(
            ev, text, self.bmin, self.bmax, self.resolution, rewrite='"local_union"' in text)
        return text


def fit_grid(lo, hi, box_min, box_max, resolution):
    """Fit Region's grid: (bmin, bmax, cell) covering lo..hi. The cell is the
    Region box's (its longest side / resolution, as without Fit Region),
    doubled while the covered box would need more than FIT_MAX_CELLS times
    resolution cells along a side (a field far larger than the box: the cost
    stays bounded); the corners are on the box's grid (box_min + whole
    cells). So where the box held the whole field the mesh is the one the
    box gives, a part that does not move is meshed the same in every frame
    while the field around it moves or grows, and `blendtool mesh
    --cell-size CELL` of the exported scene makes the same grid."""
    cell = max(max(b - a for a, b in zip(box_min, box_max)), 1e-9) / max(resolution, 1)
    while max(b - a for a, b in zip(lo, hi)) > FIT_MAX_CELLS * resolution * cell:
        cell *= 2.0
    bmin = tuple(o + math.floor((x - o) / cell) * cell for x, o in zip(lo, box_min))
    bmax = tuple(o + math.ceil((x - o) / cell) * cell for x, o in zip(hi, box_min))
    return bmin, bmax, cell


def fit_text(ev, text, bmin, bmax, resolution, rewrite=True):
    """Fit Region: (text, bmin, bmax, cell, note). The solid's extent
    (searched within FIT_SEARCH times the box bmin..bmax around its centre)
    grown by FIT_MARGIN of its longest side, on fit_grid's grid, and the
    scene text with those bounds (local unions look for their curves inside
    the bounds; with rewrite=False the text is returned as it came). When the
    solid is unbounded, not found, or too costly to bound: the box as it
    was, cell 0 (mesh by resolution) and a note saying why."""
    c = [(a + b) / 2 for a, b in zip(bmin, bmax)]
    box = max(max(b - a for a, b in zip(bmin, bmax)), 2e-3)
    h = FIT_SEARCH * box / 2
    smin, smax = [x - h for x in c], [x + h for x in c]
    # to about a cell (the grid snaps to cells anyway; a finer tol costs
    # (size / tol)^2 interval passes along a flat side)
    lo, hi, flags = ev.extent(smin, smax, box / min(max(resolution, 1), 128))
    if flags & binding.EXTENT_EMPTY:
        return text, tuple(bmin), tuple(bmax), 0.0, (
            "no surface within %g of the region's centre: meshed in the region box" % h)
    if flags & binding.EXTENT_TOUCHES:
        return text, tuple(bmin), tuple(bmax), 0.0, (
            "the field is unbounded (a slab, a half-space or a complement reaches out of any "
            "box): meshed in the region box")
    if flags & binding.EXTENT_COARSE:
        return text, tuple(bmin), tuple(bmax), 0.0, (
            "the field's extent needed more work than Fit Region allows: meshed in the region "
            "box")
    m = max(FIT_MARGIN * max(b - a for a, b in zip(lo, hi)), 1e-6)
    bmin, bmax, cell = fit_grid([x - m for x in lo], [x + m for x in hi], bmin, bmax, resolution)
    if not rewrite:
        return text, bmin, bmax, cell, ""
    scene = json.loads(text)
    scene["bounds"] = {"min": list(bmin), "max": list(bmax)}
    indent = None if text.startswith('{"') else 2
    return (json.dumps(scene, indent=indent, separators=(",", ":") if indent is None else None),
            bmin, bmax, cell, "")


def scene_text(output, depsgraph=None, render=True, resolution=None):
    """(text, paths, bmin, bmax, cell) of the scene as the field is meshed at
    resolution (default: its render resolution): with Fit Region, compiled
    once and its bounds fitted (fit_text; `blendtool mesh --cell-size CELL`
    makes the same grid), else the Region box (cell 0: `--resolution`).
    What Export writes."""
    text, paths = tree.to_json(output, depsgraph, render=render)
    s = output.libblend
    bmin, bmax = _region(output)
    cell = 0.0
    if s.fit_region:
        res = s.render_resolution if resolution is None else resolution
        with libhandle.library().parse_scene(text, output.name + ".json") as sc, \
                sc.compile() as ev:
            text, bmin, bmax, cell, _note = fit_text(ev, text, bmin, bmax, res)
    return text, paths, bmin, bmax, cell


def clipped_faces(positions, bmin, bmax):
    """The faces of the region box ("-x +z") the mesh has vertices on: where the
    region cut the solid flat (a closed mesh of a solid inside the box has none)."""
    if not len(positions):
        return ""
    faces = []
    for d in range(3):
        tol = 1e-7 * max(bmax[d] - bmin[d], 1e-12)
        if (positions[:, d] <= bmin[d] + tol).any():
            faces.append("-" + "xyz"[d])
        if (positions[:, d] >= bmax[d] - tol).any():
            faces.append("+" + "xyz"[d])
    return " ".join(faces)


# --------------------------------------------------------------------------- mesh data

def wants_analytic(normals, ntriangles):
    return normals == "ANALYTIC" or (normals == "AUTO" and ntriangles < AUTO_ANALYTIC)


def set_normals(me, mesh):
    """libblend's normals as custom split normals: one per vertex, or with
    Sharp Features one per face corner (a crease's two sides apart)."""
    if getattr(mesh, "corner_normals", None) is not None:
        compat.set_custom_loop_normals(me, mesh.loop_normals())
    else:
        compat.set_custom_normals(me, mesh.normals)


def set_mesh_data(me, mesh, normals="AUTO"):
    """Replace me's geometry by the libblend mesh (numpy arrays, foreach_set).
    normals: AUTO / ANALYTIC / FACES (props.LB_ObjectSettings.normals)."""
    import numpy as np
    nv, nt = len(mesh.positions), len(mesh.triangles)
    me.clear_geometry()
    if nt:
        me.vertices.add(nv)
        me.vertices.foreach_set("co", mesh.positions.astype(np.float32).ravel())
        me.loops.add(3 * nt)
        # uint32: the properties' own type, which foreach_set copies as one
        # block (int32 goes element by element: 9 ms against 0.5 ms for 85k
        # triangles on 3.4, bench/run_blender_anim_bench.sh)
        me.loops.foreach_set("vertex_index", mesh.triangles.astype(np.uint32).ravel())
        me.polygons.add(nt)
        compat.set_triangles(me, nt)
        compat.set_edges(me, getattr(mesh, "edges", None), getattr(mesh, "corner_edges", None))
        me.polygons.foreach_set("use_smooth", np.ones(nt, dtype=bool))
        if getattr(mesh, "materials", None):
            set_materials(me, mesh)
        if wants_analytic(normals, nt):
            set_normals(me, mesh)
        else:
            compat.clear_custom_normals(me)
    me.update()


def set_materials(me, mesh):
    """The nodes' materials as material slots (slot i is libblend's material
    i; slot 0, the render section's, is kept when it is there) and each
    face's slot. A slot's Blender material is made once and updated only
    when the scene's material changes, so edits made in Blender stay."""
    import numpy as np
    for i, m in enumerate(mesh.materials):
        if i == 0 and len(me.materials):
            continue
        name = "%s material %d" % (me.name, i)
        key = json.dumps(m, sort_keys=True)
        bm = me.materials[i] if i < len(me.materials) else None
        if bm is None:
            bm = bpy.data.materials.get(name) or bpy.data.materials.new(name)
        if bm.get("libblend_material") != key:
            bm["libblend_material"] = key
            bm.use_nodes = True
            bsdf = bm.node_tree.nodes.get("Principled BSDF")
            names = compat.principled_inputs()
            if bsdf is not None:
                bsdf.inputs[names["color"]].default_value = list(m["color"]) + [1.0]
                bsdf.inputs[names["specular"]].default_value = m["specular"]
                bsdf.inputs[names["roughness"]].default_value = 0.4
            bm.diffuse_color = list(m["color"]) + [1.0]
        if i < len(me.materials):
            me.materials[i] = bm
        else:
            me.materials.append(bm)
    me.polygons.foreach_set("material_index", mesh.material_index.astype(np.int32))


# --------------------------------------------------------------------------- jobs

def mesh_key(text, bmin, bmax, resolution, open_boundary, features=False, simplify=0.0,
             merge_flat=False, coarse_first=False):
    """What a mesh is a function of: the scene text, the region, the
    resolution, the boundary mode, Sharp Features, Merge Flat and Simplify
    with its method.
    Equal keys, equal meshes; so a field whose key did not change is not
    meshed again (frames where nothing moved, a driver that did not change
    its value, a render's first frame). Without those three options the key
    is the one bakes made before the options existed."""
    parts = [text, list(bmin), list(bmax), int(resolution), bool(open_boundary)]
    if features:
        parts.append("features")
    if simplify > 0.0:
        parts.append("simplify %r" % float(simplify))
        if coarse_first:
            parts.append("coarse first")
    if merge_flat:
        parts.append("merge flat")
    h = hashlib.sha256(json.dumps(parts).encode())
    return h.hexdigest()[:32]

def _state(name):
    st = _states.get(name)
    if st is None:
        st = _states[name] = _State()
    return st


def state_of(output):
    return _state(output.name)


def _region(output):
    s = output.libblend
    return tuple(s.bounds_min), tuple(s.bounds_max)


def region_of(output):
    """The region the field's mesh was last made in (Fit Region: the fitted
    box), else its Region Min / Max box."""
    st = _states.get(output.name)
    if output.libblend.fit_region and st is not None and st.region is not None:
        return st.region
    return _region(output)


def viewport_simplify(output):
    """The tolerance (cells) the Viewport Simplify preference gives the
    field's viewport mesh: the preference where the field's own Simplify is
    0 and Sharp Features off (Coarse First cannot keep creases, and the
    collapses cost more than they save while editing), else 0."""
    s = output.libblend
    if s.simplify > 0.0 or s.sharp_features:
        return 0.0
    return float(libhandle.viewport_simplify())


def prepare(output, resolution, depsgraph=None, viewport=False):
    """Read the tree (main thread) into a _Job; raises tree.TreeError or
    binding.LibraryError. With a depsgraph the values are that depsgraph's
    (a render's frame), else the objects' own. viewport: the mesh is the
    viewport's (live updates, playback), where the Viewport Simplify
    preference applies (viewport_simplify); renders, bakes and Apply mesh
    with the field's own settings."""
    lib = libhandle.library()
    text, paths = tree.to_json(output, depsgraph, render=False, compact=True)
    bmin, bmax = _region(output)
    s = output.libblend
    simplify, coarse = s.simplify, s.simplify_method == "COARSE"
    vs = viewport_simplify(output) if viewport else 0.0
    if vs > 0.0:
        simplify, coarse = vs, True
    return _Job(lib, text, output.name + ".json", bmin, bmax, resolution,
                s.open_boundary, libhandle.threads(), paths,
                fit=s.fit_region, features=s.sharp_features,
                simplify=simplify, cache=_state(output.name).mesh_cache(lib),
                merge_flat=s.merge_flat, coarse_first=coarse)


def _finish(output, st, job, t_start, defer_normals=False):
    if job.error:
        st.status, st.error = job.error, True
        return False
    t0 = time.perf_counter()
    mode = output.libblend.normals
    st.normals = None
    if defer_normals and wants_analytic(mode, len(job.mesh.triangles)):
        st.normals = job.mesh  # its normals, set once the field is idle
        mode = "FACES"
    set_mesh_data(output.data, job.mesh, mode)
    st.applied_key = job.key
    st.t_applied = time.perf_counter()
    st.last = {"mesh": job.seconds, "apply": time.perf_counter() - t0,
               "total": time.perf_counter() - t_start}
    st.expect = job.seconds
    cells = "%d cells" % job.resolution if not job.cell else \
        "fitted region, cell %g" % job.cell
    st.status = "%d triangles, %s, %.0f ms (libblend %.0f ms)" % (
        len(job.mesh.triangles), cells,
        1000 * st.last["total"], 1000 * job.seconds)
    st.error = False
    note_region(output, st, job)
    return True


def note_region(output, st, job):
    """Keep the region a run used, and say (panel and console, once per
    change) when the surface reached the region's boundary and was cut flat."""
    st.region = (tuple(job.bmin), tuple(job.bmax))
    warn = ""
    if job.clipped and not job.open_boundary:  # Open at Region: cut on purpose
        warn = ("field '%s': the surface reaches the region's boundary (%s) and is cut flat "
                "there%s. Fix: %s" % (
                    output.name, job.clipped, "; " + job.region_note if job.region_note else "",
                    "enlarge Region Min / Max" if job.fit or output.libblend.fit_region
                    else "turn on Fit Region, or enlarge Region Min / Max"))
    if warn and warn != st.clip_warning:
        print("libblend: " + warn)
    st.clip_warning = warn


def update_now(output, final=False, depsgraph=None, force=True):
    """Mesh the output synchronously on this thread; returns (ok, message).
    force=False skips the meshing when the mesh in Blender already is this
    state's (same mesh_key)."""
    st = _state(output.name)
    t0 = time.perf_counter()
    if st.job:
        st.job.cancel.cancel()
    try:
        job = prepare(output, output.libblend.render_resolution if final
                      else output.libblend.preview_resolution, depsgraph, viewport=not final)
    except (tree.TreeError, binding.LibraryError) as e:
        st.status, st.error = str(e), True
        return False, str(e)
    if not force and job.key == st.applied_key and st.normals is None and not st.error:
        st.dirty = False
        return True, st.status
    job.run()
    ok = _finish(output, st, job, t0)
    st.dirty = False
    return ok, st.status


def _frame(scene, depsgraph):
    return depsgraph.scene_eval.frame_current if depsgraph is not None else scene.frame_current


def cached_key(output, depsgraph=None):
    """The mesh_key a baked frame of this state must have (render resolution);
    needs no library."""
    s = output.libblend
    text, _paths = tree.to_json(output, depsgraph, render=False, compact=True)
    bmin, bmax = ("fit", "fit") if s.fit_region else _region(output)
    return mesh_key(text, bmin, bmax, s.render_resolution, s.open_boundary, s.sharp_features,
                    s.simplify, s.merge_flat, s.simplify_method == "COARSE")


def from_cache(output, frame, depsgraph=None):
    """Apply the baked mesh of frame when the field uses its bake and the
    frame's file is there and current. Returns (used, note): note says why
    not (for the status line and render logs), "" when there is no bake."""
    s = output.libblend
    if not s.use_bake:
        return False, ""
    st = _state(output.name)
    t0 = time.perf_counter()
    try:
        key = cached_key(output, depsgraph)
        if key == st.applied_key and not st.error:
            return True, ""
        path = bake.frame_path(bake.folder(output), frame)
        mesh = bake.read(path, key)
    except (tree.TreeError, bake.CacheError) as e:
        return False, str(e)
    if mesh is None:
        return False, ("field '%s': frame %d is not in its bake (%s) or the field changed since "
                       "the bake: meshed instead" % (output.name, frame, os.path.dirname(path)))
    if st.job:
        st.job.cancel.cancel()
        st.job = None
    t1 = time.perf_counter()
    set_mesh_data(output.data, mesh, output.libblend.normals)
    st.normals, st.dirty, st.error = None, False, False
    st.applied_key, st.t_applied = key, time.perf_counter()
    st.last = {"mesh": 0.0, "read": t1 - t0, "apply": st.t_applied - t1,
               "total": st.t_applied - t0}
    st.status = "%d triangles, frame %d from the bake, %.0f ms" % (
        len(mesh.triangles), frame, 1000 * st.last["total"])
    return True, ""


def frame_update(output, frame, depsgraph=None, final=True):
    """The field at a frame, synchronously: its baked mesh when it uses one
    and has that frame, else meshed (skipped when already current).
    Returns (ok, message); a bake that could not be used is reported on
    standard output (render logs) and in the status line."""
    used, note = from_cache(output, frame, depsgraph)
    if used:
        return True, _state(output.name).status
    ok, msg = update_now(output, final=final, depsgraph=depsgraph, force=False)
    if note:
        print("libblend:", note)
        if ok:
            st = _state(output.name)
            st.status = msg = st.status + " (" + note.split(": ", 1)[-1] + ")"
    return ok, msg


_baking = {"active": False}


def bake_frames(output, scene, frames, wm=None):
    """Bake: mesh output at render resolution at each frame (the scene is
    stepped through them with frame_set, then put back), write each file
    atomically, and switch the field to its bake. Returns (files, seconds).
    Raises bake.CacheError, tree.TreeError, binding.LibblendError, OSError."""
    folder = bake.folder(output)
    frames = list(frames)
    keep = scene.frame_current, scene.frame_subframe
    t0 = time.perf_counter()
    _baking["active"] = True
    if wm is not None:
        wm.progress_begin(0, len(frames))
    try:
        for i, f in enumerate(frames):
            scene.frame_set(f)
            dg = bpy.context.evaluated_depsgraph_get()
            job = prepare(output, output.libblend.render_resolution, dg)
            job.run()
            if job.error:
                raise binding.LibblendError("frame %d: %s" % (f, job.error))
            bake.write(bake.frame_path(folder, f), job.mesh, job.key, f, job.resolution,
                       output.name)
            if wm is not None:
                wm.progress_update(i + 1)
    finally:
        _baking["active"] = False
        if wm is not None:
            wm.progress_end()
        scene.frame_set(keep[0], subframe=keep[1])
    seconds = time.perf_counter() - t0
    s = output.libblend
    s.bake_info = "frames %d-%d (%d files, %d cells) in %.1f s: %s" % (
        frames[0], frames[-1], len(frames), s.render_resolution, seconds, folder)
    s.use_bake = True
    from_cache(output, scene.frame_current)
    return len(frames), seconds


def mark_dirty(obj):
    """Called when something that shapes obj's field changed."""
    out = tree.output_of(obj)
    if out is None or not out.libblend.live:
        return
    st = _state(out.name)
    st.dirty = True
    st.t_edit = time.perf_counter()
    _ensure_timer()


def _ensure_timer():
    global _timer_on
    if not _timer_on and not bpy.app.background:
        # at the next turn of Blender's loop, not a period later: the
        # edit's latency is the run's, not the run's plus a tick
        bpy.app.timers.register(tick, first_interval=0.0)
        _timer_on = True


def tick():
    """The timer: start coalesced jobs, move finished meshes in, set analytic
    normals once idle. Returns the next interval, or None when nothing is
    pending (the timer stops)."""
    global _timer_on
    pending = False
    wake = TICK  # the next interval: sooner when a run should end sooner
    for name in list(_states):
        st = _states[name]
        out = bpy.data.objects.get(name)
        if out is None or out.libblend.kind != "OUTPUT":
            if st.job:
                st.job.cancel.cancel()
            del _states[name]
            continue
        now = time.perf_counter()
        if st.job is not None:
            if st.job.done.is_set():
                job, st.job = st.job, None
                if not job.cancel.cancelled:
                    _finish(out, st, job, job.t_start, defer_normals=True)
            else:
                if st.dirty and now - st.job.t_start > CANCEL_AFTER:
                    st.job.cancel.cancel()  # obsolete and slow: the newest state goes next
                # poll again when the run should be done (the last one's
                # length from its start), so a finished mesh waits at most
                # MIN_TICK or a fraction of its run, not a whole TICK
                expect = st.expect if st.expect is not None else TICK
                left = st.job.t_run + expect - now
                wake = min(wake, max(MIN_TICK, left if left > 0 else 0.1 * expect))
                pending = True
                continue
        if st.dirty:
            st.dirty = False
            if out.libblend.use_bake and from_cache(out, bpy.context.scene.frame_current)[0]:
                continue  # scrubbing a baked field: its frame's file
            try:
                job = prepare(out, out.libblend.preview_resolution, viewport=True)
            except (tree.TreeError, binding.LibraryError) as e:
                st.status, st.error = str(e), True
                continue
            if job.key != st.applied_key or st.error:
                job.t_start = st.t_edit
                if st.expect is not None and st.expect < SYNC_BELOW:
                    # short enough to block the loop for, like an update of
                    # Blender's own metaballs: no thread, no polling
                    job.run()
                    _finish(out, st, job, job.t_start, defer_normals=True)
                    if st.normals is not None:
                        pending = True
                    continue
                job.t_run = time.perf_counter()
                st.job = job
                threading.Thread(target=job.run, name="libblend-mesh", daemon=True).start()
                wake = min(wake, max(MIN_TICK, st.expect if st.expect is not None else TICK))
                pending = True
                continue
            # else: an update that changed nothing the mesh depends on
        if st.normals is not None:
            if now - st.t_applied >= NORMALS_IDLE:
                set_normals(out.data, st.normals)
                out.data.update()
                st.normals = None
            else:
                pending = True
    if not pending:
        _timer_on = False
        return None
    return wake


def cancel_all():
    for st in _states.values():
        if st.job:
            st.job.cancel.cancel()
            st.job.done.wait(10)
            st.job = None


# --------------------------------------------------------------------------- handlers

@bpy.app.handlers.persistent
def on_depsgraph(scene, depsgraph):
    """A node changed: its transform (G / R / S, constraints, parents), or a
    setting through a driver or keyframe (which call no update callback).
    The field is marked dirty; the timer meshes it only when its scene text
    changed (mesh_key), so updates that change nothing cost one tree walk."""
    for u in depsgraph.updates:
        idb = u.id
        if isinstance(idb, bpy.types.Object):
            obj = idb.original
            if tree.is_node(obj):
                mark_dirty(obj)


_structure = {}


@bpy.app.handlers.persistent
def on_structure(scene, depsgraph):
    """Nodes added, deleted or re-parented: compare each output's node set."""
    for obj in scene.objects:
        if obj.libblend.kind != "OUTPUT":
            continue
        sig = _signature(obj)
        if _structure.get(obj.name) != sig:
            if obj.name in _structure:
                mark_dirty(obj)
            _structure[obj.name] = sig


def _signature(out):
    sig, stack = [], [out]
    while stack:
        o = stack.pop()
        for c in o.children:
            if tree.is_node(c):
                sig.append((c.name, o.name))
                stack.append(c)
    return tuple(sorted(sig))


@bpy.app.handlers.persistent
def on_undo(*_):
    cancel_all()
    for st in _states.values():
        st.applied_key = None  # undo restored some earlier mesh: mesh again
    for obj in bpy.data.objects:
        if obj.libblend.kind == "OUTPUT":
            mark_dirty(obj)


@bpy.app.handlers.persistent
def on_load(*_):
    cancel_all()
    _states.clear()
    _structure.clear()


_render = {"active": False, "meshed": [], "sub": {}}


def _render_frame(obj, frame, depsgraph=None):
    ok, _msg = frame_update(obj, frame, depsgraph, final=True)
    if ok and obj.name not in _render["meshed"]:
        _render["meshed"].append(obj.name)
    return ok


def note_subframe(obj, time, depsgraph):
    """A motion-blur step of a render: keep the field's scene at that time
    (the depsgraph's values) for the frame's velocities."""
    try:
        text = tree.to_json(obj, depsgraph, render=False, compact=True)[0]
    except tree.TreeError:
        return
    _render["sub"].setdefault(obj.name, {})[time] = text


def set_velocities(obj, frame, fps, depsgraph=None):
    """The point attribute `velocity` (scene units per second) on the field's
    mesh, which Cycles blurs by: the surface's normal motion between the
    render's motion-blur steps around frame (libblend's lb_mesh_velocities).
    Without steps on both sides the attribute is removed. Returns the
    largest speed, or None."""
    import numpy as np
    me = obj.data
    steps = _render["sub"].pop(obj.name, {})
    if me.get("libblend_velocities") == "given":
        return None  # blendtool's farm worker wrote them, from the job's own frames
    before = [t for t in steps if t < frame]
    after = [t for t in steps if t > frame]
    old = me.attributes.get("velocity")
    if old is not None:
        me.attributes.remove(old)
    n = len(me.vertices)
    if not before or not after or n == 0:
        return None
    tb, ta = max(before), min(after)
    lib = libhandle.library()
    try:
        text = tree.to_json(obj, depsgraph, render=False, compact=True)[0]
    except tree.TreeError:
        return None
    P = np.empty(3 * n, dtype=np.float32)
    me.vertices.foreach_get("co", P)
    P = P.reshape(-1, 3).astype(np.float64)
    with lib.parse_scene(text) as s0, lib.parse_scene(steps[tb]) as s1, \
            lib.parse_scene(steps[ta]) as s2, s0.compile() as e0, s1.compile() as e1, \
            s2.compile() as e2:
        # the steps are symmetric about the frame (the shutter is centred):
        # a central difference over half their distance, in frames
        v = e0.velocities(P, e1, e2, dt=(ta - tb) / 2, threads=libhandle.threads()) * fps
    a = me.attributes.new("velocity", "FLOAT_VECTOR", "POINT")
    a.data.foreach_set("vector", v.astype(np.float32).ravel())
    return float(np.abs(v).max())


@bpy.app.handlers.persistent
def on_render_init(scene, *_):
    """A final render starts (F12, blender -b -f / -a): each rendered field
    at render resolution (or from its bake) for the current frame. An
    animation's first frame change then finds it current (mesh_key) unless
    the range starts elsewhere."""
    _render["active"] = True
    for obj in scene.objects:
        if obj.libblend.kind == "OUTPUT" and not obj.hide_render:
            _render_frame(obj, scene.frame_current)


@bpy.app.handlers.persistent
def on_frame_change(scene, depsgraph=None):
    """A frame change. During a render (F12 animation, blender -b -a / -f,
    frame ranges) each frame's values live only in the render's depsgraph
    (the objects themselves still hold the previous frame's): every field is
    brought to that frame synchronously, before the frame renders, from
    that depsgraph at render resolution (or read from its bake). Otherwise
    (playback, scrubbing, frame_set in scripts) a baked field reads its
    frame's file at once, and the others are marked dirty and remesh at
    preview resolution by the live rules. Motion blur's sub-frame steps
    during a render are not meshed: the field's object motion blurs, its
    shape is the frame's own (docs/blender.md, Animation)."""
    if _baking["active"]:
        return  # a bake steps through frames itself
    outputs = [o.original for o in scene.objects if o.libblend.kind == "OUTPUT"]
    if _render["active"]:
        blur = scene.render.use_motion_blur
        if depsgraph is not None and depsgraph.scene_eval.frame_subframe != 0.0:
            # a motion-blur step: Cycles blurs a shape only between steps with the same
            # vertices, which a remeshed field never has, so the frame's own mesh stays;
            # the step's scene is kept for the frame's velocities
            if blur:
                se = depsgraph.scene_eval
                for obj in outputs:
                    if not obj.hide_render:
                        note_subframe(obj, se.frame_current + se.frame_subframe, depsgraph)
            return
        frame = _frame(scene, depsgraph)
        for obj in outputs:
            if not obj.hide_render:  # a field left out of the render is left as it is
                if _render_frame(obj, frame, depsgraph) and blur:
                    set_velocities(obj, frame, scene.render.fps / scene.render.fps_base,
                                   depsgraph)
        return
    for obj in outputs:
        if obj.libblend.use_bake and from_cache(obj, _frame(scene, depsgraph), depsgraph)[0]:
            continue
        if obj.libblend.live:
            mark_dirty(obj)


@bpy.app.handlers.persistent
def on_render_done(scene, *_):
    """After a render: back to the viewport's mesh of the current frame."""
    _render["active"] = False
    _render["sub"].clear()
    while _render["meshed"]:
        obj = bpy.data.objects.get(_render["meshed"].pop())
        if obj is not None:
            frame_update(obj, scene.frame_current, final=False)


_HANDLERS = [("depsgraph_update_post", on_depsgraph), ("depsgraph_update_post", on_structure),
             ("undo_post", on_undo), ("redo_post", on_undo), ("load_post", on_load),
             ("render_init", on_render_init), ("render_complete", on_render_done),
             ("render_cancel", on_render_done), ("frame_change_post", on_frame_change)]


def register():
    for name, fn in _HANDLERS:
        getattr(bpy.app.handlers, name).append(fn)


def unregister():
    cancel_all()
    for name, fn in _HANDLERS:
        lst = getattr(bpy.app.handlers, name)
        if fn in lst:
            lst.remove(fn)
    if bpy.app.timers.is_registered(tick):
        bpy.app.timers.unregister(tick)
