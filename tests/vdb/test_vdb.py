#!/usr/bin/python3
"""blendtool vdb and the job files' vdb output, read back as users read them:
by OpenVDB's own Python binding (pyopenvdb, Debian's python3-openvdb) and by
Blender 3.4 and 4.3 (File > Import > OpenVDB, the Volume to Mesh modifier,
an animated job's files as one sequence).

- a union (min) of three spheres, whose field is a distance field with the
  closed form min(|x - c| - r): every active voxel holds it to 1e-5 voxels,
  every voxel of the region with |d| under the band is active, every voxel
  of the region (stored or filled) has d's sign; the value and gradient
  grids hold f and grad f in closed form
- S2 (64 blended spheres) and a soft-convention scene: every active
  voxel's value is f / |grad f| (f from `blendtool eval`, phi = 0.5 - f for
  soft), and the sign of every voxel of the region is phi's
- the grid: name "surface", class level set, background band * h, voxel size
  h with voxel (i, j, k) at (i h, j h, k h), the metadata as written
- the same bytes for every thread count and run; bad options and job
  entries exit 2 naming the allowed range, and write nothing
- OpenVDB's own mesher (volumeToMesh) on the file: closed and within one
  voxel of libblend's mesh (Hausdorff over vertices: each vertex of either
  mesh to the other's triangles)
- Blender: the grid imported as a Volume; Volume to Mesh at the grid's
  resolution closed, and OpenVDB's mesh moved by half a voxel on each axis
  (Blender's placement of voxel centres), so within one voxel of libblend's
  mesh once that is undone; written with --voxel-centres blender, Blender's
  Volume to Mesh as Blender shows it is within one voxel of libblend's
  mesh; an animated job's vdb files load as one sequence

usage: test_vdb.py BLENDTOOL SOURCE_DIR WORK_DIR [BLENDER]
"""
import json
import os
import shutil
import subprocess
import sys

import jsonschema
import numpy as np
import pyopenvdb as vdb
from scipy.spatial import cKDTree

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))
sys.path.insert(0, os.path.join(HERE, "..", "mesh"))
from checks import check, failures  # noqa: E402
import meshcheck  # noqa: E402

BT, SRC, WORK = (os.path.abspath(a) for a in sys.argv[1:4])
BLENDER = sys.argv[4] if len(sys.argv) > 4 else "blender"
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)


def bt(*args, **kw):
    return subprocess.run([BT, *args], capture_output=True, text=True, timeout=600, **kw)


def path(name):
    return os.path.join(WORK, name)


SPHERES = [((0.0, 0.0, 0.0), 0.8), ((0.9, 0.2, -0.1), 0.5), ((-0.5, -0.6, 0.4), 0.45)]
BOUNDS = [-1.5, -1.5, -1.5, 1.5, 1.5, 1.5]
sphere_scene = {"format": "libblend-scene", "version": 1, "convention": "zero",
                "bounds": {"min": BOUNDS[:3], "max": BOUNDS[3:]},
                "root": {"type": "min", "args": [{"type": "sphere", "center": list(c), "radius": r}
                                                 for c, r in SPHERES]}}
SCENE = path("spheres.json")
json.dump(sphere_scene, open(SCENE, "w"))


def closed_form(P):
    """the field f = min_i |P - c_i| / r_i - 1 (a sphere's rho is |X - c| /
    r), its gradient, and its distance estimate f / |grad f| = |P - c_k| -
    r_k for the sphere k that attains the min"""
    f = np.stack([np.linalg.norm(P - np.array(c), axis=1) / r - 1.0 for c, r in SPHERES])
    k = np.argmin(f, axis=0)
    C = np.array([c for c, _ in SPHERES])[k]
    R = np.array([r for _, r in SPHERES])[k]
    dist = np.linalg.norm(P - C, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):  # a voxel at a centre
        g = (P - C) / (dist * R)[:, None]
    return f.min(axis=0), g, dist - R


