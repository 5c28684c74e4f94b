"""The hand-written example scenes of povray_include/examples/ (one per
family of macros) render in POV-Ray as they are:

    /usr/bin/python3 test_pov_examples.py SOURCE_DIR WORK_DIR

Each is rendered at 96 x 72 with only povray_include/ on the library path:
POV-Ray exits 0, prints no parse warning and no "may contain holes" (the
scene's max_gradient holds), and the object covers at least 3 % of the
image (read from POV-Ray's own PPM output)."""
import glob
import os
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from checks import read_ppm  # noqa: E402

SRC, WORK = sys.argv[1:3]
os.makedirs(WORK, exist_ok=True)
INC = os.path.join(SRC, "povray_include")
BG = (0.92, 0.93, 0.95)
scenes = sorted(glob.glob(os.path.join(INC, "examples", "*.pov")))
failures = []


if len(scenes) < 10:
    failures.append("expected at least 10 example scenes, found %d" % len(scenes))
for path in scenes:
    name = os.path.basename(path)[:-4]
    out = os.path.join(WORK, name + ".ppm")
    r = subprocess.run(["povray", "+I" + path, "+O" + out, "+FP", "+W96", "+H72", "-D", "-V",
                        "+L" + INC, "+L" + os.path.join(INC, "examples")],
                       capture_output=True, text=True, cwd=WORK)
    log = " ".join((r.stdout + r.stderr).split())
    problems = []
    if r.returncode != 0 or not os.path.exists(out):
        problems.append("povray failed: " + log[-400:])
    else:
        if "Parse Warning" in log or "Possible Parse Error" in log:
            problems.append("parse warning: " + log[log.find("Parse"):][:200])
        if "may contain holes" in log:
            problems.append("max_gradient too low: " + log[log.find("maximum gradient"):][:160])
        w, h, px = read_ppm(out)
        cover = sum(1 for p in px if max(abs(a - b) for a, b in zip(p, BG)) > 0.12) / (w * h)
        if cover < 0.03:
            problems.append("the object covers %.1f %% of the image" % (100 * cover))
    print("%-14s %s" % (name, "; ".join(problems) if problems else "renders (%d x %d)" % (96, 72)))
    failures += ["%s: %s" % (name, p) for p in problems]
if failures:
    print("\n".join(failures))
    sys.exit(1)
print("test_pov_examples: %d example scenes render" % len(scenes))
