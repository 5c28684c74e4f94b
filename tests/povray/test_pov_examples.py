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

SRC, WORK = sys.argv[1:3]
os.makedirs(WORK, exist_ok=True)
INC = os.path.join(SRC, "povray_include")
BG = (0.92, 0.93, 0.95)
scenes = sorted(glob.glob(os.path.join(INC, "examples", "*.pov")))
failures = []


def read_ppm(path):
    """Binary PPM (P6): header tokens with # comments, then RGB samples."""
    data = open(path, "rb").read()
    parts, pos = [], 0
    while len(parts) < 4:  # magic, width, height, maxval
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":
            pos = data.index(b"\n", pos) + 1
            continue
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        parts.append(data[pos:end])
        pos = end
    pos += 1
    w, h, mx = int(parts[1]), int(parts[2]), int(parts[3])
    step = 2 if mx > 255 else 1
    px = data[pos:]
    vals = [int.from_bytes(px[i:i + step], "big") / mx for i in range(0, len(px), step)]
    return w, h, [vals[i:i + 3] for i in range(0, len(vals), 3)]


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
