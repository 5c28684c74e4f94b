#!/usr/bin/python3
"""The batch kernels stay vectorised: compiles the evaluator's source the
way the library is built (-O3 -fno-math-errno, C11) with GCC's vectoriser
report and checks that the per-point loop of each named kernel is reported
"loop vectorized". A change that puts a branch that may trap, an aliasing
pair or a call into one of these loops makes this fail, naming the loop.

usage: test_vectorised.py CC SOURCE_DIR
"""
import re
import subprocess
import sys

cc, src = sys.argv[1], sys.argv[2]
# (file, function, the loop header inside it that must vectorise, which
# occurrence of that header in the function): spheres and ellipsoids, slabs,
# half-spaces, a blend left with one argument, the BT reciprocals
LOOP = "for (size_t j = 0; j < n; ++j)"
KERNELS = [
    ("libblend/src/evaluation/eval_points.c", "run_ellipsoid", LOOP, 1),
    ("libblend/src/evaluation/eval_points.c", "run_plane", LOOP, 1),
    ("libblend/src/evaluation/eval_points.c", "run_plane", LOOP, 2),
    ("libblend/src/evaluation/eval_points.c", "run_op", LOOP, 1),
    ("libblend/src/operators/bt_two.h", "lb__bt_recip", "for (size_t i = 0; i < k; ++i)", 1),
]

failures = []
reports = {}
for path, fn, header, nth in KERNELS:
    text = open("%s/%s" % (src, path)).read().split("\n")
    start = next((i for i, l in enumerate(text) if re.search(r"\b%s\(" % fn, l) and
                  not l.rstrip().endswith(";")), None)
    if start is None:
        failures.append("%s: function %s not found" % (path, fn))
        continue
    hits = [i for i in range(start, len(text)) if header in text[i]]
    line = hits[nth - 1] if len(hits) >= nth else None
    if line is None:
        failures.append("%s: %s has no loop '%s' (number %d)" % (path, fn, header, nth))
        continue
    unit = "libblend/src/evaluation/eval_points.c"  # bt_two.h is compiled through it
    if unit not in reports:
        r = subprocess.run([cc, "-O3", "-std=c11", "-fno-math-errno", "-I%s/libblend/include" % src,
                            "-I/usr/include/cjson", "-fopt-info-vec-all", "-c", "%s/%s" % (src, unit),
                            "-o", "/dev/null"], capture_output=True, text=True)
        if r.returncode:
            failures.append("%s does not compile: %s" % (unit, r.stderr[-500:]))
            reports[unit] = ""
        else:
            reports[unit] = r.stderr
    name = path.rsplit("/", 1)[1]
    # the loop header's line; GCC names the column of the loop's condition
    pat = re.compile(r"%s:%d:\d+: optimized: loop vectorized" % (re.escape(name), line + 1))
    if not pat.search(reports[unit]):
        why = [l for l in reports[unit].split("\n") if "%s:%d:" % (name, line + 1) in l and "missed" in l]
        failures.append("%s:%d (%s): the loop is not vectorised%s" % (
            path, line + 1, fn, (": " + why[-1].split("missed: ", 1)[-1]) if why else ""))
    else:
        print("ok   %s:%d %s: loop vectorized" % (path, line + 1, fn))

for f in failures:
    print("FAIL: " + f)
sys.exit(1 if failures else 0)
