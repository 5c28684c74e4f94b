"""Sharp features (blendtool mesh --features, LB_MESH_FEATURES) against
closed forms computed here, not by libblend:

    /usr/bin/python3 test_mesh_features.py BLENDTOOL SOURCE_DIR WORK_DIR

Scenes in tests/data/features. At 32, 64 and 128 cells every mesh is
closed, oriented and manifold, and:
- the cube, the cube turned off the axes and two overlapping boxes (min):
  points sampled over every triangle are within 0.01 cells of the true
  surface (exact distance to the box or the union of boxes), and every
  convex corner has a vertex within 0.01 cells; without --features the same
  meshes are off by more than 0.05 cells (so the check sees the option);
- a tilted cylinder cut by a slab: near the two crease curves (within 1.5
  cells) at most 1.1x the flat triangles' own chord error on the smooth
  side and at most 0.15x the error without --features (measured
  2026-12-04: 0.022, 0.011, 0.0056 cells against chord errors of 0.022,
  0.013, 0.0061 and 0.48, 0.41, 0.48 without);
- the clean union of two spheres: near the crease circle at most 1.1x the
  flat triangles' own chord error away from it, and at most 0.2x the
  error without --features (measured 2026-12-05: 0.047, 0.022, 0.013 cells
  against chord errors of 0.048, 0.024, 0.012 and 0.26, 0.28, 0.29
  without; 0.093, 0.081, 0.064 before the crease points were found on the
  crease itself, see docs/meshing.md);
- a local union of the same spheres with a blending volume of R = 0.005
  (under a fifth of a cell, so meshed as the sharp union it rounds): near
  the crease outside the volume at most 1.1x the chord error and 0.2x the
  error without --features, every vertex on the sharp union (measured
  2026-12-06: 0.047, 0.022, 0.010 cells; 0.083, 0.054, 0.13 before volumes
  under a quarter cell were meshed sharp); with R = 0.05 (0.46 cells at
  32) the fillet is meshed: every vertex on the blended surface;
- the stool (hsu-bounded Fig. 7) where its bounded union is the plain
  union of an ellipsoid and capsules: at most 0.95x the error without
  --features (its plate's rim, a smooth curve of radius under a cell,
  dominates both), vertices on the surface.
Corner normals (OBJ's f v//n, GLB's vertex copies): on the three box
shapes every triangle corner carries its own face's normal (the vertex
normals alone are off by up to 76 degrees at the edges); on the cylinder
cut by a slab each split corner is within 0.5 h / r radians of its side's
normal (a sliver along a crease, which has no side, either side's).
Also: the same bytes with 1 and 2 threads, and S1 (smooth: no cell
has a crease) the same bytes with and without --features."""
import json
import os
import subprocess
import sys

import numpy as np

BLENDTOOL, SRC, WORK = sys.argv[1:4]
os.makedirs(WORK, exist_ok=True)
sys.path.insert(0, os.path.join(SRC, "tests", "mesh"))
import meshcheck  # noqa: E402
from sharp_shapes import (DATA, box_like, box_normal, cell_size, cylinder_slab,  # noqa: E402
                          samples, scene, stool, union_spheres)

failures = []


def check(cond, msg):
    print(("ok   " if cond else "FAIL ") + msg)
    if not cond:
        failures.append(msg)


def mesh(name, res, *extra):
    out = os.path.join(WORK, "%s-%d%s.ply" % (name, res, "".join(extra).replace("-", "_")))
    subprocess.run([BLENDTOOL, "mesh", os.path.join(DATA, name + ".json"), "-o", out,
                    "--resolution", str(res), "--quiet"] + list(extra), check=True)
    return out


def topology(tag, V, F):
    info = meshcheck.check(V, F)
    check(info["closed"] and info["oriented"] and info["manifold"],
          "%s: closed %s, oriented %s, manifold %s (%d triangles)" %
          (tag, info["closed"], info["oriented"], info["manifold"], len(F)))


