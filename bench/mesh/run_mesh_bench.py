#!/usr/bin/python3
"""The meshing benchmark of docs/meshing.md: libblend (1 and 2 threads)
against (a) numpy + scikit-image marching cubes and (b) Blender's metaball
polygonizer (at its default stiffness 2, and at 10, whose S2 surface
matches the lattice), on S1 and S2 over [-2, 3]^3 at 128 and 256 cells, all
in one run; "vs Blender" is against stiffness 2. Every tool runs in its own process (peak memory is its own); times are
the meshing call only, best of 3 inside each process. libblend and Blender
run PASSES times each, taking turns (libblend, Blender, libblend, ...), and
the table keeps each one's fastest process: on a shared machine a burst of
load then slows a pass of one tool, not the comparison. The ratio of every
pass is printed too (numpy, the slow anchor, runs once).

Then the scale in primitives: cost per triangle (one thread) of 4096
spheres (16x16x16 lattice, spacing 0.5, radius 0.3, range 0.1, cell 5/128)
as one flat BT_4096 union and as 16 nested BT_256 unions, against S2 (64
spheres) at the same cell size, in the same run.

usage: run_mesh_bench.py BENCH_MESH_BINARY SOURCE_DIR
"""
import json
import os
import subprocess
import sys
import tempfile

bench_mesh, src = sys.argv[1], sys.argv[2]
here = os.path.dirname(os.path.abspath(__file__))
scenes = {"S1": "bench-s1-three-spheres.json", "S2": "bench-s2-64-spheres.json"}
region = ["-2", "-2", "-2", "3", "3", "3"]


def last_json(out, prefix=""):
    for line in reversed(out.splitlines()):
        if line.startswith(prefix + "{"):
            return json.loads(line[len(prefix):])
    raise RuntimeError("no result in output:\n" + out[-2000:])


PASSES = 3


def faster(r, key, x):
    """Keep the fastest process of a tool, and every pass's time."""
    r.setdefault(key + "_passes", []).append(x["seconds"])
    if key not in r or x["seconds"] < r[key]["seconds"]:
        r[key] = x


rows = []
for name in ("S1", "S2"):
    for res in (128, 256):
        r = {}
        for _ in range(PASSES):
            for t in (1, 2):
                out = subprocess.run([bench_mesh, os.path.join(src, "scenes", scenes[name]),
                                      str(res), str(t), *region], capture_output=True, text=True,
                                     check=True).stdout
                faster(r, "libblend%d" % t, last_json(out))
            for key, stiff in (("blender", "2"), ("blender10", "10")):
                out = subprocess.run(["blender", "-b", "--factory-startup", "--python",
                                      os.path.join(here, "blender_metaballs.py"), "--", name,
                                      str(res), stiff], capture_output=True, text=True,
                                     check=True).stdout
                faster(r, key, last_json(out, "BENCH "))
        out = subprocess.run(["/usr/bin/python3", os.path.join(here, "skimage_baseline.py"), name,
                              str(res)], capture_output=True, text=True, check=True).stdout
        r["numpy"] = last_json(out)
        rows.append((name, res, r))

def lattice(nested):
    """4096 spheres at -0.25 + 0.5 i (i = 0..15 per axis): the S2 lattice, extended."""
    def sphere(i):
        return {"type": "sphere", "radius": 0.3,
                "center": [-0.25 + 0.5 * (i % 16), -0.25 + 0.5 * (i // 16 % 16), -0.25 + 0.5 * (i // 256)]}

    def union(args):
        return {"type": "displacement", "op": "union", "r": 0.1, "p": 2, "args": args}
    if nested:
        root = union([union([sphere(256 * g + i) for i in range(256)]) for g in range(16)])
    else:
        root = union([sphere(i) for i in range(4096)])
    return {"format": "libblend-scene", "version": 1, "convention": "zero", "root": root}


# 218 cells of 5/128 from -0.75 (the lattice's spheres reach -0.55 and 7.55)
wide_region = ["-0.75"] * 3 + ["%.17g" % (-0.75 + 218 * 5 / 128)] * 3
wide = {}
with tempfile.TemporaryDirectory() as tmp:
    for key, nested in (("flat", False), ("nested", True)):
        path = os.path.join(tmp, key + ".json")
        with open(path, "w") as f:
            json.dump(lattice(nested), f)
        out = subprocess.run([bench_mesh, path, "218", "1", *wide_region], capture_output=True,
                             text=True, check=True).stdout
        wide[key] = last_json(out)
out = subprocess.run([bench_mesh, os.path.join(src, "scenes", scenes["S2"]), "128", "1", *region],
                     capture_output=True, text=True, check=True).stdout
wide["s2"] = last_json(out)

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

print()
print("| scene | cells | Blender stiffness | libblend (1 thread) / Blender, pass by pass |")
print("|---|---|---|---|")
for name, res, r in rows:
    for key, stiff in (("blender", 2), ("blender10", 10)):
        print("| %s | %d | %d | %s |" % (name, res, stiff, ", ".join(
            "%.2f" % (a / b) for a, b in zip(r["libblend1_passes"], r[key + "_passes"]))))

print()
print("| primitives (cell 5/128, 1 thread) | seconds | triangles | ns per triangle | vs 64 spheres |")
print("|---|---|---|---|---|")
base = wide["s2"]["seconds"] / wide["s2"]["triangles"]
for key, label in (("s2", "64 spheres (S2), one BT_64"), ("flat", "4096 spheres, one BT_4096"),
                   ("nested", "4096 spheres, 16 nested BT_256")):
    x = wide[key]
    per = x["seconds"] / x["triangles"]
    print("| %s | %.3f | %d | %.0f | %.2f |" % (label, x["seconds"], x["triangles"], per * 1e9,
                                               per / base))
