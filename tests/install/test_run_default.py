#!/usr/bin/python3
"""The README's first command, scripts/run-default.sh, run as a newcomer runs
it (against this build folder, already built: its install, configure and
build stages find nothing to do): one line per stage, the default scene's
table of points with their values and gradients, a picture (320 x 240, not
blank) and a mesh named at the end with next steps. A failing stage (a
cmake that fails) stops the script with exit 1, names the log and shows its
end.

usage: test_run_default.py SOURCE_DIR BUILD_DIR WORK_DIR
"""
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from checks import check, failures  # noqa: E402

SRC, BUILD, WORK = (os.path.abspath(a) for a in sys.argv[1:4])
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
env = dict(os.environ, LIBBLEND_BUILD=BUILD)
r = subprocess.run(["bash", os.path.join(SRC, "scripts", "run-default.sh")], cwd=WORK, env=env,
                   capture_output=True, text=True, timeout=900)
out = r.stdout
lines = out.splitlines()
check(r.returncode == 0, "run-default.sh exits 0: %d\n%s" % (r.returncode, r.stderr[-1500:]))
check(len(lines) <= 45, "a screenful on the terminal, not the build's output: %d lines" % len(lines))
stages = [l for l in lines if re.match(r"^\S.*\s+ok \(\d+ s\)$", l)]
check(len(stages) == 6, "one line per stage (install, configure, build, validate, mesh, render): "
      "%s" % stages)
rows = [l.split() for l in lines if re.match(r"^\s+-?[\d.]+\s+-?[\d.]+\s+-?[\d.]+\s+\S+", l)]
check(len(rows) == 9 and all(len(x) == 7 for x in rows) and rows[1][1] == "-0.9",
      "the eval table: 9 points, each with its value and gradient: %s" % rows[:2])
pic = re.search(r"^picture: (\S+)$", out, re.M)
mesh = re.search(r"^mesh: +(\S+)$", out, re.M)
check(pic and mesh and "next:" in out, "the picture, the mesh and next steps named:\n" + out[-900:])
if pic:
    png = os.path.join(SRC, pic.group(1)) if not os.path.isabs(pic.group(1)) else pic.group(1)
    info = subprocess.run(["iinfo", png], capture_output=True, text=True).stdout
    check(re.search(r"320 x +240", info), "the picture is 320 x 240: " + info)
    stats = subprocess.run(["oiiotool", "--stats", png], capture_output=True, text=True).stdout
    dev = re.search(r"StdDev: ([\d.]+) ([\d.]+) ([\d.]+)", stats)
    check(dev and min(float(v) for v in dev.groups()) > 10.0,
          "the picture is not blank (channel deviations): %s" % ((dev.groups() if dev else stats),))
if mesh:
    ply = os.path.join(SRC, mesh.group(1)) if not os.path.isabs(mesh.group(1)) else mesh.group(1)
    check(os.path.exists(ply) and open(ply, "rb").read(3) == b"ply", "the mesh is a PLY file")

# a stage that fails: cmake replaced by one that fails
stub = os.path.join(WORK, "stub")
os.makedirs(stub)
with open(os.path.join(stub, "cmake"), "w") as f:
    f.write("#!/bin/sh\necho 'stub cmake: this configure fails on purpose' >&2\nexit 1\n")
os.chmod(os.path.join(stub, "cmake"), 0o755)
failbuild = os.path.join(WORK, "build")
env2 = dict(env, PATH=stub + os.pathsep + os.environ["PATH"], LIBBLEND_BUILD=failbuild)
r = subprocess.run(["bash", os.path.join(SRC, "scripts", "run-default.sh")], cwd=WORK, env=env2,
                   capture_output=True, text=True, timeout=300)
log = os.path.join(failbuild, "run-default.log")
check(r.returncode == 1 and "FAILED" in r.stdout and log in r.stderr and
      "this configure fails on purpose" in r.stderr,
      "a failing stage: exit 1, FAILED, the log named and its end shown: %d\n%s\n%s" %
      (r.returncode, r.stdout[-400:], r.stderr[-800:]))
check(not os.path.exists(os.path.join(failbuild, "default.png")), "nothing rendered after it")
print("%d failures" % len(failures))
sys.exit(1 if failures else 0)
