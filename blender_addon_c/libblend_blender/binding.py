"""ctypes binding of libblend's C API: scenes, compiled evaluators, bounds,
meshes and POV-Ray export, for plain Python (numpy) and for the Blender
add-on alike. No Blender import here.

    import binding
    lib = binding.load()                      # LIBBLEND_LIBRARY or ./lib/libblend.so
    scene = lib.parse_scene(text, "my.json")  # LibblendError with the C message on bad input
    ev = scene.compile()
    values, grads = ev.eval(points)           # points: (n, 3) array
    mesh = ev.mesh(bmin, bmax, resolution=64) # mesh.positions (n, 3), mesh.triangles (t, 3)

Contract: every failure of the library becomes a LibblendError whose text is
the library's own message (file, JSON path, allowed values); a library that
is missing or of another version raises LibraryError saying which file was
tried and what to do. Handles free their C objects when garbage collected or
on close(). Library calls release the GIL (ctypes), so meshing may run on a
worker thread; no C callback is ever passed (no foreign-thread callbacks);
cancel a running mesh with a CancelToken from any thread.
"""
import ctypes
import os
import platform

try:
    import numpy as np
except ImportError:  # pragma: no cover - reported when a numpy function is used
    np = None

#: the library version this binding is written for (major, minor)
API_VERSION = (0, 1)
ENV_LIBRARY = "LIBBLEND_LIBRARY"

STATUS_NAMES = {0: "ok", 1: "invalid argument", 2: "not finite", 3: "no memory",
                4: "internal error", 5: "cancelled", 6: "i/o error"}
STATUS_CANCELLED = 5
FORMATS = {"auto": 0, "ply": 1, "obj": 2, "stl": 3, "glb": 4}
MESH_OPEN_BOUNDARY = 1
MESH_FEATURES = 4  # LB_MESH_FEATURES: keep sharp creases and corners
MESH_CORNER_NORMALS = 8  # LB_MESH_CORNER_NORMALS: a normal per side of each crease
MESH_MERGE_FLAT = 16  # LB_MESH_MERGE_FLAT: flat regions as few triangles, exact
MESH_COARSE_FIRST = 32  # LB_MESH_COARSE_FIRST: simplify by meshing coarse first


class LibblendError(Exception):
    """A failure reported by libblend; .status is the C status code."""

    def __init__(self, message, status=4):
        super().__init__(message)
        self.status = status
        self.message = message


class LibraryError(LibblendError):
    """libblend.so could not be loaded or is not the version this binding needs."""


class Cancelled(LibblendError):
    """A run was cancelled through a CancelToken."""


class _Error(ctypes.Structure):
    _fields_ = [("status", ctypes.c_int), ("message", ctypes.c_char * 512)]


class _MeshOptions(ctypes.Structure):
    _fields_ = [("bmin", ctypes.c_double * 3), ("bmax", ctypes.c_double * 3),
                ("resolution", ctypes.c_uint), ("cell_size", ctypes.c_double),
                ("flags", ctypes.c_uint), ("threads", ctypes.c_int),
                ("max_memory", ctypes.c_size_t), ("progress", ctypes.c_void_p),
                ("user", ctypes.c_void_p), ("cancel", ctypes.POINTER(ctypes.c_int)),
                ("simplify", ctypes.c_double)]


class _Mesh(ctypes.Structure):
    _fields_ = [("nvertices", ctypes.c_size_t), ("ntriangles", ctypes.c_size_t),
                ("positions", ctypes.POINTER(ctypes.c_double)),
                ("normals", ctypes.POINTER(ctypes.c_double)),
                ("triangles", ctypes.POINTER(ctypes.c_uint32)),
                ("origin", ctypes.c_double * 3), ("cell", ctypes.c_double * 3),
                ("cells", ctypes.c_uint * 3),
                ("nnormals", ctypes.c_size_t),
                ("corner_normals", ctypes.POINTER(ctypes.c_uint32))]


