#!/usr/bin/env bash
# Sharp features' cost on smooth scenes and triangle counts on sharp ones
# (bench/mesh/run_features_bench.py; docs/meshing.md, Sharp features).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-release -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build-release -j "$(nproc)" --target bench_mesh >/dev/null
/usr/bin/python3 bench/mesh/run_features_bench.py build-release/bench/bench_mesh . "${1:-5}"
