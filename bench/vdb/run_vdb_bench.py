#!/usr/bin/python3
"""blendtool vdb against blendtool mesh on S2 (64 blended spheres) at the
same cell size, one thread, interleaved runs (the best of N each): voxels
written per second (active voxels, and all voxels evaluated), the ratio of
the level set's time to the mesh's, and the file sizes (.vdb against the
mesh's .ply). Times are blendtool's own (the work, not the process start);
the wall-clock of whole runs is printed beside them.

usage: run_vdb_bench.py BLENDTOOL SOURCE_DIR WORK_DIR [RUNS]
"""
import os
import re
import subprocess
import sys
import time

bt, src, work = sys.argv[1:4]
runs = int(sys.argv[4]) if len(sys.argv) > 4 else 5
os.makedirs(work, exist_ok=True)
scene = os.path.join(src, "scenes", "bench-s2-64-spheres.json")


def run(args):
    t0 = time.perf_counter()
    r = subprocess.run([bt, *args], capture_output=True, text=True, check=True)
    wall = time.perf_counter() - t0
    return r.stdout, float(re.search(r"([0-9.]+) s\s*$", r.stdout).group(1)), wall


print("S2 (%s), one thread, best of %d interleaved runs" % (os.path.basename(scene), runs))
print("| resolution | active voxels | leaves | vdb s | mesh s | vdb / mesh | active voxels/s "
      "| voxels evaluated/s | .vdb bytes | .ply bytes | wall vdb / mesh |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for res in (256, 512):
    vout, mout = os.path.join(work, "s2.vdb"), os.path.join(work, "s2.ply")
    best = {"vdb": (1e9, 1e9), "mesh": (1e9, 1e9)}
    text = ""
    for _ in range(runs):
        text, t, w = run(["vdb", scene, "-o", vout, "--resolution", str(res), "--threads", "1"])
        best["vdb"] = (min(best["vdb"][0], t), min(best["vdb"][1], w))
        _, t, w = run(["mesh", scene, "-o", mout, "--resolution", str(res), "--threads", "1"])
        best["mesh"] = (min(best["mesh"][0], t), min(best["mesh"][1], w))
    m = re.search(r"(\d+) active voxels in (\d+) leaves", text)
    active, leaves = int(m.group(1)), int(m.group(2))
    # every voxel of a kept leaf inside the region was evaluated; the
    # leaves selected and then dropped for having no active voxel are not
    # counted here (their cost is in the time)
    tv, tm = best["vdb"][0], best["mesh"][0]
    print("| %d | %d | %d | %.3f | %.3f | %.2f | %.2e | %.2e | %d | %d | %.2f |" %
          (res, active, leaves, tv, tm, tv / tm, active / tv, leaves * 512 / tv,
           os.path.getsize(vout), os.path.getsize(mout), best["vdb"][1] / best["mesh"][1]))