# ---- boxes: exact to 0.01 cells, corners kept ----
for name in ("cube", "rotated-cube", "two-boxes"):
    dist, corners = box_like(name)
    for res in (32, 64, 128):
        h = cell_size(scene(name), res)
        V, _N, F = meshcheck.read(mesh(name, res, "--features"))
        tag = "%s at %d" % (name, res)
        topology(tag, V, F)
        err = dist(samples(V, F)).max() / h
        check(err <= 0.01, "%s: largest error %.2g cells (bar 0.01)" % (tag, err))
        cd = max(np.linalg.norm(V - c, axis=1).min() for c in corners) / h
        check(cd <= 0.01, "%s: farthest corner %.2g cells from a vertex (bar 0.01)" % (tag, cd))
    V, _N, F = meshcheck.read(mesh(name, 64))
    err = dist(samples(V, F)).max() / cell_size(scene(name), 64)
    check(err > 0.05, "%s at 64 without --features: largest error %.2g cells (> 0.05)" % (name, err))

# ---- corner normals: each side of a crease shaded with its own normal ----
def corner_mesh(name, res, ext):
    out = os.path.join(WORK, "%s-%d-corners.%s" % (name, res, ext))
    subprocess.run([BLENDTOOL, "mesh", os.path.join(DATA, name + ".json"), "-o", out,
                    "--resolution", str(res), "--quiet", "--features"], check=True)
    return out


for name in ("cube", "rotated-cube", "two-boxes"):
    normal = box_normal(name)
    for res in (32, 64):
        tag = "%s at %d" % (name, res)
        V, N, F, FN = meshcheck.read_obj_corners(corner_mesh(name, res, "obj"))
        n = normal(V[F].mean(axis=1))  # the face each (flat) triangle lies on
        cos = np.einsum("tcj,tj->tc", N[FN], n)
        vcos = np.einsum("tcj,tj->tc", N[F], n)
        check(cos.min() >= 1 - 1e-8 and vcos.min() < 0.9 and (FN >= len(V)).any(),
              "%s: every corner's OBJ normal is its face's, cos >= %.12f (bar 1 - 1e-8; the "
              "vertex normals alone reach down to %.3f; %d corners split)" %
              (tag, cos.min(), vcos.min(), (FN >= len(V)).sum()))
        # glTF has one normal per vertex: the same corner normals by copies
        Vg, Ng, Fg = meshcheck.read_glb(corner_mesh(name, res, "glb"))
        check(Fg.shape == F.shape and np.abs(Vg[Fg] - V[F]).max() < 1e-6 and
              np.abs(Ng[Fg] - N[FN]).max() < 1e-6 and len(Vg) == len(N),
              "%s: the GLB's corners have the OBJ's positions and normals (%d vertices with "
              "the copies)" % (tag, len(Vg)))

# ---- a tilted cylinder cut by a slab ----
sc = scene("cylinder-slab")
cyl_slab_distance, cyl_slab_normal, r = cylinder_slab()


def crease_errors(name, res, distance, skip=0.0):
    """the largest error within 1.5 cells of the crease and away from it, in
    cells, with --features (its topology checked) and without: distance(p)
    gives the distance to the true surface and to the crease; points nearer
    than skip to the crease are left out (a blending volume)"""
    h = cell_size(scene(name), res)
    errs = []
    for extra in (("--features",), ()):
        V, _N, F = meshcheck.read(mesh(name, res, *extra))
        if extra:
            topology("%s at %d" % (name, res), V, F)
        d, dc = distance(samples(V, F))
        near = (dc < 1.5 * h) & (dc >= skip)
        errs.append((d[near].max() / h, d[dc >= 1.5 * h].max() / h))
    return errs