def point_triangle(P, A, B, C):
    """the distance from each point P[i] to the triangle (A[i], B[i], C[i]):
    the closest point by its Voronoi region of the triangle (vertex, edge or
    face), all rows at once"""
    ab, ac, ap = B - A, C - A, P - A
    d1, d2 = (ab * ap).sum(1), (ac * ap).sum(1)
    bp = P - B
    d3, d4 = (ab * bp).sum(1), (ac * bp).sum(1)
    cp = P - C
    d5, d6 = (ab * cp).sum(1), (ac * cp).sum(1)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        den = va + vb + vc
        v, w = vb / den, vc / den
        Q = A + ab * v[:, None] + ac * w[:, None]  # inside the face
        t_ab = d1 / (d1 - d3)
        t_ac = d2 / (d2 - d6)
        t_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
    cases = [
        (d1 <= 0) & (d2 <= 0), A,
        (d3 >= 0) & (d4 <= d3), B,
        (d6 >= 0) & (d5 <= d6), C,
        (vc <= 0) & (d1 >= 0) & (d3 <= 0), A + ab * t_ab[:, None],
        (vb <= 0) & (d2 >= 0) & (d6 <= 0), A + ac * t_ac[:, None],
        (va <= 0) & ((d4 - d3) >= 0) & ((d5 - d6) >= 0), B + (C - B) * t_bc[:, None],
    ]
    done = np.zeros(len(P), bool)
    for k in range(0, len(cases), 2):
        m = cases[k] & ~done
        Q[m] = cases[k + 1][m]
        done |= m
    return np.linalg.norm(P - Q, axis=1)


def to_mesh(P, V, F, k=24):
    """each point's distance to the triangle mesh (V, F): the least over the
    k triangles whose centroids are nearest (triangles about a voxel wide)"""
    cen = V[F].mean(axis=1)
    _, near = cKDTree(cen).query(P, k=k)
    best = np.full(len(P), np.inf)
    for j in range(k):
        T = F[near[:, j]]
        best = np.minimum(best, point_triangle(P, V[T[:, 0]], V[T[:, 1]], V[T[:, 2]]))
    return best


def read(p):
    grids, meta = vdb.readAll(p)
    return {g.name: g for g in grids}, meta


def active(grid):
    """(ijk int array, values) of the active voxels"""
    ijk, val = [], []
    for it in grid.citerOnValues():
        check(it.count == 1, "%s: only voxels are active, no tiles: %s" % (grid.name, it.count))
        ijk.append(it.min)
        val.append(it.value)
    return np.array(ijk, dtype=np.int64), np.array(val)


def region_ijk(lo, hi, h):
    a = np.ceil(np.array(lo) / h - 1e-9).astype(int)
    b = np.floor(np.array(hi) / h + 1e-9).astype(int)
    return a, b


def dense(grid, a, b):
    arr = np.zeros(tuple(b - a + 1), dtype=np.float32)
    grid.copyToArray(arr, ijk=tuple(int(x) for x in a))
    return arr


def ijk_grid(a, b):
    ax = [np.arange(a[d], b[d] + 1) for d in range(3)]
    I = np.stack(np.meshgrid(*ax, indexing="ij"), axis=-1).reshape(-1, 3)
    return I


def eval_points(scene, P):
    """f and grad f at points, by blendtool eval"""
    pts = path("points.txt")
    np.savetxt(pts, P, fmt="%.17g")
    r = bt("eval", "--points", pts, scene)
    check(r.returncode == 0, "blendtool eval: %s" % r.stderr[-300:])
    out = np.loadtxt(r.stdout.splitlines()).reshape(-1, 4)
    return out[:, 0], out[:, 1:]


# ---- the spheres: closed form ----
RES, BAND = 48, 3.0
out = path("spheres.vdb")
r = bt("vdb", SCENE, "-o", out, "--resolution", str(RES), "--grids", "value,gradient")
check(r.returncode == 0 and "active voxels" in r.stdout, "blendtool vdb: %s %s" % (r.stdout, r.stderr))
grids, fmeta = read(out)
h = 3.0 / RES
S = grids["surface"]
check(sorted(grids) == ["gradient", "surface", "value"], "the three grids: %s" % sorted(grids))
check(S.gridClass == vdb.GridClass.LEVEL_SET, "class level set: %s" % S.gridClass)
check(abs(S.background - np.float32(BAND * h)) == 0, "background band * h: %s" % S.background)
vs = S.transform.voxelSize()
check(np.allclose(vs, h, rtol=1e-12), "voxel size %s, expected %s" % (vs, h))
w = S.transform.indexToWorld((3, -5, 7))
check(np.allclose(w, (3 * h, -5 * h, 7 * h), rtol=0, atol=1e-12),
      "voxel (3, -5, 7) at (3h, -5h, 7h): %s" % (w,))
