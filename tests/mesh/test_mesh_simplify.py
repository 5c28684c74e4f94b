"""Adaptive simplification (blendtool mesh --simplify TOL,
lb_mesh_options.simplify) against closed forms computed here, not by
libblend:

    /usr/bin/python3 test_mesh_simplify.py BLENDTOOL SOURCE_DIR WORK_DIR

Every simplified mesh is closed, oriented and manifold, and its vertices
are vertices of the unsimplified mesh (so on the surface). Errors are the
exact distances to the true surface of points sampled at most half a cell
apart over every triangle (a simplified triangle can be 100 cells long):
- the cube, the rotated cube and two boxes with --features: within 0.01
  cells, every convex corner kept, the cube in at most 100 triangles at 32,
  64 and 128 cells, the rotated cube and the boxes within 1.5x of libfive's
  counts at 128 (47,588 and 15,540, from issue 33);
- the tilted cylinder cut by a slab and the clean union of two spheres with
  --features: within the tolerance (0.05, 0.1 and 0.25 cells) plus the flat
  triangles' own chord error between samples (bar: 1.1 x tolerance + 0.01
  cells; the unsimplified meshes' own errors are below it, 0.048 cells at
  most), and fewer triangles for a larger tolerance;
- corner normals (OBJ) on the simplified boxes are still their faces';
- S1 and S2 (smooth) simplified: fewer triangles, the same bytes with 1 and
  2 threads;
- --coarse-first on S1 and S2 at 96 cells (0.25 cells): closed, oriented
  and manifold, fewer triangles, the same bytes with 1 and 2 threads, and
  --coarse-first without --simplify exits 2 naming the fix;
- bad tolerances exit 2 naming the option and write nothing;
- --merge-flat (no tolerance): the boxes in 12, 12 and 36 triangles, exact
  to 1e-5 cells, every corner kept; the cylinder cut by a slab with its
  caps merged, its error no larger; S1 and S2 the same bytes (nothing
  flat)."""
import os
import subprocess
import sys

import numpy as np

BLENDTOOL, SRC, WORK = sys.argv[1:4]
os.makedirs(WORK, exist_ok=True)
sys.path.insert(0, os.path.join(SRC, "tests", "mesh"))
import meshcheck  # noqa: E402
from sharp_shapes import (DATA, box_like, box_normal, cell_size, cylinder_slab,  # noqa: E402
                          scene, union_spheres)

failures = []


def check(cond, msg):
    print(("ok   " if cond else "FAIL ") + msg)
    if not cond:
        failures.append(msg)


def mesh(path, res, *extra, ext="ply"):
    tag = os.path.splitext(os.path.basename(path))[0]
    out = os.path.join(WORK, "%s-%d%s.%s" % (tag, res, "".join(extra).replace("-", "_"), ext))
    subprocess.run([BLENDTOOL, "mesh", path, "-o", out, "--resolution", str(res), "--quiet"] +
                   list(extra), check=True)
    return out


def shape(name):
    return os.path.join(DATA, name + ".json")


def dense_samples(V, F, h):
    """points over every triangle: a small one (its longest edge under 4
    cells) on a barycentric lattice at most h / 2 apart along its edges; a
    larger one (a simplified mesh's) in rows parallel to its longest edge,
    h / 4 apart, each row with points h / 4 apart, so a long thin triangle
    costs its area, not its longest edge squared (a lattice gave the
    simplified cylinder at 128 cells some 8 million points, two thirds of
    this test's time; the rows, finer across a thin triangle, find largest
    errors as large as the lattice did or up to 0.003 cells larger, 0.001
    smaller at most, 2026-12-06)"""
    P = V[F]
    longest = np.max([np.linalg.norm(P[:, i] - P[:, (i + 1) % 3], axis=1) for i in range(3)],
                     axis=0)
    step = 0.5 * h
    ks = np.maximum(2, np.ceil(longest / step)).astype(int)
    small = ks <= 8
    out = []
    for k in np.unique(ks[small]):
        Q = P[small & (ks == k)]
        i, j = np.meshgrid(np.arange(k + 1), np.arange(k + 1), indexing="ij")
        keep = i + j <= k
        b = i[keep] / k
        c = j[keep] / k
        a = 1 - b - c
        out.append((a[None, :, None] * Q[:, None, 0] + b[None, :, None] * Q[:, None, 1] +
                    c[None, :, None] * Q[:, None, 2]).reshape(-1, 3))
    step = 0.25 * h
    for T in P[~small]:
        e = [np.linalg.norm(T[(i + 1) % 3] - T[i]) for i in range(3)]
        i = int(np.argmax(e))
        a, b, c = T[i], T[(i + 1) % 3], T[(i + 2) % 3]
        ab = b - a
        base = np.linalg.norm(ab)
        height = np.linalg.norm(np.cross(ab, c - a)) / base
        rows = max(1, int(np.ceil(height / step)))
        for r in range(rows + 1):
            t = r / rows
            p, q = a + t * (c - a), b + t * (c - b)
            m = max(1, int(np.ceil((1 - t) * base / step)))
            w = np.linspace(0.0, 1.0, m + 1)[:, None]
            out.append(p + w * (q - p))
    return np.concatenate(out)


