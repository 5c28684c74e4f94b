"""The gallery cannot go stale (docs/gallery/README.md):

    /usr/bin/python3 test_gallery.py BLENDTOOL SOURCE_DIR WORK_DIR

Every job in docs/gallery/jobs/ is run again by `blendtool batch` at half
size (120 x 90 panels, into WORK_DIR); each committed panel, downsized to
120 x 90 by oiiotool, must match the new render by OpenImageIO's idiff
(at most 4 % of the pixels differing by more than 0.1, none by more than
0.8: at half size the edges, the horizon and the soft shadows' jitter
differ in up to 2.7 % of the pixels on these panels; a changed scene,
camera or light moves far more); every panel the job makes is committed,
and so is its contact sheet. The comparison does fail for another scene
(checked: Fig. 7's first panel against Fig. 8's). It is not fine enough to
tell Fig. 7's m2 = 1.2 from 0.3 (under 2 % of the pixels): that claim is
for tests on meshes.
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


def same(committed, fresh, tag):
    small = os.path.join(WORK, tag + "-committed.png")
    subprocess.run(["oiiotool", committed, "--resize", "120x90", "-o", small], check=True)
    r = subprocess.run(["idiff", "-fail", "0.1", "-failpercent", "4", "-hardfail", "0.8", "-warn",
                        "0.1", "-warnpercent", "2", small, fresh], capture_output=True, text=True)
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
    job["outputs"]["image"].update(width=120, height=90)
    job["outputs"]["contact_sheet"].update(cell_width=120, cell_height=90)
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

# the comparison can fail: Fig. 7's first panel against Fig. 8's
ok, _msg = same(os.path.join(GAL, "hsu2006-fig7", "hsu2006-fig7_0000.png"),
                os.path.join(WORK, "hsu2006-fig8", "hsu2006-fig8_hsu2006-fig8-plain_0000.png"),
                "negative")
check(not ok, "another scene's panel does not pass for Fig. 7's")

finish("test_gallery", "%d panels match their committed images" % panels)