ver = subprocess.run([BT, "--version"], capture_output=True, text=True).stdout
md = S.metadata
check(md.get("libblend:version", "?") in ver, "libblend:version %r in %r" % (md.get("libblend:version"), ver))
check(len(md.get("libblend:scene_hash", "")) == 32, "libblend:scene_hash: %r" % md.get("libblend:scene_hash"))
check(md.get("libblend:level_set") == "voxel_size %.17g band 3 voxel_centres openvdb" % h,
      "libblend:level_set: %r" % md.get("libblend:level_set"))
check(md.get("libblend:parameters") == "", "no parameters: %r" % md.get("libblend:parameters"))

ijk, val = active(S)
P = ijk * h
fc, g, d = closed_form(P)
err = np.abs(val - d).max() / h
check(err <= 1e-5, "active voxels hold f / |grad f|: %.2e voxels off" % err)
check(np.all(np.abs(val) < S.background), "active voxels inside the band")
print("spheres: %d active voxels, max error %.2e voxels" % (len(val), err))
a, b = region_ijk(BOUNDS[:3], BOUNDS[3:], h)
I = ijk_grid(a, b)
dall = closed_form(I * h)[2]
act = set(map(tuple, ijk))
want = {tuple(x) for x, dd in zip(I, dall) if abs(dd) < BAND * h * (1 - 1e-6)}
check(want <= act, "every region voxel within the band is active: %d missing" % len(want - act))
D = dense(S, a, b).reshape(-1)
nz = dall != 0
bad = np.count_nonzero(np.sign(D[nz]) != np.sign(dall[nz]))
check(bad == 0, "the sign of all %d region voxels (band and flood fill): %d wrong" % (nz.sum(), bad))
V = grids["value"]
G = grids["gradient"]
vij, vval = active(V)
check(np.array_equal(vij, ijk), "the value grid's active voxels are the band's")
check(np.abs(vval - fc).max() <= 1e-6, "value grid = f: %.2e" % np.abs(vval - fc).max())
gij, gval = active(G)
gval = np.array([tuple(x) for x in gval])
check(np.array_equal(gij, ijk) and np.abs(gval - g).max() <= 1e-6,
      "gradient grid = grad f: %.2e" % (np.abs(gval - g).max() if len(gval) == len(g) else -1))
check(G.metadata.get("vector_type") == "covariant", "gradient is covariant: %s" % G.metadata.get("vector_type"))

# the same bytes: threads, runs
o1, o2 = path("t1.vdb"), path("t2.vdb")
bt("vdb", SCENE, "-o", o1, "--resolution", str(RES), "--grids", "value,gradient", "--threads", "1")
bt("vdb", SCENE, "-o", o2, "--resolution", str(RES), "--grids", "value,gradient", "--threads", "2")
same = open(o1, "rb").read() == open(o2, "rb").read() == open(out, "rb").read()
check(same, "the same bytes for 1, 2 and all threads and on every run")
# --set: the parameters and another hash
o3 = path("set.vdb")
r = bt("vdb", SCENE, "-o", o3, "--resolution", "24", "--set", "root.args[0].radius=0.7", "-q")
g3, _ = read(o3)
m3 = g3["surface"].metadata
check(r.returncode == 0 and m3["libblend:parameters"] == "root.args[0].radius=0.7" and
      m3["libblend:scene_hash"] != md["libblend:scene_hash"], "--set: %s" % m3)
# --voxel-size and --band
o4 = path("h.vdb")
r = bt("vdb", SCENE, "-o", o4, "--voxel-size", "0.1", "--band", "1.5", "-q")
g4, _ = read(o4)
check(r.returncode == 0 and np.allclose(g4["surface"].transform.voxelSize(), 0.1) and
      abs(g4["surface"].background - np.float32(0.15)) == 0,
      "--voxel-size 0.1 --band 1.5: %s" % r.stderr)

