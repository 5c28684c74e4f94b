#!/usr/bin/python3
"""An m that can change nothing is reported where users look: `blendtool
validate` and `blendtool pov` warn on stderr (naming the file and the node's
JSON path, exit status 0), the .pov that `blendtool pov` writes carries a
#warning, and POV-Ray prints it while parsing. A scene whose m acts (the
same blend inside a later blend) gets no warning anywhere.

usage: test_pov_m_warning.py BLENDTOOL SOURCE_DIR WORK_DIR
"""
import json
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from checks import check, failures  # noqa: E402

BT, SRC, WORK = (os.path.abspath(a) for a in sys.argv[1:4])
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)


def sphere(x, y):
    return {"type": "sphere", "center": [x, y, 0], "radius": 1}


blend = {"type": "displacement", "op": "union", "r": 0.25, "m": 0.3,
         "args": [sphere(0, 0), sphere(1.2, 0), sphere(0, 1.2)]}
scenes = {
    "outer": {"type": "min", "args": [blend, sphere(3, 3)]},
    "inner": {"type": "displacement", "op": "union", "r": 0.4, "args": [blend, sphere(1, 2)]},
}
for name, root in scenes.items():
    path = os.path.join(WORK, name + ".json")
    with open(path, "w") as f:
        json.dump({"format": "libblend-scene", "version": 1, "convention": "zero",
                   "bounds": {"min": [-1.5, -1.5, -1.5], "max": [4.5, 4.5, 1.5]}, "root": root}, f)
    flagged = name == "outer"
    r = subprocess.run([BT, "validate", path], capture_output=True, text=True)
    warned = "warning" in r.stderr and "$.root.args[0]" in r.stderr and path in r.stderr
    check(r.returncode == 0 and ": ok (" in r.stdout, "%s: validate passes: %s" % (name, r.stderr))
    check(warned == flagged, "%s: validate %s: %r" % (name, "warns" if flagged else "is silent",
                                                       r.stderr))
    check(flagged <= ("Fix: leave m at 1" in r.stderr), "%s: the warning names the fix" % name)
    r = subprocess.run([BT, "validate", "--quiet", path], capture_output=True, text=True)
    check(r.returncode == 0 and r.stderr == "", "%s: validate --quiet prints nothing" % name)
    pov = os.path.join(WORK, name + ".pov")
    r = subprocess.run([BT, "pov", path, "-o", pov], capture_output=True, text=True)
    check(r.returncode == 0, "%s: pov: %s" % (name, r.stderr))
    check(("warning" in r.stderr) == flagged, "%s: pov warns on stderr: %r" % (name, r.stderr))
    text = open(pov).read() if os.path.exists(pov) else ""
    check(('#warning "libblend: m at $.root.args[0]' in text) == flagged,
          "%s: the .pov %s a #warning" % (name, "carries" if flagged else "has no"))
    r = subprocess.run(["povray", "+I" + pov, "+O" + os.path.join(WORK, name + ".png"), "+W8",
                        "+H6", "-D", "+L" + os.path.join(SRC, "povray_include")],
                       capture_output=True, text=True, cwd=WORK)
    log = " ".join((r.stdout + r.stderr).split())
    check(r.returncode == 0, "%s: POV-Ray renders: %s" % (name, log[-300:]))
    check(("Parse Warning: libblend: m at $.root.args[0] has no effect" in log) == flagged,
          "%s: POV-Ray %s the warning: %s" % (name, "prints" if flagged else "does not print",
                                               log[log.find("Parse"):][:200]))
if failures:
    sys.exit(1)
print("test_pov_m_warning: OK")