for res in (32, 64, 128):
    # a split corner's normal is its side's, taken a quarter cell from the
    # point towards its side's triangles; here the closed form is taken a
    # quarter cell towards the corner's own triangle: the two are at most
    # half a cell apart, over which the cylinder turns by 0.5 h / r
    # (measured 2026-12-04: 2.04, 1.07, 0.49 degrees). A triangle lying
    # along a crease (every vertex within 0.05 cells of one: a sliver
    # between two crease points and a grid-edge vertex next to the crease)
    # has no side of its own; its corners may take either side's normal
    # (the wall's at the point, or a cap's), but still one side's
    h = cell_size(sc, res)
    V, N, F, FN = meshcheck.read_obj_corners(corner_mesh("cylinder-slab", res, "obj"))
    P = V[F]
    d = P.mean(axis=1)[:, None, :] - P
    probe = P + np.minimum(1, 0.25 * h / np.maximum(np.linalg.norm(d, axis=2), 1e-300))[
        :, :, None] * d
    split = FN >= len(V)
    ang = np.degrees(np.arccos(np.clip(np.einsum(
        "ij,ij->i", N[FN][split], cyl_slab_normal(probe[split])), -1, 1)))
    along = (cyl_slab_distance(V)[1][F].max(axis=1) < 0.05 * h)[:, None].repeat(3, axis=1)[split]
    if along.any():
        cn, pt = N[FN][split][along], P[split][along]
        best = np.full(len(cn), 180.0)
        cyl = sc["root"]["args"][0]
        ax = np.array(cyl["axis"], float) / np.linalg.norm(cyl["axis"])
        rv = pt - np.array(cyl["point"], float)
        rv -= (rv @ ax)[:, None] * ax
        for side in (rv / np.linalg.norm(rv, axis=1)[:, None],
                     np.array([[0.0, 0.0, 1.0]]).repeat(len(cn), 0),
                     np.array([[0.0, 0.0, -1.0]]).repeat(len(cn), 0)):
            best = np.minimum(best, np.degrees(np.arccos(np.clip(
                np.einsum("ij,ij->i", cn, side), -1, 1))))
        ang[along] = best
    bar = np.degrees(0.5 * h / r)
    check(split.sum() > 100 and ang.max() <= bar,
          "cylinder-slab at %d: %d split corners, each within %.2f degrees of its side's normal "
          "(bar %.2f)" % (res, split.sum(), ang.max(), bar))

for res in (32, 64, 128):
    tag = "cylinder-slab at %d" % res
    (near, far), (plain, _far) = crease_errors("cylinder-slab", res, cyl_slab_distance)
    check(near <= 1.1 * far and near <= 0.15 * plain,
          "%s: near the creases %.3g cells with --features, %.3g without; the smooth side's "
          "flat triangles %.3g (bars: 1.1x those, 0.15x without)" % (tag, near, plain, far))

# ---- the clean union of two spheres ----
union_spheres_distance = union_spheres()


for res in (32, 64, 128):
    tag = "clean-union-spheres at %d" % res
    (near, far), (plain, _pfar) = crease_errors("clean-union-spheres", res,
                                                union_spheres_distance)
    check(near <= 1.1 * far and near <= 0.2 * plain,
          "%s: near the crease %.3g cells with --features, %.3g without; the flat triangles "
          "away from it %.3g (bars: 1.1x those, 0.2x without)" % (tag, near, plain, far))

# ---- a local union outside its blending volume: the same crease ----
# (R = 0.005: 0.05, 0.09, 0.18 cells at 32, 64, 128. A blending volume
# narrower than a quarter cell is meshed as the sharp union it rounds:
# outside the volume the surface is the union of the spheres, and the
# crease as close as the clean union's, its flat triangles' chord error)
local_distance = union_spheres("local-union-spheres")
R = scene("local-union-spheres")["root"]["radius"]
for res in (32, 64, 128):
    tag = "local-union-spheres at %d" % res
    (near, far), (plain, _pfar) = crease_errors("local-union-spheres", res, local_distance,
                                                skip=2 * R)
    check(near <= 1.1 * far and near <= 0.2 * plain,
          "%s: near the crease (outside the blending volume) %.3g cells with --features, %.3g "
          "without; the flat triangles away from it %.3g (bars: 1.1x those, 0.2x without)" %
          (tag, near, plain, far))
    # every vertex on the sharp union (closed form): the fillet is not meshed
    h = cell_size(scene("local-union-spheres"), res)
    V, _N, _F = meshcheck.read(mesh("local-union-spheres", res, "--features"))
    vd = local_distance(V)[0].max() / h
    check(vd <= 1e-5, "%s: every vertex within %.2g cells of the sharp union (bar 1e-5)" %
          (tag, vd))


def field_at(scene_path, P):
    """blendtool eval's value and gradient at the points P"""
    pts = os.path.join(WORK, "points.txt")
    np.savetxt(pts, P, fmt="%.17g")
    out = subprocess.run([BLENDTOOL, "eval", "--points", pts, scene_path], check=True,
                         capture_output=True, text=True).stdout
    R = np.array([[float(x) for x in line.split()] for line in out.splitlines()])
    return R[:, 0], R[:, 1:]


