#!/usr/bin/env bash
# The meshing benchmark (docs/meshing.md): installs the anchors (Blender,
# scikit-image), builds, runs libblend, Blender's metaballs and numpy +
# scikit-image in one run and prints the table.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh bench
cmake -S . -B build-release -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build-release -j "$(nproc)" --target bench_mesh >/dev/null
/usr/bin/python3 bench/mesh/run_mesh_bench.py build-release/bench/bench_mesh .