def topology(tag, V, F):
    info = meshcheck.check(V, F)
    check(info["closed"] and info["oriented"] and info["manifold"],
          "%s: closed %s, oriented %s, manifold %s (%d triangles)" %
          (tag, info["closed"], info["oriented"], info["manifold"], len(F)))


def subset(tag, V, V0):
    """every vertex of V is a vertex of V0 (bit for bit)"""
    have = {tuple(p) for p in V0}
    missing = sum(tuple(p) not in have for p in V)
    check(missing == 0, "%s: every vertex is one of the unsimplified mesh's (%d of %d are not)" %
          (tag, missing, len(V)))


# ---- boxes: flat faces in few triangles, exact, corners kept ----
def box_mesh(name, res, err_bar, *opts):
    """a box shape meshed with --features and opts: closed, oriented and
    manifold, its vertices the unsimplified mesh's, within err_bar cells of
    the true surface, every convex corner within 0.01 cells of a vertex;
    returns (V, F, the unsimplified F, tag)"""
    dist, corners = box_like(name)
    h = cell_size(scene(name), res)
    tag = "%s at %d %s" % (name, res, " ".join(opts))
    V0, _N0, F0 = meshcheck.read(mesh(shape(name), res, "--features"))
    V, _N, F = meshcheck.read(mesh(shape(name), res, "--features", *opts))
    topology(tag, V, F)
    subset(tag, V, V0)
    err = dist(dense_samples(V, F, h)).max() / h
    check(err <= err_bar, "%s: largest error %.2g cells (bar %g)" % (tag, err, err_bar))
    cd = max(np.linalg.norm(V - c, axis=1).min() for c in corners) / h
    check(cd <= 0.01, "%s: farthest corner %.2g cells from a vertex (bar 0.01)" % (tag, cd))
    return V, F, F0, tag


LIBFIVE_128 = {"rotated-cube": 47588, "two-boxes": 15540}
for name in ("cube", "rotated-cube", "two-boxes"):
    for res in (32, 64, 128):
        V, F, F0, tag = box_mesh(name, res, 0.01, "--simplify", "0.1")
        if name == "cube":
            check(len(F) <= 100, "%s: %d triangles (bar 100; %d unsimplified)" %
                  (tag, len(F), len(F0)))
        elif res == 128:
            bar = 1.5 * LIBFIVE_128[name]
            check(len(F) <= bar, "%s: %d triangles (bar 1.5 x libfive's %d; %d unsimplified)" %
                  (tag, len(F), LIBFIVE_128[name], len(F0)))
        # corner normals still each face's own
        if res <= 64:
            normal = box_normal(name)
            Vc, Nc, Fc, FNc = meshcheck.read_obj_corners(
                mesh(shape(name), res, "--features", "--simplify", "0.1", ext="obj"))
            cos = np.einsum("tcj,tj->tc", Nc[FNc], normal(Vc[Fc].mean(axis=1)))
            check(cos.min() >= 1 - 1e-8, "%s: every corner's OBJ normal is its face's, cos >= "
                  "%.12f (bar 1 - 1e-8)" % (tag, cos.min()))

# ---- curved shapes: within the tolerance of the true surface ----
curved = {"cylinder-slab": cylinder_slab()[0], "clean-union-spheres": union_spheres()}
for name, distance in curved.items():
    for res in (32, 64, 128):
        h = cell_size(scene(name), res)
        V0, _N0, F0 = meshcheck.read(mesh(shape(name), res, "--features"))
        err0 = distance(dense_samples(V0, F0, h))[0].max() / h
        counts = []
        for tol in (0.05, 0.1, 0.25):
            tag = "%s at %d --simplify %g" % (name, res, tol)
            V, _N, F = meshcheck.read(mesh(shape(name), res, "--features", "--simplify",
                                           str(tol)))
            topology(tag, V, F)
            subset(tag, V, V0)
            err = distance(dense_samples(V, F, h))[0].max() / h
            bar = 1.1 * tol + 0.01
            check(err <= bar, "%s: largest error %.3g cells (bar %.3g; unsimplified %.3g), %d "
                  "triangles of %d" % (tag, err, bar, err0, len(F), len(F0)))
            counts.append(len(F))
        check(counts[0] < len(F0) and counts[0] >= counts[1] >= counts[2],
              "%s at %d: %d / %d / %d triangles at 0.05 / 0.1 / 0.25 cells of %d (fewer for a "
              "larger tolerance)" % (name, res, counts[0], counts[1], counts[2], len(F0)))

