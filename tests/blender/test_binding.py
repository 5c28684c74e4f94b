"""The ctypes binding (blender_addon_c/libblend_blender/binding.py) in plain
Python with numpy, outside Blender:

    /usr/bin/python3 test_binding.py ADDON_DIR BLENDTOOL SOURCE_DIR WORK_DIR

Values against closed-form formulas, arrays against `blendtool eval` (the
same scene through the command line: the marshalling of points, values and
gradients), bounds containing samples, meshes closed and manifold with the
right volume and identical to `blendtool mesh`, thread-count independence,
cancellation, POV-Ray export, and every error as a LibblendError carrying
the library's message.
"""
import ctypes
import glob
import json
import math
import os
import subprocess
import sys
import threading

import numpy as np

ADDON, BLENDTOOL, SRC, WORK = sys.argv[1:5]
os.makedirs(WORK, exist_ok=True)
sys.path.insert(0, ADDON)
sys.path.insert(0, os.path.join(SRC, "tests", "mesh"))
import binding  # noqa: E402
import meshcheck  # noqa: E402

checks = 0


def check(cond, what):
    global checks
    checks += 1
    if not cond:
        raise AssertionError(what)


def raises(fn, cls, *needles):
    try:
        fn()
    except cls as e:
        for n in needles:
            check(n in str(e), "%r in %r" % (n, str(e)))
        return e
    raise AssertionError("expected %s from %r" % (cls.__name__, fn))


os.environ.pop(binding.ENV_LIBRARY, None)
lib = binding.load()  # the copy next to the module (lib/libblend.so)
check(lib.version[:2] == binding.API_VERSION, "version")
check(os.path.samefile(os.path.dirname(lib.path), os.path.join(ADDON, "lib")),
      "loads the add-on's own copy")

SPHERE = """{"format": "libblend-scene", "version": 1, "convention": "zero",
 "bounds": {"min": [-1, -2, -1.5], "max": [2, 1.5, 1.5]},
 "root": {"type": "sphere", "center": [0.5, -0.25, 0.125], "radius": 0.75}}"""
c, R = np.array([0.5, -0.25, 0.125]), 0.75

# ---- values and gradients against the formula
with lib.parse_scene(SPHERE, "sphere.json") as sc:
    check(sc.convention == "zero", "convention")
    check(sc.bounds == ((-1.0, -2.0, -1.5), (2.0, 1.5, 1.5)), "bounds")
    check(sc.stats["primitives"] == 1, "stats")
    check("sphere" in sc.describe(), "describe")
    ev = sc.compile()
rng = np.random.default_rng(11)
P = rng.uniform(-3, 3, size=(100000, 3))
for threads in (1, 2, 0):
    v, g = ev.eval(P, threads=threads)
    d = np.linalg.norm(P - c, axis=1)
    check(np.abs(v - (d / R - 1)).max() < 1e-14, "sphere values (threads=%d)" % threads)
    check(np.abs(g - (P - c) / (R * d[:, None])).max() < 1e-13, "sphere gradients")
v1, _ = ev.eval(P[:10], gradient=False)
check(np.array_equal(v1, v[:10]), "values without gradients")

# ---- bounds contain samples
for _ in range(200):
    a = rng.uniform(-3, 3, 3)
    b = a + rng.uniform(0, 1.5, 3)
    lo, hi = ev.bounds(a, b)
    S = rng.uniform(a, b, size=(200, 3))
    fv, _ = ev.eval(S, threads=1, gradient=False)
    check(lo <= fv.min() and fv.max() <= hi, "bounds contain the field")

# ---- a paper scene against blendtool eval
fig7 = os.path.join(SRC, "scenes", "hsu2006-fig7-m0.6.json")
Q = rng.uniform(-2.2, 2.2, size=(3000, 3))
txt = "\n".join("%.17g %.17g %.17g" % tuple(p) for p in Q)
r = subprocess.run([BLENDTOOL, "eval", fig7], input=txt, capture_output=True, text=True, check=True)
ref = np.array([[float(x) for x in line.split()] for line in r.stdout.splitlines()])
with lib.load_scene(fig7) as sc, sc.compile() as ev7:
    v, g = ev7.eval(Q)
