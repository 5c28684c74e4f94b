#!/usr/bin/env bash
# This tree's speed against revision REV's (default HEAD), in one run on
# this machine: bench_operators, bench_eval and bench_mesh built from both
# (REV from a temporary `git worktree`), run in alternation ROUNDS times
# (default 3); each figure keeps its best round. bench_mesh meshes S2, and
# simplifies S1, S2 and the stool (0.1 cells) on one thread and on every
# CPU. Prints, per benchmark, the
# ratio of this tree's time to REV's (1.00: the same; below 1: faster now)
# for every row and their geometric mean. For a restructuring that must not
# cost speed (docs/design.md).
#   bash bench/run_revision_bench.sh [REV] [ROUNDS]
set -euo pipefail
cd "$(dirname "$0")/.."
REV=${1:-HEAD}
ROUNDS=${2:-3}
# shellcheck source=scripts/revision-tree.sh
. "$PWD/scripts/revision-tree.sh"
revision_tree run_revision_bench "$REV"
build() { # SRC BUILD
  cmake -S "$1" -B "$2" -G Ninja -DCMAKE_BUILD_TYPE=Release -DLIBBLEND_TESTS=OFF \
    -DLIBBLEND_BENCH=ON >/dev/null
  cmake --build "$2" --target bench_operators bench_eval bench_mesh >/dev/null
}
build "$tmp/tree" "$tmp/old"
build . build-revision-bench
S2=$PWD/scenes/bench-s2-64-spheres.json
S1=$PWD/scenes/bench-s1-three-spheres.json
STOOL=$PWD/scenes/hsu-bounded-fig7-stool.json
NT=$(nproc)
for ((r = 1; r <= ROUNDS; r++)); do
  for side in old new; do
    b=$tmp/old/bench
    [ "$side" = new ] && b=build-revision-bench/bench
    "$b/bench_operators" --quick >"$tmp/$side.ops.$r"
    "$b/bench_eval" "$PWD/scenes" >"$tmp/$side.eval.$r"
    for res in 256 384 512; do "$b/bench_mesh" "$S2" "$res" 1; done >"$tmp/$side.mesh.$r"
    for th in 1 "$NT"; do
      for run in "S1 128:$S1 128" "S1 256:$S1 256" "S2 128:$S2 128" "S2 256:$S2 256" \
        "stool 128 features:$STOOL 128 --features"; do
        # shellcheck disable=SC2086
        set -- ${run#*:}
        echo "${run%%:*} simplified, $th threads $("$b/bench_mesh" "$1" "$2" "$th" "${@:3}" \
          --simplify 0.1)"
      done
    done >"$tmp/$side.simp.$r"
  done
done
/usr/bin/python3 - "$tmp" "$ROUNDS" "$REV" <<'PY'
import json, math, re, sys
tmp, rounds, rev = sys.argv[1], int(sys.argv[2]), sys.argv[3]


def best(side, kind):
    """row -> best time-like figure over the rounds (seconds per unit: smaller is faster)"""
    out = {}
    for r in range(1, rounds + 1):
        for line in open("%s/%s.%s.%d" % (tmp, side, kind, r)):
            rows = []
            if kind == "ops":
                m = re.match(r"(.+?)\s+(\d+)\s+([0-9.e+]+)\s+[0-9.e+]+\s+[0-9.]+x$", line.strip())
                if m:
                    rows.append(("%s k=%s" % (m.group(1).strip(), m.group(2)), 1 / float(m.group(3))))
            elif kind == "eval":
                m = re.match(r"(\w+)\s+(\S+)\s.*naive\s+(\d+) pts/s \| compiled 1 thread\s+(\d+)", line)
                if m:
                    rows.append(("%s %s naive" % (m.group(1), m.group(2)), 1 / float(m.group(3))))
                    rows.append(("%s %s compiled" % (m.group(1), m.group(2)), 1 / float(m.group(4))))
            elif line.startswith("{"):
                d = json.loads(line)
                rows.append(("S2 mesh %d cells" % d["resolution"], d["seconds"]))
            elif kind == "simp" and "{" in line:
                i = line.index("{")
                rows.append((line[:i].strip(), json.loads(line[i:])["seconds"]))
            for k, v in rows:
                out[k] = min(out.get(k, 1e30), v)
    return out


for kind, title in (("ops", "bench_operators"), ("eval", "bench_eval (1 thread)"),
                    ("mesh", "bench_mesh"), ("simp", "bench_mesh --simplify 0.1 (meshing included)")):
    o, n = best("old", kind), best("new", kind)
    keys = [k for k in o if k in n]
    ratios = [n[k] / o[k] for k in keys]
    print("%s: this tree / %s, time ratio per row" % (title, rev))
    for k, q in zip(keys, ratios):
        print("  %-52s %.2f" % (k, q))
    print("  geometric mean over %d rows: %.3f" % (
        len(ratios), math.exp(sum(math.log(q) for q in ratios) / len(ratios))))
PY
