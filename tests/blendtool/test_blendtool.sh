#!/usr/bin/env bash
# blendtool end to end: help, exit codes, messages, eval output against a
# formula computed here, atomic output, thread independence.
# usage: test_blendtool.sh BLENDTOOL SOURCE_DIR
set -uo pipefail
BT=$1
SRC=$2
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
fails=0
check() { # description, then a command that must succeed
  local what=$1
  shift
  if "$@"; then echo "ok   $what"; else echo "FAIL $what"; fails=$((fails + 1)); fi
}
run() { # run blendtool, capturing stdout, stderr and the exit code
  "$BT" "$@" >"$T/out" 2>"$T/err"
  echo $? >"$T/rc"
}
rc() { [ "$(cat "$T/rc")" = "$1" ]; }
err_has() { grep -qF -- "$1" "$T/err"; }
out_has() { grep -qF -- "$1" "$T/out"; }

run --help
check "--help exits 0 and lists the commands" rc 0
check "--help lists eval" out_has "eval"
for c in validate info eval mesh pov render section; do
  run "$c" --help
  check "$c --help exits 0" rc 0
  check "$c --help prints its usage" out_has "usage: blendtool $c"
done
run frobnicate
check "unknown command exits 2" rc 2
check "unknown command is named" err_has 'unknown command "frobnicate"'
run
check "no command exits 2" rc 2