check(ref.shape == (3000, 4), "blendtool eval output")
check(np.array_equal(v, ref[:, 0]) and np.array_equal(g, ref[:, 1:]), "binding = blendtool eval")

# ---- meshes
bmin, bmax = (-1, -2, -1.5), (2, 1.5, 1.5)
m = ev.mesh(bmin, bmax, resolution=96, threads=1)
info = meshcheck.check(m.positions, m.triangles.astype(np.int64))
exact = 4.0 / 3.0 * math.pi * R ** 3
print("sphere mesh: %d triangles, volume %.6f (exact %.6f, rel %.1e)"
      % (len(m.triangles), info["volume"], exact, abs(info["volume"] / exact - 1)))
check(info["closed"] and info["manifold"] and info["oriented"] and info["euler"] == 2, "sphere mesh")
check(abs(info["volume"] / exact - 1) < 2e-3, "sphere volume")
check(abs(m.volume() - info["volume"]) < 1e-12, "Mesh.volume")
fs, _ = ev.eval(m.positions, gradient=False)
check(np.abs(fs).max() < 1e-6, "vertices on the surface")
check(np.abs(np.linalg.norm(m.normals, axis=1) - 1).max() < 1e-12, "unit normals")
m2 = ev.mesh(bmin, bmax, resolution=96, threads=2)
check(np.array_equal(m.positions, m2.positions) and np.array_equal(m.triangles, m2.triangles),
      "same mesh for 1 and 2 threads")
ply = os.path.join(WORK, "sphere.ply")
with open(os.path.join(WORK, "sphere.json"), "w") as f:
    f.write(SPHERE)
subprocess.run([BLENDTOOL, "mesh", os.path.join(WORK, "sphere.json"), "-o", ply, "--resolution",
                "96", "--quiet"], check=True)
Vb, _, Fb = meshcheck.read(ply)
check(np.array_equal(Fb, m.triangles.astype(np.int64)) and
      np.array_equal(Vb, m.positions.astype(np.float32).astype(np.float64)), "binding = blendtool mesh")
ext = np.subtract(bmax, bmin)
check(abs(max(m.cell) - 3.5 / 96) < 1e-12 and all(m.cells[i] * m.cell[i] >= ext[i] - 1e-9
                                                   for i in range(3)), "grid reported: %r" % (m.cells,))
mo = ev.mesh((0.5, -2, -1.5), bmax, resolution=48, open_boundary=True)
io = meshcheck.check(mo.positions, mo.triangles.astype(np.int64))
check(not io["closed"], "open_boundary leaves the cut open")
empty = ev.mesh((5, 5, 5), (6, 6, 6), resolution=8)
check(len(empty.triangles) == 0 and empty.positions.shape == (0, 3), "empty region, empty mesh")

# concurrent meshing of one evaluator from Python threads (the GIL is released)
res = [None, None]


def work(i):
    res[i] = ev.mesh(bmin, bmax, resolution=64, threads=1)


ts = [threading.Thread(target=work, args=(i,)) for i in range(2)]
for t in ts:
    t.start()
for t in ts:
    t.join()
check(np.array_equal(res[0].positions, res[1].positions), "concurrent meshes agree")

# cancellation
tok = binding.CancelToken()
tok.cancel()
raises(lambda: ev.mesh(bmin, bmax, resolution=256, cancel=tok), binding.Cancelled, "cancel")

