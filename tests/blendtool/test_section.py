#!/usr/bin/python3
"""blendtool section: the surface's contour on a plane, one colour per swept
value, against closed forms.

- A sphere of radius R at c, cut by z = c_z + h: the contour is the circle of
  radius sqrt(R^2 - h^2). Along 16 rays from the centre the line's darkest
  pixel lies within 1 pixel of that radius, and inside is grey, outside
  white. Swept over two radii, each circle is found in its own colour
  (red, then orange) at its own radius.
- A soft scene (a Wyvill sphere, whose kernel is 0.5 on the primitive's
  surface) gives the circle of its radius the same way.
- The same command twice writes the same bytes; the legend carries the
  label; the metadata names the section and the parameters.
- Bad input: no --plane, --plane w=1, --region with U0 >= U1, --width 10,
  --sweep with 9 values or no list, a --label with a space, a path the scene
  does not have, a scene without bounds and no --region: exit 2, the option
  or path named, no output.

usage: test_section.py BLENDTOOL SOURCE_DIR WORK_DIR
"""
import json
import math
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
W, H = 400, 300
RED, ORANGE = (0.80, 0.12, 0.10), (0.95, 0.55, 0.05)


def scene(conv, node):
    p = os.path.join(WORK, "%s.json" % conv)
    json.dump({"format": "libblend-scene", "version": 1, "convention": conv,
               "bounds": {"min": [-2, -2, -2], "max": [2, 2, 2]}, "root": node}, open(p, "w"))
    return p


def run(*a):
    return subprocess.run([BT, "section"] + [str(x) for x in a], capture_output=True, text=True)


def pixels(png):
    ppm = png[:-4] + ".ppm"
    subprocess.run(["oiiotool", png, "--ch", "R,G,B", "-o", ppm], check=True)
    return read_ppm(ppm)


def near(p, q, tol=0.08):
    return all(abs(a - b) <= tol for a, b in zip(p, q))


def ray_radius(px, w, cx, cy, ang, colour, rmax):
    """along a ray from the point (cx, cy) (pixel i covers [i, i + 1)), the
    distance of the centre of the pixel nearest in colour to colour"""
    best, where = 9.0, None
    r = 0.0
    while r < rmax:
        x, y = int(cx + r * math.cos(ang)), int(cy - r * math.sin(ang))
        p = px[y * w + x]
        d = sum((a - b) ** 2 for a, b in zip(p, colour))
        if d < best:
            best, where = d, math.hypot(x + 0.5 - cx, y + 0.5 - cy)
        r += 0.25
    return where, best


# region -2..2 x -1.5..1.5 on 400 x 300: 100 pixels per unit, centre (200, 150)
REGION = "-2,-1.5,2,1.5"
zero = scene("zero", {"type": "sphere", "center": [0, 0, 0.3], "radius": 1.0})
out = os.path.join(WORK, "sphere.png")
r = run(zero, "-o", out, "--plane", "z=0", "--region", REGION, "--width", W, "--height", H,
        "--sweep", "root.radius=[1.0,0.6]", "--label", "R")