run validate "$SRC"/scenes/*.json "$SRC"/tests/data/scenes/*.json
check "every shipped scene validates" rc 0
check "validate reports each scene" out_has "hsu2006-fig9-m0.3.json: ok"

printf '{"format": "libblend-scene", "version": 1, "convention": "zero",\n "root": {"type": "sphere", "radius": -2}}\n' >"$T/bad.json"
run validate "$SRC/scenes/default.json" "$T/bad.json"
check "a bad scene makes validate exit 2" rc 2
check "the message names file, path and the fix" \
  err_has "$T/bad.json: \$.root.radius: -2 is out of range; allowed: 1e-9 <= value <= 1e9"
run validate "$T/missing.json"
check "a missing scene exits 2" rc 2
check "a missing scene is named" err_has "$T/missing.json: cannot open the scene file"
run validate --frob "$T/bad.json"
check "an unknown option exits 2" rc 2

run info "$SRC/scenes/default.json"
check "info exits 0" rc 0
check "info shows the convention" out_has "convention: zero"
check "info shows shared defs once" out_has "ref cube (shared, described above)"
check "info counts operators" out_has "nodes: 6 (4 primitives, 2 operators), depth 4"
run info --json "$SRC/scenes/bench-s2-64-spheres.json"
check "info --json exits 0" rc 0
check "info --json is JSON with the counts" /usr/bin/python3 -c '
import json, sys
d = json.load(open(sys.argv[1]))
assert d["convention"] == "zero" and d["primitives"] == 64 and d["operators"] == 1, d
assert d["bounds"]["min"] == [-2, -2, -2] and d["instructions"] == 65, d
' "$T/out"

# eval against |X - c| / R - 1 computed here
cat >"$T/sphere.json" <<'JSON'
{"format": "libblend-scene", "version": 1, "convention": "zero",
 "root": {"type": "sphere", "center": [0.5, -1, 2], "radius": 1.5}}
JSON
/usr/bin/python3 -c '
import random
random.seed(3)
with open("'"$T"'/pts.txt", "w") as f:
    f.write("# x y z\n\n")
    for i in range(500):
        f.write("%r %r %r\n" % tuple(random.uniform(-4, 4) for _ in range(3)))
'
run eval --points "$T/pts.txt" "$T/sphere.json"
check "eval exits 0" rc 0
cp "$T/out" "$T/eval1.txt"
check "eval matches the sphere formula to 1e-15" /usr/bin/python3 -c '
import math, sys
pts = [tuple(map(float, l.split())) for l in open(sys.argv[1]) if l.strip() and l[0] != "#"]
out = [tuple(map(float, l.split())) for l in open(sys.argv[2])]
assert len(out) == len(pts) == 500, (len(out), len(pts))
for (x, y, z), (v, gx, gy, gz) in zip(pts, out):
    d = (x - 0.5, y + 1, z - 2)
    n = math.sqrt(sum(c * c for c in d))
    assert abs(v - (n / 1.5 - 1)) <= 1e-15 * (1 + abs(v)), (v, n)
    for g, c in zip((gx, gy, gz), d):
        assert abs(g - c / (n * 1.5)) <= 1e-15, (g, c)
' "$T/pts.txt" "$T/eval1.txt"
check "eval prints %.17g" /usr/bin/python3 -c '
import sys
for l in open(sys.argv[1]):
    for tok in l.split():
        assert float("%.17g" % float(tok)) == float(tok) and tok == "%.17g" % float(tok), tok
' "$T/eval1.txt"
"$BT" eval "$T/sphere.json" <"$T/pts.txt" >"$T/stdin.txt" 2>/dev/null
check "points from stdin give the same output" cmp -s "$T/stdin.txt" "$T/eval1.txt"
run eval --threads 1 -o "$T/o1.txt" --points "$T/pts.txt" "$SRC/scenes/hsu2006-fig9-m0.3.json"
run eval --threads 2 -o "$T/o2.txt" --points "$T/pts.txt" "$SRC/scenes/hsu2006-fig9-m0.3.json"
check "-o writes the output" test -s "$T/o1.txt"
check "1 and 2 threads give identical output" cmp -s "$T/o1.txt" "$T/o2.txt"

printf '0 0 0\n1 2 3\n1 2 x\n' >"$T/badpts.txt"
run eval --points "$T/badpts.txt" -o "$T/never.txt" "$T/sphere.json"
check "a bad point line exits 2" rc 2
check "the bad line is named" err_has "$T/badpts.txt:3: expected three numbers \"x y z\", found \"1 2 x\""
check "no output file on bad input" test ! -e "$T/never.txt"
check "no temporary file left behind" bash -c "! ls '$T' | grep -q tmp"
printf '0 0 1e12\n' >"$T/far.txt"
run eval --points "$T/far.txt" "$T/sphere.json"
check "a point beyond 1e9 exits 2" rc 2
check "the far point is named" err_has "$T/far.txt:1: z = 1e+12; allowed: finite, |coordinate| <= 1e+09"
run eval --threads abc "$T/sphere.json"
check "a bad thread count exits 2" rc 2
check "the thread count message says what is allowed" err_has "expected an integer (0: one per CPU), 0 to 1024"
run eval --points "$T/pts.txt" -o "$T/no/such/dir/out.txt" "$T/sphere.json"
check "an unwritable output exits 2" rc 2
check "the output path is named" err_has "$T/no/such/dir/out.txt: cannot create the output file"
run eval --points "$T/pts.txt" "$T/bad.json"
check "eval of a bad scene exits 2 with the scene message" rc 2
check "eval passes the scene message through" err_has "\$.root.radius"
run eval "$T/sphere.json" --points
check "an option without its value exits 2" rc 2

# pov and render
args=""
for i in $(seq 0 16); do args="$args${args:+, }{\"type\": \"sphere\", \"center\": [$i, 0, 0], \"radius\": 0.6}"; done
printf '{"format": "libblend-scene", "version": 1, "convention": "zero", "bounds": {"min": [-2, -2, -2], "max": [20, 2, 2]}, "root": {"type": "scale", "op": "union", "r": 0.5, "args": [%s]}}\n' "$args" > "$T/scale17.json"
run pov "$T/scale17.json" -o "$T/scale17.pov"
check "a 17-argument scale blend is refused for POV-Ray with exit 2" rc 2
check "the refusal names the node and the limit" err_has "\$.root: a scale blend of 17 arguments; allowed in POV-Ray: at most 16"
check "no .pov written for a refused scene" test ! -e "$T/scale17.pov"
args=""
for i in $(seq 0 299); do args="$args${args:+, }{\"type\": \"sphere\", \"center\": [$i, 0, 0], \"radius\": 0.6}"; done
printf '{"format": "libblend-scene", "version": 1, "convention": "zero", "bounds": {"min": [-2, -2, -2], "max": [302, 2, 2]}, "root": {"type": "displacement", "op": "union", "r": 0.1, "p": 2, "args": [%s]}}\n' "$args" > "$T/wide300.json"
run validate "$T/wide300.json"
check "a 300-argument displacement union is a valid scene" rc 0
run mesh "$T/wide300.json" -o "$T/wide300.ply" --resolution 600
check "it meshes" rc 0
run pov "$T/wide300.json" -o "$T/wide300.pov"
check "it is refused for POV-Ray with exit 2" rc 2
check "the refusal names the node, the limit and the way out" err_has "\$.root: a displacement node of 300 arguments; allowed in POV-Ray: at most 256"
check "the refusal points to meshing" err_has "mesh the scene instead (blendtool mesh)"
check "no .pov written for it" test ! -e "$T/wide300.pov"
run pov "$SRC/scenes/bench-s2-64-spheres.json" -o "$T/s2.pov"
check "a 64-argument displacement blend exports" rc 0
check "its macro call has the 64 functions" grep -q "#declare LBa0 = array\[64\]" "$T/s2.pov"
run pov "$T/bad.json" -o "$T/bad.pov"
check "pov of a bad scene exits 2 with the scene message" rc 2
check "no .pov for a bad scene" test ! -e "$T/bad.pov"
run pov "$SRC/scenes/bench-s1-three-spheres.json" -o "$T/s1.pov"
check "pov exits 0" rc 0
check "the .pov has the isosurface and max_gradient" grep -q "max_gradient" "$T/s1.pov"
run render "$SRC/scenes/bench-s1-three-spheres.json" -o "$T/s1.jpg"
check "render wants a .png" rc 2
run render "$SRC/scenes/bench-s1-three-spheres.json" -o "$T/s1.png" --width 64 --height 48 --threads 1
check "render exits 0" rc 0
check "render writes a PNG" bash -c "head -c 8 '$T/s1.png' | od -An -c | grep -q 'P   N   G'"
check "POV-Ray finds no gradient above max_gradient" bash -c "! grep -q 'may contain holes' '$T/err'"
LIBBLEND_POVRAY_INCLUDE=/nonexistent run render "$SRC/scenes/bench-s1-three-spheres.json" -o "$T/s1b.png" --width 32 --height 24
check "render with a missing include exits 1" rc 1
check "no PNG when povray fails" test ! -e "$T/s1b.png"

echo "$fails failure(s)"
[ "$fails" -eq 0 ]
