#!/usr/bin/python3
"""The local unions of the compile-cost table (docs/scene-format.md, "Compile
cost of local unions"), written as scene files into a folder:
  spread-K   flat local_union of K spheres on a ring, each meeting its two
             neighbours (zero convention)
  lattice-K  flat local_union of K spheres in a 12-wide lattice, rows 0.9
             apart, radius 0.5, zero_scale 0.2
  crowded-K  flat local_union of K spheres on a ring of radius 1.5 (every
             one within zero_scale 1 of every other)
  nested-L   L levels of local_union(previous, local_union of two spheres),
             every level's blending volume over the same place
usage: scenes.py FOLDER"""
import json
import math
import os
import sys


def scene(bmin, bmax, root):
    return {"format": "libblend-scene", "version": 1, "convention": "zero",
            "bounds": {"min": bmin, "max": bmax}, "root": root}


def ring(k, spread):
    rad = k * 0.7 / (2 * math.pi) if spread else 1.5
    args = [{"type": "sphere", "radius": 0.5,
             "center": [rad * math.cos(2 * math.pi * i / k), rad * math.sin(2 * math.pi * i / k),
                        0.2 * math.sin(7 * i)]} for i in range(k)]
    root = {"type": "local_union", "args": args}
    if not spread:
        root["zero_scale"] = 1
    return scene([-rad - 1.5, -rad - 1.5, -1.5], [rad + 1.5, rad + 1.5, 1.5], root)


def lattice(k, w=12, sp=0.9):
    args = [{"type": "sphere", "radius": 0.5,
             "center": [(i % w) * sp, (i // w) * sp, 0.05 * ((i * 7) % 5)]} for i in range(k)]
    rows = (k + w - 1) // w
    return scene([-1, -1, -1], [(w - 1) * sp + 1, (rows - 1) * sp + 1, 1.2],
                 {"type": "local_union", "zero_scale": 0.2, "args": args})


def nested(levels):
    node = {"type": "sphere", "center": [0, 0, 0], "radius": 0.6}
    for i in range(levels):
        x, y = 0.3 * ((i % 5) - 2), 0.3 * (((i * 3) % 5) - 2)
        pair = {"type": "local_union", "args": [
            {"type": "sphere", "center": [x, y, 0.4], "radius": 0.35},
            {"type": "sphere", "center": [x + 0.3, y, 0.5], "radius": 0.3}]}
        node = {"type": "local_union", "args": [node, pair]}
    return scene([-2, -2, -1.5], [2, 2, 1.5], node)


CASES = ([("spread-%d" % k, ring(k, True)) for k in (32, 64, 128, 256)] +
         [("lattice-%d" % k, lattice(k)) for k in (24, 48, 96, 192, 252)] +
         [("crowded-%d" % k, ring(k, False)) for k in (32, 64, 128)] +
         [("nested-%d" % n, nested(n)) for n in (10, 20, 40, 60)])

if __name__ == "__main__":
    os.makedirs(sys.argv[1], exist_ok=True)
    for name, sc in CASES:
        with open(os.path.join(sys.argv[1], name + ".json"), "w") as f:
            json.dump(sc, f)
        print(name)