# ---- S2 and a soft-convention scene: f / |grad f| from blendtool eval ----
for name, scene, res in (("S2", os.path.join(SRC, "scenes", "bench-s2-64-spheres.json"), 64),
                         ("soft", os.path.join(SRC, "scenes", "bernhardt-drop-00.json"), 48)):
    o = path(name + ".vdb")
    r = bt("vdb", scene, "-o", o, "--resolution", str(res), "-q")
    check(r.returncode == 0, "%s: %s" % (name, r.stderr))
    sc = json.load(open(scene))
    soft = sc.get("convention") == "soft"
    lo, hi = sc["bounds"]["min"], sc["bounds"]["max"]
    hh = max(hi[i] - lo[i] for i in range(3)) / res
    Sg = read(o)[0]["surface"]
    ij, vv = active(Sg)
    f, gr = eval_points(scene, ij * hh)
    phi = 0.5 - f if soft else f
    est = phi / np.linalg.norm(gr, axis=1)
    e = np.abs(vv - est).max() / hh
    check(e <= 1e-5, "%s: %d active voxels hold phi / |grad phi|: %.2e voxels off" % (name, len(vv), e))
    a2, b2 = region_ijk(lo, hi, hh)
    I2 = ijk_grid(a2, b2)
    f2, _ = eval_points(scene, I2 * hh)
    phi2 = 0.5 - f2 if soft else f2
    D2 = dense(Sg, a2, b2).reshape(-1)
    nz2 = phi2 != 0
    bad2 = np.count_nonzero(np.sign(D2[nz2]) != np.sign(phi2[nz2]))
    check(bad2 == 0, "%s: the sign of all %d region voxels: %d wrong" % (name, nz2.sum(), bad2))
    print("%s: %d active voxels, max error %.2e voxels, %d region voxels signed right" %
          (name, len(vv), e, nz2.sum() - bad2))

# ---- bad input: exit 2, the allowed range, nothing written ----
bad_out = path("bad.vdb")
for args, want in ((["--band", "0.5"], "1 to 32"), (["--band", "33"], "1 to 32"),
                   (["--resolution", "0"], "8192"), (["--resolution", "9000"], "8192"),
                   (["--voxel-size", "1e-4"], "at most 8192 voxels per axis"),
                   (["--voxel-size", "-1"], "positive"), (["--grids", "density"], "value, gradient"),
                   (["--resolution", "8", "--voxel-size", "0.1"], "one of them"),
                   (["--bounds", "1,1,1,0,0,0"], "not below"),
                   (["--voxel-centres", "middle"], "openvdb")):
    r = bt("vdb", SCENE, "-o", bad_out, *args)
    check(r.returncode == 2 and want in r.stderr and not os.path.exists(bad_out),
          "%s: exit 2 with %r and no file: exit %d, %s" % (args, want, r.returncode, r.stderr.strip()))

# ---- an animated job: name_####.vdb, resumable, each frame = blendtool vdb ----
jd = path("job")
os.makedirs(jd)
job = {"format": "libblend-job", "version": 1, "name": "orbit", "scene": SCENE,
       "frames": {"first": 1, "last": 4,
                  "animate": [{"path": "root.args[1].center[0]", "keys": [[1, 0.9], [4, -0.3]]}]},
       "outputs": {"vdb": {"resolution": 32, "band": 2}}}
jf = os.path.join(jd, "orbit.json")
json.dump(job, open(jf, "w"))
schema = json.load(open(os.path.join(SRC, "docs", "libblend-job.schema.json")))
try:
    jsonschema.validate(job, schema)
except jsonschema.ValidationError as e:
    check(False, "the job file is valid by docs/libblend-job.schema.json: %s" % e.message)
r = bt("batch", jf)
seq = sorted(f for f in os.listdir(os.path.join(jd, "out")) if f.endswith(".vdb"))
check(r.returncode == 0 and seq == ["orbit_%04d.vdb" % i for i in range(1, 5)],
      "job: %s %s" % (seq, r.stderr[-400:]))