class _PovOptions(ctypes.Structure):
    _fields_ = [("include_only", ctypes.c_int), ("silhouette", ctypes.c_int),
                ("aspect", ctypes.c_double), ("max_gradient", ctypes.c_double),
                ("threads", ctypes.c_int), ("mesh_resolution", ctypes.c_int),
                ("mesh_features", ctypes.c_int), ("mesh_simplify", ctypes.c_double),
                ("mesh_merge_flat", ctypes.c_int)]


class _Material(ctypes.Structure):
    _fields_ = [("color", ctypes.c_double * 3), ("ambient", ctypes.c_double),
                ("diffuse", ctypes.c_double), ("specular", ctypes.c_double)]


class _Light(ctypes.Structure):
    _fields_ = [("location", ctypes.c_double * 3), ("color", ctypes.c_double * 3)]


class _Stats(ctypes.Structure):
    _fields_ = [("nodes", ctypes.c_size_t), ("primitives", ctypes.c_size_t),
                ("operators", ctypes.c_size_t), ("depth", ctypes.c_size_t)]


class _CacheStats(ctypes.Structure):
    _fields_ = [("blocks", ctypes.c_size_t), ("reused", ctypes.c_size_t),
                ("recycled", ctypes.c_size_t), ("bytes", ctypes.c_size_t)]


_P = ctypes.c_void_p
_D = ctypes.POINTER(ctypes.c_double)
_ERR = ctypes.POINTER(_Error)
_U32 = ctypes.POINTER(ctypes.c_uint32)

# lb_evaluator_extent's flags
EXTENT_EMPTY, EXTENT_TOUCHES, EXTENT_COARSE = 1, 2, 4

# name: (restype, argtypes)
_SIGNATURES = {
    "lb_version": (ctypes.c_int, []),
    "lb_status_string": (ctypes.c_char_p, [ctypes.c_int]),
    "lb_scene_parse": (ctypes.c_int, [ctypes.c_char_p, ctypes.c_size_t, ctypes.c_char_p,
                                      ctypes.POINTER(_P), _ERR]),
    "lb_scene_load": (ctypes.c_int, [ctypes.c_char_p, ctypes.POINTER(_P), _ERR]),
    "lb_scene_free": (None, [_P]),
    "lb_scene_convention": (ctypes.c_int, [_P]),
    "lb_scene_bounds": (ctypes.c_int, [_P, _D, _D]),
    "lb_scene_stats_get": (None, [_P, ctypes.POINTER(_Stats)]),
    "lb_scene_describe": (ctypes.c_size_t, [_P, ctypes.c_char_p, ctypes.c_size_t]),
    "lb_scene_material_count": (ctypes.c_size_t, [_P]),
    "lb_scene_material": (ctypes.c_int, [_P, ctypes.c_size_t, ctypes.POINTER(_Material)]),
    "lb_scene_material_index": (ctypes.c_int, [_P, _P, ctypes.c_size_t, _D, _D, _D, _U32, _ERR]),
    "lb_evaluator_create": (ctypes.c_int, [_P, ctypes.POINTER(_P), _ERR]),
    "lb_evaluator_create_reusing": (ctypes.c_int, [_P, _P, ctypes.POINTER(_P),
                                                   ctypes.POINTER(ctypes.c_size_t), _ERR]),
    "lb_evaluator_free": (None, [_P]),
    "lb_evaluator_size": (ctypes.c_size_t, [_P]),
    "lb_evaluator_eval": (ctypes.c_int, [_P, ctypes.c_size_t, _D, _D, _D, _D, _D, _D, _D,
                                         ctypes.c_int, _ERR]),
    "lb_evaluator_bounds": (ctypes.c_int, [_P, _D, _D, _D, _D, _ERR]),
    "lb_evaluator_extent": (ctypes.c_int, [_P, _D, _D, ctypes.c_double, _D, _D,
                                           ctypes.POINTER(ctypes.c_int), _ERR]),
    "lb_mesh_options_init": (None, [ctypes.POINTER(_MeshOptions)]),
    "lb_mesh_create": (ctypes.c_int, [_P, ctypes.POINTER(_MeshOptions),
                                      ctypes.POINTER(ctypes.POINTER(_Mesh)), _ERR]),
    "lb_mesh_free": (None, [ctypes.POINTER(_Mesh)]),
    "lb_mesh_cache_create": (ctypes.c_int, [ctypes.POINTER(_P), _ERR]),
    "lb_mesh_cache_free": (None, [_P]),
    "lb_mesh_create_cached": (ctypes.c_int, [_P, ctypes.POINTER(_MeshOptions), _P,
                                             ctypes.POINTER(ctypes.POINTER(_Mesh)), _ERR]),
    "lb_mesh_cache_stats_get": (None, [_P, ctypes.POINTER(_CacheStats)]),
    "lb_mesh_cache_recycle": (None, [_P, ctypes.POINTER(_Mesh)]),
    "lb_mesh_edges": (ctypes.c_int, [ctypes.POINTER(_Mesh), _U32, _U32,
                                     ctypes.POINTER(ctypes.c_size_t), _ERR]),
    "lb_mesh_write": (ctypes.c_int, [ctypes.POINTER(_Mesh), ctypes.c_char_p, ctypes.c_int, _ERR]),
    "lb_mesh_velocities": (ctypes.c_int, [_P, _P, _P, ctypes.POINTER(_Mesh), ctypes.c_double,
                                          ctypes.c_int, _D, _ERR]),
    "lb_render_three_point": (None, [_D, _D, _D, ctypes.POINTER(_Light)]),
    "lb_render_floor_height": (ctypes.c_int, [_P, _D, _D, _D, ctypes.c_int, _D, _ERR]),
    "lb_scene_write_pov": (ctypes.c_int, [_P, _P, ctypes.POINTER(_PovOptions), ctypes.c_char_p,
                                          _D, _ERR]),
}


