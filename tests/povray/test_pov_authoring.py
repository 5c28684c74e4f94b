"""Writing a POV-Ray scene by hand with libblend.inc, checked by POV-Ray itself:

    /usr/bin/python3 test_pov_authoring.py SOURCE_DIR WORK_DIR

- every bad parameter stops the parse with an #error naming the macro, the
  parameter, its value and what is allowed (r <= 0, p and m out of range,
  an unknown Op, a soft union's r > 1, a conic shape too large, arrays of the
  wrong length, a bad bulge family or flag, a zero scale), and nothing of
  POV-Ray's own ("Division by zero", "Expected") shows first;
- the names LB_UNION / LB_INTERSECTION / LB_DIFFERENCE and LB_Same(F, v)
  give the same field as the numbers and arrays they stand for;
- LB_Transform(F, S, R, T) is F moved the way POV-Ray moves an object with
  `scale S rotate R translate T`: at P = vrotate(Q * S, R) + T (POV-Ray's
  own transform of Q) its value is F(Q), to 1e-12.
"""
import os
import random
import subprocess
import sys

SRC, WORK = sys.argv[1:3]
os.makedirs(WORK, exist_ok=True)
INC = os.path.join(SRC, "povray_include")
failures = []

HEAD = '#version 3.7;\n#include "libblend.inc"\n' \
       '#declare F = array[2];\n#declare F[0] = LB_Sphere(<0, 0, 0>, 1);\n' \
       '#declare F[1] = LB_Sphere(<1, 0, 0>, 0.8);\n' \
       '#declare G = array[2] {function { 0.9 - x * x - y * y - z * z }, ' \
       'function { 0.8 - (x - 1) * (x - 1) - y * y - z * z }};\n'


def povray(name, body):
    path = os.path.join(WORK, name + ".pov")
    with open(path, "w") as f:
        f.write(HEAD + body)
    r = subprocess.run(["povray", "+I" + path, "-D", "-F", "+W1", "+H1", "-V", "-GR", "-GS",
                        "+L" + INC], capture_output=True, text=True, cwd=WORK)
    return r.returncode, r.stdout + r.stderr


# ---- bad parameters: each must stop with its own message
BAD = [
    ("r-zero", "#declare B = LB_Displacement(LB_UNION, F, array[2] {0.3, 0}, LB_Same(F, 2), "
     "LB_Same(F, 1));", "LB_Displacement: R[1] = 0.000000000; allowed: r > 0"),
    ("r-negative", "#declare B = LB_Displacement(LB_UNION, F, array[2] {-0.3, 0.3}, "
     "LB_Same(F, 2), LB_Same(F, 1));", "LB_Displacement: R[0] = -0.300000000"),
    ("m-zero", "#declare B = LB_Displacement(LB_UNION, F, LB_Same(F, 0.3), LB_Same(F, 2), "
     "array[2] {0, 1});", "LB_Displacement: M[0] = 0.000000000; allowed: 0.05 to 20"),
    ("p-low", "#declare B = LB_Displacement(LB_UNION, F, LB_Same(F, 0.3), array[2] {2, 0.5}, "
     "LB_Same(F, 1));", "LB_Displacement: P[1] = 0.500000000; allowed: 1.05 to 16"),
    ("op-3", "#declare B = LB_Displacement(3, F, LB_Same(F, 0.3), LB_Same(F, 2), "
     "LB_Same(F, 1));", "LB_Displacement: Op = 3.000000; allowed: LB_UNION (0)"),
    ("length", "#declare B = LB_Displacement(LB_UNION, F, array[1] {0.3}, LB_Same(F, 2), "
     "LB_Same(F, 1));", "LB_Displacement: R has 1 values for 2 functions"),
    ("soft-union-r", "#declare B = LB_SoftHyper(LB_UNION, G, array[2] {1.5, 0.5}, "
     "LB_Same(G, 2), LB_Same(G, 1));", "LB_SoftHyper: R[0] = 1.500000000; allowed: r > 0 and "
     "at most 1"),
    ("soft-m", "#declare B = LB_SoftHyper(LB_UNION, G, LB_Same(G, 0.5), LB_Same(G, 2), "
     "array[2] {0.01, 1});", "LB_SoftHyper: M[0] = 0.010000000; allowed: 0.05 to 20"),
    ("conic-shape", "#declare B = LB_Conic(LB_UNION, F[0], F[1], array[2] {0.3, 0.3}, 0.5, "
     "array[2] {1, 1});", "LB_Conic: Shape = 0.500000000; allowed: below R[0] R[1] = "
     "0.090000000"),
    ("conic-m", "#declare B = LB_Conic(LB_UNION, F[0], F[1], array[2] {0.3, 0.3}, 0, "
     "array[2] {1, 0});", "LB_Conic: M[1] = 0.000000000"),
    ("scale-r", "#declare B = LB_Scale(LB_INTERSECTION, F, array[2] {0.3, 1.5}, "
     "LB_Same(F, 2));", "LB_Scale: R[1] = 1.500000000; allowed: r > 0 and at most 1"),
    ("ricci-n", "#declare B = LB_Ricci(G, 0.5);", "LB_Ricci: N = 0.500000000; allowed: 1 to 1000"),
    ("bulge-family", "#declare B = LB_BulgeCore(5, 0, array[2] {0.3, 0.3}, array[2] {2, 2}, 0, "
     "array[2] {1, 1}, 1, 0.001);", "LB_BulgeCore: Family = 5.000000; allowed: 0"),
    ("bulge-flags", "#declare B = LB_BulgeCore(0, 0, array[2] {0.3, 0.3}, array[2] {2, 2}, 0, "
     "array[2] {1, 1}, 0, 0.001);", "LB_BulgeCore: Flags = 0.000000"),
    ("transform-scale", "#declare B = LB_Transform(F[0], <1, 0, 1>, 0, 0);",
     "LB_Transform: S = <1.000000000, 0.000000000, 1.000000000>; allowed: no zero component"),
]
for name, body, want in BAD:
    rc, out = povray(name, body)
    flat = " ".join(out.split())  # POV-Ray wraps its messages at 80 columns
    ok = rc != 0 and " ".join(want.split()) in flat and "Division by zero" not in flat
    print("%-16s %s" % (name, "refused: " + want if ok else "NOT AS EXPECTED"))
    if not ok:
        failures.append("%s: rc %d, expected %r in:\n%s" % (name, rc, want, out[-800:]))

