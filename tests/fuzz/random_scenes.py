#!/usr/bin/python3
"""Random valid scenes through every command, for a bounded time.

Each generated scene (both conventions, every primitive and operator family,
transforms, shared defs, bulge elimination, nesting up to depth 4) must:
validate (exit 0, or exit 2 with one message naming the file when the
library finds it invalid or over a limit); evaluate at 200 random points to
finite values and gradients; mesh closed, oriented and 2-manifold at two
resolutions (read back with the independent numpy reader); export to
POV-Ray. Every command must also finish within a stated time: no valid scene
may make the cost explode. Run in the sanitizer stage, with the sanitizer
build's blendtool.

usage: random_scenes.py BLENDTOOL SOURCE_DIR WORK_DIR SECONDS
"""
import json
import math
import os
import random
import shutil
import subprocess
import sys
import time

if __name__ == "__main__":
    BT, SRC, WORK, SECONDS = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
    sys.path.insert(0, os.path.join(SRC, "tests", "mesh"))
    import meshcheck  # noqa: E402

PER_COMMAND_TIMEOUT = 60  # seconds; sanitizer builds are ~3x slower
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from checks import fail, failures  # noqa: E402


def vec(r, lo=-1.0, hi=1.0):
    return [round(r.uniform(lo, hi), 3) for _ in range(3)]


def unit(r):
    while True:
        v = vec(r)
        if sum(x * x for x in v) > 0.05:
            return v


def transform(r, node):
    if r.random() < 0.3:
        node["translate"] = vec(r, -0.5, 0.5)
    if r.random() < 0.2:
        node["rotate"] = vec(r, -180, 180)
    if r.random() < 0.2:
        node["scale"] = round(r.uniform(0.5, 1.5), 3) if r.random() < 0.5 else \
            [round(r.uniform(0.5, 1.5), 3) for _ in range(3)]
    return node


def primitive(r, soft):
    kind = r.choice(["sphere", "ellipsoid", "lp", "superquadric", "slab", "cylinder", "capsule",
                     "torus"])
    c = vec(r, -0.8, 0.8)
    if kind == "sphere":
        n = {"type": kind, "center": c, "radius": round(r.uniform(0.2, 0.9), 3)}
    elif kind in ("ellipsoid", "lp", "superquadric"):
        n = {"type": kind, "center": c, "semi_axes": vec(r, 0.2, 0.9)}
        if kind == "lp":
            n["exponent"] = round(r.uniform(1.0, 8.0), 3)
        if kind == "superquadric":
            n["e1"], n["e2"] = round(r.uniform(0.2, 2), 3), round(r.uniform(0.2, 2), 3)
    elif kind == "slab":
        n = {"type": kind, "point": c, "normal": unit(r), "half_width": round(r.uniform(0.1, 0.6), 3)}
    elif kind == "cylinder":
        n = {"type": kind, "point": c, "axis": unit(r), "radius": round(r.uniform(0.1, 0.5), 3)}
    elif kind == "capsule":
        n = {"type": kind, "start": c, "end": vec(r, -0.8, 0.8),
             "radius": round(r.uniform(0.1, 0.5), 3)}
    else:
        n = {"type": kind, "center": c, "axis": unit(r), "major_radius": round(r.uniform(0.4, 0.9), 3),
             "minor_radius": round(r.uniform(0.1, 0.3), 3)}
    if soft:
        n["kernel"] = r.choice(["wyvill", "blinn"])
    return transform(r, n)


def per_arg(r, k, lo, hi):
    return round(r.uniform(lo, hi), 3) if r.random() < 0.5 else \
        [round(r.uniform(lo, hi), 3) for _ in range(k)]


def operator(r, soft, depth, defs):
    if depth <= 0 or r.random() < 0.25:
        if defs and r.random() < 0.3:
            return transform(r, {"ref": r.choice(list(defs))})
        return primitive(r, soft)
    k = r.choice([1, 2, 2, 2, 3, 4])
    kind = r.choice(["soft_hyper", "soft_conic", "soft_sum", "ricci", "perlin", "min", "max",
                     "complement", "local_union", "clean_union"] if soft else
                    ["displacement", "displacement", "conic", "scale", "rfunction", "min", "max",
                     "complement", "local_union", "clean_union"])
    if kind in ("local_union", "clean_union") and k < 2:
        k = 2
    if kind in ("conic", "soft_conic", "rfunction"):
        k = 2
    if kind == "complement":
        k = 1
    n = {"type": kind, "args": [operator(r, soft, depth - 1, defs) for _ in range(k)]}
    if kind == "displacement":
        n.update(op=r.choice(["union", "intersection", "difference"]), r=per_arg(r, k, 0.05, 0.6),
                 p=2 if r.random() < 0.5 else per_arg(r, k, 1.2, 8), m=per_arg(r, k, 0.3, 2))
        if k == 2 and r.random() < 0.25:
            n["bulge"] = {"range": True, "slope": r.random() < 0.3}
    elif kind == "conic":
        n.update(op=r.choice(["union", "intersection", "difference"]), r=per_arg(r, 2, 0.05, 0.6),
                 m=per_arg(r, 2, 0.3, 2))
        if r.random() < 0.2:
            n["bulge"] = {"range": True}
    elif kind == "scale":
        n.update(op=r.choice(["union", "intersection", "difference"]), r=per_arg(r, k, 0.05, 0.9),
                 p=per_arg(r, k, 1.5, 6))
    elif kind == "rfunction":
        n["op"] = r.choice(["union", "intersection"])
    elif kind == "soft_hyper":
        n.update(op=r.choice(["union", "intersection", "difference"]), r=per_arg(r, k, 0.05, 0.9),
                 p=per_arg(r, k, 1.5, 6), m=per_arg(r, k, 0.3, 1.5))
    elif kind == "soft_conic":
        n.update(op=r.choice(["union", "intersection", "difference"]), r=per_arg(r, 2, 0.05, 0.9),
                 m=per_arg(r, 2, 0.3, 1.5))
    elif kind == "local_union":
        if r.random() < 0.3:
            n["support"] = "feature"
        if r.random() < 0.3:
            n["exponent"] = round(r.uniform(1, 4), 3)
        if r.random() < 0.2:
            n["alpha"] = [round(r.uniform(0, 0.5), 3), round(r.uniform(0, 0.5), 3)]
    elif kind == "ricci":
        n["n"] = round(r.uniform(1, 8), 3)
    elif kind == "perlin":
        n["op"] = r.choice(["union", "intersection", "difference"])
    return transform(r, n)


