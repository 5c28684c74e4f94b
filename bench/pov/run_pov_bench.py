#!/usr/bin/python3
"""POV-Ray render cost of libblend's functions (docs: povray_include/README.md).

For hsu2006 Fig. 7 (m2 = 0.6) and S1 (three spheres), 640 x 480: the scene as
blendtool pov writes it (root-solved k-ary blends), the same primitives with a
plain min()/max() (no blend), and with a hand-written polynomial smooth-min;
for S1 also POV-Ray's native `blob` of three sphere components whose blend
reaches as far as libblend's (range 0.25: each component's radius 1.25,
strength 1, threshold (1 - 0.8^2)^2 = 0.1296, so that a lone component's
surface is the unit sphere), in place of the isosurface.
Times are povray's user CPU seconds (robust on a shared machine); the ratio is
against the plain min() render of the same scene, in the same run. Also the
max_gradient libblend computed against the largest gradient POV-Ray reports.

usage: run_pov_bench.py BLENDTOOL SOURCE_DIR WORK_DIR [SCENE...]
(SCENE: a file name of VARIANTS' keys; default all)
"""
import os
import re
import resource
import subprocess
import sys
import time

bt, src, work = sys.argv[1:4]
only = sys.argv[4:]
os.makedirs(work, exist_ok=True)
inc = os.path.join(src, "povray_include")

# per scene: the expressions replacing the blend, over the primitives' ids
# (in the order blendtool pov declares them)
VARIANTS = {
    "hsu2006-fig7-m0.6.json": {
        "plain min": "min(max(P0(x,y,z), P1(x,y,z), P2(x,y,z)), P3(x,y,z))",
        "smooth-min": "LBsmin(-LBsmin(-P0(x,y,z), -LBsmin(-P1(x,y,z), -P2(x,y,z), 0.3), 0.3), "
                      "P3(x,y,z), 0.45)",
    },
    "bench-s1-three-spheres.json": {
        "plain min": "min(P0(x,y,z), P1(x,y,z), P2(x,y,z))",
        "smooth-min": "LBsmin(LBsmin(P0(x,y,z), P1(x,y,z), 0.25), P2(x,y,z), 0.25)",
    },
}
BLOB_RADIUS, BLOB_THRESHOLD = 1.25, (1 - 0.8 ** 2) ** 2


def blob_variant(text):
    """the exported scene with its isosurface replaced by a native blob of
    the unit spheres' centres (S1's primitives are unit ellipsoids)"""
    centres = re.findall(r"LB_Ellipsoid\(<([^>]*)>, <1, 1, 1>\)", text)
    tex = re.search(r"  (texture \{.*\})\n\}\n$", text).group(1)
    comps = "".join("  sphere { <%s>, %g, 1 }\n" % (c, BLOB_RADIUS) for c in centres)
    blob = "blob {\n  threshold %.6g\n%s  %s\n}\n" % (BLOB_THRESHOLD, comps, tex)
    return text[:text.index("isosurface {")] + blob


SMIN = ("#declare LBsmin = function(a, b, k) { min(a, b) - pow(max(k - abs(a - b), 0), 2) / "
        "(4 * k) }\n")


def render(pov):
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
    r = subprocess.run(["povray", "+I" + pov, "+O" + pov[:-4] + ".png", "+L" + inc, "+W640",
                        "+H480", "-D", "+FN", "-V", "+WT1"], capture_output=True, text=True)
    cpu = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - before
    if r.returncode != 0:
        raise SystemExit("povray failed on %s:\n%s" % (pov, r.stderr[-2000:]))
    text = " ".join(r.stderr.split())
    m = re.search(r"maximum gradient found was ([0-9.]+)", text)
    return cpu, (float(m.group(1)) if m else None)


print("| scene | field | povray CPU s | vs plain min | max_gradient set | found by POV-Ray |")
print("|---|---|---|---|---|---|")
for scene, variants in VARIANTS.items():
    if only and scene not in only:
        continue
    base = os.path.join(work, scene.replace(".json", ".pov"))
    subprocess.run([bt, "pov", os.path.join(src, "scenes", scene), "-o", base], check=True)
    text = open(base).read()
    set_grad = float(re.search(r"max_gradient ([0-9.e+-]+)", text).group(1))
    prims = re.findall(r"#declare (LB[rn]\d+) = LB_(?:Sphere|Ellipsoid|Slab|Superquadric|LP|"
                       r"Cylinder|Capsule|Torus|Halfspace)\(", text)
    results = [("libblend blend (blendtool pov)", render(base))]
    for name, expr in variants.items():
        for i, p in enumerate(prims):
            expr = expr.replace("P%d(" % i, p + "(")
        # the same file, the field replaced; max_gradient: the blend's (an upper bound here)
        t = text.replace("#declare LB_Field = ", SMIN + "#declare LB_Field = function(x, y, z) { "
                         + expr + " }\n#declare LB_Unused = ")
        path = base[:-4] + "-" + name.replace(" ", "-") + ".pov"
        open(path, "w").write(t)
        results.append((name, render(path)))
    # libblend's mesh (blendtool pov --mesh 256): a mesh2 in place of the
    # isosurface (and its 9 x 9 area light without jitter); the export's own
    # wall time (meshing and writing) given beside the name
    path = base[:-4] + "-mesh256.pov"
    t0 = time.monotonic()
    subprocess.run([bt, "pov", os.path.join(src, "scenes", scene), "--mesh", "256", "-o", path],
                   check=True)
    results.append(("libblend mesh, 256 cells (export %.2f s)" % (time.monotonic() - t0),
                    render(path)))
    if scene.startswith("bench-s1"):
        path = base[:-4] + "-blob.pov"
        open(path, "w").write(blob_variant(text))
        results.append(("POV-Ray blob", render(path)))
    plain = dict(results)["plain min"][0]
    for name, (cpu, found) in results:
        print("| %s | %s | %.2f | %.2f | %s | %s |" % (
            scene.replace(".json", ""), name, cpu, cpu / plain,
            "%.3f" % set_grad if name.startswith("libblend blend") else "",
            "%.3f (ratio %.2f)" % (found, set_grad / found)
            if found and name.startswith("libblend blend")
            else ("not reported" if name.startswith("libblend blend") else "")))