def library_name(system=None):
    """The library's file name on a platform (platform.system()'s name):
    libblend.dll on Windows, libblend.dylib on macOS, else libblend.so."""
    system = system or platform.system()
    return {"Windows": "libblend.dll", "Darwin": "libblend.dylib"}.get(system, "libblend.so")


def platform_tag(system=None, machine=None):
    """This machine as Blender's extension platforms name it (linux-x64,
    windows-x64, macos-arm64, ...), for messages."""
    system = (system or platform.system()).lower()
    machine = (machine or platform.machine()).lower()
    osname = {"darwin": "macos"}.get(system, system)
    arch = {"x86_64": "x64", "amd64": "x64", "aarch64": "arm64", "arm64": "arm64"}.get(machine,
                                                                                     machine)
    return "%s-%s" % (osname, arch)


def _candidates():
    here = os.path.dirname(os.path.abspath(__file__))
    name = library_name()
    return [os.path.join(here, "lib", name), os.path.join(here, name)]


def default_path():
    """The library file load() would try: $LIBBLEND_LIBRARY, else the copy
    next to this module (lib/libblend.so)."""
    env = os.environ.get(ENV_LIBRARY)
    if env:
        return env
    for c in _candidates():
        if os.path.exists(c):
            return c
    return _candidates()[0]


def _need_numpy():
    if np is None:
        raise LibblendError("numpy is needed for arrays: install python3-numpy "
                            "(Blender's Python has it)", 1)


def _dptr(a):
    return a.ctypes.data_as(_D)


