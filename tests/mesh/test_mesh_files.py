#!/usr/bin/python3
"""blendtool mesh end to end, read back by independent readers (meshcheck.py).

usage: test_mesh_files.py BLENDTOOL SOURCE_DIR WORK_DIR
"""
import glob
import json
import os
import shutil
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import meshcheck  # noqa: E402

blendtool, src, work = sys.argv[1:4]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from checks import fail, failures  # noqa: E402


def run(*args):
    return subprocess.run([blendtool, "mesh", *args], capture_output=True, text=True)


# every scene, two resolutions, through the PLY reader
scenes = sorted(glob.glob(os.path.join(src, "scenes", "*.json")))
if len(scenes) < 17:
    fail("only %d scenes" % len(scenes))
for path in scenes:
    for res in (32, 48):
        out = os.path.join(work, "s.ply")
        r = run(path, "-o", out, "--resolution", str(res))
        if r.returncode != 0:
            fail("%s at %d: exit %d: %s" % (path, res, r.returncode, r.stderr))
            continue
        if r.stderr:
            fail("%s: stderr not empty without a terminal: %r" % (path, r.stderr))
        V, N, F = meshcheck.read(out)
        c = meshcheck.check(V, F)
        if not (c["closed"] and c["oriented"] and c["manifold"] and c["volume"] > 0
                and c["unused_vertices"] == 0):
            fail("%s at %d: %s" % (os.path.basename(path), res, c))
        if not np.allclose(np.linalg.norm(N, axis=1), 1.0, atol=1e-6):
            fail("%s: normals are not unit vectors" % path)
        if "%d vertices, %d triangles" % (len(V), len(F)) not in r.stdout:
            fail("%s: summary %r does not match the file (%d, %d)" % (path, r.stdout, len(V), len(F)))

# the four formats agree
default = os.path.join(src, "scenes", "default.json")
data = {}
for ext in ("ply", "obj", "stl", "glb"):
    out = os.path.join(work, "d." + ext)
    r = run(default, "-o", out, "--resolution", "40", "--quiet")
    if r.returncode != 0 or r.stdout or r.stderr:
        fail("%s: exit %d, out %r, err %r" % (ext, r.returncode, r.stdout, r.stderr))
        continue
    data[ext] = meshcheck.read(out)
if len(data) == 4:
    V, N, F = data["ply"]
    for ext in ("obj", "glb"):
        V2, N2, F2 = data[ext]
        if V2.shape != V.shape or not np.array_equal(F2, F) or not np.allclose(V2, V, atol=1e-6) \
                or not np.allclose(N2, N, atol=1e-6):
            fail("%s differs from the PLY" % ext)
    V3, _, F3 = data["stl"]
    if len(F3) != len(F):
        fail("STL has %d triangles, PLY %d" % (len(F3), len(F)))
    c = meshcheck.check(V3, F3)
    if len(V3) == len(V) and not (c["closed"] and c["oriented"]):
        fail("STL (vertices merged by position) is not closed: %s" % c)
    if abs(c["volume"] - meshcheck.check(V, F)["volume"]) > 1e-4 * abs(c["volume"]):
        fail("STL volume %g differs from PLY %g" % (c["volume"], meshcheck.check(V, F)["volume"]))

# a region without surface: a valid empty mesh in every format, read back
for ext in ("ply", "obj", "stl", "glb"):
    out = os.path.join(work, "empty." + ext)
    r = run(default, "-o", out, "--bounds", "100,100,100,101,101,101", "--resolution", "8")
    if r.returncode != 0 or "0 vertices, 0 triangles" not in r.stdout:
        fail("empty %s: exit %d, %r %r" % (ext, r.returncode, r.stdout, r.stderr))
        continue
    V, N, F = meshcheck.read(out)
    if len(V) or len(F):
        fail("empty %s read back with %d vertices, %d triangles" % (ext, len(V), len(F)))
    if ext == "glb":
        raw = open(out, "rb").read()
        doc = json.loads(raw[20:20 + int.from_bytes(raw[12:16], "little")])
        if "accessors" in doc or "buffers" in doc or doc["scenes"] != [{}]:
            fail("empty GLB is not a valid glTF scene without nodes: %s" % doc)

# the same bytes for 1 and 2 threads
outs = []
for t in ("1", "2"):
    out = os.path.join(work, "t%s.ply" % t)
    r = run(os.path.join(src, "scenes", "bench-s2-64-spheres.json"), "-o", out, "--threads", t,
            "--resolution", "64", "--quiet")
    outs.append(open(out, "rb").read() if r.returncode == 0 else b"")
if not outs[0] or outs[0] != outs[1]:
    fail("PLY with 1 and 2 threads differ")

# bad input: exit 2, one message naming the problem, no file left behind
nobounds = os.path.join(work, "nobounds.json")
with open(nobounds, "w") as f:
    f.write('{"format": "libblend-scene", "version": 1, "convention": "zero", '
            '"root": {"type": "sphere", "radius": 1}}')
bad = [
    ((default, "-o", os.path.join(work, "x.xyz")), "unknown mesh format"),
    ((default,), "no output given"),
    ((nobounds, "-o", os.path.join(work, "x.ply")), "the scene has no bounds"),
    ((default, "-o", os.path.join(work, "x.ply"), "--bounds", "1,2,3"), "expected six numbers"),
    ((default, "-o", os.path.join(work, "x.ply"), "--bounds", "0,0,0,1,-1,1"), "is not below"),
    ((default, "-o", os.path.join(work, "x.ply"), "--resolution", "0"), "cells along the longest side, 1 to 8192"),
    ((default, "-o", os.path.join(work, "x.ply"), "--cell-size", "1e-7"), "at most 8192 cells per axis"),
    ((os.path.join(work, "missing.json"), "-o", os.path.join(work, "x.ply")), "cannot open"),
    ((default, "-o", "/nonexistent-dir/x.ply"), "/nonexistent-dir/x.ply"),
    ((default, "-o", os.path.join(work, "x.ply"), "--frobnicate"), "unknown option"),
    ((default, "-o", os.path.join(work, "x.ply"), "--resolution", "8", "--cell-size", "0.1"),
     "--resolution and --cell-size both given"),
    ((default, "-o", work), "unknown mesh format"),
    ((default, "-o", os.path.join(work, "dir.ply")), "dir.ply: is a folder"),
]
os.makedirs(os.path.join(work, "dir.ply"), exist_ok=True)
for args, msg in bad:
    r = run(*args)
    if r.returncode != 2 or msg not in r.stderr or r.stderr.count("\n") != 1:
        fail("%s: exit %d, stderr %r; expected 2 and %r" % (args, r.returncode, r.stderr, msg))
leftovers = [f for f in os.listdir(work) if f.startswith("x.")]
if leftovers:
    fail("files left behind by failed runs: %s" % leftovers)
r = subprocess.run([blendtool, "mesh", "--help"], capture_output=True, text=True)
if r.returncode != 0 or "usage: blendtool mesh" not in r.stdout:
    fail("mesh --help")

print("%d scenes x 2 resolutions, 4 formats, threads, %d bad inputs: %d failures" % (
    len(scenes), len(bad), len(failures)))
sys.exit(1 if failures else 0)