if check(r.returncode == 0, "section of a sphere: %s" % r.stderr):
    w, h, px = pixels(out)
    check((w, h) == (W, H + 44), "image %dx%d (the plot and the 44-pixel legend)" % (w, h))
    for R, colour in ((1.0, RED), (0.6, ORANGE)):
        want = 100 * math.sqrt(R * R - 0.09)
        worst = 0.0
        for k in range(16):
            got, dist = ray_radius(px, w, 200, 150, 2 * math.pi * k / 16, colour, 140)
            worst = max(worst, abs(got - want) if got is not None else 99)
        print("R = %.1f: circle of radius %.2f px, found within %.2f px" % (R, want, worst))
        check(worst <= 1.0, "R = %.1f: contour %.2f px off the closed form" % (R, worst))
    # grey inside the first value's solid (between the two circles), white outside
    check(near(px[150 * w + 200 + 80], (0.86, 0.86, 0.86)), "grey inside: %s" %
          (px[150 * w + 200 + 80],))
    check(near(px[150 * w + 200 + 130], (1, 1, 1)), "white outside: %s" %
          (px[150 * w + 200 + 130],))
    # the legend in the two colours
    legend = px[(H + 4) * w:(H + 22) * w]
    check(any(near(p, RED, 0.15) for p in legend) and any(near(p, ORANGE, 0.15) for p in legend),
          "the legend shows both colours")
    info = subprocess.run(["oiiotool", "--info", "-v", out], capture_output=True, text=True).stdout
    check('libblend:render: "section z=0 400x300"' in info, "metadata: %s" %
          re.findall(r"libblend:render.*", info))
    check("root.radius=1 root.radius=0.6" in info, "parameters metadata: %s" %
          re.findall(r"libblend:parameters.*", info))
    again = os.path.join(WORK, "again.png")
    run(zero, "-o", again, "--plane", "z=0", "--region", REGION, "--width", W, "--height", H,
        "--sweep", "root.radius=[1.0,0.6]", "--label", "R")
    check(open(out, "rb").read() == open(again, "rb").read(), "the same bytes twice")

# soft: the kernel is 0.5 on the sphere of the given radius
soft = scene("soft", {"type": "sphere", "center": [0, 0.2, 0], "radius": 1.0, "kernel": "wyvill"})
out = os.path.join(WORK, "soft.png")
r = run(soft, "-o", out, "--plane", "y=0", "--region", REGION, "--width", W, "--height", H)
if check(r.returncode == 0, "section of a soft sphere: %s" % r.stderr):
    w, h, px = pixels(out)
    want = 100 * math.sqrt(1.0 - 0.04)
    worst = max(abs(ray_radius(px, w, 200, 150, 2 * math.pi * k / 16, RED, 140)[0] - want)
                for k in range(16))
    print("soft: circle of radius %.2f px, found within %.2f px" % (want, worst))
    check(worst <= 1.0, "soft contour %.2f px off the closed form" % worst)

# bad input
for extra, word in ((["--region", REGION], "--plane"),
                    (["--plane", "w=1"], "--plane"),
                    (["--plane", "z=0", "--region", "1,0,0,1"], "--region"),
                    (["--plane", "z=0", "--width", "10"], "--width"),
                    (["--plane", "z=0", "--sweep", "root.radius=[1,2,3,4,5,6,7,8,9]"], "--sweep"),
                    (["--plane", "z=0", "--sweep", "root.radius=1"], "--sweep"),
                    (["--plane", "z=0", "--label", "a b"], "--label"),
                    (["--plane", "z=0", "--sweep", "root.nothing.here=[1]"], "root.nothing")):
    bad = os.path.join(WORK, "bad.png")
    r = run(zero, "-o", bad, *extra)
    check(r.returncode == 2 and word in r.stderr, "%s: exit %d, %s" %
          (" ".join(extra), r.returncode, r.stderr.strip()[:200]))
    check(not os.path.exists(bad), "%s: no output" % " ".join(extra))

# a scene without bounds needs a --region
nob = os.path.join(WORK, "nobounds.json")
json.dump({"format": "libblend-scene", "version": 1, "convention": "zero",
           "root": {"type": "sphere", "center": [0, 0, 0], "radius": 1}}, open(nob, "w"))
bad = os.path.join(WORK, "nobounds.png")
r = run(nob, "-o", bad, "--plane", "z=0")
check(r.returncode == 2 and "no bounds" in r.stderr and "--region" in r.stderr,
      "no bounds: exit %d, %s" % (r.returncode, r.stderr.strip()[:200]))
check(not os.path.exists(bad), "no bounds: no output")
r = run(nob, "-o", bad, "--plane", "z=0", "--region", REGION, "--width", W, "--height", H)
check(r.returncode == 0 and os.path.exists(bad), "no bounds but --region: %s" % r.stderr)

if failures:
    sys.exit(1)
print("test_section: OK")
