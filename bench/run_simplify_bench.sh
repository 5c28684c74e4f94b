#!/usr/bin/env bash
# Adaptive simplification: triangles and meshing time with and without it
# (bench/mesh/run_simplify_bench.py), then the add-on's live update with and
# without it in headless Blender (bench/blender/bench_simplify.py);
# docs/meshing.md, Adaptive simplification.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build-release -G Ninja -DCMAKE_BUILD_TYPE=Release -DLIBBLEND_BENCH=ON >/dev/null
cmake --build build-release -j "$(nproc)" >/dev/null
/usr/bin/python3 bench/mesh/run_simplify_bench.py build-release/bench/bench_mesh . "${1:-3}"
echo
PYTHONDONTWRITEBYTECODE=1 blender -b --factory-startup --python-exit-code 1 \
  --python bench/blender/bench_simplify.py -- build-release/blender_addon "$PWD" 2>&1 |
  grep -v '^Info: \|^Blender \|^Read \|^$'
