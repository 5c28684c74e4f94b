#!/usr/bin/env bash
# Scene parsing against a baseline revision, in one run on this machine:
# bench/bench_parse (public API) built twice, against this tree's
# libblend.so and against revision REV's (default HEAD, built from a
# temporary `git worktree`), run in alternation ROUNDS times (default 3).
# Prints, per build, the geometric mean of the microseconds per parse of
# the shipped scenes (scenes/*.json; each scene's shortest time over the
# rounds), the shortest time of the 64 MiB limit case and its peak memory
# (GNU time), and the ratios this tree / REV (below 1: faster now).
#   bash bench/run_parse_bench.sh [REV] [ROUNDS]
set -euo pipefail
cd "$(dirname "$0")/.."
REV=${1:-HEAD}
ROUNDS=${2:-3}
# shellcheck source=scripts/revision-tree.sh
. "$PWD/scripts/revision-tree.sh"
revision_tree run_parse_bench "$REV"
build() { # SRC BUILD
  cmake -S "$1" -B "$2" -G Ninja -DCMAKE_BUILD_TYPE=Release -DLIBBLEND_TESTS=OFF \
    -DLIBBLEND_BENCH=OFF >/dev/null
  cmake --build "$2" --target libblend_shared >/dev/null
  local lib
  lib=$(cd "$2/libblend" && pwd)
  cc -O2 -std=c11 bench/bench_parse.c -I"$1/libblend/include" -L"$lib" -lblend \
    -Wl,-rpath,"$lib" -o "$2/bench_parse"
}
build "$tmp/tree" "$tmp/old"
build . build-parse-bench
for ((r = 1; r <= ROUNDS; r++)); do
  for side in old new; do
    bp=$tmp/old/bench_parse
    [ "$side" = new ] && bp=build-parse-bench/bench_parse
    "$bp" scenes/*.json >"$tmp/$side.$r"
    /usr/bin/time -f 'peak %M' "$bp" --limit-only 2>>"$tmp/$side.peak" >/dev/null
  done
done
/usr/bin/python3 - "$tmp" "$ROUNDS" "$REV" <<'PY'
import math, sys
tmp, rounds, rev = sys.argv[1], int(sys.argv[2]), sys.argv[3]
res = {}
for side in ("old", "new"):
    parse, limit = {}, []
    for r in range(1, rounds + 1):
        for line in open("%s/%s.%d" % (tmp, side, r)):
            f = line.split()
            if f[0] == "parse":
                parse[f[1]] = min(parse.get(f[1], 1e30), float(f[2]))
            elif f[0] == "limit":
                limit.append(float(f[2]))
    peaks = [int(l.split()[1]) for l in open("%s/%s.peak" % (tmp, side)) if l.startswith("peak")]
    gm = math.exp(sum(math.log(v) for v in parse.values()) / len(parse))
    res[side] = (gm, min(limit), max(peaks), len(parse))
for side, name in (("old", rev), ("new", "this tree")):
    gm, lim, pk, n = res[side]
    print("%-10s %d scenes: %.1f us per parse (geometric mean); 64 MiB limit case: %.3f s, "
          "peak %d KiB" % (name, n, gm, lim, pk))
o, n = res["old"], res["new"]
print("ratio this tree / %s: scenes %.2f, limit case time %.2f, peak memory %.2f" %
      (rev, n[0] / o[0], n[1] / o[1], n[2] / o[2]))
PY
