"""What `blendtool pov` writes around the field, checked on the text and
against independent numbers:

    /usr/bin/python3 test_pov_export.py BLENDTOOL SOURCE_DIR WORK_DIR

- every number outside comments, in every shipped scene's export, is the
  shortest decimal that reads back as the same double (0.3, not
  0.29999999999999999): no shorter %.{p}g form gives the same value;
- the camera is the scene's right-handed view: `sky` is the section's up
  (default +z) and `right` is negated (POV-Ray is left-handed);
- a section without lights gets the three-point default (a key light with
  an area light, a fill and a rim without shadows), placed around the
  camera as documented; a section with lights gets exactly those;
- the floor is a plane along up just under the surface: at most one coarse
  cell (5 % of the region's longest side) below the lowest vertex of a
  96-cell mesh, and never above it; "floor": false writes none; the
  background is the section's (default 0.9 grey);
- POV-Ray parses an export with the defaults (a 16 x 12 render).
"""
import json
import math
import os
import re
import struct
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from checks import args, check, finish  # noqa: E402

BLENDTOOL, SRC, WORK = args()


def export(scene, name):
    js = os.path.join(WORK, name + ".json")
    if isinstance(scene, dict):
        json.dump(scene, open(js, "w"))
    else:
        js = scene
    pov = os.path.join(WORK, name + ".pov")
    r = subprocess.run([BLENDTOOL, "pov", js, "-o", pov], capture_output=True, text=True)
    check(r.returncode == 0, "%s exports: %s" % (name, r.stderr))
    return js, open(pov).read() if r.returncode == 0 else ""


NUM = re.compile(r"(?<![A-Za-z0-9_.])(\d+\.?\d*(?:[eE][-+]?\d+)?|\.\d+(?:[eE][-+]?\d+)?)")


def numbers(text):
    for line in text.splitlines():
        code = line.split("//", 1)[0]
        for m in NUM.finditer(code):
            yield m.group(1)


def shortest(tok):
    v = float(tok)
    for p in range(1, 18):
        t = "%.*g" % (p, v)
        if float(t) == v:
            return t
    return tok


# ---- shortest numbers, on every shipped scene
scenes = sorted(f for f in os.listdir(os.path.join(SRC, "scenes")) if f.endswith(".json"))
checked = 0
for f in scenes:
    _js, text = export(os.path.join(SRC, "scenes", f), f[:-5])
    bad = [t for t in numbers(text) if len(shortest(t)) < len(t)]
    check(not bad, "%s: numbers not in shortest form: %s" % (f, bad[:5]))
    checked += len(list(numbers(text)))
check(checked > 5000, "numbers checked: %d" % checked)
print("shortest form: %d numbers in %d exports" % (checked, len(scenes)))

# ---- camera, lights, floor, background
BASE = {"format": "libblend-scene", "version": 1, "convention": "zero",
        "bounds": {"min": [-2, -2, -2], "max": [2, 2, 2]},
        "root": {"type": "displacement", "op": "union", "r": 0.3, "p": 2,
                 "args": [{"type": "sphere", "center": [0, 0, 0], "radius": 1},
                          {"type": "sphere", "center": [1.2, 0, -0.3], "radius": 0.6}]}}


def vec(s):
    return [float(v) for v in s.split(",")]


def scene(render):
    d = dict(BASE)
    if render is not None:
        d["render"] = render
    return d


cam = {"location": [3, -7, 2.5], "look_at": [0.2, 0, 0], "angle": 35}
js, text = export(scene({"camera": cam}), "defaults")
m = re.search(r"camera \{ perspective location <([^>]*)> sky <([^>]*)> up y right -x \* (\S+) "
              r"angle (\S+) look_at <([^>]*)> \}", text)
check(m is not None, "the camera: location, sky, up y, a negated right, angle, look_at")
if m:
    check(vec(m.group(1)) == cam["location"] and vec(m.group(5)) == cam["look_at"], "camera place")
    check(vec(m.group(2)) == [0, 0, 1], "sky is the default up, +z")
    check(abs(float(m.group(3)) - 4 / 3) < 1e-15 and float(m.group(4)) == 35, "aspect, angle")
