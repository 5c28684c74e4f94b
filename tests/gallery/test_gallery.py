"""The gallery cannot go stale (docs/gallery/README.md):

    /usr/bin/python3 test_gallery.py BLENDTOOL SOURCE_DIR WORK_DIR

Every job in docs/gallery/jobs/ is run again by `blendtool batch` at half
size (240 x 180 panels, into WORK_DIR; the job's antialiasing and mesh
resolution kept); each committed panel (480 x 360), downsized to 240 x 180
by oiiotool, must match the new render by OpenImageIO's idiff (at most
0.3 % of the pixels differing by more than 0.1, none by more than 0.8: the
outlines' pixels of an antialiased render at half size against a downsized
full-size one; measured on 2026-12-03: at most 0.074 % on the 46 panels);
every panel the job makes is committed, and so is its contact sheet. The
field sections (docs/gallery/sections.json) are made again and must equal
the committed ones to PNG rounding.

The comparison must fail for what the gallery is there to show: every two
panels of hsu2006 Fig. 7's close-up (m2 = 1.2, 0.9, 0.6, 0.3: the
subsequent blend's fillet, 0.05 to 0.1 apart in the scene) differ beyond
the thresholds (measured: 1.29 % to 3.53 % of the pixels, 4x the 0.3 %
bar for neighbours), and another figure's panel does not pass for Fig. 7's.
"""
import json
import os
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from checks import args, check, finish  # noqa: E402

BLENDTOOL, SRC, WORK = args()
GAL = os.path.join(SRC, "docs", "gallery")


FAIL_PERCENT, HARD = 0.3, 0.8
HALF_W, HALF_H = 240, 180


def same(committed, fresh, tag, resize=True):
    small = os.path.join(WORK, tag + "-committed.png")
    if resize:
        subprocess.run(["oiiotool", committed, "--resize", "%dx%d" % (HALF_W, HALF_H), "-o",
                        small], check=True)
    else:
        small = committed
    r = subprocess.run(["idiff", "-fail", "0.1", "-failpercent", str(FAIL_PERCENT), "-hardfail",
                        str(HARD), "-warn", "0.1", "-warnpercent", str(FAIL_PERCENT / 2), small,
                        fresh], capture_output=True, text=True)
    # idiff: 0 pass, 1 warning (over the warn thresholds, within the fail ones), 2 failure
    return r.returncode in (0, 1), " ".join(r.stdout.split())[-160:]


jobs = sorted(f for f in os.listdir(os.path.join(GAL, "jobs")) if f.endswith(".json"))
check(len(jobs) >= 9, "gallery jobs: %d" % len(jobs))
panels = 0
for jf in jobs:
    name = jf[:-5]
    job = json.load(open(os.path.join(GAL, "jobs", jf)))
    base = os.path.join(GAL, "jobs")
    for key in ("scene", "scenes"):
        if key in job:
            v = job[key]
            job[key] = ([os.path.normpath(os.path.join(base, p)) for p in v] if isinstance(v, list)
                        else os.path.normpath(os.path.join(base, v)))
    job["outputs"]["image"].update(width=HALF_W, height=HALF_H)
    job["outputs"]["contact_sheet"].update(cell_width=HALF_W, cell_height=HALF_H)
    out = os.path.join(WORK, name)
    shutil.rmtree(out, ignore_errors=True)
    job["output_dir"] = out
    small_job = os.path.join(WORK, jf)
    json.dump(job, open(small_job, "w"))
    t0 = time.monotonic()
    r = subprocess.run([BLENDTOOL, "batch", small_job, "--threads", "2"], capture_output=True,
                       text=True)
    print("%s: rendered in %.0f s" % (name, time.monotonic() - t0), flush=True)
    check(r.returncode == 0, "%s: batch at half size: %s" % (name, r.stderr[-300:]))
    fresh = sorted(f for f in os.listdir(out) if f.endswith(".png") and not f.endswith("_sheet.png"))
    committed_dir = os.path.join(GAL, name)
    check(os.path.exists(os.path.join(committed_dir, name + "_sheet.png")),
          "%s: the contact sheet is committed" % name)
    for f in fresh:
        c = os.path.join(committed_dir, f)
        check(os.path.exists(c), "%s: panel %s is committed" % (name, f))
        if os.path.exists(c):
            ok, msg = same(c, os.path.join(out, f), f[:-4])
            check(ok, "%s: %s differs from the committed panel: %s" % (name, f, msg))
            panels += 1
    extra = set(os.listdir(committed_dir)) - set(fresh) - {name + "_sheet.png"}
    check(not extra, "%s: committed panels no job makes: %s" % (name, sorted(extra)))
check(panels >= 25, "panels compared: %d" % panels)

# the field sections: made again at full size (they take a second), the same
# pixels as the committed ones (idiff within 1/255: PNG rounding)
sys.path.insert(0, os.path.join(SRC, "scripts"))
from gallery_sections import entries  # noqa: E402

sec_dir = os.path.join(WORK, "sections")
os.makedirs(sec_dir, exist_ok=True)
nsec = 0
for name, scene, sargs in entries(SRC):
    png = os.path.join(sec_dir, name + ".png")
    r = subprocess.run([BLENDTOOL, "section", scene, "-o", png, "--threads", "2"] + sargs,
                       capture_output=True, text=True)
    if not check(r.returncode == 0, "section %s: %s" % (name, r.stderr[-300:])):
        continue
    committed = os.path.join(GAL, "sections", name + ".png")
    if check(os.path.exists(committed), "section %s is committed" % name):
        r = subprocess.run(["idiff", "-fail", "0.004", "-hardfail", "0.004", committed, png],
                           capture_output=True, text=True)
        check(r.returncode in (0, 1), "section %s differs from the committed one: %s" %
              (name, " ".join(r.stdout.split())[-160:]))
        nsec += 1
check(nsec >= 3, "sections compared: %d" % nsec)
extra = set(os.listdir(os.path.join(GAL, "sections"))) - set(os.listdir(sec_dir))
check(not extra, "committed sections no entry makes: %s" % sorted(extra))

# the comparison can fail: Fig. 7's close-up panels, every two of them
fig7 = os.path.join(WORK, "hsu2006-fig7-closeup")
close = sorted(f for f in os.listdir(fig7) if f.endswith(".png") and not f.endswith("_sheet.png"))
check(len(close) == 4, "Fig. 7's close-up has 4 panels: %s" % close)
for i in range(len(close)):
    for j in range(i + 1, len(close)):
        ok, msg = same(os.path.join(fig7, close[i]), os.path.join(fig7, close[j]),
                       "fig7-%d-%d" % (i, j), resize=False)
        print("Fig. 7 close-up, panels %d and %d: %s" % (i, j, msg), flush=True)
        check(not ok, "Fig. 7's close-up panels %d and %d pass for each other" % (i, j))
# and another scene's panel does not pass for Fig. 7's
ok, _msg = same(os.path.join(GAL, "hsu2006-fig7", "hsu2006-fig7_0000.png"),
                os.path.join(WORK, "hsu2006-fig8", "hsu2006-fig8_hsu2006-fig8-plain_0000.png"),
                "negative")
check(not ok, "another scene's panel does not pass for Fig. 7's")

finish("test_gallery", "%d panels and %d sections match their committed images" %
       (panels, nsec))
