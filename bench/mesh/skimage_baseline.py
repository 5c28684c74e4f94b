"""Anchor (a): a dense grid in numpy, a polynomial smooth-min of the spheres'
distances, scikit-image's marching_cubes. Prints one JSON line.

usage: skimage_baseline.py S1|S2 RESOLUTION   (region [-2, 3]^3)
"""
import json
import resource
import sys
import time

import numpy as np
from skimage import measure


def spheres(name):
    if name == "S1":
        return [((0, 0, 0), 1.0), ((1.2, 0, 0), 1.0), ((0, 1.2, 0), 1.0)], 0.25
    c = [(-0.25 + 0.5 * i, -0.25 + 0.5 * j, -0.25 + 0.5 * k)
         for k in range(4) for j in range(4) for i in range(4)]
    return [(p, 0.3) for p in c], 0.1


def smin(a, b, k):
    """Inigo Quilez's polynomial smooth minimum."""
    h = np.clip(0.5 + 0.5 * (b - a) / k, 0.0, 1.0)
    return b + (a - b) * h - k * h * (1.0 - h)


def main():
    name, res = sys.argv[1], int(sys.argv[2])
    balls, k = spheres(name)
    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    t0 = time.perf_counter()
    n = res + 1
    ax = np.linspace(-2.0, 3.0, n)
    X, Y, Z = np.meshgrid(ax, ax, ax, indexing="ij")
    f = None
    for (c, r) in balls:
        d = np.sqrt((X - c[0]) ** 2 + (Y - c[1]) ** 2 + (Z - c[2]) ** 2) - r
        f = d if f is None else smin(f, d, k)
    h = 5.0 / res
    verts, faces, normals, _ = measure.marching_cubes(f, 0.0, spacing=(h, h, h))
    t = time.perf_counter() - t0
    print(json.dumps({"tool": "numpy+skimage", "resolution": res, "seconds": t,
                      "triangles": len(faces), "vertices": len(verts),
                      "peak_rss_kb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss,
                      "rss_before_kb": rss0}))


main()
