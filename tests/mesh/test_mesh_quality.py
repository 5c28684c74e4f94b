"""Triangle count and triangle shape of libblend's meshes against marching
cubes on the same grid (scikit-image's marching_cubes, Lewiner's method, run
on the same node values):

    /usr/bin/python3 test_mesh_quality.py BLENDTOOL SOURCE_DIR BINDING_DIR WORK_DIR

For S1 (three spheres) and S2 (64 spheres) at 128 and 256 cells over
[-2, 3]^3: libblend's triangle count within 1.25x of marching cubes', and
its smallest-angle distribution at least as good (1st and 5th percentiles
not below marching cubes', and a stated floor for the 1st percentile)."""
import os
import subprocess
import sys

import numpy as np
from skimage.measure import marching_cubes

BLENDTOOL, SRC, BINDING, WORK = sys.argv[1:5]
os.makedirs(WORK, exist_ok=True)
sys.path.insert(0, os.path.join(SRC, "tests", "mesh"))
sys.path.insert(0, BINDING)
import meshcheck  # noqa: E402
import binding  # noqa: E402

FLOOR_P1 = 0.7  # degrees: the 1st percentile of the smallest angle, at least (measured 0.8-1.1)
lib = binding.load(os.path.join(BINDING, "lib", "libblend.so"))


def min_angles(V, F):
    P = V[F]
    a = np.linalg.norm(P[:, 1] - P[:, 2], axis=1)
    b = np.linalg.norm(P[:, 2] - P[:, 0], axis=1)
    c = np.linalg.norm(P[:, 0] - P[:, 1], axis=1)
    ang = []
    for x, y, z in ((a, b, c), (b, c, a), (c, a, b)):
        cosv = np.clip((y * y + z * z - x * x) / np.maximum(2 * y * z, 1e-300), -1, 1)
        ang.append(np.degrees(np.arccos(cosv)))
    return np.min(ang, axis=0)


failures = []
for name, scene in (("S1", "bench-s1-three-spheres.json"), ("S2", "bench-s2-64-spheres.json")):
    path = os.path.join(SRC, "scenes", scene)
    for res in (128, 256):
        ply = os.path.join(WORK, "%s-%d.ply" % (name, res))
        subprocess.run([BLENDTOOL, "mesh", path, "-o", ply, "--resolution", str(res), "--open",
                        "--quiet"], check=True)
        V, _N, F = meshcheck.read(ply)
        info = meshcheck.check(V, F)
        # the same grid: [-2, 3]^3, res cells, nodes at -2 + i h
        h = 5.0 / res
        x = -2.0 + h * np.arange(res + 1)
        X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
        with lib.load_scene(path) as sc, sc.compile() as ev:
            vals = ev.eval(np.stack([X.ravel(), Y.ravel(), Z.ravel()], 1), gradient=False)[0]
        vol = vals.reshape(X.shape)
        mv, mf, _n, _v = marching_cubes(vol, 0.0, spacing=(h, h, h), method="lewiner")
        ours, theirs = min_angles(V, F.astype(np.int64)), min_angles(mv, mf.astype(np.int64))
        ratio = len(F) / len(mf)
        po = np.percentile(ours, [1, 5, 50])
        pt = np.percentile(theirs, [1, 5, 50])
        print("%s at %d: libblend %d triangles (closed %s, manifold %s), marching cubes %d: %.3fx; "
              "smallest angle percentiles 1/5/50: libblend %.1f / %.1f / %.1f, marching cubes "
              "%.1f / %.1f / %.1f degrees" % (name, res, len(F), info["closed"], info["manifold"],
                                              len(mf), ratio, *po, *pt))
        if not (info["closed"] and info["manifold"] and info["oriented"]):
            failures.append("%s at %d: not closed, manifold and oriented" % (name, res))
        if ratio > 1.25:
            failures.append("%s at %d: %.3fx the triangles of marching cubes; allowed 1.25x"
                            % (name, res, ratio))
        if po[0] < pt[0] or po[1] < pt[1]:
            failures.append("%s at %d: smallest-angle percentiles %.2f / %.2f below marching "
                            "cubes' %.2f / %.2f" % (name, res, po[0], po[1], pt[0], pt[1]))
        if po[0] < FLOOR_P1:
            failures.append("%s at %d: 1st percentile of the smallest angle %.2f below %.1f "
                            "degrees" % (name, res, po[0], FLOOR_P1))
if failures:
    print("\n".join(failures))
    sys.exit(1)
print("test_mesh_quality: passed")
