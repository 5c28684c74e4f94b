#!/usr/bin/python3
"""The shipped local-blending scenes (scenes/bernhardt-*.json, written by
scenes/make_scenes.py) through blendtool: each validates and meshes closed,
oriented and 2-manifold at two resolutions (independent numpy reader); the
drop sweep has no curve before contact and a support R that grows with every
step after; the hand near the body has no curve and meshes exactly like its
clean union (same bytes).

usage: test_local_scenes.py BLENDTOOL SOURCE_DIR WORK_DIR
"""
import glob
import json
import os
import re
import shutil
import subprocess
import sys

BT, SRC, WORK = sys.argv[1:4]
sys.path.insert(0, os.path.join(SRC, "tests", "mesh"))
import meshcheck  # noqa: E402

shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from checks import fail, failures  # noqa: E402


def bt(*args):
    return subprocess.run([BT, *args], capture_output=True, text=True, timeout=300)


def curves(path):
    """[(R, vertices)] per curve of the scene's local unions, from blendtool info"""
    r = bt("info", "--json", path)
    if r.returncode:
        fail("%s: info exit %d: %s" % (path, r.returncode, r.stderr))
        return []
    text = json.loads(r.stdout)["local_blends"]
    return [(float(m.group(2)), int(m.group(1)))
            for m in re.finditer(r"curve \d+: \w+, (\d+) vertices, .*? R ([0-9.e+-]+),", text)]


scenes = sorted(glob.glob(os.path.join(SRC, "scenes", "bernhardt-*.json")))
if len(scenes) < 17:
    fail("only %d local scenes" % len(scenes))
for path in scenes:
    name = os.path.basename(path)
    r = bt("validate", "--quiet", path)
    if r.returncode:
        fail("%s: validate exit %d: %s" % (name, r.returncode, r.stderr))
        continue
    for res in (32, 56):
        out = os.path.join(WORK, "m.ply")
        r = bt("mesh", path, "-o", out, "--resolution", str(res), "--quiet")
        if r.returncode:
            fail("%s at %d: mesh exit %d: %s" % (name, res, r.returncode, r.stderr))
            continue
        V, N, F = meshcheck.read(out)
        c = meshcheck.check(V, F)
        if not (len(F) > 100 and c["closed"] and c["oriented"] and c["manifold"]):
            fail("%s at %d: %s" % (name, res, c))

# the drop sweep: apart, then touching and deeper
drops = sorted(glob.glob(os.path.join(SRC, "scenes", "bernhardt-drop-[0-9]*.json")))
if len(drops) < 10:
    fail("the drop sweep has %d positions (want >= 10)" % len(drops))
last_r, touching = 0.0, 0
for path in drops:
    y = json.load(open(path))["root"]["args"][0]["center"][1]
    cs = curves(path)
    if y > 0.5 and cs:
        fail("%s: drop at %g does not touch but has curves %s" % (path, y, cs))
    if y < 0.5:
        touching += 1
        if len(cs) != 1 or not cs[0][0] > last_r:
            fail("%s: drop at %g: curves %s (R before %g)" % (path, y, cs, last_r))
        else:
            last_r = cs[0][0]
if touching < 6:
    fail("only %d touching positions" % touching)

# the hand near the body: no curve, the clean union's mesh byte for byte
hand = os.path.join(SRC, "scenes", "bernhardt-hand-near-body.json")
if curves(hand):
    fail("the hand near the body has an intersection curve")
sc = json.load(open(hand))
sc["root"]["type"] = "clean_union"
clean = os.path.join(WORK, "hand-clean.json")
json.dump(sc, open(clean, "w"))
outs = []
for p in (hand, clean):
    out = os.path.join(WORK, os.path.basename(p) + ".ply")
    r = bt("mesh", p, "-o", out, "--resolution", "64", "--quiet")
    outs.append(open(out, "rb").read() if r.returncode == 0 else b"")
if not outs[0] or outs[0] != outs[1]:
    fail("the hand near the body does not mesh like its clean union")

print("%d local scenes, %d drop positions (%d touching): %d failures" % (
    len(scenes), len(drops), touching, len(failures)))
sys.exit(1 if failures else 0)