class Library:
    """One loaded libblend.so. Cheap to keep; thread-safe (the C library has
    no global state)."""

    def __init__(self, path):
        self.path = path
        if not os.path.exists(path):
            how = ("$%s points to it" % ENV_LIBRARY) if os.environ.get(ENV_LIBRARY) == path else \
                "the add-on's lib/ folder should hold it"
            raise LibraryError(
                "libblend library not found for %s: %s (%s). Fix: install the add-on package "
                "built for %s, or build libblend (cmake --build BUILD) and install the zip from "
                "BUILD/blender_addon/, or set %s to the path of %s"
                % (platform_tag(), path, how, platform_tag(), ENV_LIBRARY, library_name()), 6)
        try:
            self._c = ctypes.CDLL(path)
        except OSError as e:
            raise LibraryError("libblend library %s could not be loaded on %s: %s. Fix: install "
                               "the add-on package built for %s, or point %s at a working %s"
                               % (path, platform_tag(), e, platform_tag(), ENV_LIBRARY,
                                  library_name()), 6) from None
        missing = [n for n in _SIGNATURES if not hasattr(self._c, n)]
        if "lb_version" in missing:
            raise LibraryError("%s is not libblend (no lb_version symbol). Fix: point %s at "
                               "libblend.so" % (path, ENV_LIBRARY), 6)
        self._c.lb_version.restype = ctypes.c_int
        v = self._c.lb_version()
        self.version = (v // 10000, v // 100 % 100, v % 100)
        if self.version[:2] != API_VERSION or missing:
            raise LibraryError(
                "%s is libblend %d.%d.%d but this add-on needs %d.%d.x%s. Fix: install the add-on "
                "zip built together with the library, or point %s at the matching libblend.so"
                % ((path,) + self.version + API_VERSION +
                   ((" (missing: %s)" % ", ".join(missing)) if missing else "",) + (ENV_LIBRARY,)), 6)
        for name, (res, args) in _SIGNATURES.items():
            f = getattr(self._c, name)
            f.restype = res
            f.argtypes = args

    def _check(self, status, err, what):
        if status == 0:
            return
        msg = err.message.decode("utf-8", "replace") or self._c.lb_status_string(status).decode()
        cls = Cancelled if status == STATUS_CANCELLED else LibblendError
        raise cls(msg if msg.startswith(what) else "%s: %s" % (what, msg), status)

    def three_point(self, location, look_at, up):
        """The default key, fill and rim lights for a camera
        (lb_render_three_point): [(location, strength, casts_shadows)] * 3."""
        v = [(ctypes.c_double * 3)(*map(float, a)) for a in (location, look_at, up)]
        out = (_Light * 3)()
        self._c.lb_render_three_point(v[0], v[1], v[2], out)
        return [(tuple(L.location), L.color[0], i == 0) for i, L in enumerate(out)]

    def parse_scene(self, text, name=None):
        """Parse and validate a scene from a str or bytes (JSON, docs/scene-format.md)."""
        data = text.encode("utf-8") if isinstance(text, str) else bytes(text)
        out, err = _P(), _Error()
        st = self._c.lb_scene_parse(data, len(data), name.encode("utf-8") if name else None,
                                    ctypes.byref(out), ctypes.byref(err))
        self._check(st, err, "scene")
        return Scene(self, out)

    def mesh_cache(self):
        """An empty MeshCache (lb_mesh_cache): pass it to Evaluator.mesh(cache=)
        so that meshing an edited scene recomputes only the blocks that
        changed, with the same result as without it."""
        out, err = _P(), _Error()
        st = self._c.lb_mesh_cache_create(ctypes.byref(out), ctypes.byref(err))
        self._check(st, err, "mesh cache")
        return MeshCache(self, out)

    def load_scene(self, path):
        """Read, parse and validate a scene file."""
        out, err = _P(), _Error()
        st = self._c.lb_scene_load(os.fsencode(path), ctypes.byref(out), ctypes.byref(err))
        self._check(st, err, "scene")
        return Scene(self, out)


class _Handle:
    _free = None

    def __init__(self, lib, ptr):
        self.lib = lib
        self._p = ptr

    def close(self):
        if self._p is not None and self._p.value:
            getattr(self.lib._c, self._free)(self._p)
        self._p = None

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass

    def __enter__(self):
        return self

    def __exit__(self, *a):
        self.close()

    @property
    def ptr(self):
        if self._p is None:
            raise LibblendError("%s used after close()" % type(self).__name__, 1)
        return self._p


class MeshCache(_Handle):
    """The blocks of the last mesh made through it (lb_mesh_cache). Use from
    one thread at a time."""
    _free = "lb_mesh_cache_free"

    @property
    def stats(self):
        """(blocks, reused, recycled, bytes) of the last mesh (lb_mesh_cache_stats)."""
        st = _CacheStats()
        self.lib._c.lb_mesh_cache_stats_get(self.ptr, ctypes.byref(st))
        return st.blocks, st.reused, st.recycled, st.bytes


class Scene(_Handle):
    """A parsed, validated scene (immutable)."""
    _free = "lb_scene_free"

    @property
    def convention(self):
        return "soft" if self.lib._c.lb_scene_convention(self.ptr) == 1 else "zero"

    @property
    def bounds(self):
        """((x, y, z), (x, y, z)) from the scene's "bounds", or None."""
        lo, hi = (ctypes.c_double * 3)(), (ctypes.c_double * 3)()
        if not self.lib._c.lb_scene_bounds(self.ptr, lo, hi):
            return None
        return tuple(lo), tuple(hi)

    @property
    def stats(self):
        s = _Stats()
        self.lib._c.lb_scene_stats_get(self.ptr, ctypes.byref(s))
        return {"nodes": s.nodes, "primitives": s.primitives, "operators": s.operators,
                "depth": s.depth}

    def describe(self):
        n = self.lib._c.lb_scene_describe(self.ptr, None, 0)
        buf = ctypes.create_string_buffer(n + 1)
        self.lib._c.lb_scene_describe(self.ptr, buf, n + 1)
        return buf.value.decode("utf-8", "replace")

    def materials(self):
        """The scene's materials as dicts (color, ambient, diffuse, specular);
        the first is the render section's, then those the nodes name."""
        out = []
        for i in range(self.lib._c.lb_scene_material_count(self.ptr)):
            m = _Material()
            self.lib._c.lb_scene_material(self.ptr, i, ctypes.byref(m))
            out.append({"color": tuple(m.color), "ambient": m.ambient, "diffuse": m.diffuse,
                        "specular": m.specular})
        return out

    def material_index(self, evaluator, points):
        """The material (an index into materials()) each point's surface takes
        (lb_scene_material_index); points: (n, 3). Returns uint32 (n,)."""
        _need_numpy()
        P = np.ascontiguousarray(np.asarray(points, dtype=np.float64).reshape(-1, 3).T)
        idx = np.zeros(P.shape[1], dtype=np.uint32)
        err = _Error()
        st = self.lib._c.lb_scene_material_index(
            self.ptr, evaluator.ptr if evaluator is not None else None, P.shape[1], _dptr(P[0]),
            _dptr(P[1]), _dptr(P[2]), idx.ctypes.data_as(_U32), ctypes.byref(err))
        self.lib._check(st, err, "material index")
        return idx

    def compile(self, previous=None):
        """Compile into an Evaluator (independent of this scene afterwards).
        previous: the Evaluator of the scene before an edit (may be None):
        the result is the same, but the local unions whose children did not
        change copy their curves from it instead of finding them again
        (lb_evaluator_create_reusing); Evaluator.reused_curves says how many."""
        out, err, n = _P(), _Error(), ctypes.c_size_t(0)
        st = self.lib._c.lb_evaluator_create_reusing(
            self.ptr, previous.ptr if previous is not None else None, ctypes.byref(out),
            ctypes.byref(n), ctypes.byref(err))
        self.lib._check(st, err, "compile")
        ev = Evaluator(self.lib, out)
        ev.reused_curves = n.value
        return ev

    def write_pov(self, evaluator, path, include_only=False, silhouette=False, aspect=0.0,
                  max_gradient=0.0, threads=0, mesh_resolution=0):
        """Write a renderable POV-Ray scene (atomically); returns the max_gradient written.
        The file includes "libblend.inc" (povray_include/). mesh_resolution > 0 writes
        libblend's mesh at that many cells (a mesh2) instead of the isosurface."""
        o = _PovOptions(int(bool(include_only)), int(bool(silhouette)), float(aspect),
                        float(max_gradient), int(threads), int(mesh_resolution))
        g, err = ctypes.c_double(0.0), _Error()
        st = self.lib._c.lb_scene_write_pov(self.ptr, evaluator.ptr, ctypes.byref(o),
                                            os.fsencode(path), ctypes.byref(g), ctypes.byref(err))
        self.lib._check(st, err, "pov export")
        return g.value


class CancelToken:
    """A flag the C mesher polls; cancel() from any thread stops the run
    (mesh() then raises Cancelled)."""

    def __init__(self):
        self._flag = ctypes.c_int(0)

    def cancel(self):
        self._flag.value = 1

    @property
    def cancelled(self):
        return bool(self._flag.value)


class Evaluator(_Handle):
    """A compiled scene: values, gradients, interval bounds and meshes.
    Read-only: any number of threads may use one evaluator at once."""
    _free = "lb_evaluator_free"
    reused_curves = 0  # local unions whose curves Scene.compile(previous=) copied

    def __len__(self):
        return self.lib._c.lb_evaluator_size(self.ptr)

    def eval(self, points, threads=0, gradient=True):
        """values (n,) and, if gradient, gradients (n, 3) at points (n, 3).
        threads: 0 = all CPUs, 1 = the calling thread only."""
        _need_numpy()
        P = np.asarray(points, dtype=np.float64)
        if P.ndim != 2 or P.shape[1] != 3:
            raise LibblendError("points: shape %s; allowed: (n, 3)" % (P.shape,), 1)
        x, y, z = (np.ascontiguousarray(P[:, i]) for i in range(3))
        n = len(x)
        v = np.empty(n)
        g = [np.empty(n) for _ in range(3)] if gradient else None
        err = _Error()
        null = ctypes.cast(None, _D)
        st = self.lib._c.lb_evaluator_eval(self.ptr, n, _dptr(x), _dptr(y), _dptr(z), _dptr(v),
                                           *([_dptr(a) for a in g] if g else [null] * 3),
                                           int(threads), ctypes.byref(err))
        self.lib._check(st, err, "eval")
        return (v, np.stack(g, axis=1)) if gradient else (v, None)

    def floor_height(self, bmin, bmax, up, threads=0):
        """The floor's height along up under the surface in [bmin, bmax]
        (lb_render_floor_height: a 48-cell mesh's lowest vertex less half a
        cell, or the box's lowest corner)."""
        lo, hi, u = ((ctypes.c_double * 3)(*map(float, a)) for a in (bmin, bmax, up))
        h, err = ctypes.c_double(0.0), _Error()
        st = self.lib._c.lb_render_floor_height(self.ptr, lo, hi, u, int(threads), ctypes.byref(h),
                                                ctypes.byref(err))
        self.lib._check(st, err, "floor height")
        return h.value

    def bounds(self, bmin, bmax):
        """(lo, hi): an interval containing the field everywhere in the box."""
        lo, hi, err = ctypes.c_double(), ctypes.c_double(), _Error()
        a = (ctypes.c_double * 3)(*map(float, bmin))
        b = (ctypes.c_double * 3)(*map(float, bmax))
        st = self.lib._c.lb_evaluator_bounds(self.ptr, a, b, ctypes.byref(lo), ctypes.byref(hi),
                                             ctypes.byref(err))
        self.lib._check(st, err, "bounds")
        return lo.value, hi.value

    def extent(self, smin, smax, tol):
        """((x, y, z), (x, y, z), flags): a box holding every part of the solid
        inside the search box [smin, smax], from interval bounds, to about tol;
        flags are EXTENT_EMPTY, EXTENT_TOUCHES (it may reach the search box:
        unbounded), EXTENT_COARSE (lb_evaluator_extent)."""
        a = (ctypes.c_double * 3)(*map(float, smin))
        b = (ctypes.c_double * 3)(*map(float, smax))
        lo, hi = (ctypes.c_double * 3)(), (ctypes.c_double * 3)()
        flags, err = ctypes.c_int(0), _Error()
        st = self.lib._c.lb_evaluator_extent(self.ptr, a, b, float(tol), lo, hi,
                                             ctypes.byref(flags), ctypes.byref(err))
        self.lib._check(st, err, "extent")
        return tuple(lo), tuple(hi), flags.value

    def velocities(self, positions, before=None, after=None, dt=1.0, threads=0):
        """(n, 3) velocities of this field's surface at positions (n, 3), points
        on it (a mesh's vertices), from the same scene's evaluators at t - dt
        (before) and t + dt (after), either may be None, not both; in scene
        units per unit of dt (lb_mesh_velocities: the normal motion)."""
        _need_numpy()
        P = np.ascontiguousarray(np.asarray(positions, dtype=np.float64))
        if P.ndim != 2 or P.shape[1] != 3:
            raise LibblendError("positions: shape %s; allowed: (n, 3)" % (P.shape,), 1)
        m = _Mesh()
        m.nvertices, m.ntriangles = len(P), 0
        m.positions = _dptr(P)
        v = np.empty((len(P), 3))
        err = _Error()
        st = self.lib._c.lb_mesh_velocities(self.ptr, before.ptr if before else None,
                                            after.ptr if after else None, ctypes.byref(m),
                                            float(dt), int(threads), _dptr(v), ctypes.byref(err))
        self.lib._check(st, err, "velocities")
        return v

    def mesh(self, bmin, bmax, resolution=128, cell_size=0.0, open_boundary=False, threads=0,
             max_memory=0, cancel=None, edges=False, features=False, corner_normals=True,
             simplify=0.0, cache=None, recycle=False, merge_flat=False, coarse_first=False):
        """Mesh the field over the box [bmin, bmax] (docs/meshing.md). Returns a
        Mesh holding numpy copies. Raises Cancelled if cancel.cancel() was called.
        edges=True also fills Mesh.edges and Mesh.corner_edges (lb_mesh_edges);
        features=True keeps sharp creases and corners (LB_MESH_FEATURES), and
        with corner_normals (LB_MESH_CORNER_NORMALS) gives each side of a
        crease its own normal (Mesh.corner_normals, Mesh.loop_normals());
        simplify > 0 (cells, at most 1) merges triangles wherever the surface
        stays within that tolerance of the field (lb_mesh_options.simplify);
        merge_flat=True makes each flat face a triangulation of its outline,
        the surface unchanged (LB_MESH_MERGE_FLAT); coarse_first=True (with
        simplify) meets simplify's tolerance by meshing cells of twice the
        size where they are close enough, instead of by collapses
        (LB_MESH_COARSE_FIRST);
        cache (a MeshCache) remeshes only the blocks that changed since the
        last mesh made through it (lb_mesh_create_cached), byte-identical;
        recycle=True (with a cache) gives the C mesh's arrays back to the
        cache once copied (lb_mesh_cache_recycle), to take the next output
        (faster in C; in Blender slower at 128 cells in one measurement, so
        the add-on leaves it off: docs/meshing.md)."""
        _need_numpy()
        o = _MeshOptions()
        self.lib._c.lb_mesh_options_init(ctypes.byref(o))
        for i in range(3):
            o.bmin[i], o.bmax[i] = float(bmin[i]), float(bmax[i])
        o.resolution = int(resolution)
        o.cell_size = float(cell_size)
        o.flags = (MESH_OPEN_BOUNDARY if open_boundary else 0) | (MESH_FEATURES if features else 0) \
            | (MESH_CORNER_NORMALS if features and corner_normals else 0) \
            | (MESH_MERGE_FLAT if merge_flat else 0) | (MESH_COARSE_FIRST if coarse_first else 0)
        o.threads = int(threads)
        o.max_memory = int(max_memory)
        o.simplify = float(simplify)
        if cancel is not None:
            o.cancel = ctypes.pointer(cancel._flag)
        out, err = ctypes.POINTER(_Mesh)(), _Error()
        if cache is not None:
            st = self.lib._c.lb_mesh_create_cached(self.ptr, ctypes.byref(o), cache.ptr,
                                                   ctypes.byref(out), ctypes.byref(err))
        else:
            st = self.lib._c.lb_mesh_create(self.ptr, ctypes.byref(o), ctypes.byref(out),
                                            ctypes.byref(err))
        self.lib._check(st, err, "mesh")
        try:
            m = out.contents
            nv, nt = m.nvertices, m.ntriangles
            if nv:
                pos = np.ctypeslib.as_array(m.positions, shape=(nv, 3)).copy()
                nrm = np.ctypeslib.as_array(m.normals, shape=(nv, 3)).copy()
            else:
                pos, nrm = np.zeros((0, 3)), np.zeros((0, 3))
            tri = np.ctypeslib.as_array(m.triangles, shape=(nt, 3)).copy() if nt else \
                np.zeros((0, 3), dtype=np.uint32)
            mesh = Mesh(pos, nrm, tri, tuple(m.origin), tuple(m.cell), tuple(m.cells))
            if m.corner_normals and nt:  # features: shading normals per corner
                mesh.corner_normals = np.ctypeslib.as_array(m.corner_normals,
                                                            shape=(nt, 3)).copy()
                extra = m.nnormals - nv
                mesh.split_normals = np.ctypeslib.as_array(
                    m.normals, shape=(m.nnormals, 3))[nv:].copy() if extra else \
                    np.zeros((0, 3))
            if edges:
                ed = np.empty((3 * nt, 2), dtype=np.uint32)
                ce = np.empty(3 * nt, dtype=np.uint32)
                ne = ctypes.c_size_t()
                st = self.lib._c.lb_mesh_edges(out, ed.ctypes.data_as(_U32), ce.ctypes.data_as(_U32),
                                               ctypes.byref(ne), ctypes.byref(err))
                self.lib._check(st, err, "mesh edges")
                mesh.edges, mesh.corner_edges = ed[:ne.value].copy(), ce
            return mesh
        finally:
            if cache is not None and recycle:
                self.lib._c.lb_mesh_cache_recycle(cache.ptr, out)
            else:
                self.lib._c.lb_mesh_free(out)


class Mesh:
    """A triangle mesh: positions (n, 3) float64, unit normals (n, 3) from the
    analytic gradient, triangles (t, 3) uint32 counter-clockwise from outside;
    origin, cell and cells describe the grid used."""

    def __init__(self, positions, normals, triangles, origin, cell, cells):
        self.positions, self.normals, self.triangles = positions, normals, triangles
        self.origin, self.cell, self.cells = origin, cell, cells
        # with mesh(edges=True): the unique edges (e, 2) uint32, smaller vertex
        # first, and each triangle corner's edge (3 t,) uint32 (lb_mesh_edges)
        self.edges = self.corner_edges = None
        # set by the add-on when the scene's nodes name materials: each
        # triangle's material index and the materials (Scene.materials)
        self.material_index = self.materials = None
        # with mesh(features=True): each triangle corner's shading normal as
        # an index (t, 3) uint32 into normals followed by split_normals
        # (k, 3), the normals added on the sides of creases (lb_mesh's
        # corner_normals and nnormals)
        self.corner_normals = None
        self.split_normals = np.zeros((0, 3))

    def loop_normals(self):
        """The shading normal of every triangle corner, (3 t, 3) float64, in
        the order of triangles.ravel(): the corner normals where there are
        any, else each corner's vertex normal."""
        if self.corner_normals is None:
            return self.normals[self.triangles.ravel().astype(np.int64)]
        return np.concatenate([self.normals, self.split_normals])[
            self.corner_normals.ravel().astype(np.int64)]

    def volume(self):
        """Enclosed volume (divergence theorem); exact for a closed mesh."""
        V = self.positions[self.triangles.astype(np.int64)]
        return float(np.einsum("ij,ij->i", V[:, 0], np.cross(V[:, 1], V[:, 2])).sum() / 6.0)


def load(path=None):
    """Load libblend.so (path, else $LIBBLEND_LIBRARY, else the add-on's lib/ copy)."""
    return Library(path or default_path())
