#!/usr/bin/python3
"""Every valid random scene meshes closed: thousands of them, in process.

The scenes of random_scenes.py (both conventions, every operator family,
shared defs, bulge elimination, nesting up to depth 4), from fixed seeds
0..N-1 so that every run checks the same ones, then from a seed of this run
(printed, so a failure can be replayed) for the rest of the time budget.
Each is parsed and compiled through the library (the ctypes binding, no
process per scene) and meshed at 12 cells on two threads and 20 on one, and
at 20 on two with sharp features (LB_MESH_FEATURES, with corner normals),
and, for one seed in four, at 20 on two with features simplified
(simplify = 0.25 cells: the pass samples the field far more than the
meshing, and every seed would add 90 s), and for every other seed at 32 on
two meshed coarse first (LB_MESH_COARSE_FIRST, 0.25 cells);
every non-empty mesh must be closed, oriented and 2-manifold (tests/mesh's
numpy checks), its corner normals within their contract, and the
scenes found wrong before (by an issue, or by this test's fresh seeds:
barthe-underflow.json, seed 578775895819, failed to compile) must mesh
closed at 20, 64 and 97 cells, and at 64 and 97 with sharp features, and
at 64 with features simplified (tests/data/regressions/).

usage: random_meshes.py ADDON_DIR SOURCE_DIR FIXED_COUNT EXTRA_SECONDS
"""
import glob
import json
import os
import random
import sys
import time

ADDON, SRC, FIXED, EXTRA = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4])
sys.path.insert(0, ADDON)
sys.path.insert(0, os.path.join(SRC, "tests", "mesh"))
sys.path.insert(0, os.path.join(SRC, "tests", "fuzz"))
import binding  # noqa: E402
import meshcheck  # noqa: E402
import random_scenes  # noqa: E402

lib = binding.load()  # the add-on's own copy of the library (lib/)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from checks import fail, failures  # noqa: E402


def closed(text, name, runs):
    """None when refused by a limit, else the number of meshes checked"""
    try:
        sc = lib.parse_scene(text, name)
    except binding.LibblendError as e:
        fail("%s: parse: %s" % (name, e))
        return 0
    with sc:
        try:
            ev = sc.compile()
        except binding.LibblendError as e:
            if "allowed" in str(e) or "limit" in str(e):
                return None  # over a documented limit: refused, with the rule
            fail("%s: compile: %s" % (name, e))
            return 0
        with ev:
            lo, hi = sc.bounds
            n = 0
            for run in runs:
                res, th, feat, simp = run[:4]
                coarse = len(run) > 4 and run[4]
                how = "%d cells, %d threads%s%s%s" % (
                    res, th, " with sharp features" if feat else "",
                    ", simplify %g" % simp if simp else "", ", coarse first" if coarse else "")
                try:
                    m = ev.mesh(lo, hi, resolution=res, threads=th, features=feat, simplify=simp,
                                coarse_first=coarse)
                except binding.LibblendError as e:  # a valid scene must mesh
                    fail("%s: mesh at %s: %s" % (name, how, e))
                    return n
                if not len(m.triangles):
                    continue
                c = meshcheck.check(m.positions, m.triangles)
                n += 1
                if not (c["closed"] and c["oriented"] and c["manifold"]):
                    fail("%s: mesh at %s: %s" % (name, how, c))
                    return n
                if m.corner_normals is not None and not corners_ok(m):
                    fail("%s: mesh at %s: corner normals out of contract" % (name, how))
                    return n
            return n


def corners_ok(m):
    """lb_mesh.corner_normals' contract: each corner names its own vertex's
    normal or an added one of unit length that only that vertex's corners
    use, and every added normal is used"""
    import numpy as np
    nv, cn, tri = len(m.positions), m.corner_normals.ravel(), m.triangles.ravel()
    added = cn >= nv
    if not np.all(cn[~added] == tri[~added]) or cn.max() >= nv + len(m.split_normals):
        return False
    owner = np.full(len(m.split_normals), -1, dtype=np.int64)
    owner[cn[added] - nv] = tri[added]
    return bool(np.all(owner[cn[added] - nv] == tri[added]) and np.all(owner >= 0) and
                np.allclose(np.linalg.norm(m.split_normals, axis=1), 1.0, atol=1e-12))


# the scenes an issue found open
for p in sorted(glob.glob(os.path.join(SRC, "tests", "data", "regressions", "*.json"))):
    n = closed(open(p).read(), os.path.basename(p),
               ((20, 1, False, 0), (64, 2, False, 0), (97, 1, False, 0), (64, 2, True, 0),
                (97, 1, True, 0), (64, 2, True, 0.25), (64, 2, False, 0.25, True)))
    if not n:
        fail("%s: nothing meshed" % p)

t0 = time.monotonic()
stats = {"scenes": 0, "meshes": 0, "refused": 0, "empty": 0}


def run(seed):
    sc, _ = random_scenes.scene(seed)
    runs = ((12, 2, False, 0), (20, 1, False, 0), (20, 2, True, 0))
    if seed % 2 == 0:
        runs += ((32, 2, False, 0.25, True),)
    if seed % 4 == 0:
        runs += ((20, 2, True, 0.25),)
    n = closed(json.dumps(sc), "seed %d" % seed, runs)
    stats["scenes"] += 1
    if n is None:
        stats["refused"] += 1
    elif n == 0:
        stats["empty"] += 1
    else:
        stats["meshes"] += n


for seed in range(FIXED):
    run(seed)
fixed_time = time.monotonic() - t0
base = random.SystemRandom().randrange(1 << 40)
extra = 0
while time.monotonic() - t0 < fixed_time + EXTRA:
    run(base + extra)
    extra += 1
print("%d fixed seeds in %.0f s, %d more from seed %d in %.0f s: %d meshes checked closed, "
      "%d scenes refused by a limit, %d empty; %d failures" % (
          FIXED, fixed_time, extra, base, time.monotonic() - t0 - fixed_time, stats["meshes"],
          stats["refused"], stats["empty"], len(failures)))
if stats["meshes"] < 3 * FIXED // 2:
    fail("only %d meshes checked (want >= %d)" % (stats["meshes"], 3 * FIXED // 2))
sys.exit(1 if failures else 0)