# ---- smooth scenes: fewer triangles, thread count ----
for sname in ("bench-s1-three-spheres", "bench-s2-64-spheres"):
    path = os.path.join(SRC, "scenes", sname + ".json")
    V0, _N0, F0 = meshcheck.read(mesh(path, 96))
    outs = []
    for th in ("1", "2"):
        out = mesh(path, 96, "--simplify", "0.1", "--threads", th)
        outs.append(open(out, "rb").read())
    V, _N, F = meshcheck.read(out)
    tag = "%s at 96 --simplify 0.1" % sname
    topology(tag, V, F)
    subset(tag, V, V0)
    check(len(F) < 0.8 * len(F0), "%s: %d triangles of %d (bar: under 0.8x)" %
          (tag, len(F), len(F0)))
    check(outs[0] == outs[1], "%s: the same bytes with 1 and 2 threads" % tag)

# ---- --coarse-first: the tolerance met by meshing coarse cells ----
# (its vertices on coarse edges are not the uniform mesh's: no subset check;
# tests/test_mesh.c's test_coarse_first checks them on the surface and a
# sphere's triangles against its closed form)
for sname in ("bench-s1-three-spheres", "bench-s2-64-spheres"):
    path = os.path.join(SRC, "scenes", sname + ".json")
    _V0, _N0, F0 = meshcheck.read(mesh(path, 96))
    outs = [open(mesh(path, 96, "--simplify", "0.25", "--coarse-first", "--threads", th),
                 "rb").read() for th in ("1", "2")]
    V, _N, F = meshcheck.read(mesh(path, 96, "--simplify", "0.25", "--coarse-first",
                                   "--threads", "2"))
    tag = "%s at 96 --simplify 0.25 --coarse-first" % sname
    topology(tag, V, F)
    check(len(F) < 0.95 * len(F0), "%s: %d triangles of %d (bar: under 0.95x)" %
          (tag, len(F), len(F0)))
    check(outs[0] == outs[1], "%s: the same bytes with 1 and 2 threads" % tag)
out = os.path.join(WORK, "bad-coarse.ply")
p = subprocess.run([BLENDTOOL, "mesh", shape("cube"), "-o", out, "--resolution", "16",
                    "--coarse-first"], capture_output=True, text=True)
check(p.returncode == 2 and "--coarse-first" in p.stderr and "--simplify TOL" in p.stderr and
      not os.path.exists(out), "--coarse-first alone: exit %d, %r, nothing written" %
      (p.returncode, p.stderr.strip()))

# ---- --merge-flat: flat regions merged, no tolerance ----
# the boxes' faces become two triangles each, exact, every corner kept; the
# cylinder cut by a slab has its caps merged and its wall untouched (its
# error no larger); smooth scenes have nothing flat (the same bytes)
for name in ("cube", "rotated-cube", "two-boxes"):
    for res in (32, 64, 128):
        V, F, F0, tag = box_mesh(name, res, 1e-5, "--merge-flat")
        want = 36 if name == "two-boxes" else 12
        check(len(F) == want, "%s: %d triangles (want %d; %d unmerged)" % (tag, len(F), want,
                                                                          len(F0)))
# (at 32 and 64 cells: at 128 the merged caps' long triangles, sampled half
# a cell apart, are some 10^8 points)
distance = cylinder_slab()[0]
for res in (32, 64):
    h = cell_size(scene("cylinder-slab"), res)
    tag = "cylinder-slab at %d --merge-flat" % res
    V0, _N0, F0 = meshcheck.read(mesh(shape("cylinder-slab"), res, "--features"))
    V, _N, F = meshcheck.read(mesh(shape("cylinder-slab"), res, "--features", "--merge-flat"))
    topology(tag, V, F)
    subset(tag, V, V0)
    err0 = distance(dense_samples(V0, F0, h))[0].max() / h
    err = distance(dense_samples(V, F, h))[0].max() / h
    check(err <= err0 + 1e-6 and len(F) < 0.8 * len(F0),
          "%s: largest error %.3g cells (unmerged %.3g), %d triangles of %d" %
          (tag, err, err0, len(F), len(F0)))
for sname in ("bench-s1-three-spheres", "bench-s2-64-spheres"):
    path = os.path.join(SRC, "scenes", sname + ".json")
    a = open(mesh(path, 96, "--features"), "rb").read()
    b = open(mesh(path, 96, "--features", "--merge-flat"), "rb").read()
    check(a == b, "%s at 96: nothing flat, the same bytes with --merge-flat" % sname)

# ---- bad tolerances ----
for bad in ("0", "-0.1", "1.5", "nan", "inf", "0.1x", ""):
    out = os.path.join(WORK, "bad.ply")
    if os.path.exists(out):
        os.remove(out)
    p = subprocess.run([BLENDTOOL, "mesh", shape("cube"), "-o", out, "--resolution", "16",
                        "--simplify", bad], capture_output=True, text=True)
    check(p.returncode == 2 and "--simplify" in p.stderr and "at most 1" in p.stderr and
          not os.path.exists(out),
          "--simplify %r: exit %d, %r, nothing written" % (bad, p.returncode, p.stderr.strip()))

if failures:
    print("%d check(s) failed" % len(failures))
    sys.exit(1)
print("all simplification checks passed")
