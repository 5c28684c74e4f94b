#!/usr/bin/python3
"""blendtool render --quiet and --antialias, with POV-Ray for real.

--quiet: POV-Ray's banner and progress (about 120 lines per render) stay out
of the terminal, and come back when povray fails. --antialias: POV-Ray's
adaptive antialiasing without jitter: a silhouette that is two-valued
without it gets intermediate values on its outline (and only there), the
same bytes twice at one thread, and the setting in the image's metadata.

usage: test_render_options.py BLENDTOOL SOURCE_DIR WORK_DIR
"""
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from checks import check, failures  # noqa: E402

BT, SRC, WORK = (os.path.abspath(a) for a in sys.argv[1:4])
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
SCENE = os.path.join(SRC, "scenes", "default.json")
BANNER = "Persistence of Vision"


def render(name, *opts, env=None):
    out = os.path.join(WORK, name)
    r = subprocess.run([BT, "render", SCENE, "-o", out, "--width", "96", "--height", "72",
                        "--threads", "1", *opts], capture_output=True, text=True, env=env)
    return r, out


def pixels(png):
    """the image's 8-bit RGB values, through OpenImageIO's oiiotool as a PPM"""
    ppm = png[:-4] + ".ppm"
    subprocess.run(["oiiotool", png, "--ch", "R,G,B", "-o", ppm], check=True)
    data = open(ppm, "rb").read()
    fields, pos = [], 0
    while len(fields) < 4:  # P6 width height maxval, then one whitespace byte
        while data[pos:pos + 1].isspace():
            pos += 1
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    w, h = int(fields[1]), int(fields[2])
    return w, h, data[pos + 1:pos + 1 + 3 * w * h]


# ---- without --quiet POV-Ray speaks; with it, it does not
r, _ = render("loud.png")
check(r.returncode == 0 and BANNER in r.stderr and len(r.stderr.splitlines()) > 50,
      "without --quiet POV-Ray's banner and progress stream: %d lines" % len(r.stderr.splitlines()))
r, out = render("quiet.png", "--quiet")
check(r.returncode == 0 and os.path.exists(out), "--quiet renders: " + r.stderr[-400:])
check(BANNER not in r.stderr and len(r.stderr.splitlines()) <= 2,
      "--quiet keeps POV-Ray's output off stderr: %r" % r.stderr[-600:])
check(os.path.exists(out) and
      open(out, "rb").read() == open(os.path.join(WORK, "loud.png"), "rb").read(),
      "--quiet changes nothing in the image")

# ---- a failing povray under --quiet shows what POV-Ray said
bad_inc = os.path.join(WORK, "bad-include")
os.makedirs(bad_inc)
with open(os.path.join(bad_inc, "libblend.inc"), "w") as f:
    f.write("#declare LB_Broken = ;\n")
env = dict(os.environ, LIBBLEND_POVRAY_INCLUDE=bad_inc)
r, out = render("broken.png", "--quiet", env=env)
check(r.returncode == 1 and not os.path.exists(out), "a failing povray: exit 1, no image: %d" %
      r.returncode)
# POV-Ray wraps its messages at 80 columns, so where "Parse Error" breaks
# depends on the path's length: compare with the line breaks as spaces
check("Parse Error" in " ".join(r.stderr.split()) and "povray failed" in r.stderr,
      "--quiet shows POV-Ray's error when it fails: %r" % r.stderr[-800:])

# ---- --antialias on a silhouette: intermediate values on the outline only
r, plain = render("sil.png", "--silhouette", "--quiet")
check(r.returncode == 0, "silhouette render: " + r.stderr[-400:])
r, aa = render("sil-aa.png", "--silhouette", "--quiet", "--antialias")
check(r.returncode == 0, "--antialias renders: " + r.stderr[-400:])
r2, aa2 = render("sil-aa2.png", "--silhouette", "--quiet", "--antialias")
check(r2.returncode == 0 and os.path.exists(aa) and
      open(aa, "rb").read() == open(aa2, "rb").read(),
      "--antialias at one thread: the same bytes twice")
if not (os.path.exists(plain) and os.path.exists(aa)):
    check(False, "the silhouette renders exist")
else:
    w, h, p0 = pixels(plain)
    _, _, p1 = pixels(aa)
    vals0 = set(p0)
    check(vals0 <= {0, 255} and 0 in vals0 and 255 in vals0,
          "without --antialias the silhouette has two values: %s" % sorted(vals0)[:10])
    mid = [i // 3 for i in range(len(p1)) if 0 < p1[i] < 255]
    check(len(mid) >= 2 * (w + h) // 4, "--antialias gives the outline intermediate values: %d "
          "pixels" % len(mid))


    def on_outline(k):
        """is pixel k beside (or at) a change of value in the plain render?"""
        y, x = divmod(k, w)
        v = p0[3 * k]
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                yy, xx = y + dy, x + dx
                if 0 <= yy < h and 0 <= xx < w and p0[3 * (yy * w + xx)] != v:
                    return True
        return False


    away = [k for k in set(mid) if not on_outline(k)]
    print("silhouette %dx%d: %d pixels with intermediate values under --antialias" % (w, h, len(set(mid))))
    check(not away, "intermediate values only on the outline: %d pixels away from it" % len(away))
info = subprocess.run(["iinfo", "-v", aa], capture_output=True, text=True).stdout
check("antialias" in info and "libblend:render" in info,
      "the image's libblend:render metadata names antialias:\n" + info)
print("%d failures" % len(failures))
sys.exit(1 if failures else 0)
