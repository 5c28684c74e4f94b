"""Triangles at a given maximum error against the field: libblend's
simplification against meshoptimizer's meshopt_simplify on the same mesh
(docs/meshing.md, Adaptive simplification):

    /usr/bin/python3 bench/mesh/run_meshopt_error.py ADDON_LIB_DIR SCENE RES TOL TARGETS

The scene is meshed at RES cells through the add-on's binding (two
threads), simplified by libblend at TOL cells, and the unsimplified mesh is
handed to meshoptimizer (Debian's libmeshoptimizer-dev, through ctypes; a
benchmark dependency only) at each of TARGETS (comma-separated, cells of
its own quadric error). Every triangle is sampled at most a quarter cell
apart (bench/mesh/meshopt_floor.py); each sample is moved onto the surface
by Newton steps along the field's gradient (bench/mesh/coarse_floor.py),
and the distance moved (in cells; at least the distance to the surface, so
an upper bound on each sample's error) gives the largest, 99th and 50th
percentile errors. Samples where the steps do not reach the surface are
counted and left out. Run by bench/run_simplify_bench.sh; not a test."""
import os
import sys

import numpy as np

ADDON, SCENE, RES, TOL, TARGETS = sys.argv[1:6]
RES, TOL = int(RES), float(TOL)
sys.path.insert(0, ADDON)
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import binding  # noqa: E402
import coarse_floor  # noqa: E402
import meshopt_floor  # noqa: E402

mo = meshopt_floor.load()
if mo is None:
    sys.exit("meshoptimizer not found: apt-get install libmeshoptimizer-dev")


def errors(ev, V, F, h):
    d, _tri, off = coarse_floor.sample_errors(ev, V, F, h)
    d = d[~off]
    return "%.3f / %.3f / %.3f cells (%d of %d samples not on the surface after 6 steps)" % (
        d.max(), np.percentile(d, 99), np.percentile(d, 50), off.sum(), len(off))


lib = binding.load()
sc = lib.load_scene(SCENE)
ev = sc.compile()
lo, hi = sc.bounds
h = max(b - a for a, b in zip(lo, hi)) / RES
m = ev.mesh(lo, hi, resolution=RES, threads=2)
ms = ev.mesh(lo, hi, resolution=RES, threads=2, simplify=TOL)
print("%s at %d cells; error largest / 99th / 50th percentile:" % (SCENE, RES))
print("  unsimplified: %d triangles, %s" % (len(m.triangles), errors(ev, m.positions,
                                                                     m.triangles, h)))
print("  libblend, %g cells: %d triangles, %s" % (TOL, len(ms.triangles),
                                                  errors(ev, ms.positions, ms.triangles, h)))
for t in (float(x) for x in TARGETS.split(",")):
    F, own, _ = meshopt_floor.simplify(mo, m.positions, m.triangles, t * h)
    print("  meshoptimizer, %g cells (its own error %.3f): %d triangles, %s" % (
        t, own / h, len(F), errors(ev, m.positions, F, h)))