r2 = bt("batch", jf)
check("4 skipped" in r2.stderr, "job rerun skips the complete frames: %s" % r2.stderr[-300:])
one = path("frame1.vdb")
bt("vdb", SCENE, "-o", one, "--resolution", "32", "--band", "2", "--set", "root.args[1].center[0]=0.9", "-q")
check(open(one, "rb").read() == open(os.path.join(jd, "out", "orbit_0001.vdb"), "rb").read(),
      "frame 1 of the job is byte for byte blendtool vdb with the frame's value")
for bad_vdb, where in (({"band": 0.5}, "$.outputs.vdb.band"), ({"resolution": 9000}, "$.outputs.vdb"),
                       ({"grids": ["density"]}, "$.outputs.vdb.grids"),
                       ({"voxel_centres": "houdini"}, "$.outputs.vdb.voxel_centres"),
                       ({"resolution": 8, "voxel_size": 0.1}, "$.outputs.vdb.voxel_size")):
    bj = dict(job, outputs={"vdb": bad_vdb}, output_dir="bad-out")
    bf = os.path.join(jd, "bad.json")
    json.dump(bj, open(bf, "w"))
    try:
        jsonschema.validate(bj, schema)
        check(False, "the schema refuses %s too" % bad_vdb)
    except jsonschema.ValidationError:
        pass
    r = bt("batch", bf)
    check(r.returncode == 2 and where in r.stderr and not os.path.exists(os.path.join(jd, "bad-out")),
          "job %s: exit 2 naming %s: %d %s" % (bad_vdb, where, r.returncode, r.stderr.strip()))

# ---- Blender: import, Volume to Mesh, the sequence ----
ply = path("spheres.ply")
r = bt("mesh", SCENE, "-o", ply, "--cell-size", repr(h), "-q")
check(r.returncode == 0, "libblend's mesh: %s" % r.stderr)
LV, _, LF = meshcheck.read_ply(ply)
# OpenVDB's own mesher on the file (pyopenvdb: tools::volumeToMesh): closed,
# within one voxel of libblend's mesh
pts, tris, quads = S.convertToPolygons(isovalue=0.0, adaptivity=0.0)
OV = np.array(pts, dtype=np.float64)
OF = np.concatenate([np.array(tris, dtype=np.int64).reshape(-1, 3),
                     np.array(quads, dtype=np.int64).reshape(-1, 4)[:, [0, 1, 2]],
                     np.array(quads, dtype=np.int64).reshape(-1, 4)[:, [0, 2, 3]]])
E = np.sort(np.concatenate([OF[:, [0, 1]], OF[:, [1, 2]], OF[:, [2, 0]]]), axis=1)
_, ecount = np.unique(E, axis=0, return_counts=True)
o1, o2 = to_mesh(OV, LV, LF).max(), to_mesh(LV, OV, OF).max()
check(len(OV) > 1000 and np.all(ecount == 2) and max(o1, o2) <= h,
      "OpenVDB's volumeToMesh: closed (%d open edges), within one voxel of libblend's mesh: "
      "%.3f, %.3f voxels" % (np.count_nonzero(ecount != 2), o1 / h, o2 / h))
print("OpenVDB's volumeToMesh: %d vertices, Hausdorff to libblend's mesh %.3f / %.3f voxels" %
      (len(OV), o1 / h, o2 / h))
# the same grid placed for Blender: the transform moved by -h/2 on each axis
bout = path("spheres-blender.vdb")
r = bt("vdb", SCENE, "-o", bout, "--resolution", str(RES), "--voxel-centres", "blender", "-q")
Sb = read(bout)[0]["surface"]
check(r.returncode == 0 and np.allclose(Sb.transform.indexToWorld((0, 0, 0)), (-h / 2,) * 3, atol=1e-12)
      and np.allclose(Sb.transform.indexToWorld((2, 0, 0)), (2 * h - h / 2, -h / 2, -h / 2), atol=1e-12)
      and Sb.metadata["libblend:level_set"].endswith("voxel_centres blender")
      and S.metadata["libblend:level_set"].endswith("voxel_centres openvdb"),
      "--voxel-centres blender: voxel (i, j, k) at ((i - 1/2) h, ...): %s %s" %
      (r.stderr, Sb.metadata.get("libblend:level_set")))