def scene(seed):
    r = random.Random(seed)
    soft = r.random() < 0.35
    defs = {}
    for i in range(r.choice([0, 0, 1, 2])):
        defs[f"d{i}"] = operator(r, soft, r.randint(0, 2), dict(defs))
    s = {"format": "libblend-scene", "version": 1, "convention": "soft" if soft else "zero",
         "bounds": {"min": [-2, -2, -2], "max": [2, 2, 2]},
         "root": operator(r, soft, r.randint(1, 4), defs)}
    if defs:
        s["defs"] = defs
    return s, r


def bt(*args, stdin=None):
    t = time.monotonic()
    try:
        p = subprocess.run([BT, *args], input=stdin, capture_output=True,
                           timeout=PER_COMMAND_TIMEOUT)
    except subprocess.TimeoutExpired:
        return None, b"", b"timeout", PER_COMMAND_TIMEOUT
    return p.returncode, p.stdout, p.stderr, time.monotonic() - t


def check(seed):
    sc, r = scene(seed)
    path = os.path.join(WORK, f"s{seed}.json")
    with open(path, "w") as f:
        json.dump(sc, f)
    rc, out, err, _ = bt("validate", path)
    if rc is None:
        return fail(f"seed {seed}: validate took over {PER_COMMAND_TIMEOUT} s")
    if rc == 2:
        lines = err.decode().strip().splitlines()
        if len(lines) != 1 or path not in lines[0]:
            fail(f"seed {seed}: a refusal must be one line naming the file: {err!r}")
        return "refused"
    if rc != 0:
        return fail(f"seed {seed}: validate exit {rc}: {err!r}")
    pts = "".join(f"{r.uniform(-2, 2)} {r.uniform(-2, 2)} {r.uniform(-2, 2)}\n" for _ in range(200))
    rc, out, err, _ = bt("eval", path, stdin=pts.encode())
    if rc != 0:
        return fail(f"seed {seed}: eval exit {rc}: {err[-400:]!r}")
    vals = [[float(x) for x in line.split()] for line in out.decode().splitlines()]
    if len(vals) != 200 or not all(math.isfinite(x) for v in vals for x in v):
        return fail(f"seed {seed}: eval gave {len(vals)} rows or non-finite values")
    for res in (12, 20):
        mesh = os.path.join(WORK, f"m{seed}.ply")
        rc, out, err, _ = bt("mesh", path, "-o", mesh, "--resolution", str(res), "--quiet",
                             "--threads", "2")
        if rc != 0:
            return fail(f"seed {seed}: mesh at {res} exit {rc}: {err[-400:]!r}")
        V, N, F = meshcheck.read(mesh)
        if len(F):
            c = meshcheck.check(V, F)
            if not (c["closed"] and c["oriented"] and c["manifold"]):
                fail(f"seed {seed}: mesh at {res} not closed/oriented/manifold: {c}")
        os.remove(mesh)
    pov = os.path.join(WORK, f"p{seed}.pov")
    rc, out, err, _ = bt("pov", path, "-o", pov)
    if rc not in (0, 2) or (rc == 2 and b"POV-Ray" not in err and b"allowed" not in err):
        fail(f"seed {seed}: pov exit {rc}: {err[-300:]!r}")
    if os.path.exists(pov):
        os.remove(pov)
    os.remove(path)
    return "ok"


def main():
    shutil.rmtree(WORK, ignore_errors=True)
    os.makedirs(WORK)
    t0 = time.monotonic()
    seed, ok, refused = 0, 0, 0
    while time.monotonic() - t0 < SECONDS:
        res = check(seed)
        ok += res == "ok"
        refused += res == "refused"
        seed += 1
    print(f"{seed} random scenes in {time.monotonic() - t0:.0f} s: {ok} through validate, eval, "
          f"mesh (2 resolutions) and pov; {refused} refused by a limit; {len(failures)} failures")
    if ok < 20:
        fail(f"only {ok} scenes fully checked (want >= 20)")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
