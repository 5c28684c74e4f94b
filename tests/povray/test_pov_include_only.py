#!/usr/bin/python3
"""A libblend field in a hand-written POV-Ray scene: `blendtool pov
--include-only` bakes the field (a local union's curves included) into an
include that declares LB_Field, LB_Surface (< 0 inside, 0 on the surface),
LB_FieldMin / LB_FieldMax, LB_FieldMaxGradient and LB_FieldAccuracy.

- The include shipped beside povray_include/examples/local_union.pov is what
  blendtool makes from local_union.json today (numbers to 1e-9 relative).
- A scene written by hand around that include, with only those names, gives
  the same silhouette as `blendtool render --silhouette` of the same scene
  from the same camera (the local-union example, soft convention, and the
  default scene, zero convention): at most 0.1 % of the pixels differ, and
  the object covers at least 3 % of the image. POV-Ray prints no parse
  warning and no "may contain holes" for the hand-written scene.

usage: test_pov_include_only.py BLENDTOOL SOURCE_DIR WORK_DIR
"""
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from checks import check, failures, read_ppm  # noqa: E402

BT, SRC, WORK = (os.path.abspath(a) for a in sys.argv[1:4])
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
INC = os.path.join(SRC, "povray_include")
EXAMPLE = "povray_include/examples/local_union.json"
SHIPPED = os.path.join(INC, "examples", "local_union_field.inc")
W, H = 160, 120
NUMBER = re.compile(r"-?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?")


def tokens(text):
    """numbers as floats, everything else as the text between them"""
    out, pos = [], 0
    for m in NUMBER.finditer(text):
        out.append(text[pos:m.start()])
        out.append(float(m.group()))
        pos = m.end()
    out.append(text[pos:])
    return out


def same_text(a, b):
    ta, tb = tokens(a), tokens(b)
    if len(ta) != len(tb):
        return "%d tokens against %d" % (len(ta), len(tb))
    for i, (x, y) in enumerate(zip(ta, tb)):
        if isinstance(x, float) and isinstance(y, float):
            if abs(x - y) > 1e-9 * max(1.0, abs(x), abs(y)):
                return "number %d: %r against %r" % (i, x, y)
        elif x != y:
            return "text %r against %r" % (x[:80], y[:80])
    return None


def read_mask(path):
    """the image's pixels as object (True: brighter than half) or not"""
    w, h, px = read_ppm(path)
    return w, h, [p[0] > 0.5 for p in px]


# ---- the shipped include is today's output
r = subprocess.run([BT, "pov", EXAMPLE, "--include-only", "-o", os.path.join(WORK, "fresh.inc")],
                   capture_output=True, text=True, cwd=SRC)
check(r.returncode == 0, "include-only export of %s: %s" % (EXAMPLE, r.stderr))
if r.returncode == 0:
    diff = same_text(open(SHIPPED).read(), open(os.path.join(WORK, "fresh.inc")).read())
    check(diff is None, "%s is stale (%s); make it again with: cd %s && blendtool pov %s "
          "--include-only -o %s" % (SHIPPED, diff, SRC, EXAMPLE, os.path.relpath(SHIPPED, SRC)))


def compare(name, scene):
    d = os.path.join(WORK, name)
    os.makedirs(d)
    full = os.path.join(d, "full.pov")
    r = subprocess.run([BT, "pov", scene, "--silhouette", "--width", str(W), "--height", str(H),
                        "-o", full], capture_output=True, text=True)
    if not check(r.returncode == 0, "%s: blendtool pov --silhouette: %s" % (name, r.stderr)):
        return
    camera = re.search(r"^camera \{.*\}$", open(full).read(), re.M)
    if not check(camera is not None, "%s: no camera line in blendtool's scene" % name):
        return
    r = subprocess.run([BT, "pov", scene, "--include-only", "-o", os.path.join(d, "field.inc")],
                       capture_output=True, text=True)
    if not check(r.returncode == 0, "%s: include-only export: %s" % (name, r.stderr)):
        return
    inc_text = open(os.path.join(d, "field.inc")).read()
    for word in ("LB_Field", "LB_Surface", "LB_FieldMin", "LB_FieldMax", "LB_FieldMaxGradient",
                 "LB_FieldAccuracy"):
        check("#declare %s =" % word in inc_text, "%s: the include declares %s" % (name, word))
    hand = os.path.join(d, "hand.pov")
    with open(hand, "w") as f:
        f.write('#version 3.7;\n#include "libblend.inc"\n#include "field.inc"\n'
                "global_settings { assumed_gamma 1.0 }\nbackground { rgb 0 }\n%s\n"
                "isosurface { function { LB_Surface(x, y, z) } threshold 0\n"
                "  contained_by { box { LB_FieldMin, LB_FieldMax } }\n"
                "  max_gradient LB_FieldMaxGradient accuracy LB_FieldAccuracy\n"
                "  pigment { rgb 1 } finish { ambient 1 diffuse 0 } }\n" % camera.group())
    ppm = os.path.join(d, "hand.ppm")
    r = subprocess.run(["povray", "+I" + hand, "+O" + ppm, "+FP", "+W%d" % W, "+H%d" % H, "-D",
                        "-V", "+WT1", "+L" + INC], capture_output=True, text=True, cwd=d)
    log = " ".join((r.stdout + r.stderr).split())
    if not check(r.returncode == 0 and os.path.exists(ppm),
                 "%s: the hand-written scene renders: %s" % (name, log[-400:])):
        return
    check("Parse Warning" not in log, "%s: parse warning: %s" % (name, log[log.find("Parse"):][:200]))
    check("may contain holes" not in log, "%s: LB_FieldMaxGradient holds: %s" %
          (name, log[log.find("maximum gradient"):][:160]))
    png = os.path.join(d, "tool.png")
    r = subprocess.run([BT, "render", scene, "--silhouette", "--quiet", "--threads", "1",
                        "--width", str(W), "--height", str(H), "-o", png],
                       capture_output=True, text=True)
    if not check(r.returncode == 0, "%s: blendtool render --silhouette: %s" % (name, r.stderr)):
        return
    tool_ppm = os.path.join(d, "tool.ppm")
    subprocess.run(["oiiotool", png, "--ch", "R,G,B", "-o", tool_ppm], check=True)
    w1, h1, a = read_mask(ppm)
    w2, h2, b = read_mask(tool_ppm)
    if not check((w1, h1) == (w2, h2) == (W, H), "%s: image sizes %dx%d and %dx%d" %
                 (name, w1, h1, w2, h2)):
        return
    cover = sum(a) / len(a)
    differ = sum(1 for p, q in zip(a, b) if p != q)
    print("%-12s object %.1f %% of the image, %d of %d pixels differ" %
          (name, 100 * cover, differ, len(a)))
    check(cover >= 0.03, "%s: the object covers only %.1f %% of the image" % (name, 100 * cover))
    check(differ <= 0.001 * len(a), "%s: %d pixels differ between the hand-written scene and "
          "blendtool render (at most %d)" % (name, differ, int(0.001 * len(a))))


compare("local-union", os.path.join(SRC, EXAMPLE))
compare("default", os.path.join(SRC, "scenes", "default.json"))
if failures:
    sys.exit(1)
print("test_pov_include_only: OK")