# ---- POV-Ray export
with lib.load_scene(fig7) as sc, sc.compile() as ev7:
    pov = os.path.join(WORK, "fig7.pov")
    g = sc.write_pov(ev7, pov, threads=1)
    text = open(pov).read()
    check(g > 1 and ("max_gradient %.17g\n" % g) in text, "max_gradient written: %g" % g)
    check('#include "libblend.inc"' in text and "isosurface" in text, "a POV-Ray scene")
    inc_only = os.path.join(WORK, "fig7-functions.inc")
    sc.write_pov(ev7, inc_only, include_only=True)
    inc_text = open(inc_only).read()
    check("\nisosurface {" not in inc_text and "\ncamera {" not in inc_text
          and "#declare LB_Surface = LB_Field;" in inc_text
          and "#declare LB_FieldMaxGradient = " in inc_text,
          "include only: the field and what a hand-written scene needs, no object or camera")
    meshed = os.path.join(WORK, "fig7-mesh.pov")
    sc.write_pov(ev7, meshed, threads=1, mesh_resolution=32)
    mtext = open(meshed).read()
    check("mesh2 {" in mtext and "\nisosurface {" not in mtext,
          "mesh_resolution reaches the C struct: a mesh2 instead of the isosurface")
    raises(lambda: sc.write_pov(ev7, meshed, mesh_resolution=5000), binding.LibblendError,
           "mesh_resolution 5000")

# ---- velocities (lb_mesh_velocities): the sphere moved by +-dt s, at its
# mesh's vertices: the normal part (s . n) n of the speed s, to 1 %
s_vel, dt = np.array([0.6, -0.3, 0.2]), 1e-3
def moved(k):
    return lib.parse_scene(SPHERE.replace('"center": [0.5, -0.25, 0.125]', '"center": [%r, %r, %r]'
                                          % tuple(c + k * dt * s_vel)), "moved.json").compile()
with moved(-1) as evb, moved(1) as eva:
    m = ev.mesh((-1, -2, -1.5), (2, 1.5, 1.5), resolution=32, threads=1)
    V = ev.velocities(m.positions, before=evb, after=eva, dt=dt, threads=1)
    N = (m.positions - c) / np.linalg.norm(m.positions - c, axis=1)[:, None]
    want = (N @ s_vel)[:, None] * N
    worst = float(np.abs(V - want).max())
    check(V.shape == m.positions.shape and worst < 0.01 * np.linalg.norm(s_vel),
          "velocities: worst error %.2e of the speed %.2f" % (worst, np.linalg.norm(s_vel)))
    raises(lambda: ev.velocities(m.positions, dt=dt), binding.LibblendError, "lb_mesh_velocities")
    raises(lambda: ev.velocities(m.positions, after=eva, dt=0.0), binding.LibblendError, "dt")

# ---- compiling against the previous evaluator (lb_evaluator_create_reusing):
# a flat local union of 6 spheres is a fold of 5; moving the last sphere
# copies 4 folds' curves, and the evaluator is the fresh compile's
def ring(dx):
    args = [{"type": "sphere", "center": [1.2 * math.cos(q * math.pi / 3) + (dx if q == 5 else 0),
                                          1.2 * math.sin(q * math.pi / 3), 0], "radius": 0.6}
            for q in range(6)]
    return json.dumps({"format": "libblend-scene", "version": 1, "convention": "zero",
                       "bounds": {"min": [-2, -2, -1], "max": [2, 2, 1]},
                       "root": {"type": "local_union", "args": args}})


with lib.parse_scene(ring(0)) as s0, lib.parse_scene(ring(0.03)) as s1, s0.compile() as e0, \
        s1.compile(previous=e0) as e1, s1.compile() as ef:
    Q = np.random.default_rng(5).uniform(-2, 2, (2000, 3)) * [1, 1, 0.5]
    check(e0.reused_curves == 0 and e1.reused_curves == 4 and ef.reused_curves == 0,
          "compile(previous=): 4 of 5 local unions' curves copied (%d)" % e1.reused_curves)
    a, b = e1.eval(Q), ef.eval(Q)
    check(np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1]),
          "compile(previous=) evaluates as a fresh compile, bit for bit")

# ---- errors
raises(lambda: lib.parse_scene('{"format": "libblend-scene",\n "version": 1, }', "a.json"),
       binding.LibblendError, "a.json:2:", "invalid JSON")
raises(lambda: lib.parse_scene(SPHERE.replace('"radius": 0.75', '"radius": -1'), "b.json"),
       binding.LibblendError, "b.json", "$.root.radius")
raises(lambda: lib.load_scene(os.path.join(WORK, "missing.json")), binding.LibblendError,
       "missing.json")