# ---- the names and LB_Same are what they stand for; LB_Transform is POV-Ray's transform
random.seed(7)
pts = [(random.uniform(-2, 3), random.uniform(-2, 2), random.uniform(-2, 2)) for _ in range(200)]
body = ['#declare A = LB_Displacement(LB_DIFFERENCE, F, LB_Same(F, 0.3), LB_Same(F, 2.5), '
        'LB_Same(F, 0.7))',
        '#declare N = LB_Displacement(2, F, array[2] {0.3, 0.3}, array[2] {2.5, 2.5}, '
        'array[2] {0.7, 0.7})',
        '#declare S = <1.5, 0.7, 2>; #declare R = <30, -50, 110>; #declare T = <0.3, -1, 2>;',
        '#declare E = LB_Ellipsoid(<0.2, 0.1, -0.3>, <1, 0.6, 0.4>)',
        '#declare M = LB_Transform(E, S, R, T)',
        '#declare U = LB_Transform(E, 2, <0, 0, 90>, <1, 0, 0>)',
        '#fopen FO "authoring.txt" write']
for (x, y, z) in pts:
    body.append('#declare Q = <%.17g, %.17g, %.17g>; #declare P = vrotate(Q * S, R) + T; '
                '#declare P2 = vrotate(Q * 2, <0, 0, 90>) + <1, 0, 0>;' % (x, y, z))
    body.append('#write (FO, str(A(Q.x, Q.y, Q.z) - N(Q.x, Q.y, Q.z), 0, 17), " ", '
                'str(M(P.x, P.y, P.z) - E(Q.x, Q.y, Q.z), 0, 17), " ", '
                'str(U(P2.x, P2.y, P2.z) - E(Q.x, Q.y, Q.z), 0, 17), " ", '
                'str(E(Q.x, Q.y, Q.z), 0, 17), "\\n")')
body.append('#fclose FO')
rc, out = povray("valid", "\n".join(body) + "\n")
if rc != 0:
    failures.append("valid calls failed:\n" + out[-1500:])
else:
    rows = [list(map(float, l.split())) for l in open(os.path.join(WORK, "authoring.txt"))]
    d_names = max(abs(r[0]) for r in rows)
    d_tr = max(abs(r[1]) for r in rows)
    d_tr2 = max(abs(r[2]) for r in rows)
    spread = max(r[3] for r in rows) - min(r[3] for r in rows)
    print("LB_DIFFERENCE + LB_Same vs 2 + arrays: max |difference| %.3g over %d points"
          % (d_names, len(rows)))
    print("LB_Transform vs POV-Ray's scale / rotate / translate: max |difference| %.3g and %.3g "
          "(field values span %.3g)" % (d_tr, d_tr2, spread))
    if d_names != 0.0:
        failures.append("names / LB_Same differ from numbers / arrays: %g" % d_names)
    if d_tr > 1e-12 or d_tr2 > 1e-12 or spread < 1.0:
        failures.append("LB_Transform is not POV-Ray's transform: %g, %g" % (d_tr, d_tr2))
if failures:
    print("\n".join(failures))
    sys.exit(1)
print("test_pov_authoring: %d refusals and the valid calls checked" % len(BAD))
