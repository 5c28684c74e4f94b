#!/usr/bin/env bash
# Sharp features' cost on smooth scenes and triangle counts on sharp ones
# (bench/mesh/run_features_bench.py; docs/meshing.md, Sharp features).
# Also the mesher as it was when issue 33 asked for features (3e57bab, the
# commit before them, from a temporary `git worktree`), run in the same
# rounds: the time with features against the mesher users had then; and
# the same meshings counted in instructions (valgrind), which this shared
# machine does not move.
#   bash bench/run_features_bench.sh [ROUNDS]
set -euo pipefail
cd "$(dirname "$0")/.."
BASE_REV=3e57bab
# shellcheck source=scripts/revision-tree.sh
. "$PWD/scripts/revision-tree.sh"
revision_tree run_features_bench "$BASE_REV"
cmake -S "$tmp/tree" -B "$tmp/base" -G Ninja -DCMAKE_BUILD_TYPE=Release -DLIBBLEND_TESTS=OFF \
  -DLIBBLEND_BENCH=ON >/dev/null
cmake --build "$tmp/base" --target bench_mesh >/dev/null
cmake -S . -B build-release -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build-release -j "$(nproc)" --target bench_mesh bench_alternate >/dev/null
/usr/bin/python3 bench/mesh/run_features_bench.py build-release/bench/bench_mesh . "${1:-5}" \
  "$tmp/base/bench/bench_mesh"
