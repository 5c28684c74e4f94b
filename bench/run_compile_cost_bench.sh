#!/usr/bin/env bash
# Local unions' compile cost against a baseline revision, in one run on this
# machine: blendtool built from this tree and from revision REV (default
# HEAD, a temporary `git worktree`), `blendtool info` on the scenes of
# bench/compile_cost/scenes.py (spread and crowded rings, a lattice, nested
# levels). Prints per scene the compile cost (instruction runs, or
# "refused" past LB_SCENE_MAX_COMPILE_COST) and the shortest wall time of
# ROUNDS runs (default 3) for both builds, and per family the growth
# exponent of the cost between its first and last accepted sizes.
#   bash bench/run_compile_cost_bench.sh [REV] [ROUNDS]
set -euo pipefail
cd "$(dirname "$0")/.."
REV=${1:-HEAD}
ROUNDS=${2:-3}
# shellcheck source=scripts/revision-tree.sh
. "$PWD/scripts/revision-tree.sh"
revision_tree run_compile_cost_bench "$REV"
build() { # SRC BUILD
  cmake -S "$1" -B "$2" -G Ninja -DCMAKE_BUILD_TYPE=Release -DLIBBLEND_TESTS=OFF \
    -DLIBBLEND_BENCH=OFF >/dev/null
  cmake --build "$2" --target blendtool >/dev/null
}
build "$tmp/tree" "$tmp/old"
build . build-compile-bench
/usr/bin/python3 bench/compile_cost/scenes.py "$tmp/scenes" >"$tmp/names"
/usr/bin/python3 - "$tmp" "$ROUNDS" "$REV" <<'PY'
import math, re, subprocess, sys, time
tmp, rounds, rev = sys.argv[1], int(sys.argv[2]), sys.argv[3]
tools = {rev: tmp + "/old/tools/blendtool", "this tree": "build-compile-bench/tools/blendtool"}
names = open(tmp + "/names").read().split()
res = {}
for name in names:
    for side, bt in tools.items():
        best, cost = 1e30, None
        for _ in range(rounds):
            t0 = time.monotonic()
            r = subprocess.run([bt, "info", "%s/scenes/%s.json" % (tmp, name)],
                               capture_output=True, text=True)
            best = min(best, time.monotonic() - t0)
            m = re.search(r"compile cost: (\d+)", r.stdout)
            cost = float(m.group(1)) if m else None
        res[name, side] = (cost, best)
    print("%-12s" % name + "".join(
        " | %s: %s %.2f s" % (side, "%.3g" % res[name, side][0] if res[name, side][0] else "refused",
                              res[name, side][1]) for side in tools), flush=True)
for fam in ("spread", "lattice", "crowded", "nested"):
    for side in tools:
        pts = [(int(n.split("-")[1]), res[n, side][0]) for n in names
               if n.startswith(fam + "-") and res[n, side][0]]
        if len(pts) >= 2:
            (k0, c0), (k1, c1) = pts[0], pts[-1]
            print("%-8s %-10s cost ~ k^%.2f (%d -> %d)" %
                  (fam, side, math.log(c1 / c0) / math.log(k1 / k0), k0, k1))
PY