# A blending volume a quarter cell wide or more is meshed as the blend it is:
# the same spheres with R = 0.05, at 32 cells (R = 0.46 cells) with
# --features, have every vertex on the blended surface (|f| / |grad f| to
# 1e-6 cells), and vertices inside the volume off the sharp union by more
# than a hundredth of a cell (the fillet kept)
wide = scene("local-union-spheres")
wide["root"]["radius"] = 0.05
wide_path = os.path.join(WORK, "local-union-wide.json")
with open(wide_path, "w") as f:
    json.dump(wide, f)
h = cell_size(wide, 32)
out = os.path.join(WORK, "local-union-wide.ply")
subprocess.run([BLENDTOOL, "mesh", wide_path, "-o", out, "--resolution", "32", "--quiet",
                "--features"], check=True)
V, _N, F = meshcheck.read(out)
topology("local union, R = 0.05, at 32", V, F)
val, grad = field_at(wide_path, V)
on = (np.abs(val) / np.linalg.norm(grad, axis=1)).max() / h
dsharp, dcrease = local_distance(V)
fillet = dsharp[dcrease < 0.05].max() / h
check(on <= 1e-6 and fillet >= 0.01,
      "local union, R = 0.46 cells, at 32: vertices within %.2g cells of the blended surface "
      "(bar 1e-6), %.3g cells off the sharp union inside the volume (at least 0.01: the fillet "
      "is meshed)" % (on, fillet))

# ---- the stool (hsu-bounded Fig. 7) outside its blends ----
# Where at most one bounding solid reaches, the bounded union is the plain
# union of its ellipsoid plate and capsule legs, whose distances are closed
# forms (inside the overlaps the blends have none). There the plate's rim
# is a smooth curve of radius c^2 / a = 0.0144, a sixth of a cell at 32
# cells and two thirds at 128: flat triangles with vertices on the surface
# cut it by a good part of a cell with or without --features, so the bar is
# the mesh without them (measured 2026-12-05: 0.26, 0.13, 0.12 cells with,
# 0.29, 0.27, 0.16 without), and every vertex there on the surface.
stool_path = os.path.join(SRC, "scenes", "hsu-bounded-fig7-stool.json")
stool_distance, stool_lone = stool(stool_path)
with open(stool_path) as f:
    stool_scene = json.load(f)
for res in (32, 64, 128):
    h = cell_size(stool_scene, res)
    errs = []
    for extra in (["--features"], []):
        out = os.path.join(WORK, "stool-%d%s.ply" % (res, "".join(extra).replace("-", "_")))
        subprocess.run([BLENDTOOL, "mesh", stool_path, "-o", out, "--resolution", str(res),
                        "--quiet"] + extra, check=True)
        V, _N, F = meshcheck.read(out)
        lone = stool_lone(V)
        keep = lone[F].all(axis=1)
        errs.append((stool_distance(samples(V, F[keep])).max() / h,
                     stool_distance(V[lone]).max() / h, keep.sum()))
        if extra:
            topology("stool at %d" % res, V, F)
    (err, verr, n), (plain, _pverr, _pn) = errs
    check(n > 1000 and err <= 0.95 * plain and verr <= 1e-5,
          "stool at %d: outside its blends (%d triangles) %.3g cells from the true surface with "
          "--features, %.3g without (bar 0.95x), vertices within %.2g cells (bar 1e-5)" %
          (res, n, err, plain, verr))

# ---- thread count, and smooth scenes untouched ----
for name in ("rotated-cube", "clean-union-spheres", "local-union-spheres"):
    outs = []
    for th in ("1", "2"):
        out = os.path.join(WORK, "%s-threads%s.ply" % (name, th))
        subprocess.run([BLENDTOOL, "mesh", os.path.join(DATA, name + ".json"), "-o", out,
                        "--resolution", "96", "--quiet", "--features", "--threads", th],
                       check=True)
        outs.append(open(out, "rb").read())
    check(outs[0] == outs[1], "%s at 96: the same bytes with 1 and 2 threads" % name)
s1 = os.path.join(SRC, "scenes", "bench-s1-three-spheres.json")
outs = []
for extra in (["--features"], []):
    out = os.path.join(WORK, "s1%s.ply" % "".join(extra).replace("-", "_"))
    subprocess.run([BLENDTOOL, "mesh", s1, "-o", out, "--resolution", "128", "--quiet"] + extra,
                   check=True)
    outs.append(open(out, "rb").read())
check(outs[0] == outs[1], "S1 at 128: the same bytes with and without --features")

if failures:
    print("%d check(s) failed" % len(failures))
    sys.exit(1)
print("all sharp-feature checks passed")
