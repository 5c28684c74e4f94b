"""Adaptive simplification's triangles and cost (docs/meshing.md, Adaptive
simplification):

    /usr/bin/python3 bench/mesh/run_simplify_bench.py BENCH_MESH SOURCE_DIR [ROUNDS]

For the sharp shapes of tests/data/features (with LB_MESH_FEATURES), the
stool of the bounded-blending paper (with features) and S1 / S2 (without),
lb_mesh_create on one thread with simplify = 0.1 cells against without, the
runs alternating ROUNDS times (3) in this process's run so that the
machine's load hits both alike; the ratio of the medians of the best-of-3
times (bench_mesh), and the triangle counts. libfive's counts are issue 33's
(its mesher built from its own source, at errors of 0 to 6e-6 cells); the
simplified meshes' errors are measured by tests/mesh/test_mesh_simplify.py
against closed forms (the boxes: 2.5e-6 cells at 128). Then, for the
shapes where the collapses do the work (curved ones), the same runs on one
thread and on every CPU (the simplification's parallel passes; the meshing
is parallel too, so the simplification's own time is the difference),
alternating likewise. Run by bench/run_simplify_bench.sh; not a test."""
import json
import os
import statistics
import subprocess
import sys

BENCH, SRC = sys.argv[1], sys.argv[2]
ROUNDS = int(sys.argv[3]) if len(sys.argv) > 3 else 3
LIBFIVE = {("cube", 64): 12, ("cube", 256): 12, ("rotated-cube", 128): 47588,
           ("two-boxes", 128): 15540}


def run(scene, res, features, simplify, threads=1):
    args = [BENCH, scene, str(res), str(threads)] + (["--features"] if features else []) + \
        (["--simplify", str(simplify)] if simplify else [])
    return json.loads(subprocess.run(args, check=True, capture_output=True,
                                     text=True).stdout.strip().splitlines()[-1])


rows = []
for shape in ("cube", "rotated-cube", "two-boxes", "cylinder-slab", "clean-union-spheres"):
    for res in (64, 128, 256):
        rows.append((shape, os.path.join(SRC, "tests", "data", "features", shape + ".json"), res,
                     True))
rows.append(("stool (hsu-bounded Fig. 7)",
             os.path.join(SRC, "scenes", "hsu-bounded-fig7-stool.json"), 128, True))
for name, f in (("S1", "bench-s1-three-spheres.json"), ("S2", "bench-s2-64-spheres.json")):
    for res in (128, 256):
        rows.append((name, os.path.join(SRC, "scenes", f), res, False))

print("| scene | cells | features | triangles | simplified (0.1 cells) | libfive | time (s) | "
      "simplified (s) | ratio |")
print("|---|---|---|---|---|---|---|---|---|")
for name, scene, res, feat in rows:
    t = {0: [], 0.1: []}
    tri = {}
    for _ in range(ROUNDS):
        for simp in (0, 0.1):
            r = run(scene, res, feat, simp)
            t[simp].append(r["seconds"])
            tri[simp] = r["triangles"]
    a, b = statistics.median(t[0]), statistics.median(t[0.1])
    five = LIBFIVE.get((name, res))
    print("| %s | %d | %s | %d | %d | %s | %.4f | %.4f | %.1f |" %
          (name, res, "on" if feat else "off", tri[0], tri[0.1],
           "{:,}".format(five) if five else "", a, b, b / a))

NT = os.cpu_count() or 1
print("\n| scene | cells | one thread: meshing / simplified (s) | %d threads: meshing / "
      "simplified (s) | the simplification alone, 1 / %d threads (s) | speed-up |" % (NT, NT))
print("|---|---|---|---|---|---|")
for name, scene, res, feat in rows:
    if name in ("cube", "rotated-cube", "two-boxes"):
        continue  # flat: merged before any collapse
    t = {k: [] for k in ((1, 0), (1, 0.1), (NT, 0), (NT, 0.1))}
    for _ in range(ROUNDS):
        for th, simp in t:
            t[(th, simp)].append(run(scene, res, feat, simp, th)["seconds"])
    m = {k: statistics.median(v) for k, v in t.items()}
    one, many = m[(1, 0.1)] - m[(1, 0)], m[(NT, 0.1)] - m[(NT, 0)]
    print("| %s | %d | %.3f / %.3f | %.3f / %.3f | %.3f / %.3f | %.2fx |" %
          (name, res, m[(1, 0)], m[(1, 0.1)], m[(NT, 0)], m[(NT, 0.1)], one, many, one / many))