root = ["bash", os.path.join(SRC, "scripts", "debian-root.sh"), "trixie-blender4", "run", WORK, SRC, "--"]
for label, cmd in (("Blender 3.4", [BLENDER]), ("Blender 4.3", root + ["blender"])):
    res = path("blender-%s.json" % label[-3:])
    r = subprocess.run(cmd + ["-b", "--factory-startup", "--python-exit-code", "1", "--python",
                              os.path.join(HERE, "blender_vdb.py"), "--", out, bout,
                              os.path.join(jd, "out"), res],
                       capture_output=True, text=True, timeout=600)
    check(r.returncode == 0 and os.path.exists(res), "%s ran: %s" % (label, r.stdout[-800:] + r.stderr[-800:]))
    if not os.path.exists(res):
        continue
    R = json.load(open(res))
    RB = R["blender"]
    R.update(R.pop("openvdb"))
    names = [(x["name"], x["type"]) for x in R["grids"]]
    check(("surface", "FLOAT") in names and not R["load_error"],
          "%s imports the grids: %s %r" % (label, names, R["load_error"]))
    BV = np.array(R["vertices"])
    check(len(BV) > 1000 and R["open_edges"] == 0,
          "%s: Volume to Mesh closed: %d vertices, %d open edges" % (label, len(BV), R["open_edges"]))
    if len(BV):
        # Blender puts an OpenVDB voxel's centre half a voxel up each axis
        # (its cells span [i, i + 1) in index space): its Volume to Mesh is
        # OpenVDB's own volumeToMesh moved by (h/2, h/2, h/2), to float precision
        shift = cKDTree(OV).query(BV - h / 2)[0].max() / h if len(OV) else 1
        check(len(BV) == len(OV) and shift <= 1e-4,
              "%s: Volume to Mesh is OpenVDB's volumeToMesh moved by half a voxel: %d / %d "
              "vertices, %.2e voxels" % (label, len(BV), len(OV), shift))
        BF = np.array(R["triangles"], dtype=np.int64)
        BV0 = BV - h / 2
        h1 = to_mesh(BV0, LV, LF).max()
        h2 = to_mesh(LV, BV0, BF).max()
        r1, r2 = to_mesh(BV, LV, LF).max(), to_mesh(LV, BV, BF).max()
        check(max(h1, h2) <= h, "%s: Volume to Mesh (voxel centres as written) within one voxel of "
              "libblend's mesh: %.3f, %.3f voxels" % (label, h1 / h, h2 / h))
        print("%s: Volume to Mesh %d vertices, Hausdorff to libblend's mesh %.3f / %.3f voxels "
              "(%.3f / %.3f with Blender's half-voxel placement)" %
              (label, len(BV), h1 / h, h2 / h, r1 / h, r2 / h))
    # written with --voxel-centres blender, Blender's own Volume to Mesh as
    # Blender shows it is within one voxel of libblend's mesh
    XV, XF = np.array(RB["vertices"]), np.array(RB["triangles"], dtype=np.int64)
    check(len(XV) > 1000 and RB["open_edges"] == 0 and not RB["load_error"],
          "%s, --voxel-centres blender: Volume to Mesh closed: %d vertices, %d open edges" %
          (label, len(XV), RB["open_edges"]))
    if len(XV):
        x1, x2 = to_mesh(XV, LV, LF).max(), to_mesh(LV, XV, XF).max()
        check(max(x1, x2) <= h, "%s, --voxel-centres blender: Volume to Mesh within one voxel of "
              "libblend's mesh: %.3f, %.3f voxels" % (label, x1 / h, x2 / h))
        print("%s, --voxel-centres blender: Volume to Mesh as Blender shows it, Hausdorff to "
              "libblend's mesh %.3f / %.3f voxels" % (label, x1 / h, x2 / h))
    sq = R["sequence"]
    check(sq["is_sequence"] and sq["frame_duration"] == 4 and sq["frame_start"] == 1,
          "%s: the job's files are one sequence of 4 frames: %s" % (label, sq))
    bx = sq["boxes"]
    check(len(bx) == 4 and bx[0] != bx[3], "%s: the sequence's frames differ: %s" % (label, bx))

print("%d failures" % len(failures))
sys.exit(1 if failures else 0)
