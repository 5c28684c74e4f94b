#!/usr/bin/python3
"""POV-Ray renders of libblend's mesh (`blendtool render --mesh N`, a job's
`outputs.image.mesh`) instead of the isosurface:

- the .pov holds one mesh2 of smooth triangles with exactly the vertices and
  triangles of `blendtool mesh --resolution N` of the same scene (an
  independent path: the PLY writer), a normal per vertex, no isosurface;
- its silhouette covers the isosurface's: for a zero-convention scene, a
  soft local union and a soft-object intersection, at most 1 % of the
  pixels differ (the outline's pixels: the mesh lies within half a cell of
  the surface), the object covering at least 3 % of the image;
- with --features --simplify 0.1 the cube (max of three slabs) is a mesh2
  of 8 vertices and 12 triangles whose corners name their face's normal
  (normal_indices); POV-Ray renders it with the isosurface's silhouette and
  shading (at most 0.5 % of the object's pixels off its shade by 0.05,
  against 3.75 % for the smooth mesh, measured 2026-12-04: 0.30 %); --features
  without --mesh exits 2;
- with --features --merge-flat (no tolerance) the cube is the same 8
  vertices and 12 triangles, and its silhouette the isosurface's;
  --merge-flat without --mesh exits 2;
- materials stay the scene's: a two-material scene shaded both ways has
  the same mean colour over the object to 3 % per channel, and each
  material's colour dominates the half of the image where its primitive is;
- bad values are refused with exit 2 and a message naming the option or the
  job path: --mesh 0, 1025, "x", --mesh with --include-only, a job's
  "mesh": 0, "antialias": "yes", a sweep "label" with a space;
- a job's antialias, mesh and label reach the image: its libblend:render
  metadata says "antialias mesh 64", its libblend:parameters "r_a=0.5".

usage: test_pov_mesh.py BLENDTOOL SOURCE_DIR WORK_DIR
"""
import json
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from checks import args, check, failures, read_ppm  # noqa: E402

BT, SRC, WORK = (os.path.abspath(a) for a in args())
shutil.rmtree(WORK)
os.makedirs(WORK)
W, H = 160, 120
RES = 128


def run(*cmd):
    return subprocess.run([str(c) for c in cmd], capture_output=True, text=True)


def ppm_of(png):
    ppm = png[:-4] + ".ppm"
    subprocess.run(["oiiotool", png, "--ch", "R,G,B", "-o", ppm], check=True)
    return read_ppm(ppm)


# ---- the mesh2 is libblend's mesh
scene = os.path.join(SRC, "scenes", "bernhardt-compare-local.json")
pov = os.path.join(WORK, "local.pov")
r = run(BT, "pov", scene, "--mesh", RES, "-o", pov)
if check(r.returncode == 0, "pov --mesh: %s" % r.stderr):
    text = open(pov).read()
    check("isosurface" not in text, "no isosurface in a --mesh scene")
    m = re.search(r"mesh2 \{\s*vertex_vectors \{ (\d+),.*?normal_vectors \{ (\d+),.*?"
                  r"face_indices \{ (\d+),", text, re.S)
    if check(m is not None, "one mesh2 with vertices, normals and faces"):
        ply = os.path.join(WORK, "local.ply")
        r = run(BT, "mesh", scene, "--resolution", RES, "--quiet", "-o", ply)
        check(r.returncode == 0, "blendtool mesh: %s" % r.stderr)
        head = open(ply, "rb").read(600).decode("ascii", "replace")
        nv = int(re.search(r"element vertex (\d+)", head).group(1))
        nf = int(re.search(r"element face (\d+)", head).group(1))
        print("mesh2: %s vertices, %s normals, %s triangles; PLY %d and %d" %
              (m.group(1), m.group(2), m.group(3), nv, nf))
        check(int(m.group(1)) == nv == int(m.group(2)), "vertex counts %s / %s against the "
              "PLY's %d" % (m.group(1), m.group(2), nv))
        check(int(m.group(3)) == nf, "triangles %s against the PLY's %d" % (m.group(3), nf))


# ---- silhouettes: mesh against isosurface
def silhouette(name, scene, mesh_opts=()):
    masks = []
    for extra in ([], ["--mesh", str(RES)] + list(mesh_opts)):
        png = os.path.join(WORK, "%s%s.png" % (name, "-mesh" if extra else ""))
        r = run(BT, "render", scene, "--silhouette", "--quiet", "--threads", "2", "--width", W,
                "--height", H, "-o", png, *extra)
        if not check(r.returncode == 0, "%s: render --silhouette %s: %s" %
                     (name, " ".join(extra), r.stderr)):
            return
        w, h, px = ppm_of(png)
        masks.append([p[0] > 0.5 for p in px])
    a, b = masks
    cover = sum(a) / len(a)
    differ = sum(1 for p, q in zip(a, b) if p != q)
    print("%-10s object %.1f %% of the image; mesh and isosurface differ in %d of %d pixels" %
          (name, 100 * cover, differ, len(a)))
    check(cover >= 0.03, "%s: the object covers %.1f %% of the image" % (name, 100 * cover))
    check(differ <= 0.01 * len(a), "%s: %d pixels differ (at most %d)" %
          (name, differ, int(0.01 * len(a))))


