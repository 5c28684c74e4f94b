#!/usr/bin/python3
"""The meshing benchmark of docs/meshing.md: libblend (1 and 2 threads)
against (a) numpy + scikit-image marching cubes and (b) Blender's metaball
polygonizer (at its default stiffness 2, and at 10, whose S2 surface
matches the lattice), on S1 and S2 over [-2, 3]^3 at 128 and 256 cells, all
in one run; "vs Blender" is against stiffness 2. Every tool runs in its own process (peak memory is its own); times are
the meshing call only, best of 3 inside each process.

usage: run_mesh_bench.py BENCH_MESH_BINARY SOURCE_DIR
"""
import json
import os
import subprocess
import sys

bench_mesh, src = sys.argv[1], sys.argv[2]
here = os.path.dirname(os.path.abspath(__file__))
scenes = {"S1": "bench-s1-three-spheres.json", "S2": "bench-s2-64-spheres.json"}
region = ["-2", "-2", "-2", "3", "3", "3"]


def last_json(out, prefix=""):
    for line in reversed(out.splitlines()):
        if line.startswith(prefix + "{"):
            return json.loads(line[len(prefix):])
    raise RuntimeError("no result in output:\n" + out[-2000:])


rows = []
for name in ("S1", "S2"):
    for res in (128, 256):
        r = {}
        for t in (1, 2):
            out = subprocess.run([bench_mesh, os.path.join(src, "scenes", scenes[name]), str(res),
                                  str(t), *region], capture_output=True, text=True, check=True).stdout
            r["libblend%d" % t] = last_json(out)
        out = subprocess.run(["/usr/bin/python3", os.path.join(here, "skimage_baseline.py"), name,
                              str(res)], capture_output=True, text=True, check=True).stdout
        r["numpy"] = last_json(out)
        for key, stiff in (("blender", "2"), ("blender10", "10")):
            out = subprocess.run(["blender", "-b", "--factory-startup", "--python",
                                  os.path.join(here, "blender_metaballs.py"), "--", name, str(res),
                                  stiff], capture_output=True, text=True, check=True).stdout
            r[key] = last_json(out, "BENCH ")
        rows.append((name, res, r))

print("| scene | cells | tool | seconds | vs Blender | vs numpy | triangles | peak RSS MiB | RSS growth MiB |")
print("|---|---|---|---|---|---|---|---|---|")
for name, res, r in rows:
    for key, label in (("libblend1", "libblend, 1 thread"), ("libblend2", "libblend, 2 threads"),
                       ("blender", "Blender metaballs"),
                       ("blender10", "Blender metaballs, stiffness 10"),
                       ("numpy", "numpy + skimage")):
        x = r[key]
        print("| %s | %d | %s | %.3f | %.2f | %.3f | %d | %.0f | %.0f |" % (
            name, res, label, x["seconds"], x["seconds"] / r["blender"]["seconds"],
            x["seconds"] / r["numpy"]["seconds"], x["triangles"], x["peak_rss_kb"] / 1024.0,
            (x["peak_rss_kb"] - x["rss_before_kb"]) / 1024.0))
