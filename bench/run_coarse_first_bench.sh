#!/usr/bin/env bash
# Simplify's methods in the add-on's live update: none, Coarse First
# (LB_MESH_COARSE_FIRST) and the collapses, one primitive moved per update,
# in headless Blender (bench/blender/bench_coarse_first.py); docs/meshing.md,
# Coarse first.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build-release -G Ninja -DCMAKE_BUILD_TYPE=Release -DLIBBLEND_BENCH=ON >/dev/null
cmake --build build-release -j "$(nproc)" >/dev/null
PYTHONDONTWRITEBYTECODE=1 blender -b --factory-startup --python-exit-code 1 \
  --python bench/blender/bench_coarse_first.py -- build-release/blender_addon "$PWD" 2>&1 |
  grep -v '^Info: \|^Blender \|^Read \|^$'
