"""Sharp features' cost and triangle counts (docs/meshing.md, Sharp features):

    /usr/bin/python3 bench/mesh/run_features_bench.py BENCH_MESH SOURCE_DIR [ROUNDS [BASE_BENCH_MESH]]

For S1 and S2 at 128 and 256 cells on one thread, lb_mesh_create's time with
LB_MESH_FEATURES (and with LB_MESH_CORNER_NORMALS too) against without, the
runs alternating ROUNDS times (3)
in this process's run so that the machine's load hits both alike; the ratio
of the medians of the best-of-3 times (bench_mesh). With BASE_BENCH_MESH (the
mesher before features, built by bench/run_features_bench.sh) also that
mesher's time in the same rounds, and the time with features against it. Then
the same in one process (bench_alternate, beside BENCH_MESH: the libraries
loaded side by side and alternated 10 x ROUNDS times at 128 cells, 3 x
ROUNDS at 256; lower quartiles), where the drift between processes started
seconds apart does not enter. Then the same meshings' instructions (valgrind's callgrind, counted inside
lb_mesh_create alone): the same every run, where this shared machine's
times move by a tenth and more between runs. Then the sharp shapes of
tests/data/features at 64 cells: triangles with and without (the errors are
the test's). Run by bench/run_features_bench.sh; not a test."""
import json
import os
import re
import statistics
import subprocess
import sys

BENCH, SRC = sys.argv[1], sys.argv[2]
ROUNDS = int(sys.argv[3]) if len(sys.argv) > 3 else 3
BASE = sys.argv[4] if len(sys.argv) > 4 else None


def run(scene, res, features):
    """features: False, True, "corners" (with corner normals) or "base" (BASE, without)"""
    args = [BASE if features == "base" else BENCH, scene, str(res), "1"] + (
        ["--corner-normals"] if features == "corners" else
        ["--features"] if features is True else [])
    return json.loads(subprocess.run(args, check=True, capture_output=True,
                                     text=True).stdout.strip().splitlines()[-1])


KINDS = (False, True, "corners") + (("base",) if BASE else ())


def cases():
    """(name, scene path, cells) of every row: S1 and S2 at 128 and 256 cells"""
    for name, f in (("S1", "bench-s1-three-spheres.json"), ("S2", "bench-s2-64-spheres.json")):
        for res in (128, 256):
            yield name, os.path.join(SRC, "scenes", f), res


print("| scene | cells | without (s) | with (s) | with / without | with corner normals (s) "
      "| corners / without | triangles without / with |" +
      (" before features (s) | with / before |" if BASE else ""))
print("|---|---|---|---|---|---|---|---|" + ("---|---|" if BASE else ""))
for name, scene, res in cases():
    t = {k: [] for k in KINDS}
    tri = {}
    for _ in range(ROUNDS):
        for feat in KINDS:
            r = run(scene, res, feat)
            t[feat].append(r["seconds"])
            tri[feat] = r["triangles"]
    a, b, c = (statistics.median(t[k]) for k in (False, True, "corners"))
    extra = ""
    if BASE:
        z = statistics.median(t["base"])
        extra = " %.4f | %.3f |" % (z, b / z)
    print("| %s | %d | %.4f | %.4f | %.3f | %.4f | %.3f | %d / %d |%s" %
          (name, res, a, b, b / a, c, c / a, tri[False], tri[True], extra))

# the same in one process: bench_alternate beside bench_mesh, the library beside it
LIB = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(BENCH))), "libblend",
                   "libblend.so")
ALT = os.path.join(os.path.dirname(os.path.abspath(BENCH)), "bench_alternate")
print()
print("| scene | cells | rounds in one process | with / without | with corner normals / without |" +
      (" before features / without | with / before |" if BASE else ""))
print("|---|---|---|---|---|" + ("---|---|" if BASE else ""))
for name, scene, res in cases():
    n = (10 if res == 128 else 3) * ROUNDS
    confs = [LIB + "@0", LIB + "@4", LIB + "@12"]
    if BASE:
        confs.append(os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(BASE))),
                                  "libblend", "libblend.so") + "@0")
    out = subprocess.run([ALT, scene, str(res), str(n)] + confs, check=True,
                         capture_output=True, text=True).stdout
    q = [json.loads(line)["ratio_q25"] for line in out.strip().splitlines()]
    extra = " %.3f | %.3f |" % (q[3], q[1] / q[3]) if BASE else ""
    print("| %s | %d | %d | %.3f | %.3f |%s" % (name, res, n, q[1], q[2], extra))


def instructions(scene, res, features):
    """instructions per lb_mesh_create (bench_mesh makes 3)"""
    args = [BASE if features == "base" else BENCH, scene, str(res), "1"] + (
        ["--features"] if features is True else [])
    r = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null",
                        "--toggle-collect=lb_mesh_create"] + args,
                       check=True, capture_output=True, text=True)
    return int(re.search(r"Collected : (\d+)", r.stderr).group(1)) / 3


print()
print("| scene | cells | instructions without | with | with / without |" +
      (" before features | with / before |" if BASE else ""))
print("|---|---|---|---|---|" + ("---|---|" if BASE else ""))
for name, scene, res in cases():
    a, b = instructions(scene, res, False), instructions(scene, res, True)
    extra = ""
    if BASE:
        z = instructions(scene, res, "base")
        extra = " %.1f M | %.3f |" % (z / 1e6, b / z)
    print("| %s | %d | %.1f M | %.1f M | %.3f |%s" % (name, res, a / 1e6, b / 1e6, b / a, extra))
print()
print("| shape | cells | triangles without | triangles with |")
print("|---|---|---|---|")
for shape in ("cube", "rotated-cube", "two-boxes", "cylinder-slab", "clean-union-spheres"):
    scene = os.path.join(SRC, "tests", "data", "features", shape + ".json")
    print("| %s | 64 | %d | %d |" % (shape, run(scene, 64, False)["triangles"],
                                     run(scene, 64, True)["triangles"]))