lights = re.findall(r"light_source \{ <([^>]*)> rgb (\S+)( area_light[^}]*| shadowless) \}", text)
check(len(lights) == 3, "three default lights: %d" % len(lights))
if len(lights) == 3:
    # the documented placement: at + L (a right + b up + c forward)
    L = math.dist(cam["location"], cam["look_at"])
    f = [(a - b) / L for a, b in zip(cam["look_at"], cam["location"])]
    z = [0, 0, 1]
    r = [f[1] * z[2] - f[2] * z[1], f[2] * z[0] - f[0] * z[2], f[0] * z[1] - f[1] * z[0]]
    rl = math.sqrt(sum(v * v for v in r))
    r = [v / rl for v in r]
    u = [r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]]
    want = [((-0.7, 0.9, -0.5), 0.85), ((1.0, 0.2, -0.6), 0.35), ((0.4, 1.0, 1.1), 0.5)]
    for k, ((a, b, c), w) in enumerate(want):
        P = [cam["look_at"][d] + L * (a * r[d] + b * u[d] + c * f[d]) for d in range(3)]
        check(math.dist(P, vec(lights[k][0])) < 1e-9 * L and float(lights[k][1]) == w,
              "default light %d where documented" % k)
    check("area_light" in lights[0][2] and "shadowless" in lights[1][2] and
          "shadowless" in lights[2][2], "soft key light, fill and rim without shadows")
bg = re.search(r"background \{ rgb <([^>]*)> \}", text)
check(bg is not None and vec(bg.group(1)) == [0.9, 0.9, 0.9], "default background 0.9 grey")
fl = re.search(r"plane \{ <([^>]*)>, (\S+) pigment \{ rgb <([^>]*)> \}", text)
check(fl is not None and vec(fl.group(1)) == [0, 0, 1] and vec(fl.group(3)) == [0.75] * 3,
      "a floor along +z, 0.75 grey")
if fl:
    ply = os.path.join(WORK, "defaults.ply")
    subprocess.run([BLENDTOOL, "mesh", js, "-o", ply, "--resolution", "96", "--quiet"], check=True)
    with open(ply, "rb") as fp:
        head = b""
        while not head.endswith(b"end_header\n"):
            head += fp.readline()
        nv = int(re.search(rb"element vertex (\d+)", head).group(1))
        data = fp.read(nv * 24)
    zmin = min(struct.unpack_from("<6f", data, 24 * i)[2] for i in range(nv))
    h = float(fl.group(2))
    print("floor at z = %.4f, lowest vertex of the surface %.4f" % (h, zmin))
    check(h <= zmin and h >= zmin - 0.05 * 4, "the floor is just under the surface")

# lights, up, floor off, background given
up = [0, 1, 0]
js, text = export(scene({"camera": {"location": [0, 0, 8], "look_at": [0, 0, 0], "up": up},
                         "lights": [{"location": [5, 5, 5], "color": [1, 0.5, 0.25]}],
                         "floor": False, "background": [0.1, 0.2, 0.3]}), "given")
m = re.search(r"sky <([^>]*)>", text)
check(m is not None and vec(m.group(1)) == up, "sky is the section's up")
check(re.findall(r"light_source \{[^}]*\}", text) == ["light_source { <5, 5, 5> rgb <1, 0.5, 0.25> }"],
      "exactly the section's light")
check("plane {" not in text, "floor false: no plane")
check("background { rgb <0.1, 0.2, 0.3> }" in text, "the section's background")
up2 = [0, 2, 0]
_js, text2 = export(scene({"camera": {"location": [0, 0, 8], "up": up2}}), "unit-up")
check("sky <0, 1, 0>" in text2, "up is written as a unit vector")

# ---- POV-Ray reads the defaults
png = os.path.join(WORK, "defaults.png")
r = subprocess.run([BLENDTOOL, "render", os.path.join(WORK, "defaults.json"), "-o", png,
                    "--width", "16", "--height", "12"], capture_output=True, text=True)
check(r.returncode == 0 and os.path.exists(png), "POV-Ray renders the defaults: " + r.stderr[-400:])

finish("test_pov_export", "all checks passed")