raises(lambda: ev.eval(np.zeros((4, 2))), binding.LibblendError, "(n, 3)")
raises(lambda: ev.eval([[1e300, 0, 0]]), binding.LibblendError)
raises(lambda: ev.mesh((0, 0, 0), (1, 1, 1), resolution=0), binding.LibblendError, "resolution")
raises(lambda: ev.mesh((0, 0, 0), (0, 1, 1)), binding.LibblendError)
raises(lambda: ev.bounds((1, 1, 1), (0, 0, 0)), binding.LibblendError)
raises(lambda: ev.mesh(bmin, bmax, resolution=8192, max_memory=1 << 20), binding.LibblendError,
       "memory")
ev.close()
raises(lambda: ev.eval(P[:1]), binding.LibblendError, "after close")
ev.close()  # twice is fine

# ---- the library itself
raises(lambda: binding.load(os.path.join(WORK, "nope", "libblend.so")), binding.LibraryError,
       "not found", "nope", "for linux-x64")
# the file and the platform in messages, by platform (the Windows and macOS
# packages carry libblend.dll / libblend.dylib)
check(binding.library_name("Windows") == "libblend.dll" and
      binding.library_name("Darwin") == "libblend.dylib" and
      binding.library_name("Linux") == "libblend.so" and binding.library_name() == "libblend.so",
      "the library's file name by platform")
check(binding.platform_tag("Windows", "AMD64") == "windows-x64" and
      binding.platform_tag("Darwin", "arm64") == "macos-arm64" and
      binding.platform_tag("Linux", "aarch64") == "linux-arm64" and
      binding.platform_tag() == "linux-x64", "platform tags as Blender's extensions name them")
libm = (glob.glob("/usr/lib/x86_64-linux-gnu/libm.so.6") + glob.glob("/lib/*/libm.so.6"))[0]
raises(lambda: binding.load(libm), binding.LibraryError, "is not libblend")
notlib = os.path.join(WORK, "garbage.so")
with open(notlib, "wb") as f:
    f.write(b"not an ELF file")
raises(lambda: binding.load(notlib), binding.LibraryError, "could not be loaded on linux-x64")
# a libblend of another version: a stub library with only lb_version
stub_dir = os.path.join(WORK, "stub")
os.makedirs(stub_dir, exist_ok=True)
with open(os.path.join(stub_dir, "v.c"), "w") as f:
    f.write("int lb_version(void) { return 20304; }\n")
subprocess.run(["cc", "-shared", "-fPIC", "-o", os.path.join(stub_dir, "libblend.so"),
                os.path.join(stub_dir, "v.c")], check=True)
raises(lambda: binding.load(os.path.join(stub_dir, "libblend.so")), binding.LibraryError,
       "is libblend 2.3.4 but this add-on needs 0.1.x", "lb_scene_parse")
os.environ[binding.ENV_LIBRARY] = os.path.join(WORK, "env", "libblend.so")
raises(lambda: binding.load(), binding.LibraryError, "LIBBLEND_LIBRARY")
del os.environ[binding.ENV_LIBRARY]
# ---- the add-on's metadata: Blender 4.2+ reads the manifest, 3.4 reads bl_info
import ast  # noqa: E402
import tomllib  # noqa: E402

with open(os.path.join(ADDON, "blender_manifest.toml"), "rb") as f:
    man = tomllib.load(f)
for key in ("schema_version", "id", "version", "name", "tagline", "maintainer", "type",
            "blender_version_min", "license"):
    check(key in man, "manifest has " + key)
check(man["type"] == "add-on" and man["schema_version"] == "1.0.0", "manifest kind")
tree_ = ast.parse(open(os.path.join(ADDON, "__init__.py")).read())
bl_info = next(ast.literal_eval(n.value) for n in tree_.body if isinstance(n, ast.Assign)
               and getattr(n.targets[0], "id", "") == "bl_info")
check(man["version"] == "%d.%d.%d" % bl_info["version"], "manifest and bl_info versions agree")
check("%d.%d" % tuple(lib.version[:2]) == man["version"].rsplit(".", 1)[0],
      "the add-on's version is the library's")
check(bl_info["blender"] <= (3, 4, 0), "bl_info admits Blender 3.4")
print("test_binding: %d checks passed" % checks)