silhouette("default", os.path.join(SRC, "scenes", "default.json"))
silhouette("local", scene)
silhouette("soft-box", os.path.join(SRC, "scenes", "hsu-nonuniform-fig5-h0.5.json"))

# ---- sharp features and simplification in the mesh2: the cube (max of three
# slabs) in 12 triangles whose corners name their face's normal through
# normal_indices; POV-Ray parses and renders it: the same silhouette as the
# isosurface, and flat faces (each face's pixels one shade, as the
# isosurface's: smooth vertex normals would shade a cube's faces as a ball)
cube = os.path.join(SRC, "tests", "data", "features", "cube.json")
cpov = os.path.join(WORK, "cube.pov")
r = run(BT, "pov", cube, "--mesh", 32, "--features", "--simplify", "0.1", "-o", cpov)
if check(r.returncode == 0, "pov --mesh 32 --features --simplify 0.1: %s" % r.stderr):
    text = open(cpov).read()
    nf = re.search(r"face_indices \{ (\d+),", text)
    ni = re.search(r"normal_indices \{ (\d+),((?:\s*<\d+, \d+, \d+>,?)+)", text)
    nn = re.search(r"normal_vectors \{ (\d+),", text)
    vv = re.search(r"vertex_vectors \{ (\d+),", text)
    check(nf and ni and nn and vv and int(nf.group(1)) == 12 and int(ni.group(1)) == 12 and
          int(vv.group(1)) == 8 and int(nn.group(1)) > 8,
          "the cube's mesh2: %s vertices, %s normals, %s faces, %s normal_indices" %
          (vv and vv.group(1), nn and nn.group(1), nf and nf.group(1), ni and ni.group(1)))
silhouette("cube", cube, ("--features", "--simplify", "0.1"))
shades = []
for extra in ([], ["--mesh", "32", "--features", "--simplify", "0.1"], ["--mesh", "32"]):
    png = os.path.join(WORK, "cube-shade%d.png" % len(shades))
    r = run(BT, "render", cube, "--quiet", "--threads", "1", "--width", W, "--height", H,
            "-o", png, *extra)
    if check(r.returncode == 0, "render the cube %s: %s" % (" ".join(extra), r.stderr)):
        shades.append(ppm_of(png)[2])
if len(shades) == 3:
    iso, sharp, smooth = shades
    obj = [i for i, p in enumerate(iso) if max(p) > 0.05 and max(sharp[i]) > 0.05]

    def diff(a):
        return sorted(max(abs(a[i][c] - iso[i][c]) for c in range(3)) for i in obj)
    ds, dm = diff(sharp), diff(smooth)
    off_s = sum(d > 0.05 for d in ds) / len(ds)
    off_m = sum(d > 0.05 for d in dm) / len(dm)
    print("cube: %.2f %% of the object's pixels off the isosurface's shade by more than 0.05 "
          "with --features, %.2f %% without" % (100 * off_s, 100 * off_m))
    check(len(obj) > 1000 and off_s <= 0.005 and off_m > 4 * max(off_s, 0.002),
          "the cube's faces shade as the isosurface's with --features (%.2f %% of the pixels "
          "off; %.2f %% without)" % (100 * off_s, 100 * off_m))
# flat regions merged without a tolerance (no vertex moves): the same cube
fpov = os.path.join(WORK, "cube-flat.pov")
r = run(BT, "pov", cube, "--mesh", 32, "--features", "--merge-flat", "-o", fpov)
if check(r.returncode == 0, "pov --mesh 32 --features --merge-flat: %s" % r.stderr):
    text = open(fpov).read()
    nf = re.search(r"face_indices \{ (\d+),", text)
    vv = re.search(r"vertex_vectors \{ (\d+),", text)
    check(nf and vv and int(nf.group(1)) == 12 and int(vv.group(1)) == 8,
          "the cube's mesh2 with --merge-flat: %s vertices, %s faces (without it: thousands)" %
          (vv and vv.group(1), nf and nf.group(1)))
silhouette("cube-flat", cube, ("--features", "--merge-flat"))
for opt in ("--features", "--merge-flat"):
    r = run(BT, "pov", cube, opt, "-o", os.path.join(WORK, "bad.pov"))
    check(r.returncode == 2 and "--mesh" in r.stderr and opt in r.stderr and
          not os.path.exists(os.path.join(WORK, "bad.pov")),
          "pov %s without --mesh: exit %d, %s" % (opt, r.returncode, r.stderr.strip()))

# ---- materials: the same colours both ways
two = json.load(open(scene))
two["root"]["args"][0]["material"] = {"color": [0.9, 0.2, 0.1]}
two["root"]["args"][1]["material"] = {"color": [0.1, 0.3, 0.9]}
two["render"]["camera"] = {"location": [0.6, -8, 0], "look_at": [0.6, 0, 0], "angle": 40}
two["render"]["floor"] = False
two["render"]["background"] = [0, 0, 0]
two_path = os.path.join(WORK, "two.json")
json.dump(two, open(two_path, "w"))
means = []
for extra in ([], ["--mesh", str(RES)]):
    png = os.path.join(WORK, "two%s.png" % ("-mesh" if extra else ""))
    r = run(BT, "render", two_path, "--quiet", "--threads", "2", "--width", W, "--height", H,
            "-o", png, *extra)
    if not check(r.returncode == 0, "two materials %s: %s" % (" ".join(extra), r.stderr)):
        continue
    w, h, px = ppm_of(png)
    obj = [p for p in px if max(p) > 0.02]
    means.append([sum(p[c] for p in obj) / len(obj) for c in range(3)])
    # the big sphere (red) is on the image's left, the small one (blue) on its right
    left = [p for i, p in enumerate(px) if i % w < w * 0.35 and max(p) > 0.02]
    right = [p for i, p in enumerate(px) if i % w > w * 0.72 and max(p) > 0.02]
    lr = [sum(p[c] for p in left) / max(1, len(left)) for c in range(3)]
    rr = [sum(p[c] for p in right) / max(1, len(right)) for c in range(3)]
    check(len(left) > 50 and lr[0] > 2 * lr[2], "%s: left half red (%s)" % (extra, lr))
    check(len(right) > 50 and rr[2] > 2 * rr[0], "%s: right half blue (%s)" % (extra, rr))
if len(means) == 2:
    print("mean colour over the object: isosurface %s, mesh %s" %
          (["%.3f" % v for v in means[0]], ["%.3f" % v for v in means[1]]))
    for c in range(3):
        check(abs(means[0][c] - means[1][c]) <= 0.03 * max(means[0][c], 0.1),
              "channel %d: %.4f against %.4f" % (c, means[0][c], means[1][c]))

# ---- bad values
for extra, word in ((["--mesh", "0"], "--mesh"), (["--mesh", "1025"], "--mesh"),
                    (["--mesh", "x"], "--mesh"), (["--mesh", "64", "--include-only"], "--mesh")):
    r = run(BT, "pov", scene, "-o", os.path.join(WORK, "bad.pov"), *extra)
    check(r.returncode == 2 and word in r.stderr, "pov %s: exit %d, %s" %
          (" ".join(extra), r.returncode, r.stderr.strip()))
    check(not os.path.exists(os.path.join(WORK, "bad.pov")), "pov %s: no output" % extra)


def job(image, axis=None):
    j = {"format": "libblend-job", "version": 1, "name": "meshjob", "scene": scene,
         "outputs": {"image": dict({"width": 64, "height": 48}, **image)},
         "output_dir": os.path.join(WORK, "jobout")}
    if axis:
        j["sweep"] = [axis]
    p = os.path.join(WORK, "job.json")
    json.dump(j, open(p, "w"))
    return p


for image, axis, where in (({"mesh": 0}, None, "$.outputs.image"),
                           ({"antialias": "yes"}, None, "$.outputs.image.antialias"),
                           ({}, {"path": "root.alpha[0]", "values": [0.5], "label": "r a"},
                            "$.sweep[0]")):
    r = run(BT, "batch", job(image, axis), "--list")
    check(r.returncode == 2 and where in r.stderr, "job %s %s: exit %d, %s" %
          (image, axis, r.returncode, r.stderr.strip()))

r = run(BT, "batch", job({"mesh": 64, "antialias": True},
                         {"path": "root.alpha[0]", "values": [0.05, 0.5], "label": "r_a"}),
        "--threads", "2")
if check(r.returncode == 0, "job with mesh, antialias and a label: %s" % r.stderr):
    png = os.path.join(WORK, "jobout", "meshjob_0001.png")
    info = run("oiiotool", "--info", "-v", png).stdout
    check('libblend:render: "64x48 quality 9 antialias mesh 64"' in info,
          "render metadata: %s" % re.findall(r"libblend:render.*", info))
    check('libblend:parameters: "r_a=0.5"' in info,
          "parameters metadata: %s" % re.findall(r"libblend:parameters.*", info))

if failures:
    sys.exit(1)
print("test_pov_mesh: OK")
